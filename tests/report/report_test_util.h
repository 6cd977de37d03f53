// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Checks shared by the report tests: closedness of a mesh, small Zometool frames.
#pragma once

#include <map>
#include <utility>

#include "zomefab/core/tri_mesh.h"
#include "zomefab/zome/structure.h"

namespace zomefab::test {

/// Every directed edge appears exactly once and its reverse exactly once: closed, 2-manifold
/// along edges, consistently oriented. Triangles with a repeated vertex fail too.
inline bool isClosedOriented(const TriMesh& m) {
    std::map<std::pair<uint32_t, uint32_t>, int> edges;
    for (const Triangle& t : m.triangles)
        for (int k = 0; k < 3; ++k) {
            if (t[k] == t[(k + 1) % 3]) return false;
            if (++edges[{t[k], t[(k + 1) % 3]}] > 1) return false;
        }
    for (const auto& [e, n] : edges)
        if (!edges.count({e.second, e.first})) return false;
    return !m.triangles.empty();
}

/// @p m with bit-identical positions merged (flat-shaded meshes split vertices per face).
inline TriMesh weldedByPosition(TriMesh m) {
    weldIdenticalVertices(m);
    return m;
}

/// A small frame with every colour: ball 0 at the origin, a B0 (hole 0, +x), a Y0 (hole 30), an
/// R0 (hole 50) and a B1 (hole 2, +z) to four more balls.
inline zome::Structure colourFrame() {
    zome::Structure s;
    const zome::BallId origin = s.addBall(zome::GoldenVector3{});
    for (const auto& [hole, size] : {std::pair<int, int>{0, 0}, {30, 0}, {50, 0}, {2, 1}}) {
        s.addBall(zome::strutVector(hole, size));
        s.addStrut(origin, hole, size);
    }
    return s;
}

}  // namespace zomefab::test
