// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The mount module alone (docs/mounting.md): depth rasters tell a body pushed along +d from
/// one that would hit an obstacle ahead, beside or behind it; a cut face orders its two pieces;
/// the mounting order respects the blocking relation and reports a cycle (two pieces that block
/// each other) instead of an order.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "zomefab/core/vec.h"
#include "zomefab/mount/plan.h"
#include "zomefab/mount/sweep.h"

using namespace zomefab;
using namespace zomefab::mount;

namespace {

Box3d box(const Vec3d& lo, const Vec3d& hi) {
    Box3d b;
    b.expand(lo);
    b.expand(hi);
    return b;
}

/// A 10 mm square plate in the plane z = z0 (two triangles), the moving body.
void addPlate(DepthRaster& r, double z0, uint32_t id) {
    r.addTriangle({-5, -5, z0}, {5, -5, z0}, {5, 5, z0}, 0.0, id);
    r.addTriangle({-5, -5, z0}, {5, 5, z0}, {-5, 5, z0}, 0.0, id);
}

/// Does the plate at z = 0, pushed along +z (as far as @p reachMm; 0: without end), hit a sphere
/// of radius 2 at @p center?
SweepHit plateAgainstSphere(const Vec3d& center, double reachMm = 0.0) {
    const SweepAxes axes({0, 0, 1});
    const DepthRaster obstacles(axes, box({-40, -40, -40}, {40, 40, 40}), 0.5, true);
    DepthRaster frame = obstacles;
    DepthRaster body(obstacles, box({-6, -6, -1}, {6, 6, 1}), false),
        far(obstacles, box({-6, -6, -1}, {6, 6, 1}), true);
    addPlate(body, 0.0, 3);
    addPlate(far, 0.0, 3);
    if (reachMm > 0) frame.limitReach(far, reachMm);
    frame.addSphere(center, 2.0, 0.0, 7);
    return worstHit(frame, body, 0.0);
}

}  // namespace

TEST_CASE("mount: sweep axes are orthonormal and right-handed for any direction") {
    for (const Vec3d& d : {Vec3d{0, 0, 1}, Vec3d{1, 2, 3}, Vec3d{-1, 0, 0}, Vec3d{0.3, -0.9, 0.1}}) {
        const SweepAxes a(d);
        CHECK(norm(a.u) == doctest::Approx(1));
        CHECK(norm(a.v) == doctest::Approx(1));
        CHECK(dot(a.u, a.v) == doctest::Approx(0).epsilon(1e-12));
        CHECK(dot(a.u, a.d) == doctest::Approx(0).epsilon(1e-12));
        CHECK(dot(cross(a.u, a.v), a.d) == doctest::Approx(1));
        CHECK(dot(a.d, normalized(d)) == doctest::Approx(1));
    }
}

TEST_CASE("mount: a body pushed along +d hits what lies ahead of it, not what is beside or behind") {
    const SweepHit ahead = plateAgainstSphere({1, 1, 30});
    CHECK(ahead.isHit);
    CHECK(ahead.obstacle == 7);
    CHECK(ahead.mover == 3);
    CHECK(ahead.overlapMm > 27.9);  // the sphere reaches 28–32 mm ahead of the plate
    CHECK(ahead.overlapMm < 32.1);
    CHECK_FALSE(plateAgainstSphere({1, 1, -30}).isHit);  // behind: the path leaves it
    CHECK_FALSE(plateAgainstSphere({9, 0, 30}).isHit);   // beside: 9 − 2 > 5, its shadow misses
    CHECK(plateAgainstSphere({6.5, 0, 30}).isHit);       // its shadow overlaps the plate's edge
}

TEST_CASE("mount: a body pushed only so far (a stave's lift) hits what it reaches, not what lies beyond") {
    CHECK(plateAgainstSphere({1, 1, 30}).isHit);             // without end: the sphere 28 mm ahead
    CHECK_FALSE(plateAgainstSphere({1, 1, 30}, 8.0).isHit);  // 8 mm: short of it
    CHECK(plateAgainstSphere({1, 1, 9}, 8.0).isHit);         // its near side 7 mm ahead: met
    const SweepHit clipped = plateAgainstSphere({1, 1, 9}, 8.0);
    CHECK(clipped.overlapMm <= 8.0 + 1e-6);                   // counted only as far as the reach
    CHECK_FALSE(plateAgainstSphere({1, 1, -30}, 8.0).isHit);  // behind: still not
    CHECK_FALSE(plateAgainstSphere({9, 0, 5}, 8.0).isHit);    // beside: its shadow misses
}

TEST_CASE("mount: an edge-on face draws nothing unless grown; a window shares the pixel lattice") {
    const SweepAxes axes({0, 0, 1});
    DepthRaster r(axes, box({-10, -10, -10}, {10, 10, 10}), 0.5, true);
    r.addTriangle({0, -5, -5}, {0, 5, -5}, {0, 0, 5}, 0.0, 1);  // contains the direction
    int drawn = 0;
    for (int j = 0; j < r.height(); ++j)
        for (int i = 0; i < r.width(); ++i) drawn += std::isfinite(r.depth(i, j)) ? 1 : 0;
    CHECK(drawn == 0);
    r.addTriangle({0, -5, -5}, {0, 5, -5}, {0, 0, 5}, 0.5, 1);
    for (int j = 0; j < r.height(); ++j)
        for (int i = 0; i < r.width(); ++i) drawn += std::isfinite(r.depth(i, j)) ? 1 : 0;
    CHECK(drawn > 0);
    const DepthRaster w(r, box({2, 3, 0}, {4, 5, 1}), false);
    const double di = (w.u0() - r.u0()) / r.pixelMm(), dj = (w.v0() - r.v0()) / r.pixelMm();
    CHECK(di == doctest::Approx(std::round(di)).epsilon(1e-9));
    CHECK(dj == doctest::Approx(std::round(dj)).epsilon(1e-9));
    CHECK(w.width() < r.width());
}

TEST_CASE("mount: a cut face lets a piece slide along it or leave it, never go into its neighbour") {
    const Vec3d n{0, 0, 1};  // from a into b
    // b pushed on along −d_b: with d_b = +z it comes from above, away from a: b after a is fine;
    // a with d_a = +z would have to come down through b, so a must go first.
    FaceOrder f = faceOrder(n, {0, 0, 1}, {0, 0, 1});
    CHECK(f.isBAfterAOk);
    CHECK_FALSE(f.isAAfterBOk);
    f = faceOrder(n, {0, 0, -1}, {0, 0, 1});  // each leaves the face: either order
    CHECK(f.isBAfterAOk);
    CHECK(f.isAAfterBOk);
    f = faceOrder(n, {0, 0, 1}, {0, 0, -1});  // each would go into the other: no order
    CHECK_FALSE(f.isBAfterAOk);
    CHECK_FALSE(f.isAAfterBOk);
    f = faceOrder(n, {1, 0, 0}, {0, 1, 0});  // sliding along the face
    CHECK(f.isBAfterAOk);
    CHECK(f.isAAfterBOk);
    const Vec3d tilted = normalized({1, 0, -0.01});  // 0.6° into a
    CHECK_FALSE(faceOrder(n, {0, 0, -1}, tilted).isBAfterAOk);
    CHECK(faceOrder(n, {0, 0, -1}, tilted, 0.02).isBAfterAOk);
}

TEST_CASE("mount: the mounting order respects every constraint; a cycle gives no order") {
    const std::vector<std::pair<uint32_t, uint32_t>> before{{2, 0}, {0, 1}, {3, 1}};
    const std::vector<uint32_t> order = mountingOrder(4, before, {0, 0, 0, 0});
    REQUIRE(order.size() == 4);
    auto at = [&](uint32_t b) { return std::find(order.begin(), order.end(), b) - order.begin(); };
    for (const auto& [a, b] : before) CHECK(at(a) < at(b));
    CHECK(order == std::vector<uint32_t>{2, 0, 3, 1});  // lowest id among the ready ones
    // Priority decides among the ready bodies: 3 before 2 now.
    CHECK(mountingOrder(4, before, {5, 5, 5, 1}) == std::vector<uint32_t>{3, 2, 0, 1});

    // Two pieces that block each other (and one that waits on them): no order, the cycle named.
    std::vector<uint32_t> cycle;
    CHECK(mountingOrder(3, {{0, 1}, {1, 0}, {1, 2}}, {0, 0, 0}, &cycle).empty());
    std::sort(cycle.begin(), cycle.end());
    CHECK(cycle == std::vector<uint32_t>{0, 1});
}
