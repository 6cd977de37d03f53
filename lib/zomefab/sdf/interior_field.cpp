// SPDX-License-Identifier: GPL-3.0-or-later
// The dense interior field: one copyToDense of the "interior" level set.
#include "zomefab/sdf/interior_field.h"

#include <openvdb/tools/Dense.h>

#include <limits>

#include "zomefab/core/error.h"
#include "zomefab/sdf/level_set_grid.h"

namespace zomefab::sdf {

Box3d InteriorField::boundsMm() const {
    Box3d box;
    if (mValues.empty()) return box;
    box.expand(mOriginMm);
    box.expand({mOriginMm[0] + (mDims[0] - 1) * mVoxelMm, mOriginMm[1] + (mDims[1] - 1) * mVoxelMm,
                mOriginMm[2] + (mDims[2] - 1) * mVoxelMm});
    return box;
}

Vec3d InteriorField::smoothGradient(const Vec3d& p) const {
    // Central differences at the eight corners of p's cell, blended trilinearly. At grid points
    // the values are exact distances, so the direction error is O((voxel / r)²) for a surface of
    // curvature radius r, against O(voxel / r) for the trilinear interpolant's own gradient.
    int i0[3];
    double f[3];
    bool isInterior = true;  // the cell's neighbours along every axis exist: no clamping needed
    for (int a = 0; a < 3; ++a) {
        const double x = std::min(std::max((p[a] - mOriginMm[a]) * mInvVoxel, 0.0), double(mDims[a] - 1));
        i0[a] = std::min(int(x), mDims[a] - 2);
        f[a] = x - i0[a];
        isInterior = isInterior && i0[a] >= 1 && i0[a] + 2 <= mDims[a] - 1;
    }
    Vec3d g{0, 0, 0};
    if (isInterior) {
        const ptrdiff_t sz = 1, sy = mDims[2], sx = ptrdiff_t(mDims[1]) * mDims[2];
        const float* base = &mValues[size_t(i0[0]) * size_t(sx) + size_t(i0[1]) * size_t(sy) + size_t(i0[2])];
        for (int corner = 0; corner < 8; ++corner) {
            const int a = corner & 1, b = (corner >> 1) & 1, c = (corner >> 2) & 1;
            const float* v = base + a * sx + b * sy + c * sz;
            const double w = (a ? f[0] : 1 - f[0]) * (b ? f[1] : 1 - f[1]) * (c ? f[2] : 1 - f[2]);
            g[0] += w * (double(v[sx]) - double(v[-sx]));
            g[1] += w * (double(v[sy]) - double(v[-sy]));
            g[2] += w * (double(v[sz]) - double(v[-sz]));
        }
        const double scale = 0.5 * mInvVoxel;
        return {g[0] * scale, g[1] * scale, g[2] * scale};
    }
    for (int corner = 0; corner < 8; ++corner) {
        const int c[3] = {i0[0] + (corner & 1), i0[1] + ((corner >> 1) & 1), i0[2] + ((corner >> 2) & 1)};
        double w = 1;
        for (int a = 0; a < 3; ++a) w *= ((corner >> a) & 1) ? f[a] : 1 - f[a];
        for (int a = 0; a < 3; ++a) {
            int lo[3] = {c[0], c[1], c[2]}, hi[3] = {c[0], c[1], c[2]};
            lo[a] = std::max(c[a] - 1, 0);
            hi[a] = std::min(c[a] + 1, mDims[a] - 1);
            const double d = double(at(hi[0], hi[1], hi[2])) - double(at(lo[0], lo[1], lo[2]));
            g[a] += w * d / (double(hi[a] - lo[a]) * mVoxelMm);
        }
    }
    return g;
}

Vec3d InteriorField::closestSurfacePointMm(const Vec3d& p) const {
    if (mValues.empty()) return p;
    // Outside the box, answer for the nearest box point: the field is not known beyond it.
    Vec3d q = p;
    for (int a = 0; a < 3; ++a)
        q[a] = std::min(std::max(p[a], mOriginMm[a]), mOriginMm[a] + (mDims[a] - 1) * mVoxelMm);
    // δ(p) = p − φ(p) ∇φ/|∇φ| (paper §4.3.1), then the same step once more from that point: near
    // the surface φ and ∇φ are most accurate, so the second step removes what is left of φ.
    for (int step = 0; step < 2; ++step) {
        const Vec3d g = smoothGradient(q);
        const double norm = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
        if (!(norm > 1e-9)) return step == 0 ? p : q;
        const double t = sample(q).signedDistanceMm / norm;
        q = {q[0] - t * g[0], q[1] - t * g[1], q[2] - t * g[2]};
    }
    return q;
}

InteriorField makeInteriorField(const LevelSet& levelSet, RunContext& context) {
    if (levelSet.empty() || levelSet.activeVoxelCount() == 0)
        throw Error(ErrorCode::ProcessingFailed, "cannot build an interior field from an empty level set");
    const openvdb::FloatGrid::ConstPtr grid = levelSetGrid(levelSet);
    openvdb::CoordBBox bbox = grid->evalActiveVoxelBoundingBox();
    // At least two samples per axis so every query has a cell to interpolate in.
    for (int a = 0; a < 3; ++a)
        if (bbox.dim()[a] < 2) bbox.max()[a] = bbox.min()[a] + 1;
    const openvdb::Coord dim = bbox.dim();
    const double count = double(dim[0]) * double(dim[1]) * double(dim[2]);
    if (count > double(std::numeric_limits<int32_t>::max())) {
        throw Error(ErrorCode::Usage, "the interior field would need " + std::to_string(size_t(count)) +
                                          " samples; use a larger field voxel size");
    }
    context.throwIfCancelled();
    context.progress("interior field", 0.0);

    InteriorField field;
    field.mVoxelMm = grid->voxelSize()[0];
    field.mInvVoxel = 1.0 / field.mVoxelMm;
    const openvdb::Vec3d origin = grid->indexToWorld(bbox.min());
    field.mOriginMm = {origin[0], origin[1], origin[2]};
    for (int a = 0; a < 3; ++a) field.mDims[a] = dim[a];
    field.mInteriorBandMm = levelSet.info().interiorBandMm;
    field.mExteriorBandMm = levelSet.info().exteriorBandMm;
    field.mValues.resize(size_t(count));
    // LayoutZYX: z varies fastest, then y, then x; the same order as InteriorField::at().
    openvdb::tools::Dense<float, openvdb::tools::LayoutZYX> dense(bbox, field.mValues.data());
    openvdb::tools::copyToDense(*grid, dense, /*serial=*/false);
    context.throwIfCancelled();
    context.progress("interior field", 1.0);
    return field;
}

}  // namespace zomefab::sdf
