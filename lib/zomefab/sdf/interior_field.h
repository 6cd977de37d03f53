// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The interior distance field and the forbidden zone F(p) for the frame optimisation
/// (paper §4.3.1). Light: no OpenVDB here. The field is a dense float array resampled once from the
/// "interior" level set, so a query is eight loads and a few multiplies (docs/benchmarks.md),
/// and, being read-only after construction, it is safe for any number of concurrent readers
/// (parallel annealing chains).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::sdf {

/// Parameters of the forbidden zone F (paper §4.3.1; defaults are the paper's).
struct ForbiddenZoneOptions {
    /// Nothing of the frame may come closer to the surface (Fabrication::frameClearanceMm).
    double dMinMm = Fabrication{}.frameClearanceMm;
    double dMaxMm = Fabrication{}.frameReachMm();  ///< = b0, the shortest blue strut
    double fThick = 90.0;                          ///< penalty closer than dMin (and outside the object)
    double fMax = 70.0;                            ///< penalty at and beyond dMax
};

/// The forbidden-zone penalty F for a node @p depthMm inside the surface (negative outside):
///   F = fThick                                      for depth < dMin (outside included),
///   F = fMax · ((depth − dMin) / (dMax − dMin))²    for dMin ≤ depth < dMax,
///   F = fMax                                        for depth ≥ dMax.
/// The quadratic starts at 0 at dMin, so nodes just beyond the shell are preferred (the paper's
/// figure caption), and grows to fMax at dMax; docs/sdf.md explains the choice. NaN gives fThick.
inline double forbiddenZone(double depthMm, const ForbiddenZoneOptions& options = {}) {
    if (!(depthMm >= options.dMinMm)) return options.fThick;
    if (depthMm >= options.dMaxMm) return options.fMax;
    const double t = (depthMm - options.dMinMm) / (options.dMaxMm - options.dMinMm);
    return options.fMax * t * t;
}

/// φ and its gradient at one point.
struct FieldSample {
    double signedDistanceMm = 0;  ///< φ: negative inside
    Vec3d gradient{0, 0, 0};      ///< ∇φ (unit length where φ is a true distance, 0 where clamped)
};

/// Signed distance to the object's surface sampled on a dense grid, trilinearly interpolated.
/// Exact at the grid points inside the object (when built from an "interior" grid) and up to the
/// grid's exterior band outside; beyond the band φ is clamped to the band width. Outside the
/// array's box, φ is the value at the nearest box point plus the distance to it.
class InteriorField {
public:
    InteriorField() = default;

    bool empty() const { return mValues.empty(); }
    double voxelMm() const { return mVoxelMm; }
    /// The box covered by the samples, in mm.
    Box3d boundsMm() const;
    /// Deepest exact distance: the source grid's interior band (+infinity for a whole interior).
    double interiorBandMm() const { return mInteriorBandMm; }
    /// How far outside φ is exact.
    double exteriorBandMm() const { return mExteriorBandMm; }
    size_t memoryBytes() const { return mValues.size() * sizeof(float); }

    /// φ and ∇φ at @p pointMm (the gradient of the trilinear interpolant).
    FieldSample sample(const Vec3d& pointMm) const;
    /// φ(p): negative inside, in mm.
    double signedDistanceMm(const Vec3d& pointMm) const { return sample(pointMm).signedDistanceMm; }
    /// −φ(p): the distance to the surface of a point inside (negative outside), what
    /// forbiddenZone() takes.
    double depthMm(const Vec3d& pointMm) const { return -signedDistanceMm(pointMm); }
    bool isInside(const Vec3d& pointMm) const { return signedDistanceMm(pointMm) < 0; }
    /// δ(p) = p − φ(p)·∇φ/|∇φ|, the nearest surface point (paper §4.3.1), with ∇φ from central
    /// differences (more accurate in direction than sample()'s gradient) and a second step from
    /// the first foot point. About 8× the cost of sample(). Near the medial axis (where several
    /// surface points are nearly as close) the answer is one of them; where the gradient vanishes
    /// (clamped values far outside) returns @p pointMm itself.
    Vec3d closestSurfacePointMm(const Vec3d& pointMm) const;

private:
    friend InteriorField makeInteriorField(const LevelSet&, RunContext&);

    Vec3d smoothGradient(const Vec3d& pointMm) const;
    float at(int i, int j, int k) const {
        return mValues[(size_t(i) * size_t(mDims[1]) + size_t(j)) * size_t(mDims[2]) + size_t(k)];
    }

    Vec3d mOriginMm{0, 0, 0};  ///< position of sample (0, 0, 0)
    double mVoxelMm = 1;
    double mInvVoxel = 1;
    int mDims[3] = {0, 0, 0};  ///< samples along x, y, z (each ≥ 2)
    double mInteriorBandMm = 0;
    double mExteriorBandMm = 0;
    std::vector<float> mValues;  ///< x-major, z fastest
};

/// Resamples @p levelSet (normally the "interior" grid of ObjectField) onto a dense array over its
/// active bounding box at the level set's own voxel, the grid points falling on the voxel centres.
/// Memory: 4 bytes × the box volume / voxel³ (29 MB for the bunny at 400 mm and 2 mm voxels).
/// @throw Error(ProcessingFailed) for an empty level set; Error(Usage) when the box would need more
///        than 2^31 samples; Error(Cancelled).
InteriorField makeInteriorField(const LevelSet& levelSet, RunContext& context);

inline FieldSample InteriorField::sample(const Vec3d& p) const {
    FieldSample s;
    if (mValues.empty()) return s;
    // Continuous sample coordinates, clamped into the box; the part outside is added as distance.
    double c[3];
    double outside2 = 0;
    double outsideDir[3] = {0, 0, 0};
    for (int a = 0; a < 3; ++a) {
        const double x = (p[a] - mOriginMm[a]) * mInvVoxel;
        const double hi = double(mDims[a] - 1);
        const double cl = std::min(std::max(x, 0.0), hi);
        const double d = (x - cl) * mVoxelMm;
        outside2 += d * d;
        outsideDir[a] = d;
        c[a] = cl;
    }
    int i0[3];
    double f[3];
    for (int a = 0; a < 3; ++a) {
        i0[a] = std::min(int(c[a]), mDims[a] - 2);
        f[a] = c[a] - i0[a];
    }
    const size_t sz = 1, sy = size_t(mDims[2]), sx = size_t(mDims[1]) * sy;
    const float* v = &mValues[size_t(i0[0]) * sx + size_t(i0[1]) * sy + size_t(i0[2])];
    const double v000 = v[0], v001 = v[sz], v010 = v[sy], v011 = v[sy + sz];
    const double v100 = v[sx], v101 = v[sx + sz], v110 = v[sx + sy], v111 = v[sx + sy + sz];
    const double fx = f[0], fy = f[1], fz = f[2];
    // Trilinear value and its exact partial derivatives (per sample spacing).
    const double a00 = v000 + (v001 - v000) * fz, a01 = v010 + (v011 - v010) * fz;
    const double a10 = v100 + (v101 - v100) * fz, a11 = v110 + (v111 - v110) * fz;
    const double b0 = a00 + (a01 - a00) * fy, b1 = a10 + (a11 - a10) * fy;
    s.signedDistanceMm = b0 + (b1 - b0) * fx;
    const double dx = b1 - b0;
    const double dy = (a01 - a00) + ((a11 - a10) - (a01 - a00)) * fx;
    const double dz0 = (v001 - v000) + ((v011 - v010) - (v001 - v000)) * fy;
    const double dz1 = (v101 - v100) + ((v111 - v110) - (v101 - v100)) * fy;
    const double dz = dz0 + (dz1 - dz0) * fx;
    s.gradient = {dx * mInvVoxel, dy * mInvVoxel, dz * mInvVoxel};
    if (outside2 > 0) {
        const double d = std::sqrt(outside2);
        s.signedDistanceMm += d;
        s.gradient = {outsideDir[0] / d, outsideDir[1] / d, outsideDir[2] / d};
    }
    return s;
}

}  // namespace zomefab::sdf
