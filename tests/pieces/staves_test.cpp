// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Staves where three tunnels cross at one point (docs/mounting.md, "Three tunnels through one
/// point"): a stave slides out of its nearer mouth and is lifted across its axis, it takes only
/// directions that keep its seams and its edges in the prism, and the stave pieces of a carved
/// cube are cut into rings and four staves each.
#include "zomefab/pieces/detail/staves.h"

#include <doctest/doctest.h>

#include <cmath>
#include <tuple>
#include <vector>

#include "tunnel_fixtures.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/zome/zome_system.h"

using namespace zomefab;
using namespace zomefab::pieces::detail;

namespace {

/// A planner's input of @p n staves of one tunnel along x sliding out toward +x, the p-th at
/// @p ringOf(p) = (−its ring's depth, whether a side stave, its lift's sign) in its rank.
template <class RingOf>
PlannerInput stavesAlongX(uint32_t n, RingOf ringOf) {
    PlannerInput input;
    input.pieces.resize(n);
    input.staves.resize(n);
    for (uint32_t p = 0; p < n; ++p) {
        const auto [negDepth, isSide, lift] = ringOf(p);
        Stave st;
        st.slideGrid = {1, 0, 0};
        st.isSide = isSide;
        st.rank = {0, 10.0, 20.0, 1.0, negDepth, isSide ? 0 : 1, lift};
        input.staves[p] = st;
    }
    return input;
}

}  // namespace

TEST_CASE(
    "staveOf: a stave slides out of its nearer mouth, is lifted across its axis, and takes only directions "
    "that keep its seams") {
    const VoxelField three = cubeWithTunnels(64, 10.0, {0, 1, 2}, 4.0);
    bool isTriple = false;
    const std::vector<TunnelPrism> prisms = crossingPrisms(three, 8.0, 6.0, 5.0, &isTriple, true);
    REQUIRE(prisms.size() == 3);
    CellSet set;
    set.isLining = true;
    set.ringDepthMm = 20.0;
    set.prisms.push_back({std::make_shared<const TunnelPrism>(prisms[0]), true});  // along x: u = y, v = z
    // Voxels on the tunnel's top (+z), near the high-x mouth.
    const std::vector<Vec3d> top{{50, 31.5, 43}, {55, 33, 43}, {52, 30, 44}};
    const std::optional<Stave> st = staveOf(set, top);
    REQUIRE(st.has_value());
    CHECK(st->slideGrid[0] == 1.0);
    CHECK(st->liftGrid[2] == 1.0);
    CHECK_FALSE(st->isSide);
    CHECK(std::get<4>(st->rank) == doctest::Approx(-20.0));
    // Its hole points down toward the axis; tilted toward its mouth by 20° it may be, back toward
    // the deeper staves or across its seams (along y) not.
    const double c = std::cos(20.0 * kPi / 180.0), s = std::sin(20.0 * kPi / 180.0);
    CHECK(isStaveDirection(*st, {0, 0, -1}));
    CHECK(isStaveDirection(*st, {s, 0, -c}));
    CHECK_FALSE(isStaveDirection(*st, {-s, 0, -c}));
    CHECK_FALSE(isStaveDirection(*st, {0, s, -c}));
    CHECK_FALSE(isStaveDirection(*st, {0, 0, 1}));
    // A side stave (on −y, near the low-x mouth): the same.
    const std::vector<Vec3d> side{{10, 19, 31.5}, {12, 19, 33}, {8, 20, 30}};
    const std::optional<Stave> sd = staveOf(set, side);
    REQUIRE(sd.has_value());
    CHECK(sd->slideGrid[0] == -1.0);
    CHECK(sd->liftGrid[1] == -1.0);
    CHECK(sd->isSide);
    CHECK(isStaveDirection(*sd, {0, 1, 0}));
    CHECK(isStaveDirection(*sd, {-s, c, 0}));       // toward its mouth (−x here)
    CHECK_FALSE(isStaveDirection(*sd, {0, c, s}));  // round the axis: its edges past the corners
    CHECK_FALSE(isStaveDirection(*sd, {s, c, 0}));  // toward the deeper staves (+x here)
    // First in the order by its axis; a late tunnel's stave after every axis's (TunnelPrism::priority).
    CHECK(std::get<0>(st->rank) == 0);
    TunnelPrism late = prisms[0];
    late.priority = late.axis + kLatePriority;
    CellSet lateSet = set;
    lateSet.prisms[0].prism = std::make_shared<const TunnelPrism>(late);
    const std::optional<Stave> lateStave = staveOf(lateSet, top);
    REQUIRE(lateStave.has_value());
    CHECK(std::get<0>(lateStave->rank) == kLatePriority);
    CHECK(lateStave->rank > st->rank);
    // A piece of no staved prism is no stave.
    CellSet plain;
    CHECK_FALSE(staveOf(plain, top).has_value());
}

/// The cube with three tunnels crossing, the lining the z prism keeps (it keeps every overlap) as
/// piece 0 and the rest of the shell as piece 1.
struct ZLining {
    VoxelField three;
    std::vector<TunnelPrism> prisms;
    std::vector<zomefab::pieces::Piece> pieces = std::vector<zomefab::pieces::Piece>(2);
    std::vector<CellSet> sets = std::vector<CellSet>(2);
    size_t lining = 0;  ///< its inside voxels

    explicit ZLining(double hollowWallMm = 0.0)
        : three(cubeWithTunnels(64, 10.0, {0, 1, 2}, 4.0, hollowWallMm)) {
        bool isTriple = false;
        prisms = crossingPrisms(three, 8.0, 6.0, 5.0, &isTriple, true);
        REQUIRE(prisms.size() == 3);
        const std::vector<uint32_t> owner = prismOwners(three, prisms, true);
        pieces[0].id = 0, pieces[1].id = 1;
        sets[0].isLining = true;
        sets[0].prisms.push_back({std::make_shared<const TunnelPrism>(prisms[2]), true});
        for (size_t s = 0; s < three.owner.size(); ++s)
            if (three.isInside(s)) three.owner[s] = owner[s] == 2 ? 0 : 1, lining += owner[s] == 2;
    }
};

TEST_CASE("cutStaves: a staved lining is cut at its tunnel's middle and each ring into four staves") {
    ZLining z;
    VoxelField& three = z.three;
    const std::vector<TunnelPrism>& prisms = z.prisms;
    std::vector<zomefab::pieces::Piece>& pieces = z.pieces;
    std::vector<CellSet>& sets = z.sets;
    const size_t lining = z.lining;
    REQUIRE(lining > 1000);
    // Two halves of 32 mm, one ring each (under kStaveRingMm), four staves per ring: seven cuts.
    CHECK(cutStaves(pieces, sets, three, 6.0, 0.0, 0.0) == 7);  // 64 mm: longer than a mouth ring (18 mm)
    REQUIRE(pieces.size() == 9);
    const double c = prisms[2].centerUMm, off = std::sqrt(0.5) * prisms[2].coreRadiusMm;
    std::vector<std::vector<Vec3d>> voxels(pieces.size());
    for (size_t s = 0; s < three.owner.size(); ++s)
        if (three.isInside(s)) voxels[three.owner[s]].push_back(three.world(three.coordOf(s)));
    size_t sides = 0, tops = 0;
    for (uint32_t p = 0; p < pieces.size(); ++p) {
        if (p == 1) continue;
        REQUIRE(!voxels[p].empty());
        CHECK(isStaveSet(sets[p]));
        const std::optional<Stave> st = staveOf(sets[p], voxels[p]);
        REQUIRE(st.has_value());
        CHECK(sets[p].ringDepthMm == doctest::Approx(32.0).epsilon(0.05));  // a half's far end: the middle
        // Every voxel of a stave lies on its own side of the half (z) and of the seams (x at ±off).
        const double slide = st->slideGrid[2];
        for (const Vec3d& x : voxels[p]) {
            CHECK((x[2] - 31.5) * slide >= -0.5);
            if (st->isSide)
                CHECK((x[0] - c) * st->liftGrid[0] >= off - 1e-9);
            else
                CHECK(std::abs(x[0] - c) <= off + 1e-9);
        }
        (st->isSide ? sides : tops) += 1;
    }
    CHECK(sides == 4);
    CHECK(tops == 4);
}

TEST_CASE("cutStaves: a cut that would leave less than the least volume on one side is not made") {
    ZLining z;
    const double voxelMm3 = z.three.voxelMm * z.three.voxelMm * z.three.voxelMm;
    const double ringMm3 = 0.5 * double(z.lining) * voxelMm3;  // a half of 32 mm: one ring
    // A side stave is about a quarter of its ring: with 35 % of a ring as the least, the seams across
    // u are not cut, the one across v is (halves): per ring one cut, and the middle.
    CHECK(cutStaves(z.pieces, z.sets, z.three, 6.0, 0.0, 0.35 * ringMm3) == 3);
    REQUIRE(z.pieces.size() == 5);
    std::vector<size_t> count(z.pieces.size(), 0);
    for (size_t s = 0; s < z.three.owner.size(); ++s)
        if (z.three.isInside(s)) ++count[z.three.owner[s]];
    for (uint32_t p = 0; p < z.pieces.size(); ++p) {
        if (p == 1) continue;  // the rest of the shell
        CHECK(isStaveSet(z.sets[p]));
        CHECK(double(count[p]) * voxelMm3 >= 0.35 * ringMm3);
    }
    // The tunnel of the staves a plan places nowhere, once: made late in another attempt.
    std::vector<int> holes(z.pieces.size(), -1);
    const std::vector<TunnelKey> unheld = unheldTunnels(holes, z.sets);
    REQUIRE(unheld.size() == 1);
    CHECK(unheld[0].axis == 2);
    CHECK(isTunnelOf(unheld[0], z.prisms[2], 0.01));
    for (int& h : holes) h = 0;
    CHECK(unheldTunnels(holes, z.sets).empty());
    // With no least volume, the same lining is cut into eight staves.
    ZLining all;
    CHECK(cutStaves(all.pieces, all.sets, all.three, 6.0, 0.0, 0.0) == 7);
}

TEST_CASE("cutStaves: a lining at a mouth no longer than a mouth ring stays one ring") {
    ZLining z;
    std::vector<CellSet>& sets = z.sets;
    // The z lining runs from mouth to mouth, 63 mm between its voxels' centres: under three walls of 24 mm.
    CHECK(cutStaves(z.pieces, sets, z.three, 24.0, 0.0, 0.0) == 0);
    REQUIRE(z.pieces.size() == 2);
    CHECK(sets[0].isMouthRing);
    CHECK(sets[0].ringDepthMm == doctest::Approx(63.0).epsilon(0.05));
    CHECK(isStavedLining(sets[0]));
    CHECK_FALSE(isStaveSet(sets[0]));
    CHECK_FALSE(staveOf(sets[0], {Vec3d{31.5, 31.5, 31.5}}).has_value());
    CHECK_FALSE(isStavedLining(sets[1]));
}

TEST_CASE("staveUnderThinWall: a stave whose face lies a little hollow away") {
    // A hollow cube with walls of 4 mm: between the z tunnel's lining (radius 10 to 14 mm round the
    // middle, 31.5 mm) and the faces' walls (from 60 mm) lies a hollow about 14 mm across.
    ZLining z(4.0);
    REQUIRE(cutStaves(z.pieces, z.sets, z.three, 6.0, 0.0, 0.0) == 7);  // no gap: cut square to the grid
    std::vector<std::vector<Vec3d>> voxels(z.pieces.size());
    for (size_t s = 0; s < z.three.owner.size(); ++s)
        if (z.three.isInside(s)) voxels[z.three.owner[s]].push_back(z.three.world(z.three.coordOf(s)));
    size_t near = 0, far = 0, staves = 0;
    for (uint32_t p = 0; p < z.pieces.size(); ++p) {
        const std::optional<Stave> st = staveOf(z.sets[p], voxels[p]);
        if (!st) continue;
        ++staves;
        near += staveUnderThinWall(*st, p, voxels[p], z.three, 24.0) ? 1 : 0;
        far += staveUnderThinWall(*st, p, voxels[p], z.three, 4.0) ? 1 : 0;
    }
    CHECK(staves == 8);
    CHECK(near == 8);
    CHECK(far == 0);
    CHECK(ballGapMm(8.75, 19.0, 16.0) == doctest::Approx(23.5));
    // A plan that places every stave nowhere: its first problem says how many, and how many are thin.
    zomefab::pieces::Pieces out;
    out.pieces = z.pieces;
    out.plan.holeOfPiece.assign(out.pieces.size(), -1);
    CHECK(noteUnheldStaves(out, z.sets, z.three, 24.0) == 8);
    REQUIRE_FALSE(out.plan.problems.empty());
    const std::string& first = out.plan.problems[0];
    CHECK(first.find("8 of the 8 staves lining them have no peg") != std::string::npos);
    CHECK(first.find(
              "8 of them under a wall too thin for a ball behind them (another wall less than 24.0 mm") !=
          std::string::npos);
    CHECK(out.crossingTunnelPieces == 8);
    zomefab::pieces::Pieces thick;
    thick.pieces = z.pieces;
    thick.plan.holeOfPiece.assign(thick.pieces.size(), -1);
    CHECK(noteUnheldStaves(thick, z.sets, z.three, 4.0) == 8);
    CHECK(thick.plan.problems[0].find("too thin") == std::string::npos);
}

TEST_CASE("cutStaves: a lining under a face's thin wall is cut into staves turned 45° about its axis") {
    // The hollow cube of 4 mm walls: square to the grid each stave faces a face's wall 14 to 18 mm of
    // hollow away, along a diagonal 19 to 24 mm; a ball needing 18 mm fits only there.
    ZLining z(4.0);
    REQUIRE(cutStaves(z.pieces, z.sets, z.three, 6.0, 18.0, 0.0) == 7);
    std::vector<std::vector<Vec3d>> voxels(z.pieces.size());
    for (size_t s = 0; s < z.three.owner.size(); ++s)
        if (z.three.isInside(s)) voxels[z.three.owner[s]].push_back(z.three.world(z.three.coordOf(s)));
    const Vec3d c{z.prisms[2].centerUMm, z.prisms[2].centerVMm, 0.0};
    const double off = std::sqrt(0.5) * z.prisms[2].coreRadiusMm;
    size_t staves = 0, thin = 0, sides = 0;
    for (uint32_t p = 0; p < z.pieces.size(); ++p) {
        const std::optional<Stave> st = staveOf(z.sets[p], voxels[p]);
        if (!st) continue;
        ++staves;
        CHECK(z.sets[p].isStaveTurned);
        // Lifted along a diagonal of x and y, across the z axis.
        CHECK(std::abs(st->liftGrid[0]) == doctest::Approx(std::sqrt(0.5)));
        CHECK(std::abs(st->liftGrid[1]) == doctest::Approx(std::sqrt(0.5)));
        CHECK(st->liftGrid[2] == 0.0);
        // A side stave lies beyond its seam, across its lift; top and bottom between the seams.
        for (const Vec3d& x : voxels[p]) {
            const Vec3d r{x[0] - c[0], x[1] - c[1], 0.0};
            if (st->isSide)
                CHECK(dot(r, st->liftGrid) >= off - 1e-9);
            else
                CHECK(std::abs(dot(r, st->seamGrid)) <= off + 1e-9);
        }
        sides += st->isSide ? 1 : 0;
        thin += staveUnderThinWall(*st, p, voxels[p], z.three, 18.0) ? 1 : 0;
    }
    CHECK(staves == 8);
    CHECK(sides == 4);
    CHECK(thin == 0);  // square to the grid all 8 would (14 to 18 mm)
    // The lean a turned stave needs: a yellow hole (±1, ±1, ±1) beside its diagonal.
    CHECK(std::acos(std::sqrt(2.0 / 3.0)) * 180.0 / kPi < kStaveLeanDeg);
}

TEST_CASE(
    "markCrossings and splitMm: where three tunnels cross, a lining is split at the crossing nearest "
    "its middle") {
    ZLining z;
    std::vector<TunnelPrism> prisms = z.prisms;
    markCrossings(prisms);
    for (const TunnelPrism& p : prisms) {
        REQUIRE(p.crossingsMm.size() == 1);  // the other two cross at one point
        CHECK(p.crossingsMm[0].first == doctest::Approx(31.5).epsilon(0.02));
        CHECK(p.splitMm() == doctest::Approx(31.5).epsilon(0.02));
    }
    // The cheese at 700 mm: a tunnel along z crossed at 87.5, 262.5, 437.5 and 612.5 mm.
    TunnelPrism t;
    t.axis = 2, t.loMm = 0.0, t.hiMm = 700.0;
    CHECK(t.splitMm() == 350.0);
    t.crossingsMm = {{87.5, 42.0}, {262.5, 42.0}, {437.5, 42.0}, {612.5, 42.0}};
    CHECK(t.splitMm() == 262.5);  // a tie: the lower
}

TEST_CASE("isMouthRingExtent: a lining between a face and the first crossing with no room for a ball") {
    TunnelPrism t;
    t.axis = 2, t.loMm = 0.0, t.hiMm = 700.0, t.voxelMm = 1.0;
    t.crossingsMm = {{87.5, 42.0}, {262.5, 42.0}, {437.5, 42.0}, {612.5, 42.0}};
    // 87.5 mm from the face to the crossing's axis, 42 mm to its wall, two walls of 16 mm: 13.5 mm of
    // hollow, less than a ball's 23.7.
    CHECK(isMouthRingExtent(t, 0.0, 77.0, 1.0, 16.0, 23.7));
    CHECK(isMouthRingExtent(t, 623.0, 700.0, 1.0, 16.0, 23.7));
    CHECK_FALSE(isMouthRingExtent(t, 0.0, 77.0, 1.0, 16.0, 10.0));    // a ball fits: 77 mm is 4.8 walls
    CHECK_FALSE(isMouthRingExtent(t, 98.0, 252.0, 1.0, 16.0, 23.7));  // at no mouth
    CHECK_FALSE(isMouthRingExtent(t, 0.0, 100.0, 1.0, 16.0, 23.7));   // past the crossing
    CHECK(isMouthRingExtent(t, 0.0, 40.0, 1.0, 16.0, 10.0));          // within three walls
    // The three-tunnel cube: 150 mm from a face to a crossing 90 mm across, room for a ball.
    TunnelPrism cube;
    cube.axis = 0, cube.loMm = 0.0, cube.hiMm = 300.0;
    cube.crossingsMm = {{150.0, 45.0}};
    CHECK_FALSE(isMouthRingExtent(cube, 0.0, 87.0, 1.0, 16.0, 23.7));
}

TEST_CASE(
    "glueStavesInPlace: a stave no hole holds slides to its place after its ring and is glued onto it") {
    // Two rings of a tunnel along x sliding out toward +x: pieces 0-3 the deeper ring (0, 1 sides;
    // 2, 3 top and bottom), 4-7 the shallower. Holes hold all but 2 and 3 (2 shares seams with both
    // held sides, 3 only with 2: a chain) and 6 (no seam large enough with a stave on before it).
    const PlannerInput input = stavesAlongX(8, [](uint32_t p) {
        const bool isSide = p % 4 < 2;
        return std::make_tuple(p < 4 ? -160.0 : -80.0, isSide, p % 2 ? -1.0 : 1.0);
    });
    FaceContacts faces;
    auto seam = [&](uint32_t a, uint32_t b, size_t voxelFaces) {
        faces[{std::min(a, b), std::max(a, b)}].push_back({{0, 1, 0}, voxelFaces, true});
    };
    seam(0, 2, 900), seam(1, 2, 900), seam(2, 3, 900);
    seam(4, 6, 100), seam(5, 6, 100);  // under 150 mm²
    StaveOrder order{{0, 1, 2, 3, 4, 5, 6, 7}, {7, 7, -1, -1, 7, 7, -1, 7}, {}};
    const Transform4d identity = Transform4d::identity();
    const std::vector<size_t> perm = glueStavesInPlace(order, input, faces, identity, 1.0);
    // The deeper ring first: its held staves, then 2, then 3 on it; 6 stays unheld after 4, 5, 7.
    CHECK(perm == std::vector<size_t>{0, 1, 2, 3, 4, 5, 7, 6});
    CHECK(order.pieces == std::vector<uint32_t>{0, 1, 2, 3, 4, 5, 7, 6});
    REQUIRE(order.hosts.size() == 8);
    CHECK(order.hosts[2] == std::vector<uint32_t>{0, 1});
    CHECK(order.hosts[3] == std::vector<uint32_t>{2});
    CHECK(order.holes[2] >= 0);
    // Its hole lies along its slide (it is taken off out of its mouth, straight).
    CHECK(dot(gridDirection(order.holes[2], identity), Vec3d{1, 0, 0}) == doctest::Approx(1.0));
    CHECK(order.holes[7] == -1);
    CHECK(order.hosts[7].empty());
    // Its step: one leg along that hole, glued onto both sides.
    mount::InstallationPlan plan;
    plan.holeOfPiece.assign(8, -1);
    order.holes[7] = 7;  // (as if a hole held it: a plan with no problem)
    addStaveSteps(plan, input, order, identity);
    REQUIRE(plan.steps.size() == 8);
    CHECK(plan.steps[2].pieces == std::vector<uint32_t>{2});
    CHECK_FALSE(plan.steps[2].hasTwoLegs());
    CHECK(plan.steps[0].hasTwoLegs());
    CHECK(plan.gluedOn == std::vector<std::pair<uint32_t, uint32_t>>{{0, 2}, {1, 2}, {2, 3}});
    plan.holeOfPiece[2] = order.holes[2];
    CHECK(isGluedOn(plan, 2));
    CHECK_FALSE(isGluedOn(plan, 0));
}

TEST_CASE("orderStaveRings: a ring with a stave no hole holds waits for the staves it can be glued onto") {
    // Three rings of one stave each, in rank order: ring 0's stave (0) no hole holds, and its only
    // seam is with ring 2's stave (2); rings 1 and 2 are held, ring 1 in ring 2's way.
    StaveRings g;
    g.ringOf = {0, 1, 2};
    g.later = {{}, {2}, {}};
    g.isHeld = {0, 1, 1};
    g.canSlideIn = {1, 1, 1};
    g.seamMates = {{2}, {}, {0}};
    size_t cycles = 9;
    CHECK(orderStaveRings(g, &cycles) == std::vector<size_t>{1, 2, 0});
    CHECK(cycles == 0);
    // With ring 2 in ring 0's way out, ring 0 goes on before it all the same (and stays unheld).
    g.later = {{2}, {2}, {}};
    CHECK(orderStaveRings(g) == std::vector<size_t>{1, 0, 2});
    // A stave that cannot slide in (no hole along its slide) is glued onto nothing: its ring goes
    // last, where it keeps nothing waiting.
    g.later = {{}, {2}, {}};
    g.canSlideIn = {0, 1, 1};
    CHECK(orderStaveRings(g) == std::vector<size_t>{1, 2, 0});
    // Rings in each other's way: the first left in rank order goes on, and the cycle is counted.
    g.canSlideIn = {1, 1, 1};
    g.later = {{1}, {0}, {}};
    CHECK(orderStaveRings(g, &cycles) == std::vector<size_t>{2, 0, 1});
    CHECK(cycles == 1);
}

TEST_CASE("orderStaveRings: a ring's staves glued round the ring count as held; the rest keep rank order") {
    // Ring 0: staves 0 (held), 1 (glued onto 0), 2 (glued onto 1: a chain); ring 1: stave 3, held.
    StaveRings g;
    g.ringOf = {0, 0, 0, 1};
    g.later = {{}, {}};
    g.isHeld = {1, 0, 0, 1};
    g.canSlideIn = {1, 1, 1, 1};
    g.seamMates = {{1}, {0, 2}, {1}, {}};
    CHECK(orderStaveRings(g) == std::vector<size_t>{0, 1, 2, 3});
    // A stave of ring 0 that is only glued onto a stave that is itself unheld waits for nothing.
    g.isHeld = {0, 0, 0, 1};
    g.seamMates = {{}, {2}, {1}, {}};
    CHECK(orderStaveRings(g) == std::vector<size_t>{3, 0, 1, 2});
}

TEST_CASE("addStaveSteps: staves go on among the other steps where the disassembly put them") {
    // Staves 0 (held, slid in and lifted) and 1 (glued in place onto 0); the plan's own steps are
    // pieces 5 and 6. Slots: stave 0 first, then piece 5, stave 1, piece 6.
    PlannerInput input = stavesAlongX(7, [](uint32_t) { return std::make_tuple(-10.0, true, 1.0); });
    mount::InstallationPlan plan;
    plan.steps = {{{5}, 3}, {{6}, 4}};
    const StaveOrder order{{0, 1}, {7, 8}, {{}, {0}}};
    addStaveSteps(plan, input, order, Transform4d::identity(), {{0, 0}, {1, 1}});
    REQUIRE(plan.steps.size() == 4);
    CHECK(plan.steps[0].pieces == std::vector<uint32_t>{0});
    CHECK(plan.steps[0].hasTwoLegs());
    CHECK(plan.steps[1].pieces == std::vector<uint32_t>{5});
    CHECK(plan.steps[2].pieces == std::vector<uint32_t>{1});
    CHECK_FALSE(plan.steps[2].hasTwoLegs());
    CHECK(plan.steps[3].pieces == std::vector<uint32_t>{6});
    CHECK(plan.gluedOn == std::vector<std::pair<uint32_t, uint32_t>>{{0, 1}});
    // No slots: every stave first, in the order's order.
    mount::InstallationPlan first;
    first.steps = {{{5}, 3}};
    addStaveSteps(first, input, order, Transform4d::identity());
    REQUIRE(first.steps.size() == 3);
    CHECK(first.steps[0].pieces == std::vector<uint32_t>{0});
    CHECK(first.steps[1].pieces == std::vector<uint32_t>{1});
    CHECK(first.steps[2].pieces == std::vector<uint32_t>{5});
}

TEST_CASE("fixedStaves: a ring is a run of staves of one ring, hosts by their index") {
    const PlannerInput input = stavesAlongX(
        3, [](uint32_t p) { return std::make_tuple(p < 2 ? -20.0 : -10.0, p != 1, p == 0 ? 1.0 : -1.0); });
    const StaveOrder order{{0, 1, 2}, {7, 7, 8}, {{}, {}, {0}}};
    const FixedStaves f = fixedStaves(order, input);
    CHECK(f.ringOf == std::vector<size_t>{0, 0, 1});
    CHECK(f.hosts == std::vector<std::vector<size_t>>{{}, {}, {0}});
    REQUIRE(f.slideGrid.size() == 3);
    CHECK(f.slideGrid[2][0] == 1.0);
}

TEST_CASE("staveRings: a stave in another's way out along its tunnel puts that one's ring later") {
    // A tunnel along x whose staves slide out toward +x: stave 0 deep (x 0-10), stave 1 shallower
    // in the same columns (x 20-30), stave 2 shallower still but beside them (y 20-30).
    auto box = [](uint32_t p, double x0, double y0) {
        MountBody b;
        b.pieces = {p};
        for (double x = x0; x <= x0 + 10; x += 1.0)
            for (double y = y0; y <= y0 + 10; y += 1.0)
                for (double z = 0; z <= 10; z += 1.0) {
                    b.voxels.push_back({x, y, z});
                    b.nearCutOf.push_back({kNone, kNone});
                    b.cutLayer.push_back({0, 0});
                    b.bounds.expand({x, y, z});
                }
        return b;
    };
    const std::vector<MountBody> bodies{box(0, 0, 0), box(1, 20, 0), box(2, 40, 20)};
    const PlannerInput input =
        stavesAlongX(3, [](uint32_t p) { return std::make_tuple(-100.0 + 30.0 * p, true, 1.0); });
    const StaveOrder order{{0, 1, 2}, {7, 7, -1}, {}};
    const StaveRings g = staveRings(order, bodies, input, {}, Transform4d::identity(), 1.0);
    CHECK(g.ringOf == std::vector<size_t>{0, 1, 2});
    REQUIRE(g.later.size() == 3);
    CHECK(g.later[0] == std::vector<size_t>{1});
    CHECK(g.later[1].empty());
    CHECK(g.later[2].empty());
    CHECK(g.isHeld == std::vector<uint8_t>{1, 1, 0});
    CHECK(g.canSlideIn == std::vector<uint8_t>{1, 1, 1});  // a blue hole along x
}

TEST_CASE("mouthRingSlide: a mouth ring slides out of the mouth on its side of the tunnel's split") {
    auto prism = std::make_shared<TunnelPrism>();
    prism->axis = 2, prism->loMm = 0.0, prism->hiMm = 700.0;
    prism->isStaved = true;
    CellSet ring;
    ring.isLining = true;
    ring.isMouthRing = true;
    ring.prisms = {{prism, true}};
    const std::vector<Vec3d> top{{0, 0, 650}, {0, 0, 690}}, bottom{{0, 0, 10}, {0, 0, 70}};
    REQUIRE(mouthRingSlide(ring, top).has_value());
    CHECK(*mouthRingSlide(ring, top) == Vec3d{0, 0, 1});
    CHECK(*mouthRingSlide(ring, bottom) == Vec3d{0, 0, -1});
    // A stave, or a lining of a prism not staved, is no mouth ring.
    ring.isMouthRing = false;
    CHECK_FALSE(mouthRingSlide(ring, top).has_value());
    ring.isMouthRing = true;
    prism->isStaved = false;
    CHECK_FALSE(mouthRingSlide(ring, top).has_value());
}
