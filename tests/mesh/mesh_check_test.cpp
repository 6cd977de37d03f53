// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/mesh/mesh_check.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/io/mesh_io.h"

using namespace zomefab;
using namespace zomefab::test;
using zomefab::mesh::checkMesh;
using zomefab::mesh::MeshReport;
using zomefab::mesh::validateClosedMesh;

namespace {

/// Appends @p b to @p a (vertex indices shifted).
TriMesh merged(TriMesh a, const TriMesh& b) {
    const uint32_t base = uint32_t(a.positions.size());
    a.positions.insert(a.positions.end(), b.positions.begin(), b.positions.end());
    for (Triangle t : b.triangles) a.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    return a;
}

TriMesh flipped(TriMesh m) {
    for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
    return m;
}

/// validateClosedMesh's error message, or "" when it succeeds.
std::string validationError(const TriMesh& m, const std::string& name = "m.stl") {
    try {
        validateClosedMesh(m, {}, name, RunContext::silent());
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::InvalidInput);
        CHECK(std::string(e.what()).find('\n') == std::string::npos);
        return e.what();
    }
    return "";
}

bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace

TEST_CASE("mesh_check: a closed box") {
    const MeshReport r = checkMesh(makeBox({0, 0, 0}, {2, 3, 4}));
    CHECK(r.vertexCount == 8);
    CHECK(r.triangleCount == 12);
    CHECK(r.volume == doctest::Approx(24.0));
    CHECK(r.area == doctest::Approx(2 * (6 + 8 + 12)));
    CHECK(r.isClosed());
    CHECK(r.isConsistentlyOriented());
    CHECK(r.components == 1);
    CHECK(r.boundaryEdges == 0);
    CHECK(r.boundaryLoops == 0);
    CHECK(r.boundaryBounds.isEmpty());
    CHECK(r.nonManifoldEdges == 0);
    CHECK(r.degenerateTriangles == 0);
    CHECK(r.duplicateTriangles == 0);
    CHECK(r.nonFiniteVertices == 0);
    CHECK(r.unreferencedVertices == 0);
    CHECK(r.bounds.max[2] == 4);
    CHECK(checkMesh(flipped(makeBox({0, 0, 0}, {2, 3, 4}))).volume == doctest::Approx(-24.0));
}

TEST_CASE("mesh_check: open, non-manifold, inconsistent, degenerate, duplicate, non-finite, components") {
    TriMesh open = makeBox({0, 0, 0}, {1, 1, 1});
    open.triangles.pop_back();  // one triangle missing: a 3-edge hole
    MeshReport r = checkMesh(open);
    CHECK(!r.isClosed());
    CHECK(r.boundaryEdges == 3);
    CHECK(r.boundaryLoops == 1);
    CHECK(!r.boundaryBounds.isEmpty());

    TriMesh twoHoles = makeSphere({0, 0, 0}, 1, 8, 12);
    twoHoles.triangles.erase(twoHoles.triangles.begin() + 40);
    twoHoles.triangles.erase(twoHoles.triangles.begin());  // a cap triangle: far from the other hole
    r = checkMesh(twoHoles);
    CHECK(r.boundaryEdges == 6);
    CHECK(r.boundaryLoops == 2);

    TriMesh fin = makeBox({0, 0, 0}, {1, 1, 1});
    fin.positions.push_back({0.5f, 5.f, 5.f});
    fin.triangles.push_back({0, 1, 8});  // a third triangle on the box edge 0-1
    r = checkMesh(fin);
    CHECK(r.nonManifoldEdges == 1);
    CHECK(r.boundaryEdges == 2);
    CHECK(!r.isClosed());

    TriMesh oneFlipped = makeBox({0, 0, 0}, {1, 1, 1});
    std::swap(oneFlipped.triangles[4][1], oneFlipped.triangles[4][2]);
    r = checkMesh(oneFlipped);
    CHECK(r.inconsistentEdges == 3);
    CHECK(r.isClosed());
    CHECK(!r.isConsistentlyOriented());

    TriMesh messy = makeBox({0, 0, 0}, {1, 1, 1});
    messy.triangles.push_back({1, 1, 2});           // repeated index
    messy.triangles.push_back(messy.triangles[0]);  // duplicate
    messy.triangles.push_back(
        {messy.triangles[1][2], messy.triangles[1][0], messy.triangles[1][1]});  // rotated duplicate
    messy.positions.push_back({0.5f, 0.f, 0.f});  // on the edge 0-1: a zero-area triangle
    messy.triangles.push_back({0, 1, 8});
    messy.positions.push_back({9.f, 9.f, 9.f});  // unreferenced
    r = checkMesh(messy);
    CHECK(r.degenerateTriangles == 2);
    CHECK(r.duplicateTriangles == 2);
    CHECK(r.unreferencedVertices == 1);

    TriMesh nan = makeBox({0, 0, 0}, {1, 1, 1});
    nan.positions[3][0] = std::numeric_limits<float>::quiet_NaN();
    CHECK(checkMesh(nan).nonFiniteVertices == 1);

    r = checkMesh(merged(makeBox({0, 0, 0}, {1, 1, 1}), makeSphere({5, 5, 5}, 1, 6, 8)));
    CHECK(r.components == 2);
    CHECK(r.isClosed());

    TriMesh bad = makeBox({0, 0, 0}, {1, 1, 1});
    bad.triangles[0][1] = 42;
    CHECK_THROWS_AS(checkMesh(bad), Error);
}

TEST_CASE("validate: a good closed mesh passes unchanged") {
    const TriMesh box = makeBox({0, 0, 0}, {1, 2, 3});
    RunContext context;
    const TriMesh out = validateClosedMesh(box, {}, "box.stl", context);
    CHECK(out.positions == box.positions);
    CHECK(out.triangles == box.triangles);
    CHECK(context.warnings().empty());
}

TEST_CASE("validate: an inside-out mesh is flipped with a warning") {
    RunContext context;
    const TriMesh out = validateClosedMesh(flipped(makeSphere({0, 0, 0}, 2)), {}, "inv.stl", context);
    CHECK(checkMesh(out).volume > 0);
    REQUIRE(context.warnings().size() == 1);
    CHECK(contains(context.warnings()[0], "inv.stl: the mesh was inside out"));
}

TEST_CASE("validate: inconsistent orientation is made consistent, then outward") {
    TriMesh box = makeBox({0, 0, 0}, {1, 1, 1});
    std::swap(box.triangles[4][1], box.triangles[4][2]);
    std::swap(box.triangles[7][1], box.triangles[7][2]);
    RunContext context;
    TriMesh out = validateClosedMesh(box, {}, "x.stl", context);
    MeshReport r = checkMesh(out);
    CHECK(r.isConsistentlyOriented());
    CHECK(r.volume == doctest::Approx(1.0));
    CHECK(out.triangles == makeBox({0, 0, 0}, {1, 1, 1}).triangles);
    CHECK(context.warnings().size() == 1);

    // Mostly inside out, two triangles right: consistent first (flip the two), then outward (flip all).
    TriMesh inv = flipped(makeBox({0, 0, 0}, {1, 1, 1}));
    std::swap(inv.triangles[0][1], inv.triangles[0][2]);
    std::swap(inv.triangles[5][1], inv.triangles[5][2]);
    out = validateClosedMesh(inv, {}, "y.stl", RunContext::silent());
    CHECK(checkMesh(out).volume == doctest::Approx(1.0));
    CHECK(checkMesh(out).isConsistentlyOriented());
}

TEST_CASE("validate: a cavity faces inward; only a wrongly oriented component is flipped") {
    const TriMesh outer = makeBox({0, 0, 0}, {10, 10, 10});
    const TriMesh cavity = makeSphere({5, 5, 5}, 2, 12, 24);
    const TriMesh apart = makeBox({20, 0, 0}, {21, 1, 1});
    const double cavityVolume = -checkMesh(cavity).volume;

    // Correct as given: outer outward, cavity inward, separate box outward -> unchanged.
    RunContext ok;
    const TriMesh right = merged(merged(outer, flipped(cavity)), apart);
    CHECK(validateClosedMesh(right, {}, "ok.stl", ok).triangles == right.triangles);
    CHECK(ok.warnings().empty());

    // The cavity outward and the separate box inward: both are fixed, the outer box is kept.
    RunContext fixed;
    const TriMesh wrong = merged(merged(outer, cavity), flipped(apart));
    const TriMesh out = validateClosedMesh(wrong, {}, "cav.stl", fixed);
    CHECK(out.triangles == right.triangles);
    CHECK(checkMesh(out).volume == doctest::Approx(1000.0 + cavityVolume + 1.0));
    REQUIRE(fixed.warnings().size() == 1);
    CHECK(contains(fixed.warnings()[0], "2 of 3 components were inside out"));
}

TEST_CASE("validate: open meshes say how many boundary edges, in how many loops, and where") {
    TriMesh open = makeBox({0, 0, 0}, {1, 1, 1});
    open.triangles.pop_back();
    CHECK(contains(validationError(open, "open.stl"),
                   "open.stl: open mesh: 3 boundary edges in 1 loop, between (1, 0, 0) and (1, 1, 1)"));

    // The original Stanford scan has five holes in its base.
    const TriMesh bunny = readMesh(dataPath("bunny_stanford_open_69k.stl"));
    const std::string message = validationError(bunny, "bun_zipper.stl");
    CHECK(contains(message, "bun_zipper.stl: open mesh: 223 boundary edges in 5 loops, between ("));
}

TEST_CASE("validate: the other reasons to refuse a mesh") {
    TriMesh nan = makeBox({0, 0, 0}, {1, 1, 1});
    nan.positions[2][1] = std::numeric_limits<float>::infinity();
    CHECK(contains(validationError(nan, "nan.obj"), "nan.obj: vertex 2 has a non-finite coordinate"));

    // A closed but flat surface: the two sides of a square, triangulated along different diagonals.
    TriMesh flat;
    flat.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
    flat.triangles = {{0, 1, 2}, {0, 2, 3}, {1, 0, 3}, {1, 3, 2}};
    CHECK(checkMesh(flat).isClosed());
    CHECK(contains(validationError(flat, "flat.obj"), "flat.obj: zero volume"));

    // Two boxes sharing one edge (welded through an STL round trip): closed, but not manifold.
    const TriMesh boxes = merged(makeBox({0, 0, 0}, {1, 1, 1}), makeBox({1, 1, 0}, {2, 2, 1}));
    const TriMesh touching = parseMesh(serializeMesh(boxes, MeshFormat::Stl), MeshFormat::Stl, "two.stl");
    CHECK(checkMesh(touching).nonManifoldEdges == 1);
    CHECK(checkMesh(touching).boundaryEdges == 0);
    CHECK(contains(
        validationError(touching, "two.stl"),
        "two.stl: non-manifold mesh: 1 edges shared by three or more triangles, between (1, 1, 0) and "
        "(1, 1, 1)"));

    // The real projective plane (6 vertices, 10 triangles): closed and manifold, not orientable.
    TriMesh rp2;
    for (int i = 0; i < 6; ++i) rp2.positions.push_back({float(i), float(i * i % 7), float(i * i * i % 5)});
    for (Triangle t :
         {Triangle{1, 2, 3}, Triangle{1, 3, 4}, Triangle{1, 4, 5}, Triangle{1, 5, 6}, Triangle{1, 6, 2},
          Triangle{2, 3, 5}, Triangle{3, 4, 6}, Triangle{4, 5, 2}, Triangle{5, 6, 3}, Triangle{6, 2, 4}})
        rp2.triangles.push_back({t[0] - 1, t[1] - 1, t[2] - 1});
    CHECK(checkMesh(rp2).isClosed());
    CHECK(contains(validationError(rp2, "rp2.obj"), "rp2.obj: non-orientable surface"));

    CHECK(contains(validationError(TriMesh{}, "none.stl"), "none.stl: no triangles"));
}

TEST_CASE("validate: degenerate and duplicate triangles are dropped; salient flags follow") {
    TriMesh m = makeBox({0, 0, 0}, {1, 1, 1});
    m.salientFaces.assign(12, 0);
    m.salientFaces[11] = 1;
    m.triangles.insert(m.triangles.begin(), {2, 2, 5});  // repeated index
    m.salientFaces.insert(m.salientFaces.begin(), 1);
    m.triangles.push_back(m.triangles[3]);  // duplicate
    m.salientFaces.push_back(1);
    m.positions.push_back({7, 7, 7});  // unreferenced
    RunContext context;
    const TriMesh out = validateClosedMesh(m, {}, "d.ply", context);
    CHECK(out.triangles == makeBox({0, 0, 0}, {1, 1, 1}).triangles);
    CHECK(out.positions.size() == 8);
    REQUIRE(out.salientFaces.size() == 12);
    CHECK(out.salientFaces[11] == 1);
    CHECK(out.salientFaces[0] == 0);
    CHECK(context.warnings().size() == 2);

    TriMesh badFlags = makeBox({0, 0, 0}, {1, 1, 1});
    badFlags.salientFaces.assign(3, 1);
    CHECK(contains(validationError(badFlags, "f.ply"), "salient-face flags (3) do not match"));
}

TEST_CASE("validate: the bundled closed meshes all pass, keeping their triangles") {
    for (const char* name : {"bunny_npm_3674.stl", "dino_cgal_8k.stl", "cheese_cgal_18k.stl"}) {
        INFO(name);
        const TriMesh m = readMesh(dataPath(name));
        RunContext context;
        const TriMesh out = validateClosedMesh(m, {}, name, context);
        CHECK(out.triangleCount() == m.triangleCount());
        CHECK(checkMesh(out).volume > 0);
        CHECK(context.warnings().empty());
    }
}

TEST_CASE("validate: cancellation is honoured") {
    std::atomic<bool> cancel{true};
    RunContext context({}, {}, &cancel);
    CHECK_THROWS_AS(validateClosedMesh(makeBox({0, 0, 0}, {1, 1, 1}), {}, "c.stl", context), Error);
}

TEST_CASE("validate --repair: small holes are filled, closed and consistently oriented") {
    mesh::ValidateOptions repair;
    repair.repair = true;
    // One missing triangle: the fill is exactly that triangle.
    TriMesh box = makeBox({0, 0, 0}, {1, 1, 1});
    const Triangle missing = box.triangles.back();
    box.triangles.pop_back();
    RunContext context;
    TriMesh out = validateClosedMesh(box, repair, "box.stl", context);
    REQUIRE(out.triangleCount() == 12);
    CHECK(std::is_permutation(out.triangles.back().begin(), out.triangles.back().end(), missing.begin()));
    CHECK(checkMesh(out).isClosed());
    CHECK(checkMesh(out).volume == doctest::Approx(1.0));
    REQUIRE(context.warnings().size() == 1);
    CHECK(contains(context.warnings()[0], "box.stl: filled 1 hole with 1 triangles"));

    // A whole face and one triangle of the opposite face missing: two holes; salient flags are
    // kept and the filling triangles are not salient.
    TriMesh two = makeBox({0, 0, 0}, {2, 2, 2});
    two.triangles.erase(two.triangles.begin() + 2);                         // half the z = 2 face
    two.triangles.erase(two.triangles.begin(), two.triangles.begin() + 2);  // the z = 0 face
    two.salientFaces.assign(two.triangleCount(), 1);
    out = validateClosedMesh(two, repair, "two.stl", RunContext::silent());
    MeshReport r = checkMesh(out);
    CHECK(r.isClosed());
    CHECK(r.isConsistentlyOriented());
    CHECK(r.volume == doctest::Approx(8.0));
    CHECK(out.triangleCount() == 12);
    REQUIRE(out.salientFaces.size() == 12);
    CHECK(out.salientFaces[8] == 1);
    CHECK(out.salientFaces[11] == 0);

    // The Stanford scan: five holes, 223 boundary edges, filled with 223 - 2 * 5 triangles.
    const TriMesh bunny = readMesh(dataPath("bunny_stanford_open_69k.stl"));
    RunContext bunnyContext;
    out = validateClosedMesh(bunny, repair, "bun_zipper.stl", bunnyContext);
    r = checkMesh(out);
    CHECK(r.boundaryEdges == 0);
    CHECK(r.nonManifoldEdges == 0);
    CHECK(r.inconsistentEdges == 0);
    CHECK(r.components == 1);
    CHECK(r.volume > 0);
    CHECK(out.triangleCount() == bunny.triangleCount() + 223 - 10);
    CHECK(contains(bunnyContext.warnings().at(0), "filled 5 holes with 213 triangles"));

    // Holes larger than maxHoleEdges stay open and are reported.
    repair.maxHoleEdges = 3;
    try {
        validateClosedMesh(two, repair, "two.stl", RunContext::silent());
        FAIL("the 4-edge hole is larger than maxHoleEdges");
    } catch (const Error& e) {
        CHECK(contains(e.what(), "two.stl: open mesh: 4 boundary edges in 1 loop"));
    }
    repair.maxHoleEdges = 300;
    try {
        validateClosedMesh(two, repair, "x", RunContext::silent());
    } catch (...) {
        FAIL("should have been repaired");
    }
}

TEST_CASE("validate --repair: a boundary that touches itself is left open") {
    // Two triangles meeting at one vertex: each is a hole of its own, pinched at vertex 0.
    TriMesh bowtie;
    bowtie.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {-1, 0, 0}, {-1, -1, 0}};
    bowtie.triangles = {{0, 1, 2}, {0, 3, 4}};
    mesh::ValidateOptions repair;
    repair.repair = true;
    try {
        validateClosedMesh(bowtie, repair, "bowtie.obj", RunContext::silent());
        FAIL("a pinched boundary must not be filled");
    } catch (const Error& e) {
        CHECK(contains(e.what(), "bowtie.obj: open mesh: 6 boundary edges"));
    }
}

TEST_CASE("removeCavities: drops a sealed inner pocket, keeps the solid and separate solids") {
    TriMesh solid = test::makeBox({0, 0, 0}, {10, 10, 10});
    TriMesh pocket = test::makeBox({4, 4, 4}, {6, 6, 7});  // 12 mm³, inward: a cavity
    for (Triangle& t : pocket.triangles) std::swap(t[1], t[2]);
    TriMesh second = test::makeBox({20, 0, 0}, {22, 2, 2});  // a separate positive solid stays
    TriMesh m = solid;
    for (const TriMesh* part : {&pocket, &second}) {
        const uint32_t base = uint32_t(m.positions.size());
        m.positions.insert(m.positions.end(), part->positions.begin(), part->positions.end());
        for (Triangle t : part->triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    }
    REQUIRE(mesh::checkMesh(m).volume == doctest::Approx(1000 - 12 + 8));
    TriMesh keepAll = m;
    CHECK(mesh::removeCavities(keepAll, 11.9).cavities == 0);  // the pocket is larger than allowed
    CHECK(keepAll.triangles == m.triangles);
    const mesh::CavityRemoval removal = mesh::removeCavities(m, 12.1);
    CHECK(removal.cavities == 1);
    CHECK(removal.volumeMm3 == doctest::Approx(12));
    const mesh::MeshReport after = mesh::checkMesh(m);
    CHECK(after.volume == doctest::Approx(1008));
    CHECK(after.triangleCount == 24);
    CHECK(after.vertexCount == 16);
    CHECK(after.isClosed());

    TriMesh plain = solid;
    CHECK(mesh::removeCavities(plain, 1e9).cavities == 0);
    CHECK(plain.triangles == solid.triangles);
}
