// SPDX-License-Identifier: GPL-3.0-or-later
// Level set -> triangle mesh with openvdb::tools::volumeToMesh (dual contouring).
#include <openvdb/tools/VolumeToMesh.h>

#include <cmath>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/sdf/level_set_grid.h"

namespace zomefab::sdf {

namespace {

double squaredDistance(const openvdb::Vec3s& a, const openvdb::Vec3s& b) { return (a - b).lengthSqr(); }


}  // namespace

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

    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*grid, points, triangles, quads, options.isoMm, options.adaptivity,
                                 /*relaxDisorientedTriangles=*/true);
    context.throwIfCancelled();

    TriMesh mesh;
    mesh.positions.resize(points.size());
    for (size_t i = 0; i < points.size(); ++i) mesh.positions[i] = {points[i][0], points[i][1], points[i][2]};
    mesh.triangles.reserve(triangles.size() + 2 * quads.size());
    // OpenVDB winds its polygons clockwise seen from φ > iso (Houdini's convention); zomefab's
    // meshes are counter-clockwise from outside, so every polygon is reversed.
    for (const openvdb::Vec3I& t : triangles) mesh.triangles.push_back({t[0], t[2], t[1]});
    for (const openvdb::Vec4I& q : quads) {
        // Split along the shorter diagonal: better-shaped triangles, and a deterministic choice.
        if (squaredDistance(points[q[0]], points[q[2]]) <= squaredDistance(points[q[1]], points[q[3]])) {
            mesh.triangles.push_back({q[0], q[2], q[1]});
            mesh.triangles.push_back({q[0], q[3], q[2]});
        } else {
            mesh.triangles.push_back({q[0], q[3], q[1]});
            mesh.triangles.push_back({q[1], q[3], q[2]});
        }
    }
    if (options.minComponentVolumeMm3 > 0) {
        const VertexComponents components = vertexComponents(mesh);
        const size_t dropped = keepComponents(mesh, components, [&](uint32_t root) {
            return std::abs(components.volume[root]) >= options.minComponentVolumeMm3;
        });
        if (dropped > 0)
            context.debug("dropped " + std::to_string(dropped) + " surface fragments enclosing less than " +
                          formatNumber(options.minComponentVolumeMm3) + " mm³");
    }
    context.progress("mesh", 1.0);
    if (mesh.triangles.empty())
        throw Error(ErrorCode::ProcessingFailed,
                    "the level set '" + levelSet.info().name + "' has no surface");
    return mesh;
}

}  // namespace zomefab::sdf
