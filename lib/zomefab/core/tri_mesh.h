// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The triangle mesh value type shared by every stage (flat arrays, like Manifold's MeshGL).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace zomefab {

using Vec3f = std::array<float, 3>;
using Vec3d = std::array<double, 3>;
using Triangle = std::array<uint32_t, 3>;

/// An indexed triangle mesh. Coordinates are in the file's units until scaled, then in millimetres.
struct TriMesh {
    std::vector<Vec3f> positions;     ///< #V points
    std::vector<Triangle> triangles;  ///< #F vertex-index triples, counter-clockwise seen from outside
    /// Empty, or one flag per triangle: 1 = the user marked the face salient (PLY `salient` face
    /// property), seams must not cross it (paper §5.1).
    std::vector<uint8_t> salientFaces;

    size_t vertexCount() const { return positions.size(); }
    size_t triangleCount() const { return triangles.size(); }
    bool empty() const { return triangles.empty(); }
};

/// Axis-aligned bounding box; empty when min > max.
struct Box3d {
    Vec3d min{1e300, 1e300, 1e300};
    Vec3d max{-1e300, -1e300, -1e300};

    bool isEmpty() const { return min[0] > max[0]; }
    void expand(const Vec3d& p);
    Vec3d size() const;
};

/// A triangle that names one vertex twice: no area and no proper edges.
inline bool hasRepeatedIndex(const Triangle& t) { return t[0] == t[1] || t[1] == t[2] || t[0] == t[2]; }

/// Bounding box of the mesh's referenced and unreferenced vertices.
Box3d boundingBox(const TriMesh& mesh);

/// Appends @p other's vertices and triangles to @p mesh (its indices shifted): one more shell.
void appendMesh(TriMesh& mesh, const TriMesh& other);

/// Merges vertices with bit-identical coordinates (−0 = +0) into one, in first-seen order, and
/// renumbers the triangles. Triangles are kept as they are, including any that now repeat a vertex.
void weldIdenticalVertices(TriMesh& mesh);

/// Whether the triangle's corners are collinear to rounding: twice its area at most 1e-9 × its
/// longest edge squared (mesh::checkMesh's "degenerate"), or a vertex named twice.
bool isDegenerate(const TriMesh& mesh, const Triangle& t);

/// Merges the two ends of every edge no longer than @p maxEdge into one vertex (points a few
/// float roundings apart, as the adaptive mesher can leave; such a sliver's facet normal is noise in
/// float, and slicers and admesh "fix" it), then drops the triangles that now name a vertex twice
/// and the pairs that now cover each other face to face. What is left of a closed mesh stays
/// closed. Returns how many triangles were dropped.
size_t collapseShortEdges(TriMesh& mesh, double maxEdge);

/// Removes needles from a closed mesh: a degenerate triangle (a, b, c) whose corner c lies on its
/// longest edge ab is flipped with its neighbour (b, a, d) across that edge into (a, d, c) and
/// (d, b, c), which cover the same surface. Where the new edge cd already exists, or the neighbour
/// is missing or shared by more than two triangles, the needle is left. Returns how many were
/// flipped away.
size_t flipNeedles(TriMesh& mesh);

/// Signed volume of the closed, oriented surface made of @p triangles (divergence theorem), each
/// corner taken relative to @p origin so that the sum stays well conditioned far from the
/// coordinate origin. Cubed mesh units (mm³ after scaling); > 0 for an outward surface.
double signedVolume(const TriMesh& mesh, const std::vector<uint32_t>& triangles, const Vec3d& origin);
/// The same over every triangle.
double signedVolume(const TriMesh& mesh, const Vec3d& origin = {0, 0, 0});
/// Area of all triangles, squared mesh units (mm² after scaling).
double surfaceArea(const TriMesh& mesh);

/// The vertex-connected components of a mesh (triangles sharing a vertex are connected).
struct VertexComponents {
    std::vector<uint32_t> rootOf;  ///< per vertex: the smallest vertex index of its component
    /// Indexed by root: the component's signed volume, corners relative to the root's position.
    std::vector<double> volume;
};
VertexComponents vertexComponents(const TriMesh& mesh);

/// Keeps the triangles of the components whose root passes @p isKept, in their order; the kept
/// vertices are renumbered in order of first use and salientFaces follow their triangles. The one
/// component filter of the library (specks left by a mesher, sealed cavities). Returns how many
/// components were dropped.
size_t keepComponents(TriMesh& mesh, const VertexComponents& components,
                      const std::function<bool(uint32_t root)>& isKept);

}  // namespace zomefab
