// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The triangle adjacency the surface partition works on: per-face centroids, normals and
/// areas, the edge-adjacent face pairs 𝒩 of the paper's Eq. (1), and connected components of a
/// per-face labelling.
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::partition {

/// Per-face geometry and edge adjacency of a triangle mesh (millimetres).
struct FaceGraph {
    std::vector<Vec3d> centroidsMm;  ///< #F face centroids
    std::vector<Vec3d> normals;      ///< #F unit normals; (0,0,0) for degenerate faces
    std::vector<double> areasMm2;    ///< #F face areas
    /// CSR adjacency: the faces sharing an edge with face f are
    /// neighbors[offsets[f] .. offsets[f+1]), in increasing order, each pair listed both ways.
    /// A non-manifold edge joins every pair of its faces.
    std::vector<uint32_t> offsets;
    std::vector<uint32_t> neighbors;

    size_t faceCount() const { return centroidsMm.size(); }
};

/// Builds the face graph of @p meshMm. Deterministic; parallel over faces.
/// @throw Error(InvalidInput) when a triangle references a missing vertex.
FaceGraph buildFaceGraph(const TriMesh& meshMm);

/// Dihedral angle θ between faces @p a and @p b as used in the smoothness term (paper Eq. 3):
/// the angle between their normals in radians, 0 for coplanar faces, π for a fold onto itself.
double dihedralAngleRad(const FaceGraph& graph, uint32_t a, uint32_t b);

/// Connected components of the faces with equal @p labels (edge adjacency).
/// @param componentOf receives the component of each face; components are numbered in order of
///   their lowest face index.
/// @return the number of components
uint32_t labelComponents(const FaceGraph& graph, const std::vector<uint32_t>& labels,
                         std::vector<uint32_t>& componentOf);

}  // namespace zomefab::partition
