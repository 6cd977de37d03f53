// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Test and benchmark scaffolding for the partition stage: meshes in millimetres and a B0
/// cube-lattice frame inside them (a stand-in for zf-frame's output, built in code).
#pragma once

#include <string>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/zome/structure.h"

namespace zomefab::partition::test {

/// A data/ mesh scaled to @p heightMm along z (rotated from +y up when @p isYUp), with the
/// transform from its file coordinates.
struct MeshMm {
    TriMesh mesh;
    Transform4d transformMm;
};
MeshMm loadMeshMm(const std::string& dataName, double heightMm, bool isYUp);

/// A B0 cube lattice (blue struts) of the balls whose centres lie inside @p meshMm at least
/// @p minDepthMm from its surface, and its boundary layer (balls missing one of their six cube
/// neighbours: the outermost balls of frame::outermostBalls for such a lattice).
struct LatticeFrame {
    zome::Structure structure;
    std::vector<zome::BallId> outermost;
};
LatticeFrame makeLatticeFrame(const TriMesh& meshMm, double minDepthMm, double b0Mm = 47.3);

/// Is @p p inside the closed mesh (ray parity along +x)?
bool isInside(const TriMesh& meshMm, const Vec3d& p);

/// Splits every triangle into four (edge midpoints shared), @p levels times.
TriMesh subdivide(const TriMesh& mesh, int levels);

}  // namespace zomefab::partition::test
