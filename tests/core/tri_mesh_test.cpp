// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/tri_mesh.h"

#include <doctest/doctest.h>

#include <set>

using namespace zomefab;

TEST_CASE("tri_mesh: welding merges bit-identical points in first-seen order") {
    TriMesh m;
    m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {-0.0f, 0, 0}, {0, 0, 1}, {1, 0, 1e-7f}};
    m.triangles = {{0, 1, 2}, {3, 2, 4}, {4, 1, 5}, {0, 6, 5}};
    weldIdenticalVertices(m);
    // Points 3 and 1 are the same, 4 (−0) is 0; 6 differs from 1 by 1e-7 and stays.
    REQUIRE(m.positions.size() == 5);
    CHECK(m.positions[0] == Vec3f{0, 0, 0});
    CHECK(m.positions[3] == Vec3f{0, 0, 1});
    CHECK(m.positions[4] == Vec3f{1, 0, 1e-7f});
    CHECK(m.triangles[0] == Triangle{0, 1, 2});
    CHECK(m.triangles[1] == Triangle{1, 2, 0});
    CHECK(m.triangles[2] == Triangle{0, 1, 3});  // now repeats nothing, kept as is
    CHECK(m.triangles[3] == Triangle{0, 4, 3});
    // A triangle that collapses is kept: callers decide.
    TriMesh c;
    c.positions = {{0, 0, 0}, {0, 0, 0}, {1, 0, 0}};
    c.triangles = {{0, 1, 2}};
    weldIdenticalVertices(c);
    CHECK(c.positions.size() == 2);
    CHECK(c.triangles[0] == Triangle{0, 0, 1});
}

TEST_CASE("tri_mesh: a needle in a closed mesh is flipped away with its neighbour") {
    // A tetrahedron A B D E whose front face is split at C, the middle of AB, with the needle
    // (A, B, C) left between the split face and the bottom face (A, D, B).
    TriMesh m;
    m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {1, 0, 0}};
    m.triangles = {{0, 2, 1}, {0, 4, 3}, {4, 1, 3}, {0, 3, 2}, {1, 2, 3}, {0, 1, 4}};
    REQUIRE(isDegenerate(m, m.triangles[5]));
    CHECK(flipNeedles(m) == 1);
    CHECK(m.triangles.size() == 6);
    size_t degenerate = 0;
    for (const Triangle& t : m.triangles) degenerate += isDegenerate(m, t) ? 1 : 0;
    CHECK(degenerate == 0);
    CHECK(signedVolume(m) == doctest::Approx(8.0 / 6.0));
    // Still closed and oriented: every directed edge has its reverse exactly once.
    std::multiset<std::pair<uint32_t, uint32_t>> edges;
    for (const Triangle& t : m.triangles)
        for (int k = 0; k < 3; ++k) edges.insert({t[size_t(k)], t[size_t((k + 1) % 3)]});
    for (const auto& [from, to] : edges) CHECK(edges.count({to, from}) == 1);
    // Nothing to do on a mesh without needles, and a needle without a neighbour is left.
    CHECK(flipNeedles(m) == 0);
    TriMesh lone;
    lone.positions = {{0, 0, 0}, {2, 0, 0}, {1, 0, 0}};
    lone.triangles = {{0, 1, 2}};
    CHECK(flipNeedles(lone) == 0);
    CHECK(lone.triangles[0] == Triangle{0, 1, 2});
}

TEST_CASE("tri_mesh: edges a rounding long collapse, and the slivers on them go") {
    // The tetrahedron A B D E with its corner E split into three points 0.5 nm apart along z: the
    // three faces at E meet them, three slivers and the speck (E1, E3, E2) close the gaps.
    TriMesh m;
    m.positions = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}, {0, 0, 2}, {0, 0, 2.0000005f}, {0, 0, 2.000001f}};
    m.triangles = {{0, 1, 3}, {0, 4, 2}, {1, 2, 5}, {0, 2, 1}, {1, 5, 3}, {0, 3, 4}, {2, 4, 5}, {3, 5, 4}};
    REQUIRE(isDegenerate(m, m.triangles[7]));
    CHECK(collapseShortEdges(m, 1e-7) == 0);  // edges of 0.5 nm: above a 0.1 nm limit, left
    CHECK(m.triangles.size() == 8);
    CHECK(collapseShortEdges(m, 1e-4) == 4);  // the speck and the three slivers
    REQUIRE(m.triangles.size() == 4);
    for (const Triangle& t : m.triangles) CHECK(!isDegenerate(m, t));
    CHECK(signedVolume(m) == doctest::Approx(8.0 / 6.0));
}
