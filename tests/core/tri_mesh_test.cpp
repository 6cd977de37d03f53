// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/tri_mesh.h"

#include <doctest/doctest.h>

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
