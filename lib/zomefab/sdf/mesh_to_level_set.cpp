// SPDX-License-Identifier: GPL-3.0-or-later
// Mesh -> narrow-band level set with openvdb::tools::meshToVolume, reading the TriMesh in place.
#include <openvdb/tools/MeshToVolume.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/sdf/level_set_grid.h"

namespace zomefab::sdf {

namespace {

/// OpenVDB's MeshDataAdapter over a TriMesh: no copy of the positions or triangles. OpenVDB asks
/// for index-space points; the grid transform is a pure scale (voxel centre i at i·voxelMm).
class TriMeshAdapter {
public:
    TriMeshAdapter(const TriMesh& mesh, double voxelMm) : mMesh(mesh), mInvVoxel(1.0 / voxelMm) {}
    size_t polygonCount() const { return mMesh.triangles.size(); }
    size_t pointCount() const { return mMesh.positions.size(); }
    size_t vertexCount(size_t) const { return 3; }
    void getIndexSpacePoint(size_t polygon, size_t corner, openvdb::Vec3d& pos) const {
        const Vec3f& p = mMesh.positions[mMesh.triangles[polygon][corner]];
        pos = openvdb::Vec3d(p[0], p[1], p[2]) * mInvVoxel;
    }

private:
    const TriMesh& mMesh;
    double mInvVoxel;
};

void requirePositive(double value, const char* what) {
    if (!(std::isfinite(value) && value > 0))
        throw Error(ErrorCode::Usage,
                    std::string(what) + " must be a positive number of mm, got " + formatNumber(value));
}

/// The input checks meshToVolume itself does not do (it would read out of bounds or loop on NaN).
/// Returns the mesh's signed volume (divergence theorem), mm³.
double checkMesh(const TriMesh& mesh, Box3d& bounds, double& areaMm2) {
    if (mesh.triangles.empty()) throw Error(ErrorCode::InvalidInput, "the mesh has no triangles");
    for (const Vec3f& p : mesh.positions) {
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            throw Error(ErrorCode::InvalidInput, "the mesh has a non-finite vertex coordinate");
    }
    const size_t n = mesh.positions.size();
    double area2 = 0;
    for (const Triangle& t : mesh.triangles) {
        if (t[0] >= n || t[1] >= n || t[2] >= n)
            throw Error(ErrorCode::InvalidInput, "a triangle refers to a vertex that does not exist");
        const Vec3f& a = mesh.positions[t[0]];
        const Vec3f& b = mesh.positions[t[1]];
        const Vec3f& c = mesh.positions[t[2]];
        const double ab[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
        const double ac[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
        const double cr[3] = {ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2],
                              ab[0] * ac[1] - ab[1] * ac[0]};
        area2 += std::sqrt(cr[0] * cr[0] + cr[1] * cr[1] + cr[2] * cr[2]);
    }
    bounds = boundingBox(mesh);
    areaMm2 = area2 / 2;
    return signedVolume(mesh);
}

/// What a finished conversion looks like from outside: how much is inside, and whether the inside
/// reaches the border of the computed region (which only a leaking sign fill can do).
struct InsideStats {
    double insideVoxels = 0;
    bool touchesBorder = false;
};

InsideStats insideStats(const openvdb::FloatGrid& grid) {
    InsideStats stats;
    const openvdb::CoordBBox bbox = grid.evalActiveVoxelBoundingBox();
    const openvdb::FloatTree& tree = grid.tree();
    for (auto it = tree.cbeginValueAll(); it; ++it) {
        if (!(*it < 0)) continue;
        stats.insideVoxels += double(it.getVoxelCount());
        if (it.isVoxelValue()) {
            const openvdb::Coord c = it.getCoord();
            for (int a = 0; a < 3; ++a)
                if (c[a] <= bbox.min()[a] || c[a] >= bbox.max()[a]) stats.touchesBorder = true;
        } else {
            // A tile: inside tiles are enclosed by leaf voxels, so one at the border means a leak.
            openvdb::CoordBBox tileBox;
            it.getBoundingBox(tileBox);
            for (int a = 0; a < 3; ++a)
                if (tileBox.min()[a] <= bbox.min()[a] || tileBox.max()[a] >= bbox.max()[a])
                    stats.touchesBorder = true;
        }
    }
    return stats;
}

}  // namespace

LevelSet meshToLevelSet(const TriMesh& mesh, const MeshToLevelSetOptions& options, RunContext& context) {
    requirePositive(options.voxelMm, "the voxel size");
    if (!(options.interiorBandMm >= 0) || !(options.exteriorBandMm >= 0) ||
        !std::isfinite(options.exteriorBandMm))
        throw Error(ErrorCode::Usage, "band widths must be ≥ 0 mm (the interior one may be infinite)");
    Box3d bounds;
    double areaMm2 = 0;
    const double meshVolume = std::abs(checkMesh(mesh, bounds, areaMm2));
    const double voxel = options.voxelMm;
    const double halfWidthMm = kHalfWidthVoxels * voxel;
    const bool isWholeInterior = std::isinf(options.interiorBandMm);

    // Refuse requests that cannot fit rather than exhaust memory: index coordinates are 32-bit,
    // and a band holds about area / voxel² × band voxels (the whole inside: volume / voxel³).
    const Vec3d size = bounds.size();
    const double maxExtent =
        std::max({size[0], size[1], size[2]}) + 2 * (options.exteriorBandMm + halfWidthMm);
    const double bandVoxels =
        (options.exteriorBandMm + (isWholeInterior ? 0.0 : options.interiorBandMm)) / voxel +
        2.0 * kHalfWidthVoxels;
    const double estimatedVoxels = areaMm2 / (voxel * voxel) * bandVoxels +
                                   (isWholeInterior ? meshVolume / (voxel * voxel * voxel) : 0.0);
    constexpr double kMaxVoxels = 1.0e9;  // ~4 GB of float values plus the tree
    if (maxExtent / voxel > double(1 << 30) || estimatedVoxels > kMaxVoxels) {
        throw Error(ErrorCode::Usage, "a " + formatNumber(voxel) + " mm voxel is too small for a " +
                                          formatNumber(maxExtent) + " mm mesh (about " +
                                          formatNumber(std::round(estimatedVoxels / 1e6)) +
                                          " million voxels); use a larger voxel size");
    }

    const openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(voxel);
    const float exteriorVoxels = float(options.exteriorBandMm / voxel + kHalfWidthVoxels);
    const float interiorVoxels = isWholeInterior ? std::numeric_limits<float>::max()
                                                 : float(options.interiorBandMm / voxel + kHalfWidthVoxels);
    VdbInterrupter interrupter(context, "level set '" + options.name + "'");
    const TriMeshAdapter adapter(mesh, voxel);
    openvdb::FloatGrid::Ptr grid = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
        interrupter, adapter, *transform, exteriorVoxels, interiorVoxels);
    context.throwIfCancelled();

    // The sign comes from a flood fill from outside (OpenVDB), so an open or self-intersecting
    // surface shows up as an inside that is missing, much smaller than the mesh's volume, or that
    // reaches the border of the band (docs/sdf.md, "Failure detection").
    const InsideStats stats = insideStats(*grid);
    const double insideVolume = stats.insideVoxels * voxel * voxel * voxel;
    if (stats.insideVoxels == 0) {
        throw Error(
            ErrorCode::ProcessingFailed,
            "the level set has no inside: the mesh is open, inside out with holes, or thinner than a " +
                formatNumber(voxel) + " mm voxel everywhere");
    }
    if (stats.touchesBorder) {
        throw Error(ErrorCode::ProcessingFailed,
                    "the level set's inside leaks to its bounding box: the mesh is not closed or it "
                    "self-intersects");
    }
    // A closed mesh's voxelised volume matches its divergence volume within a few voxel layers;
    // a leaking fill loses most of it. Half is far outside any discretisation error.
    if (insideVolume < 0.5 * meshVolume) {
        throw Error(ErrorCode::ProcessingFailed,
                    "the level set's inside (" + formatNumber(std::round(insideVolume)) +
                        " mm³) is far smaller than the mesh's volume (" +
                        formatNumber(std::round(meshVolume)) +
                        " mm³): the mesh is not closed or it self-intersects, so the inside leaked out");
    }

    LevelSetInfo info;
    info.name = options.name;
    info.voxelMm = voxel;
    info.exteriorBandMm = options.exteriorBandMm;
    info.interiorBandMm = options.interiorBandMm;
    return wrapLevelSetGrid(std::move(grid), std::move(info));
}

void checkObjectFieldOptions(const ObjectFieldOptions& options) {
    requirePositive(options.voxelMm, "the voxel size");
    requirePositive(options.fieldVoxelMm, "the interior field's voxel size");
    if (!(options.fieldExteriorMm >= 0) || !std::isfinite(options.fieldExteriorMm))
        throw Error(ErrorCode::Usage, "the interior field's exterior band must be ≥ 0 mm");
    if (!(options.maxMemoryGb >= 0) || !std::isfinite(options.maxMemoryGb) || options.maxMemoryGb > 1e6)
        throw Error(ErrorCode::Usage,
                    "--max-memory-gb must be in [0, 1e6] (0 = 75 % of this machine's memory)");
}

MemoryEstimate estimateRunBytes(const TriMesh& meshMm, const Fabrication& fabrication,
                                const ObjectFieldOptions& options) {
    const double areaMm2 = surfaceArea(meshMm);
    const double volumeMm3 = std::fabs(signedVolume(meshMm));
    MemoryEstimate e;
    const double v = options.voxelMm, f = options.fieldVoxelMm;
    e.objectVoxels = areaMm2 * (fabrication.wallMm + 3.0 * v) / (v * v * v);
    e.interiorVoxels = (volumeMm3 + areaMm2 * options.fieldExteriorMm) / (f * f * f);
    constexpr double kBytesPerVoxel = 40.0;
    e.bytes = kBytesPerVoxel * (e.objectVoxels + e.interiorVoxels);
    return e;
}

double memoryBudgetBytes(double maxMemoryGb) {
    if (maxMemoryGb > 0) return maxMemoryGb * 1e9;
    const double pages = double(::sysconf(_SC_PHYS_PAGES)), pageBytes = double(::sysconf(_SC_PAGESIZE));
    return pages > 0 && pageBytes > 0 ? 0.75 * pages * pageBytes : 8e9;
}

namespace {

/// Refuses (exit 3) a size whose grids would not fit the budget, with the estimate and what lowers it.
void requireMemory(const TriMesh& meshMm, const Fabrication& fabrication, const ObjectFieldOptions& options) {
    const MemoryEstimate e = estimateRunBytes(meshMm, fabrication, options);
    const double budget = memoryBudgetBytes(options.maxMemoryGb);
    if (e.bytes <= budget) return;
    // The object band shrinks with the voxel squared, the interior grid with its cube: growing both
    // voxels by the cube root of the excess is enough.
    const double grow = std::cbrt(e.bytes / budget) * 1.05;
    throw Error(
        ErrorCode::ProcessingFailed,
        formatNumbers("this size needs about %.1f GB (%.0f M voxels in the object band at --voxel-mm %g, "
                      "%.0f M in the interior grid at --field-voxel-mm %g), more than the %.1f GB budget",
                      e.bytes / 1e9, e.objectVoxels / 1e6, options.voxelMm, e.interiorVoxels / 1e6,
                      options.fieldVoxelMm, budget / 1e9) +
            formatNumbers(": use --voxel-mm %.2g --field-voxel-mm %.2g, a smaller --height-mm, or a larger "
                          "--max-memory-gb",
                          std::ceil(options.voxelMm * grow * 100) / 100,
                          std::ceil(options.fieldVoxelMm * grow * 100) / 100));
}

}  // namespace

ObjectField makeObjectField(const TriMesh& meshMm, const Fabrication& fabrication,
                            const ObjectFieldOptions& options, RunContext& context) {
    checkFabrication(fabrication);
    checkObjectFieldOptions(options);
    requireMemory(meshMm, fabrication, options);  // before any grid is allocated
    ObjectField field;
    MeshToLevelSetOptions object;
    object.voxelMm = options.voxelMm;
    object.interiorBandMm = fabrication.wallMm;  // what makeShell reads
    object.name = "object";
    field.object = meshToLevelSet(meshMm, object, context);
    MeshToLevelSetOptions interior;
    interior.voxelMm = options.fieldVoxelMm;
    interior.interiorBandMm = std::numeric_limits<double>::infinity();
    interior.exteriorBandMm = options.fieldExteriorMm;
    interior.name = "interior";
    field.interior = meshToLevelSet(meshMm, interior, context);
    return field;
}

}  // namespace zomefab::sdf
