// SPDX-License-Identifier: GPL-3.0-or-later
/// @file What orientation.cpp scores a direction with: the piece mesh in double precision and the
/// support it would need (support.cpp). docs/pieces.md, "Orientation".
#pragma once

#include <array>
#include <cmath>
#include <initializer_list>
#include <vector>

#include "zomefab/core/tri_mesh.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/orientation.h"

namespace zomefab::pieces::detail {

/// The mesh in double precision, with each triangle's vector area (area × unit outward normal),
/// and the printer's steepest overhang without support (Fabrication::overhangDeg) its support is
/// estimated with.
struct MeshD {
    std::vector<Vec3d> points;
    std::vector<Triangle> triangles;
    std::vector<Vec3d> vectorArea;
    /// sin(overhang): a facet whose unit normal has more than this along "down" needs support.
    double overhangSin = std::sin(kOverhangDeg * kPi / 180.0);
    explicit MeshD(const TriMesh& m, double overhangDeg = kOverhangDeg)
        : triangles(m.triangles), overhangSin(std::sin(overhangDeg * kPi / 180.0)) {
        points.reserve(m.positions.size());
        for (const Vec3f& p : m.positions) points.push_back(toD(p));
        vectorArea.reserve(triangles.size());
        for (const Triangle& t : triangles) {
            const Vec3d& a = points[t[0]];
            vectorArea.push_back(scale(cross(sub(points[t[1]], a), sub(points[t[2]], a)), 0.5));
        }
    }
};

/// @p count unit directions spread evenly over the sphere (a Fibonacci spiral, z from 1 to −1).
std::vector<Vec3d> fibonacciSphere(int count);

/// Rows of a rotation taking @p down (unit) to (0, 0, −1): x, y in the bed's plane, z up.
std::array<Vec3d, 3> rotationDown(const Vec3d& down);

/// How points lie on a printer with a given direction down, turned about the vertical for the
/// best fit.
struct BedPlacement {
    std::array<Vec3d, 3> rows{};  ///< rotationDown(down): x, y on the bed, z up (before the turn)
    double ratio = 1e30;          ///< max(ex/Px, ey/Py, ez/Pz) at the best turn: ≤ 1 fits
    double angleRad = 0;          ///< that turn about the vertical
};

/// @p points lying with @p down (unit) down on a printer of @p printerMm (x, y the bed, z the
/// height), at the turn about the vertical that fits best: 1° steps over a half turn of their
/// convex footprint, then 0.05° about the best. The one "fits lying this way" test of the pieces
/// (orientation.cpp, support_cuts.cpp).
BedPlacement placeOnBed(const std::vector<Vec3d>& points, const Vec3d& down, const Vec3d& printerMm);

/// placeOnBed(@p points, @p down, @p printerMm).ratio ≤ 1, answered at the first turn that fits.
bool fitsOnBed(const std::vector<Vec3d>& points, const Vec3d& down, const Vec3d& printerMm);

/// The smallest coordinate of the mesh's points along @p up, mm.
double lowestAlong(const MeshD& m, const Vec3d& up);

/// estimateSupport's area, and the cheap volume: columns down to the bed (no piece below counted).
SupportEstimate supportOf(const MeshD& m, const Vec3d& down);

/// supportColumns' answer.
struct SupportColumns {
    double volumeMm3 = 0;  ///< estimateSupport's volume
    /// The footprint of the columns that stand on the bed (not on the piece), mm²: with the
    /// piece's own first layer, what holds it on the bed.
    double bedMm2 = 0;
    double footprintMm2 = 0;  ///< the cells with a column, mm² (measureFootprint)
    double edgeMm = 0;        ///< the sides between those cells and the others, mm (measureFootprint)
};

/// Columns under the overhangs down to the first up-facing surface below, or the bed; their
/// footprint and its edge only with @p measureFootprint (the orientation search does without).
SupportColumns supportColumns(const MeshD& m, const Vec3d& down, bool measureFootprint = false);

/// estimateSupport's volume: supportColumns(@p m, @p down).volumeMm3.
double supportColumnsMm3(const MeshD& m, const Vec3d& down);

/// estimateSupport on the double-precision mesh (@p down unit).
SupportEstimate estimateSupport(const MeshD& m, const Vec3d& down, const SupportModel& model = {});

/// skinVolumes on the double-precision mesh (@p up unit).
SkinVolumes skinVolumes(const MeshD& m, const Vec3d& up, const SkinModel& model, double volumeMm3);

/// skinSeconds on the double-precision mesh of volume @p volumeMm3 (@p up unit).
double skinSeconds(const MeshD& m, const Vec3d& up, const PrintTimeModel& model, double volumeMm3);

/// Hill-climbs @p objective down from @p down by tilts of @p stepsDeg (each up to @p iterations
/// times) about two perpendicular axes, keeping to directions where @p allowed; @p value is
/// objective(@p down) on entry and at the result on return.
template <class Objective, class Allowed>
Vec3d tiltTowardsLess(Vec3d down, double& value, Objective&& objective, Allowed&& allowed,
                      std::initializer_list<double> stepsDeg = {4.0, 2.0, 1.0}, int iterations = 8) {
    for (const double stepDeg : stepsDeg) {
        const double step = std::tan(stepDeg * kPi / 180.0);
        for (int iteration = 0; iteration < iterations; ++iteration) {
            const std::array<Vec3d, 3> rows = rotationDown(down);
            std::vector<std::pair<double, Vec3d>> smaller;  // the tilts that lower the objective
            for (const Vec3d& side : {rows[0], scale(rows[0], -1.0), rows[1], scale(rows[1], -1.0)}) {
                const Vec3d d = normalized(madd(down, step, side));
                const double v = objective(d);
                if (v < value - 1e-9 * std::abs(value) - 1e-9) smaller.push_back({v, d});
            }
            std::stable_sort(smaller.begin(), smaller.end(),
                             [](const auto& x, const auto& y) { return x.first < y.first; });
            bool isMoved = false;
            for (const auto& [v, d] : smaller)
                if (allowed(d)) {
                    down = d, value = v, isMoved = true;
                    break;
                }
            if (!isMoved) break;
        }
    }
    return down;
}

}  // namespace zomefab::pieces::detail
