// SPDX-License-Identifier: GPL-3.0-or-later
// Level set -> triangle mesh with openvdb::tools::volumeToMesh (dual contouring).
#include <openvdb/tools/VolumeToMesh.h>

#include <cmath>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/sdf/level_set_grid.h"

namespace zomefab::sdf {

TriMesh meshFloatGrid(const openvdb::FloatGrid& grid, const LevelSetToMeshOptions& options,
                      const openvdb::BoolTree::Ptr& fullResolution,
                      const openvdb::FloatGrid::ConstPtr& adaptivityWeight) {
    openvdb::tools::VolumeToMesh mesher(options.isoMm, options.adaptivity,
                                        /*relaxDisorientedTriangles=*/true);
    if (fullResolution) mesher.setAdaptivityMask(fullResolution);
    if (adaptivityWeight) mesher.setSpatialAdaptivity(adaptivityWeight);
    mesher(grid);
    TriMesh mesh;
    const openvdb::tools::PointList& points = mesher.pointList();
    mesh.positions.resize(mesher.pointListSize());
    for (size_t i = 0; i < mesh.positions.size(); ++i)
        mesh.positions[i] = {points[i][0], points[i][1], points[i][2]};
    auto d2 = [&](uint32_t a, uint32_t b) { return (points[a] - points[b]).lengthSqr(); };
    const openvdb::tools::PolygonPoolList& pools = mesher.polygonPoolList();
    for (size_t n = 0; n < mesher.polygonPoolListSize(); ++n) {
        const openvdb::tools::PolygonPool& pool = pools[n];
        for (size_t i = 0; i < pool.numQuads(); ++i) {
            const openvdb::Vec4I& q = pool.quad(i);
            if (d2(q[0], q[2]) <= d2(q[1], q[3])) {
                mesh.triangles.push_back({q[0], q[2], q[1]});
                mesh.triangles.push_back({q[0], q[3], q[2]});
            } else {
                mesh.triangles.push_back({q[0], q[3], q[1]});
                mesh.triangles.push_back({q[1], q[3], q[2]});
            }
        }
        for (size_t i = 0; i < pool.numTriangles(); ++i) {
            const openvdb::Vec3I& t = pool.triangle(i);
            mesh.triangles.push_back({t[0], t[2], t[1]});
        }
    }
    if (options.minComponentVolumeMm3 > 0) {
        const VertexComponents components = vertexComponents(mesh);
        keepComponents(mesh, components, [&](uint32_t root) {
            return std::abs(components.volume[root]) >= options.minComponentVolumeMm3;
        });
    }
    return mesh;
}

void checkMeshingOptions(const LevelSetToMeshOptions& options) {
    if (!(options.minComponentVolumeMm3 >= 0))
        throw Error(ErrorCode::Usage, "the smallest component volume must be ≥ 0 mm³");
    if (!(options.adaptivity >= 0 && options.adaptivity <= 1))
        throw Error(ErrorCode::Usage,
                    "adaptivity must be in [0, 1], got " + formatNumber(options.adaptivity));
    if (!std::isfinite(options.isoMm))
        throw Error(ErrorCode::Usage, "the iso-value must be a finite number of mm");
}

TriMesh levelSetToMesh(const LevelSet& levelSet, const LevelSetToMeshOptions& options, RunContext& context) {
    checkMeshingOptions(options);
    const openvdb::FloatGrid::ConstPtr grid = levelSetGrid(levelSet);
    const double voxel = grid->voxelSize()[0];
    // The iso-surface must lie inside the band with a voxel to spare for the mesher's stencil.
    const double exteriorLimit = levelSet.info().exteriorBandMm + (kHalfWidthVoxels - 1) * voxel;
    const double interiorLimit = levelSet.info().interiorBandMm + (kHalfWidthVoxels - 1) * voxel;
    if (!std::isfinite(options.isoMm) || options.isoMm > exteriorLimit || options.isoMm < -interiorLimit) {
        throw Error(ErrorCode::Usage,
                    "iso-value " + formatNumber(options.isoMm) + " mm is outside the level set's band [" +
                        formatNumber(-interiorLimit) + ", " + formatNumber(exteriorLimit) + "] mm");
    }
    if (grid->activeVoxelCount() == 0)
        throw Error(ErrorCode::ProcessingFailed, "the level set '" + levelSet.info().name + "' is empty");
    context.throwIfCancelled();
    context.progress("mesh", 0.0);

    TriMesh mesh = meshFloatGrid(*grid, options);
    context.throwIfCancelled();
    context.progress("mesh", 1.0);
    if (mesh.triangles.empty())
        throw Error(ErrorCode::ProcessingFailed,
                    "the level set '" + levelSet.info().name + "' has no surface");
    return mesh;
}

}  // namespace zomefab::sdf
