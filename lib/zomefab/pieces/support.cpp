// SPDX-License-Identifier: GPL-3.0-or-later
// The support a piece would need in an orientation (orientation.h, estimateSupport), and how it
// lies on the bed in one (placeOnBed).
#include "zomefab/pieces/detail/support.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace zomefab::pieces {

using namespace detail;
namespace detail {

/// Rows of a rotation taking @p down (unit) to (0, 0, −1).
std::vector<Vec3d> fibonacciSphere(int count) {
    std::vector<Vec3d> out;
    for (int i = 0; i < count; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / count;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = i * kPi * (3.0 - std::sqrt(5.0));
        out.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
    return out;
}

std::array<Vec3d, 3> rotationDown(const Vec3d& down) {
    const Vec3d z = scale(down, -1.0);
    // A deterministic perpendicular: cross with the axis least aligned with z.
    int least = 0;
    for (int k = 1; k < 3; ++k)
        if (std::abs(z[size_t(k)]) < std::abs(z[size_t(least)])) least = k;
    Vec3d helper{0, 0, 0};
    helper[size_t(least)] = 1.0;
    const Vec3d x = normalized(cross(helper, z));
    const Vec3d y = cross(z, x);
    return {x, y, z};
}

namespace {

/// Convex hull (Andrew's monotone chain) of 2D points, counter-clockwise.
std::vector<std::array<double, 2>> convexHull(std::vector<std::array<double, 2>> p) {
    std::sort(p.begin(), p.end());
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) return p;
    std::vector<std::array<double, 2>> h(2 * p.size());
    auto turn = [](const std::array<double, 2>& o, const std::array<double, 2>& a,
                   const std::array<double, 2>& b) {
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    };
    size_t k = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && turn(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
        while (k >= t && turn(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
        h[k++] = p[i - 1];
    }
    h.resize(k - 1);
    return h;
}

/// The best turn about the vertical of points already rotated so that "down" is −z; with
/// @p isFitEnough, the first turn that fits (ratio ≤ 1) instead.
BedPlacement bestTurn(const std::vector<std::array<double, 2>>& hull, double heightMm, const Vec3d& printer,
                      bool isFitEnough) {
    auto ratioAt = [&](double angle) {
        const double c = std::cos(angle), s = std::sin(angle);
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (const auto& q : hull) {
            const double x = c * q[0] - s * q[1], y = s * q[0] + c * q[1];
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        }
        return std::max({(x1 - x0) / printer[0], (y1 - y0) / printer[1], heightMm / printer[2]});
    };
    BedPlacement best;
    auto consider = [&](double a) {
        const double r = ratioAt(a);
        if (r < best.ratio - 1e-12) best.ratio = r, best.angleRad = a;
        return isFitEnough && best.ratio <= 1.0;
    };
    // 1° steps over a half turn (a half turn maps the box onto itself), then 0.05° around the best.
    for (int i = 0; i < 180; ++i)
        if (consider(i * kPi / 180.0)) return best;
    const double centre = best.angleRad;
    for (int i = -20; i <= 20; ++i)
        if (consider(centre + i * 0.05 * kPi / 180.0)) return best;
    return best;
}

/// @p points seen with @p down down: rotationDown's rows, the convex hull of their footprint on
/// the bed, and their height.
struct Lying {
    std::array<Vec3d, 3> rows{};
    std::vector<std::array<double, 2>> hull;
    double heightMm = 0;
};

Lying lying(const std::vector<Vec3d>& points, const Vec3d& down) {
    Lying out;
    out.rows = rotationDown(down);
    std::vector<std::array<double, 2>> projected;
    projected.reserve(points.size());
    double z0 = 1e300, z1 = -1e300;
    for (const Vec3d& p : points) {
        projected.push_back({dot(out.rows[0], p), dot(out.rows[1], p)});
        const double z = dot(out.rows[2], p);
        z0 = std::min(z0, z), z1 = std::max(z1, z);
    }
    out.hull = convexHull(std::move(projected));
    out.heightMm = z1 - z0;
    return out;
}

}  // namespace

BedPlacement placeOnBed(const std::vector<Vec3d>& points, const Vec3d& down, const Vec3d& printerMm) {
    const Lying l = lying(points, down);
    BedPlacement placement = bestTurn(l.hull, l.heightMm, printerMm, false);
    placement.rows = l.rows;
    return placement;
}

bool fitsOnBed(const std::vector<Vec3d>& points, const Vec3d& down, const Vec3d& printerMm) {
    const Lying l = lying(points, down);
    // The ratio is at least the height's share at every turn.
    if (l.heightMm > printerMm[2]) return false;
    return bestTurn(l.hull, l.heightMm, printerMm, true).ratio <= 1.0;
}

/// The smallest coordinate of the mesh's points along @p up, mm.
double lowestAlong(const MeshD& m, const Vec3d& up) {
    double lowest = 1e300;
    for (const Vec3d& p : m.points) lowest = std::min(lowest, dot(up, p));
    return lowest;
}

namespace {

/// A facet of vector area @p vectorArea faces down (along unit @p down) more steeply than the
/// printer's overhang (@p overhangSin, MeshD) from the vertical: it needs support.
bool isOverhang(const Vec3d& vectorArea, const Vec3d& down, double overhangSin) {
    const double area = norm(vectorArea);
    return area > 0 && dot(vectorArea, down) > overhangSin * area;
}

}  // namespace

SupportEstimate supportOf(const MeshD& m, const Vec3d& down) {
    const Vec3d up = scale(down, -1.0);
    const double lowest = lowestAlong(m, up);
    SupportEstimate out;
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        if (!isOverhang(m.vectorArea[i], down, m.overhangSin)) continue;
        const Triangle& t = m.triangles[i];
        const double h =
            (dot(up, m.points[t[0]]) + dot(up, m.points[t[1]]) + dot(up, m.points[t[2]])) / 3.0 - lowest;
        if (h <= kBaseHeightMm) continue;  // on the bed: the first layer, not an overhang
        out.areaMm2 += norm(m.vectorArea[i]);
        out.volumeMm3 += dot(m.vectorArea[i], down) * h;  // the area projected on the bed × height
    }
    return out;
}

/// Cell of the height map supportColumnsMm3 builds, mm.
constexpr double kColumnCellMm = 2.0;

namespace {

/// Sorts @p cells and drops repeats; returns how many remain.
size_t sortUnique(std::vector<uint64_t>& cells) {
    std::sort(cells.begin(), cells.end());
    cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
    return cells.size();
}

/// Sides of the sorted, unique cells (i << 32 | j) that border a cell not among them.
size_t cellSides(const std::vector<uint64_t>& cells) {
    const auto has = [&](uint64_t i, uint64_t j) {
        return std::binary_search(cells.begin(), cells.end(), i << 32 | j);
    };
    size_t sides = 0;
    for (const uint64_t c : cells) {
        const uint64_t i = c >> 32, j = c & 0xffffffffu;
        sides += size_t(!has(i + 1, j)) + size_t(i == 0 || !has(i - 1, j)) + size_t(!has(i, j + 1)) +
                 size_t(j == 0 || !has(i, j - 1));
    }
    return sides;
}

}  // namespace

/// The volume of support columns under the overhangs (as supportOf) when a column stops at the
/// first up-facing surface of the piece below it, or the bed: what a slicer that builds supports
/// on the model too would fill, mm³. For cup-shaped pieces the columns inside the cup end on the
/// cup's own floor, so this ranks orientations as PrusaSlicer does where supportOf does not. The
/// mesh is sampled on a kColumnCellMm grid in the bed's plane: each up-facing facet leaves its
/// height at the cell centres it covers, each overhanging facet adds, per cell centre it covers,
/// the gap to the highest of those below it.
SupportColumns supportColumns(const MeshD& m, const Vec3d& down, bool measureFootprint) {
    const std::array<Vec3d, 3> rows = rotationDown(down);  // rows[2] = up
    std::vector<Vec3d> q(m.points.size());
    double x0 = 1e300, y0 = 1e300, z0 = 1e300;
    for (size_t i = 0; i < q.size(); ++i) {
        q[i] = {dot(rows[0], m.points[i]), dot(rows[1], m.points[i]), dot(rows[2], m.points[i])};
        x0 = std::min(x0, q[i][0]), y0 = std::min(y0, q[i][1]), z0 = std::min(z0, q[i][2]);
    }
    // Visits the cell centres inside the triangle's projection with the triangle's height there.
    auto forCells = [&](const Triangle& t, auto&& visit) {
        const Vec3d &a = q[t[0]], &b = q[t[1]], &c = q[t[2]];
        const double det = (b[0] - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (b[1] - a[1]);
        if (std::abs(det) < 1e-12) return;
        const int i0 = int(std::ceil((std::min({a[0], b[0], c[0]}) - x0) / kColumnCellMm - 0.5));
        const int i1 = int(std::floor((std::max({a[0], b[0], c[0]}) - x0) / kColumnCellMm - 0.5));
        const int j0 = int(std::ceil((std::min({a[1], b[1], c[1]}) - y0) / kColumnCellMm - 0.5));
        const int j1 = int(std::floor((std::max({a[1], b[1], c[1]}) - y0) / kColumnCellMm - 0.5));
        for (int i = std::max(i0, 0); i <= i1; ++i)
            for (int j = std::max(j0, 0); j <= j1; ++j) {
                const double x = x0 + (i + 0.5) * kColumnCellMm, y = y0 + (j + 0.5) * kColumnCellMm;
                const double u = ((x - a[0]) * (c[1] - a[1]) - (c[0] - a[0]) * (y - a[1])) / det;
                const double v = ((b[0] - a[0]) * (y - a[1]) - (x - a[0]) * (b[1] - a[1])) / det;
                if (u < 0 || v < 0 || u + v > 1) continue;
                visit(uint64_t(i) << 32 | uint64_t(j), a[2] + u * (b[2] - a[2]) + v * (c[2] - a[2]));
            }
    };
    std::vector<std::pair<uint64_t, double>> floors;  // (cell, height) of up-facing surfaces
    for (size_t k = 0; k < m.triangles.size(); ++k)
        if (dot(m.vectorArea[k], rows[2]) > 0)
            forCells(m.triangles[k], [&](uint64_t cell, double z) { floors.push_back({cell, z}); });
    std::sort(floors.begin(), floors.end());
    SupportColumns out;
    std::vector<uint64_t> onBed;  // cells with a column standing on the bed
    std::vector<uint64_t> used;   // cells with any column
    for (size_t k = 0; k < m.triangles.size(); ++k) {
        if (!isOverhang(m.vectorArea[k], down, m.overhangSin)) continue;
        forCells(m.triangles[k], [&](uint64_t cell, double z) {
            if (z - z0 <= kBaseHeightMm) return;
            // The highest floor in this cell below the overhang (half a cell of slack for the
            // facets of the same wall).
            auto it =
                std::lower_bound(floors.begin(), floors.end(), std::make_pair(cell, z - 0.5 * kColumnCellMm));
            double floor = z0;
            if (it != floors.begin() && std::prev(it)->first == cell) floor = std::prev(it)->second;
            else
                onBed.push_back(cell);
            if (measureFootprint) used.push_back(cell);
            out.volumeMm3 += (z - floor) * kColumnCellMm * kColumnCellMm;
        });
    }
    out.bedMm2 = double(sortUnique(onBed)) * kColumnCellMm * kColumnCellMm;
    if (measureFootprint) {
        out.footprintMm2 = double(sortUnique(used)) * kColumnCellMm * kColumnCellMm;
        out.edgeMm = double(cellSides(used)) * kColumnCellMm;
    }
    return out;
}

double supportColumnsMm3(const MeshD& m, const Vec3d& down) { return supportColumns(m, down).volumeMm3; }

SupportEstimate estimateSupport(const MeshD& m, const Vec3d& down, const SupportModel& model) {
    const SupportColumns columns = supportColumns(m, down, true);
    return {supportOf(m, down).areaMm2, columns.volumeMm3, columns.footprintMm2, columns.edgeMm,
            pieces::supportFilamentMm3(columns.footprintMm2, columns.edgeMm, columns.volumeMm3, model)};
}

SkinVolumes skinVolumes(const MeshD& m, const Vec3d& up, const SkinModel& model, double volumeMm3) {
    SkinVolumes out;
    for (const Vec3d& vectorArea : m.vectorArea) {
        const double area = norm(vectorArea);
        if (area == 0.0) continue;
        const double cosZ = dot(vectorArea, up) / area;
        const double sinZ = std::sqrt(std::max(0.0, 1.0 - cosZ * cosZ));
        // Normal-direction depth of the perimeters (horizontal t_w) and of the solid layers
        // (vertical t_s); where both apply the deeper wins, the solid layers only add the rest.
        const double wall = model.perimeterMm * sinZ;
        double skin = (cosZ > 0.0 ? model.topMm : model.bottomMm) * std::abs(cosZ);
        if (cosZ != 0.0 && sinZ <= model.maxSlopeTan * std::abs(cosZ)) skin += model.marginMm * sinZ;
        out.perimeterMm3 += area * wall;
        out.solidMm3 += area * std::max(0.0, skin - wall);
    }
    const double shell = out.perimeterMm3 + out.solidMm3;
    if (shell > volumeMm3 && shell > 0.0) {
        // Walls thinner than two skins: everything is perimeter or solid layer.
        out.perimeterMm3 *= volumeMm3 / shell;
        out.solidMm3 *= volumeMm3 / shell;
    }
    return out;
}

double skinSeconds(const MeshD& m, const Vec3d& up, const PrintTimeModel& model, double volumeMm3) {
    const SkinVolumes skin = skinVolumes(m, up, model.skin, volumeMm3);
    const double interior = std::max(0.0, volumeMm3 - skin.perimeterMm3 - skin.solidMm3);
    return skin.perimeterMm3 * model.perimeterSPerMm3 + skin.solidMm3 * model.solidSPerMm3 +
           interior * model.interiorSPerMm3;
}

}  // namespace detail

double supportFilamentMm3(double footprintMm2, double edgeMm, double volumeMm3, const SupportModel& model) {
    if (footprintMm2 <= 0.0) return 0.0;
    const double meanHeightMm = volumeMm3 / footprintMm2;
    return model.interfaceMm * footprintMm2 + model.bodyShare * volumeMm3 +
           model.sheathMm * edgeMm * meanHeightMm;
}

SupportEstimate estimateSupport(const TriMesh& meshMm, const Vec3d& down, double overhangDeg,
                                const SupportModel& model) {
    return detail::estimateSupport(MeshD(meshMm, overhangDeg), normalized(down), model);
}

SkinVolumes skinVolumes(const TriMesh& meshMm, const Vec3d& up, const SkinModel& model, double volumeMm3) {
    return detail::skinVolumes(MeshD(meshMm), normalized(up), model, volumeMm3);
}

double skinSeconds(const TriMesh& meshMm, const Vec3d& up, const PrintTimeModel& model) {
    return detail::skinSeconds(MeshD(meshMm), normalized(up), model, std::max(0.0, signedVolume(meshMm)));
}

}  // namespace zomefab::pieces
