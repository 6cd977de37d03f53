// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Narrow-band level sets of the object and the hollow shell (paper §6), behind a light handle.
/// This header does not include OpenVDB; stages that need the openvdb::FloatGrid itself include
/// zomefab/sdf/level_set_grid.h. Conventions (docs/sdf.md): world units are millimetres, φ < 0
/// inside, |∇φ| = 1 within the band, values beyond the band are clamped to ± the band width.
#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::sdf {

/// Half width of every narrow band, in voxels: OpenVDB's LEVEL_SET_HALF_WIDTH, what csg*,
/// volumeToMesh and the samplers expect on each side of the zero crossing.
constexpr int kHalfWidthVoxels = 3;

/// What a level set is and where it came from; written as grid metadata into .vdb files
/// (docs/sdf.md, "Metadata") so later tools can carry it into their outputs.
struct LevelSetInfo {
    std::string name;    ///< grid name: "object", "interior" or "shell"
    double voxelMm = 0;  ///< voxel edge length
    /// φ is the exact distance up to this far outside the surface (then clamped)
    double exteriorBandMm = 0;
    /// ... and up to this deep inside; +infinity when every inside voxel holds its exact distance
    double interiorBandMm = 0;
    double shellMm = 0;       ///< wall thickness of a "shell" grid, 0 for the others
    std::string sourceFile;   ///< the mesh the object was built from ("-" = stdin), may be empty
    std::string generator;    ///< "zomefab 0.1.0" of the tool that wrote the grid
    Transform4d transformMm;  ///< input-mesh coordinates -> the grid's millimetres
};

namespace detail {
struct LevelSetAccess;
}

/// An immutable signed distance grid plus its LevelSetInfo. Copies share the grid (cheap); no
/// zomefab function modifies a grid once it is wrapped in a LevelSet. The info is a plain value.
class LevelSet {
public:
    /// An empty level set (no grid): what a default-constructed result holds.
    LevelSet();

    bool empty() const { return !mImpl; }
    const LevelSetInfo& info() const { return mInfo; }
    LevelSetInfo& info() { return mInfo; }

    size_t activeVoxelCount() const;
    /// Memory held by the grid's tree, in bytes.
    size_t memoryBytes() const;
    /// Bounding box of the active voxels' centres, in mm; empty for an empty grid.
    Box3d activeBoundsMm() const;
    /// φ at @p pointMm by trilinear interpolation. Convenient, not fast: use InteriorField in
    /// hot loops.
    double valueMm(const Vec3d& pointMm) const;
    /// Volume of the inside {φ < 0} in mm³, counted by voxels (first order, for checks only).
    double insideVolumeMm3() const;

private:
    friend struct detail::LevelSetAccess;
    struct Impl;
    std::shared_ptr<const Impl> mImpl;
    LevelSetInfo mInfo;
};

/// Mesh -> level set (openvdb::tools::meshToVolume over the TriMesh, no copy).
struct MeshToLevelSetOptions {
    /// Voxel edge length. 1 mm meets the round-trip goal (Hausdorff 95th percentile ≤ 0.5 mm on the
    /// bunny at 400 mm) within the speed goal; see docs/sdf.md.
    double voxelMm = 1.0;
    /// φ is exact at least this deep inside (the kHalfWidthVoxels band comes on top);
    /// +infinity = the whole interior.
    double interiorBandMm = 0;
    /// φ is exact at least this far outside (the kHalfWidthVoxels band comes on top).
    double exteriorBandMm = 0;
    std::string name = "object";  ///< the grid name
};

/// Signed distance to @p meshMm (millimetres, closed, outward triangles).
/// @throw Error(Usage) for a voxel or band that is not positive and finite, or a voxel too small
///        for the mesh (more than 2^30 voxels across or about 10^9 in the band); Error(InvalidInput) for an
///        empty mesh, vertex indices out of range or non-finite coordinates; Error(ProcessingFailed) when the
///        result has no inside or its inside leaks to the bounding box (an open or badly self-intersecting
///        mesh); Error(Cancelled) when @p context is cancelled.
LevelSet meshToLevelSet(const TriMesh& meshMm, const MeshToLevelSetOptions& options, RunContext& context);

/// What zf-sdf builds from the scaled input mesh.
struct ObjectFieldOptions {
    double voxelMm = 1.0;  ///< voxel of the "object" grid (see MeshToLevelSetOptions)
    /// Voxel of the "interior" grid for the frame optimisation (exact distances over the whole
    /// inside); on the bunny at 400 mm 2 mm gives a 95th-percentile depth error of 0.08 mm at a
    /// quarter of the 1 mm build time and 1/8 of its memory (docs/sdf.md).
    double fieldVoxelMm = 2.0;
    /// The "interior" grid is exact this far outside too (frame nodes that stray outside).
    double fieldExteriorMm = 10.0;
    /// Memory budget of the run, GB: makeObjectField refuses, before it allocates anything, a size
    /// whose grids would need more (estimateRunBytes). 0 = 75 % of the machine's physical memory.
    double maxMemoryGb = 0.0;
};

/// What a run at this size will need at its peak, estimated from the mesh before any grid exists:
/// the "object" band (surface area × (wall + 3 voxels) / voxel³), the "interior" grid (volume and
/// its exterior band at fieldVoxelMm), 40 bytes per voxel for the grids and what the later stages
/// build from them (calibrated on the bunny at 400 and 800 mm: 452 MB / 2.36 GB estimated, 479 MB /
/// 1.89 GB measured; docs/sdf.md, "Memory guard").
struct MemoryEstimate {
    double objectVoxels = 0, interiorVoxels = 0;
    double bytes = 0;
};
MemoryEstimate estimateRunBytes(const TriMesh& meshMm, const Fabrication& fabrication,
                                const ObjectFieldOptions& options);

/// The budget in bytes: @p maxMemoryGb, or 75 % of the physical memory when it is 0.
double memoryBudgetBytes(double maxMemoryGb);

/// The object's distance fields: "object" (fine, exact as deep as the wall is thick) and
/// "interior" (coarse, whole inside), both in the mesh's millimetres.
struct ObjectField {
    LevelSet object;
    LevelSet interior;
};

/// @throw Error(Usage) for a voxel, depth or band that is not a positive (≥ 0 for the band)
///        finite number of mm. Tools call it before reading input, so bad options fail fast.
void checkObjectFieldOptions(const ObjectFieldOptions& options);

/// Both grids of ObjectField from @p meshMm; the "object" grid is exact Fabrication::wallMm deep,
/// which is what makeShell needs. @throw as checkObjectFieldOptions and meshToLevelSet.
ObjectField makeObjectField(const TriMesh& meshMm, const Fabrication& fabrication,
                            const ObjectFieldOptions& options, RunContext& context);

/// The hollow shell {x : −wallMm ≤ φ(x) ≤ 0} (paper §6) of Fabrication::wallMm: csgDifference of
/// @p object and its inward offset {φ < −wallMm}, the offset read from the object's deep interior
/// band (no LevelSetFilter::offset).
/// @throw Error(Usage) when the wall is under 1 mm or deeper than the object's interior band
///        (info().interiorBandMm; rebuild the object with zf-sdf --shell-mm of this wall);
///        Error(ProcessingFailed) for an object with no inside; Error(Cancelled).
/// Where the object is thinner than 2·wallMm the offset is empty and the shell is solid there.
LevelSet makeShell(const LevelSet& object, const Fabrication& fabrication, RunContext& context);

/// Level set -> triangle mesh (openvdb::tools::volumeToMesh).
struct LevelSetToMeshOptions {
    double isoMm = 0;  ///< which level set {φ = isoMm} to extract; |isoMm| inside the band
    /// 0 = uniform (one vertex per surface voxel), up to 1 = merge flat regions into larger
    /// triangles (fewer triangles, less accurate).
    double adaptivity = 0;
    /// Closed pieces enclosing less than this volume are dropped: the pin-head cavities and
    /// specks the mesher leaves where an iso-surface barely touches a voxel (at the tip of a thin
    /// offset, e.g. a shell's inner wall inside an ear). 1 mm³ is a 1 mm voxel; 0 keeps everything.
    double minComponentVolumeMm3 = 1.0;
};

/// @throw Error(Usage) for adaptivity outside [0, 1], a non-finite iso-value or a negative
///        minComponentVolumeMm3.
void checkMeshingOptions(const LevelSetToMeshOptions& options);

/// A closed triangle mesh (quads split along their shorter diagonal) oriented outward: the
/// normals point to φ > isoMm, so a shell's inner wall faces its cavity. Millimetres. Vertex
/// order follows OpenVDB's deterministic output, so the same grid gives the same mesh.
/// @throw Error(Usage) for adaptivity outside [0, 1] or an iso-value outside the band;
///        Error(ProcessingFailed) for an empty level set; Error(Cancelled).
TriMesh levelSetToMesh(const LevelSet& levelSet, const LevelSetToMeshOptions& options, RunContext& context);

}  // namespace zomefab::sdf
