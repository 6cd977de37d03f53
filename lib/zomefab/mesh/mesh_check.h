// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Stage 1: check the input mesh (closedness, manifoldness, orientation, volume) and make it
/// fit for the later stages, which need a closed, consistently outward-oriented surface.
#pragma once

#include <cstddef>
#include <string>

#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::mesh {

/// Everything zf-info reports about a mesh. Lengths in the mesh's units (mm after scaling).
struct MeshReport {
    size_t vertexCount = 0;
    size_t triangleCount = 0;
    size_t unreferencedVertices = 0;  ///< vertices no triangle uses
    Box3d bounds;                     ///< of all finite vertices
    double volume = 0;                ///< signed, divergence theorem; > 0 for an outward closed mesh
    double area = 0;
    size_t boundaryEdges = 0;        ///< edges used by exactly one triangle
    size_t boundaryLoops = 0;        ///< connected chains of boundary edges (holes)
    Box3d boundaryBounds;            ///< where the boundary edges are (empty when none)
    size_t nonManifoldEdges = 0;     ///< edges used by three or more triangles
    Box3d nonManifoldBounds;         ///< where they are (empty when none)
    size_t inconsistentEdges = 0;    ///< two-triangle edges traversed in the same direction by both
    size_t degenerateTriangles = 0;  ///< repeated vertex index, or twice the area <= 1e-9 x longest edge^2
    size_t duplicateTriangles = 0;   ///< same three vertices as an earlier triangle (any order)
    size_t nonFiniteVertices = 0;    ///< NaN or infinite coordinates
    size_t components = 0;           ///< edge-connected components of triangles
    bool isClosed() const { return boundaryEdges == 0 && nonManifoldEdges == 0 && triangleCount > 0; }
    bool isConsistentlyOriented() const { return inconsistentEdges == 0; }
};

/// Measures @p mesh without changing it. Serial and deterministic; O(F log F).
/// @pre every triangle index is < mesh.vertexCount() (readMesh guarantees it).
/// @throw Error(InvalidInput) when a triangle refers to a vertex that does not exist.
MeshReport checkMesh(const TriMesh& mesh);

/// What removeCavities() removed.
struct CavityRemoval {
    size_t cavities = 0;     ///< closed components of negative volume
    double volumeMm3 = 0.0;  ///< their total volume (positive)
};

/// Drops the vertex-connected components of negative signed volume up to @p maxVolumeMm3 from a
/// closed, outward mesh: small cavities sealed inside the solid (e.g. a gap a voxel wide left between
/// two unioned level sets), which a slicer would print as empty pockets and which make admesh count
/// extra parts. The solid is then full there. Larger cavities are kept: the hollow inside a closed
/// shell is one. Unused vertices are dropped; the other triangles keep their order.
/// Deterministic, O(F α(V)).
CavityRemoval removeCavities(TriMesh& mesh, double maxVolumeMm3);

struct ValidateOptions {
    /// |volume| below this fraction of the bounding-box diagonal cubed counts as zero volume
    /// (a flat or self-cancelling surface); 1e-9 keeps a 100 x 100 x 0.01 mm plate.
    double minRelativeVolume = 1e-9;
    /// Close holes: every boundary loop of at most maxHoleEdges edges is filled with the
    /// minimum-area triangulation of its vertices (no new vertices), oriented to match its
    /// neighbours. Loops that touch themselves or would need an edge the mesh already has are
    /// left open (and then reported).
    bool repair = false;
    size_t maxHoleEdges = 300;  ///< larger holes are not filled
};

/// Makes @p mesh fit for the later stages or says exactly why it cannot be. In order:
/// rejects an empty mesh and non-finite coordinates; drops triangles with a repeated vertex index
/// and duplicate triangles (warning); drops unreferenced vertices; fills small holes when
/// options.repair (warning; filled faces are not salient); rejects an open mesh (count,
/// loops and bounding box of the boundary edges) and non-manifold edges; makes the orientation
/// consistent within each component and outward (a component nested inside an odd number of
/// others faces inward: a cavity), warning when it flips anything; rejects zero volume.
/// salientFaces, when present, follow their triangles.
/// @throw Error(InvalidInput) naming @p sourceName; Error(Cancelled) when @p context is cancelled.
TriMesh validateClosedMesh(TriMesh mesh, const ValidateOptions& options, const std::string& sourceName,
                           RunContext& context);

}  // namespace zomefab::mesh
