// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The triangle mesh value type shared by every stage (flat arrays, like Manifold's MeshGL).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
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

/// Merges vertices with bit-identical coordinates (−0 = +0) into one, in first-seen order, and
/// renumbers the triangles. Triangles are kept as they are, including any that now repeat a vertex.
void weldIdenticalVertices(TriMesh& mesh);

}  // namespace zomefab
