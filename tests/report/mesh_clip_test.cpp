// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Planar cuts with caps: volumes, closedness, holes in the cut, vertices on the plane.
#include "zomefab/report/mesh_clip.h"

#include <doctest/doctest.h>

#include <cmath>

#include "report_fixtures.h"
#include "report_test_util.h"
#include "zomefab/core/error.h"

using namespace zomefab;
using namespace zomefab::report;
using namespace zomefab::test;

TEST_CASE("mesh_clip: a box cut across keeps the exact part, closed and outward") {
    const TriMesh box = makeBox({0, 0, 0}, {10, 20, 30});
    const TriMesh below = clipByPlane(box, 0, 3.0, true);
    const TriMesh above = clipByPlane(box, 0, 3.0, false);
    CHECK(isClosedOriented(below));
    CHECK(isClosedOriented(above));
    CHECK(signedVolume(below) == doctest::Approx(3.0 * 600.0).epsilon(1e-6));
    CHECK(signedVolume(above) == doctest::Approx(7.0 * 600.0).epsilon(1e-6));
    CHECK(surfaceArea(below) == doctest::Approx(2 * (3 * 20 + 3 * 30 + 20 * 30)).epsilon(1e-6));
    const Box3d b = boundingBox(below);
    CHECK(b.max[0] == doctest::Approx(3.0));
    CHECK(b.min[0] == 0.0);
}

TEST_CASE("mesh_clip: nothing or everything on the kept side") {
    const TriMesh box = makeBox({0, 0, 0}, {1, 1, 1});
    CHECK(clipByPlane(box, 2, -1.0, true).triangles.empty());
    const TriMesh all = clipByPlane(box, 2, 5.0, true);
    CHECK(all.triangles.size() == box.triangles.size());
    CHECK(signedVolume(all) == doctest::Approx(1.0));
}

TEST_CASE("mesh_clip: the cap of a hollow sphere is an annulus (hole bridged into the outer loop)") {
    // 49 rings: no vertex on the equator, the cut crosses every meridian edge.
    const TriMesh shell = sphereShell({0, 0, 0}, 50, 10, 49, 96);
    const double whole = signedVolume(shell);
    for (bool keepBelow : {true, false}) {
        const TriMesh half = clipByPlane(shell, 2, 0.0, keepBelow);
        CHECK(isClosedOriented(half));
        CHECK(signedVolume(half) == doctest::Approx(0.5 * whole).epsilon(1e-6));
    }
    // Through x: the cap lies in the yz plane.
    const TriMesh side = clipByPlane(shell, 0, 0.0, false);
    CHECK(isClosedOriented(side));
    CHECK(signedVolume(side) == doctest::Approx(0.5 * whole).epsilon(1e-3));
}

TEST_CASE("mesh_clip: two cavities in one cut and two separate outer loops") {
    // A 100 mm box with two cavities side by side, cut through both: one outer loop, two holes.
    const TriMesh twoCavities = merged(
        makeBox({0, 0, 0}, {100, 40, 40}),
        merged(reversed(makeBox({10, 10, 10}, {40, 30, 30})), reversed(makeBox({60, 10, 10}, {90, 30, 30}))));
    const TriMesh cut = clipByPlane(twoCavities, 2, 20.0, true);
    CHECK(isClosedOriented(cut));
    CHECK(signedVolume(cut) == doctest::Approx(100.0 * 40 * 20 - 2 * 30.0 * 20 * 10).epsilon(1e-6));
    // Two disjoint boxes cut by one plane: two caps.
    const TriMesh two = merged(makeBox({0, 0, 0}, {10, 10, 10}), makeBox({20, 0, 0}, {30, 10, 10}));
    const TriMesh lower = clipByPlane(two, 2, 4.0, true);
    CHECK(isClosedOriented(lower));
    CHECK(signedVolume(lower) == doctest::Approx(2 * 400.0).epsilon(1e-6));
}

TEST_CASE("mesh_clip: vertices exactly on the plane move the plane a little, not the result's topology") {
    // 48 rings put a vertex ring exactly on z = 0.
    const TriMesh sphere = makeSphere({0, 0, 0}, 20, 48, 96);
    const TriMesh top = clipByPlane(sphere, 2, 0.0, false);
    CHECK(isClosedOriented(top));
    CHECK(signedVolume(top) == doctest::Approx(0.5 * signedVolume(sphere)).epsilon(1e-3));
    const Box3d b = boundingBox(top);
    CHECK(std::abs(b.min[2]) <= 0.01);
}

TEST_CASE("mesh_clip: clipToBox of a sphere around a cube gives the cube") {
    // The cube's corners (8.66 mm from the centre) lie inside the 10 mm sphere: six caps, no sphere left.
    const TriMesh sphere = makeSphere({0, 0, 0}, 10, 64, 128);
    Box3d box;
    box.min = {-5, -5, -5};
    box.max = {5, 5, 5};
    const TriMesh cube = clipToBox(sphere, box);
    CHECK(isClosedOriented(cube));
    CHECK(signedVolume(cube) == doctest::Approx(1000.0).epsilon(1e-5));
    CHECK(surfaceArea(cube) == doctest::Approx(600.0).epsilon(1e-5));
}

TEST_CASE("mesh_clip: the shell piece fixture is closed and has the octant's volume") {
    const TriMesh piece = shellPiece(80, 16);
    CHECK(isClosedOriented(piece));
    const double pi = std::acos(-1.0);
    const double exact = (4.0 / 3.0) * pi * (80.0 * 80 * 80 - 64.0 * 64 * 64) / 8.0;
    CHECK(signedVolume(piece) == doctest::Approx(exact).epsilon(0.01));  // tessellation
}

TEST_CASE("mesh_clip: same input, same output") {
    const TriMesh a = shellPiece(60, 8), b = shellPiece(60, 8);
    CHECK(a.positions == b.positions);
    CHECK(a.triangles == b.triangles);
}

TEST_CASE("mesh_clip: an open mesh is refused with a one-line message") {
    TriMesh open = makeBox({0, 0, 0}, {10, 10, 10});
    open.triangles.erase(open.triangles.begin() + 4);  // a side triangle the cut crosses
    bool thrown = false;
    try {
        clipByPlane(open, 2, 5.0, true);
    } catch (const Error& e) {
        thrown = true;
        CHECK(e.code() == ErrorCode::InvalidInput);
        CHECK(std::string(e.what()).find("mesh is not closed") != std::string::npos);
        CHECK(std::string(e.what()).find("z = 5.0000 mm") != std::string::npos);
    }
    CHECK(thrown);
    CHECK_THROWS_AS(clipByPlane(makeBox({0, 0, 0}, {1, 1, 1}), 3, 0.5, true), Error);
}
