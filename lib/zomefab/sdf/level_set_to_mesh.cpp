// SPDX-License-Identifier: GPL-3.0-or-later
// Level set -> triangle mesh with openvdb::tools::volumeToMesh (dual contouring).
#include <openvdb/tools/VolumeToMesh.h>

#include <cmath>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/sdf/level_set_grid.h"

namespace zomefab::sdf {

namespace {

double squaredDistance(const openvdb::Vec3s& a, const openvdb::Vec3s& b) { return (a - b).lengthSqr(); }

/// Drops the vertex-connected components of @p mesh that enclose less than @p minVolumeMm3 (by
/// absolute signed volume) and compacts the vertices. Returns how many components were dropped.
size_t dropTinyComponents(TriMesh& mesh, double minVolumeMm3) {
    const size_t nv = mesh.positions.size();
    std::vector<uint32_t> parent(nv);
    for (uint32_t i = 0; i < nv; ++i) parent[i] = i;
    auto find = [&](uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    for (const Triangle& t : mesh.triangles) {
        const uint32_t a = find(t[0]);
        parent[find(t[1])] = a;
        parent[find(t[2])] = a;
    }
    // Signed volume per component (divergence theorem), relative to the component's first vertex
    // to keep the sums well conditioned far from the origin.
    std::vector<double> volume6(nv, 0.0);
    for (const Triangle& t : mesh.triangles) {
        const uint32_t root = find(t[0]);
        const Vec3f& o = mesh.positions[root];
        double p[3][3];
        for (int k = 0; k < 3; ++k)
            for (int a = 0; a < 3; ++a) p[k][a] = double(mesh.positions[t[k]][a]) - o[a];
        volume6[root] += p[0][0] * (p[1][1] * p[2][2] - p[1][2] * p[2][1]) -
                         p[0][1] * (p[1][0] * p[2][2] - p[1][2] * p[2][0]) +
                         p[0][2] * (p[1][0] * p[2][1] - p[1][1] * p[2][0]);
    }
    std::vector<uint8_t> isKept(nv, 0);
    size_t dropped = 0;
    for (uint32_t v = 0; v < nv; ++v) {
        if (find(v) != v) continue;
        isKept[v] = std::abs(volume6[v]) / 6.0 >= minVolumeMm3;
    }
    std::vector<Triangle> kept;
    kept.reserve(mesh.triangles.size());
    std::vector<uint8_t> isCounted(nv, 0);
    for (const Triangle& t : mesh.triangles) {
        const uint32_t root = find(t[0]);
        if (isKept[root]) {
            kept.push_back(t);
        } else if (!isCounted[root]) {
            isCounted[root] = 1;
            ++dropped;
        }
    }
    if (dropped == 0) return 0;
    // Compact: renumber the referenced vertices in their original order (deterministic).
    std::vector<uint32_t> newIndex(nv, UINT32_MAX);
    for (const Triangle& t : kept)
        for (uint32_t v : t) newIndex[v] = 0;
    std::vector<Vec3f> positions;
    for (uint32_t v = 0; v < nv; ++v) {
        if (newIndex[v] == UINT32_MAX) continue;
        newIndex[v] = uint32_t(positions.size());
        positions.push_back(mesh.positions[v]);
    }
    for (Triangle& t : kept)
        for (uint32_t& v : t) v = newIndex[v];
    mesh.positions = std::move(positions);
    mesh.triangles = std::move(kept);
    return dropped;
}

std::string formatNumber(double value) {
    std::ostringstream s;
    s << value;
    return s.str();
}

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
        const size_t dropped = dropTinyComponents(mesh, options.minComponentVolumeMm3);
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
