// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Stage 1: validate the input mesh (closedness, manifoldness, orientation, volume).
#pragma once

#include <cstddef>

#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::mesh {

/// Everything zf-info reports about a mesh. Lengths in the mesh's units (mm after scaling).
struct MeshReport {
    size_t vertexCount = 0;
    size_t triangleCount = 0;
    Box3d bounds;
    double volume = 0;               ///< signed, divergence theorem; > 0 for an outward closed mesh
    double area = 0;
    size_t boundaryEdges = 0;        ///< edges used by exactly one triangle
    Box3d boundaryBounds;            ///< where the boundary edges are (empty when none)
    size_t nonManifoldEdges = 0;     ///< edges used by three or more triangles
    size_t inconsistentEdges = 0;    ///< two-triangle edges traversed in the same direction by both
    size_t degenerateTriangles = 0;  ///< repeated vertex index or zero area
    size_t duplicateTriangles = 0;   ///< same three vertices as an earlier triangle (any order)
    size_t nonFiniteVertices = 0;    ///< NaN or infinite coordinates
    size_t components = 0;           ///< edge-connected components of triangles
    bool isClosed() const { return boundaryEdges == 0 && nonManifoldEdges == 0 && triangleCount > 0; }
    bool isConsistentlyOriented() const { return inconsistentEdges == 0; }
};

MeshReport checkMesh(const TriMesh& mesh);

struct ValidateOptions {
    bool repair = false;  ///< close small holes (boundary loops up to maxHoleEdges edges)
    size_t maxHoleEdges = 200;
};

/// Makes @p mesh fit for the later stages or says exactly why it cannot be: non-finite
/// coordinates, an open mesh (count and bounding box of the boundary edges), zero volume.
/// Flips an inside-out closed mesh; drops degenerate and duplicate triangles with a warning.
/// @throw Error(InvalidInput) naming @p sourceName.
TriMesh validateClosedMesh(TriMesh mesh, const ValidateOptions& options, const std::string& sourceName,
                           RunContext& context);

}  // namespace zomefab::mesh
