// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The mounting order (docs/mounting.md, "Order"): the disassembly finds an order whenever
/// one exists for some choice of directions, names the bodies that keep each other from any, and
/// places a body no peg can hold after a piece it can be glued onto. Bodies are built by hand:
/// slabs of voxel centres with their direction options and cut faces.
#include "zomefab/pieces/detail/mounting.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/pieces/detail/replan.h"
#include "zomefab/zome/holes.h"

using namespace zomefab;
using namespace zomefab::pieces::detail;

namespace {

const int kUp = zome::nearestHole({0, 0, 1});
const int kDown = zome::nearestHole({0, 0, -1});
const int kRight = zome::nearestHole({1, 0, 0});

/// A body of one piece: a slab of 1 mm voxels over [x0, x1] × [0, 10] × [z0, z1], every voxel on
/// its surface (the planner only ever asks for those).
MountBody slab(uint32_t piece, double x0, double x1, double z0, double z1) {
    MountBody b;
    b.pieces = {piece};
    for (double x = x0; x <= x1 + 1e-9; x += 1.0)
        for (double y = 0; y <= 10 + 1e-9; y += 1.0)
            for (double z = z0; z <= z1 + 1e-9; z += 1.0) {
                b.voxels.push_back({x, y, z});
                b.nearCutOf.push_back({kNone, kNone});
                b.cutLayer.push_back({0, 0});
                b.bounds.expand({x, y, z});
            }
    return b;
}

/// Every voxel of @p a near its cut face with @p b and the other way round (in the planner, the
/// voxels within two of the seam): the face, not the sweep, orders the two.
void nearEachOther(MountBody& a, MountBody& b) {
    for (auto [m, other] : {std::pair{&a, &b}, std::pair{&b, &a}})
        for (size_t i = 0; i < m->voxels.size(); ++i) {
            const size_t k = m->nearCutOf[i][0] == kNone ? 0 : 1;
            m->nearCutOf[i][k] = other->pieces[0], m->cutLayer[i][k] = 1;
        }
}

/// Marks the voxels of @p m where @p isNear holds as @p layer layers from its cut face with piece
/// @p other (1: on it), as the planner marks them.
template <class IsNear>
void markNear(MountBody& m, uint32_t other, IsNear isNear, uint8_t layer = 1) {
    for (size_t i = 0; i < m.voxels.size(); ++i)
        if (isNear(m.voxels[i])) m.nearCutOf[i][0] = other, m.cutLayer[i][0] = layer;
}

/// A direction the body could take: free of the frame, with @p tenons tenons.
DirectionOption option(int hole, size_t tenons) {
    DirectionOption o;
    o.hole = hole;
    o.tenons = tenons;
    o.isTested = true;
    o.isFree = true;
    return o;
}

Disassembly disassembleAll(const std::vector<MountBody>& bodies, const FaceContacts& faces = {}) {
    SweepCache cache;
    return disassemble(bodies, faces, Transform4d::identity(), 1.0, GlueOnRule{}, cache, RunContext::silent());
}

}  // namespace

TEST_CASE("mounting: a body in another's path goes on first") {
    // B lies under A; B comes down from above (pushed off upward), so it must pass A's place first.
    MountBody a = slab(0, 0, 10, 20, 25), b = slab(1, 0, 10, 0, 5);
    a.options = {option(kUp, 2)};
    b.options = {option(kUp, 2)};
    const Disassembly d = disassembleAll({a, b});
    CHECK(d.stuck.empty());
    REQUIRE(d.order.size() == 2);
    CHECK(d.order[0] == 1);
    CHECK(d.order[1] == 0);
    CHECK(d.holes[0] == kUp);
    CHECK(d.holes[1] == kUp);
    CHECK(std::count(d.before.begin(), d.before.end(), std::make_pair(uint32_t(1), uint32_t(0))) == 1);
}

TEST_CASE("mounting: each body takes a direction that lets an order exist, not its best one") {
    // A's best direction (down) runs into B below it; its second (up) is free. B can only go up,
    // through A's place. The only order: B first (up), then A (up).
    MountBody a = slab(0, 0, 10, 20, 25), b = slab(1, 0, 10, 0, 5);
    a.options = {option(kDown, 4), option(kUp, 1)};
    b.options = {option(kUp, 2)};
    const Disassembly d = disassembleAll({a, b});
    CHECK(d.stuck.empty());
    CHECK(d.holes[0] == kUp);
    REQUIRE(d.order.size() == 2);
    CHECK(d.order.front() == 1);
}

TEST_CASE("mounting: two bodies in each other's way along every direction are stuck, and named") {
    MountBody a = slab(0, 0, 10, 0, 5), b = slab(1, 0, 10, 20, 25);
    a.options = {option(kUp, 2)};    // runs into B
    b.options = {option(kDown, 2)};  // runs into A
    const Disassembly d = disassembleAll({a, b});
    CHECK(d.order.empty());
    CHECK(d.stuck == std::vector<uint32_t>{0, 1});
    REQUIRE(d.stuckBlockers.size() == 2);
    CHECK(d.stuckBlockers[0] == std::vector<uint32_t>{1});
    CHECK(d.stuckBlockers[1] == std::vector<uint32_t>{0});
    CHECK(d.holes[0] == -1);
}

TEST_CASE("mounting: a body slides past the voxels of one beside it, on either side") {
    // B (x 0 to 10) pushed off upward passes A (x 11 to 21) beside it, a voxel apart; A pushed off
    // to the left runs into B. A second part of A (x -10 to -5) makes their shadows meet, so they
    // are swept. The only order: A first, then B. With the voxel centres on the raster's pixel
    // corners, A's voxels covered B's last column too (on one side), and neither could go.
    MountBody a = slab(0, 11, 21, 5, 15), b = slab(1, 0, 10, 0, 10);
    a.addVoxelsOf(slab(0, -10, -5, 5, 15));
    a.options = {option(zome::nearestHole({-1, 0, 0}), 2)};
    b.options = {option(kUp, 2)};
    const Disassembly d = disassembleAll({a, b});
    CHECK(d.stuck.empty());
    CHECK(d.order == std::vector<uint32_t>{0, 1});
    // Mirrored (B on A's right, A pushed off to the right): the same.
    MountBody a2 = slab(0, 0, 10, 5, 15), b2 = slab(1, 11, 21, 0, 10);
    a2.addVoxelsOf(slab(0, 27, 32, 5, 15));
    a2.options = {option(kRight, 2)};
    b2.options = {option(kUp, 2)};
    const Disassembly e = disassembleAll({a2, b2});
    CHECK(e.stuck.empty());
    CHECK(e.order == std::vector<uint32_t>{0, 1});
    // A voxel of B in A's column is met: B one voxel wider, into x = 11.
    MountBody b3 = slab(1, 0, 11, 0, 10);
    b3.options = {option(kUp, 2)};
    CHECK(disassembleAll({a, b3}).stuck.size() == 2);
}

TEST_CASE("mounting: a cut face lets the neighbour slide along it or leave it, never go into it") {
    // A and B side by side, touching across the plane x = 10.5 (normal from A into B: +x).
    MountBody a = slab(0, 0, 10, 0, 10), b = slab(1, 11, 21, 0, 10);
    nearEachOther(a, b);
    const FaceContacts faces = {{{0, 1}, {CutContact{{1, 0, 0}, 121}}}};
    a.options = {option(kRight, 2)};  // A pushed off to the right goes into B: A first
    b.options = {option(kUp, 2)};     // B slides off along the face
    const Disassembly d = disassembleAll({a, b}, faces);
    CHECK(d.stuck.empty());
    REQUIRE(d.order.size() == 2);
    CHECK(d.order[0] == 0);
    // Both pushed into each other: stuck by the face alone.
    b.options = {option(zome::nearestHole({-1, 0, 0}), 2)};
    CHECK(disassembleAll({a, b}, faces).stuck.size() == 2);
}

TEST_CASE("mounting: a body no peg can hold is glued onto a piece put on before it") {
    // C (no tenons) sits on top of A, across the plane z = 10.5; it goes on from above after A.
    MountBody a = slab(0, 0, 10, 0, 10), c = slab(1, 0, 10, 11, 15);
    nearEachOther(a, c);
    const FaceContacts faces = {{{0, 1}, {CutContact{{0, 0, 1}, 400}}}};
    a.options = {option(kRight, 2)};
    c.glueOptions = {option(kRight, 0), option(kUp, 0)};
    c.glueOptions[0].isFree = false;  // the frame is in the way to the right
    REQUIRE(c.isHosted());
    const Disassembly d = disassembleAll({a, c}, faces);
    CHECK(d.stuck.empty());
    REQUIRE(d.order.size() == 2);
    CHECK(d.order[0] == 0);
    CHECK(d.holes[1] == kUp);
    CHECK(d.gluedOn == std::vector<std::pair<uint32_t, uint32_t>>{{0, 1}});
    // A face too small to glue on, or met too obliquely, gives it nothing to hold on to.
    const FaceContacts tiny = {{{0, 1}, {CutContact{{0, 0, 1}, 20}}}};
    CHECK(disassembleAll({a, c}, tiny).holes[1] == -1);
    c.glueOptions = {option(kRight, 0)};
    CHECK(disassembleAll({a, c}, faces).holes[1] == -1);
}

TEST_CASE("mounting: a mouth ring slid into its mouth is glued on across a face along its way") {
    // A holds; C lies beside A across the plane x = 10.5 and can only leave upward, along that face:
    // the 60° rule finds no face to glue it on across; as a mouth ring leaving its mouth upward (a
    // sleeve glued round its outside) it goes on after A, glued onto it.
    MountBody a = slab(0, 0, 10, 0, 10), c = slab(1, 11, 21, 0, 10);
    nearEachOther(a, c);
    const FaceContacts faces = {{{0, 1}, {CutContact{{1, 0, 0}, 400}}}};
    a.options = {option(kDown, 2)};
    c.glueOptions = {option(kUp, 0)};
    CHECK(disassembleAll({a, c}, faces).holes[1] == -1);
    c.sleeveGrid = {0, 0, 1};
    const Disassembly d = disassembleAll({a, c}, faces);
    CHECK(d.stuck.empty());
    CHECK(d.order == std::vector<uint32_t>{0, 1});
    CHECK(d.holes[1] == kUp);
    CHECK(d.gluedOn == std::vector<std::pair<uint32_t, uint32_t>>{{0, 1}});
    // Only along its way out: a sleeve whose mouth faces elsewhere is not glued on.
    c.sleeveGrid = {1, 0, 0};
    CHECK(disassembleAll({a, c}, faces).holes[1] == -1);
}

TEST_CASE("mounting: a ring of staves in a body's only way goes on after it, when its way out is free") {
    // A (piece 0) can only leave upward, through stave S (piece 1) above it; S, fixed, slides out of
    // its tunnel along +x. Staves in place throughout leave A stuck; with S's ring taken away where
    // nothing else can leave, A goes on first, then S.
    MountBody a = slab(0, 0, 10, 0, 5), st = slab(1, 0, 10, 20, 25);
    a.options = {option(kUp, 2)};
    SweepCache cache;
    auto run = [&](const FixedStaves* staves) {
        return disassemble({a, st}, {}, Transform4d::identity(), 1.0, GlueOnRule{}, cache,
                           RunContext::silent(), 1, staves);
    };
    CHECK(run(nullptr).stuck == std::vector<uint32_t>{0});
    const FixedStaves staves{{0}, {{1, 0, 0}}, {{}}};
    const Disassembly d = run(&staves);
    CHECK(d.stuck.empty());
    CHECK(d.ringsTakenAway == 1);
    CHECK(d.order == std::vector<uint32_t>{0, 1});
    CHECK(d.holes[0] == kUp);
    CHECK(std::count(d.before.begin(), d.before.end(), std::make_pair(uint32_t(0), uint32_t(1))) == 1);
    // S sliding out downward would run into A: it stays, and A is stuck.
    const FixedStaves down{{0}, {{0, 0, -1}}, {{}}};
    const Disassembly e = run(&down);
    CHECK(e.stuck == std::vector<uint32_t>{0});
    CHECK(e.ringsTakenAway == 0);
    // A ring no body left needs out of the way stays first.
    a.options = {option(zome::nearestHole({-1, 0, 0}), 2)};
    const Disassembly f = run(&staves);
    CHECK(f.stuck.empty());
    CHECK(f.ringsTakenAway == 0);
    CHECK(f.order == std::vector<uint32_t>{1, 0});
}

TEST_CASE("mounting: a ring of staves another stave is glued in place onto stays while that one is on") {
    // A leaves only upward through stave S (ring 0); stave T (ring 1, beside S) is glued in place
    // onto S, and T's way out (+x) runs into A. S may not go while T is on, T not while A is: stuck.
    MountBody a = slab(0, 0, 10, 0, 5), s = slab(1, 0, 10, 20, 25), t = slab(2, -20, -10, 0, 5);
    a.options = {option(kUp, 2)};
    SweepCache cache;
    const FixedStaves staves{{0, 1}, {{1, 0, 0}, {1, 0, 0}}, {{}, {0}}};
    const Disassembly d = disassemble({a, s, t}, {}, Transform4d::identity(), 1.0, GlueOnRule{}, cache,
                                      RunContext::silent(), 2, &staves);
    CHECK(d.stuck == std::vector<uint32_t>{0});
    // Not glued onto S, T stays in place and S goes after A.
    const FixedStaves apart{{0, 1}, {{1, 0, 0}, {1, 0, 0}}, {{}, {}}};
    const Disassembly e = disassemble({a, s, t}, {}, Transform4d::identity(), 1.0, GlueOnRule{}, cache,
                                      RunContext::silent(), 2, &apart);
    CHECK(e.stuck.empty());
    CHECK(e.order == std::vector<uint32_t>{2, 0, 1});
}

TEST_CASE("mounting: a piece glued on goes on before its only host leaves") {
    // A holds; C sits on A, D beside C (across x = 10.5). Neither C nor D has pegs: D can only be
    // glued onto C, so C must not be taken away first, though it comes first by index.
    MountBody a = slab(0, 0, 10, 0, 10), c = slab(1, 0, 10, 11, 15), d = slab(2, 11, 21, 11, 15);
    nearEachOther(a, c);
    nearEachOther(c, d);
    const FaceContacts faces = {{{0, 1}, {CutContact{{0, 0, 1}, 400}}},
                                {{1, 2}, {CutContact{{1, 0, 0}, 400}}}};
    a.options = {option(zome::nearestHole({-1, 0, 0}), 2)};
    c.glueOptions = {option(kUp, 0)};
    d.glueOptions = {option(kRight, 0)};
    const Disassembly r = disassembleAll({a, c, d}, faces);
    CHECK(r.stuck.empty());
    CHECK(r.order == std::vector<uint32_t>{0, 1, 2});
    CHECK(r.gluedOn == std::vector<std::pair<uint32_t, uint32_t>>{{0, 1}, {1, 2}});
}

TEST_CASE("mounting: every pair of bodies in each other's way is glued into one in the same round") {
    // Two pairs far apart, each of two slabs whose only directions run into each other (A up into
    // B, B down into A): no order exists until each pair is glued; glued, each pair goes on along
    // either direction (no frame: every path is free). Both pairs are glued in one round, and the
    // bodies left after gluing keep their pieces (a self-move once emptied the first body's list).
    PlannerInput input;
    input.pieces = {slab(0, 0, 10, 0, 5), slab(1, 0, 10, 20, 25), slab(2, 100, 110, 0, 5),
                    slab(3, 100, 110, 20, 25)};
    input.candidatesByHole = {{{kUp, {2, 1.0}}}, {{kDown, {2, 1.0}}}, {{kUp, {2, 1.0}}}, {{kDown, {2, 1.0}}}};
    const FaceContacts faces = {{{0, 1}, {CutContact{{0, 0, 1}, 121}}},
                                {{2, 3}, {CutContact{{0, 0, 1}, 121}}}};
    const zome::Structure noFrame;
    Box3d bounds;
    for (const MountBody& b : input.pieces) bounds.expand(b.bounds.min), bounds.expand(b.bounds.max);
    const FrameSweeps sweeps(noFrame, Transform4d::identity(), bounds, 1.0, 0.5);
    std::vector<std::string> messages;
    const RunContext context([&](LogLevel, const std::string& m) { messages.push_back(m); }, nullptr);
    const mount::InstallationPlan plan = planMounting(input, sweeps, faces, 1.0, {kUp, kDown}, 2, context);
    CHECK(plan.isBuildable());
    CHECK(plan.glued == std::vector<std::pair<uint32_t, uint32_t>>{{0, 1}, {2, 3}});
    REQUIRE(plan.steps.size() == 2);
    std::vector<uint32_t> mounted;
    for (const mount::MountStep& step : plan.steps)
        mounted.insert(mounted.end(), step.pieces.begin(), step.pieces.end());
    std::sort(mounted.begin(), mounted.end());
    CHECK(mounted == std::vector<uint32_t>{0, 1, 2, 3});
    CHECK(std::count_if(messages.begin(), messages.end(), [](const std::string& m) {
              return m.find("2 pairs glued into one") != std::string::npos;
          }) == 1);
    // A mouth ring (piece 3, slid into its mouth along x) is never glued into a group: it goes on
    // after its tunnel's staves, which the piece glued to it may have to go on before.
    input.sleeves = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {1, 0, 0}};
    const mount::InstallationPlan ring = planMounting(input, sweeps, faces, 1.0, {kUp, kDown}, 2, context);
    CHECK_FALSE(ring.isBuildable());
    CHECK(ring.glued == std::vector<std::pair<uint32_t, uint32_t>>{{0, 1}});
}

TEST_CASE("mounting: a voxel near one neighbour's seam is still swept against the other bodies") {
    // A slides up along its seam with C (x = 10.5); C's arm reaches over A at z 20–21, under D
    // (seam z = 21.5). The arm's voxels are near D's seam, not A's: A pushed off upward meets them,
    // so A goes on before C. (Left out of every sweep, as once, they let A go on last.)
    MountBody a = slab(0, 0, 10, 0, 10), c = slab(2, 11, 21, 0, 10), arm = slab(2, 0, 21, 20, 21),
              d = slab(3, 0, 10, 22, 25);
    // Two voxels deep on each side of a seam, as the planner marks them.
    markNear(a, 2, [](const Vec3d& x) { return x[0] >= 9; });
    markNear(c, 0, [](const Vec3d& x) { return x[0] <= 12; });
    markNear(arm, 3, [](const Vec3d&) { return true; });  // the arm is two voxels thick
    markNear(d, 2, [](const Vec3d& x) { return x[2] <= 23; });
    c.addVoxelsOf(arm);  // an arm of the same piece
    const FaceContacts faces = {{{0, 2}, {CutContact{{1, 0, 0}, 121}}},
                                {{2, 3}, {CutContact{{0, 0, 1}, 121}}}};
    a.options = {option(kUp, 2)};
    c.options = {option(kRight, 2)};
    d.options = {option(kUp, 2)};
    MountBody b = slab(1, 200, 210, 0, 5);  // bodies are named by their index: piece 1 far away
    b.options = {option(kUp, 2)};
    const Disassembly r = disassembleAll({a, b, c, d}, faces);
    CHECK(r.stuck.empty());
    CHECK(std::count(r.before.begin(), r.before.end(), std::make_pair(uint32_t(0), uint32_t(2))) == 1);
}

TEST_CASE("mounting: a voxel near a seam is swept against the neighbour's voxels away from it") {
    // A slides up along its seam with C (x = 10.5), whose arm reaches round A's top, over A's seam
    // voxels (x 9–10, z 14–15), away from the seam. A pushed off upward meets the arm, so A goes on
    // before C. (With A's near-seam voxels left out of every sweep against C, as once, A went on
    // last and ran into the arm: a 400 mm cube with a tunnel, 11.6 mm into a neighbour.)
    MountBody a = slab(0, 0, 10, 0, 10), c = slab(2, 11, 21, 0, 10), arm = slab(2, 9, 21, 14, 15);
    markNear(a, 2, [](const Vec3d& x) { return x[0] >= 9; });
    markNear(c, 0, [](const Vec3d& x) { return x[0] <= 12; });
    c.addVoxelsOf(arm);  // an arm of the same piece
    const FaceContacts faces = {{{0, 2}, {CutContact{{1, 0, 0}, 121}}}};
    a.options = {option(kUp, 2)};
    c.options = {option(kRight, 2)};
    MountBody b = slab(1, 200, 210, 0, 5);  // bodies are named by their index: piece 1 far away
    b.options = {option(kUp, 2)};
    const Disassembly r = disassembleAll({a, b, c}, faces);
    CHECK(r.stuck.empty());
    CHECK(std::count(r.before.begin(), r.before.end(), std::make_pair(uint32_t(0), uint32_t(2))) == 1);
    // Where the arm lies just behind the seam (its voxels three layers from A's face, as behind a
    // seam along a diagonal plane), A's seam voxels are not swept against it and the face lets A
    // slide up: no order between them.
    markNear(
        c, 0, [](const Vec3d& x) { return x[2] >= 14; }, kWideCutLayers - 1);
    const Disassembly free = disassembleAll({a, b, c}, faces);
    CHECK(free.stuck.empty());
    CHECK(std::count(free.before.begin(), free.before.end(), std::make_pair(uint32_t(0), uint32_t(2))) == 0);
}

TEST_CASE("mounting: a tenon of a piece already on that lies in a later piece's path is given up") {
    // Piece 0 (z 0–5) holds a tenon whose stem rises from a ball at z = −40 to its wall; piece 1
    // comes down from above after it (pushed off upward from z −60) through the stem.
    PlannerInput input;
    input.pieces = {slab(0, 0, 10, 0, 5), slab(1, 0, 10, -60, -55)};
    const pieces::TenonOptions o;
    pieces::Tenon t;
    t.ball = 7;
    t.hole = kUp;
    t.piece = 0;
    t.axisGrid = t.axisFrame = {0, 0, 1};
    t.longSideGrid = {1, 0, 0};
    t.ballCenterGridMm = {5, 5, -40};
    t.shoulderMm = 10;
    t.baseMm = 39;
    t.endMm = 40;
    t.pegTipMm = 6;
    pieces::TenonPlan tenons;
    tenons.perPiece = {{t}, {}};
    std::vector<pieces::TenonCandidate> candidates(1);
    candidates[0].tenon = t;
    candidates[0].piece = 0;
    mount::InstallationPlan plan;
    plan.steps = {{{0}, kUp}, {{1}, kUp}};
    std::set<std::pair<zome::BallId, int>> lost;
    CHECK(markTenonsInPaths(plan, tenons, input, Transform4d::identity(), o, 1.0, candidates, lost) == 1);
    CHECK(lost.count({7, kUp}) == 1);
    CHECK(candidates[0].rejection == "in another piece's path");
    // The other order, or piece 1 beside the stem: nothing in the way.
    candidates[0].rejection.clear();
    lost.clear();
    std::swap(plan.steps[0], plan.steps[1]);
    CHECK(markTenonsInPaths(plan, tenons, input, Transform4d::identity(), o, 1.0, candidates, lost) == 0);
    std::swap(plan.steps[0], plan.steps[1]);
    input.pieces[1] = slab(1, 20, 30, -60, -55);
    CHECK(markTenonsInPaths(plan, tenons, input, Transform4d::identity(), o, 1.0, candidates, lost) == 0);
    CHECK(candidates[0].rejection.empty());
    CHECK(lost.empty());
}

TEST_CASE("mounting: a piece no hole reaches and nothing can be glued onto is unplaceable") {
    // Pieces 0–3, none placed. 0 has a usable candidate; 1 shares a 400 mm² face with 0 (a host to
    // glue on, once 0 is on); 2 shares only 20 mm² with 0 and has no usable candidate; 3 touches
    // nothing. A re-cut keeps 2's and 3's walls and only splits their faces.
    mount::InstallationPlan plan;
    plan.holeOfPiece = {-1, -1, -1, -1};
    plan.problems = {"no order"};
    PlannerInput input;
    input.candidatesByHole = {{{kUp, {2, 1.0}}}, {}, {}, {}};
    const FaceContacts faces = {{{0, 1}, {CutContact{{0, 0, 1}, 400}}},
                                {{0, 2}, {CutContact{{1, 0, 0}, 20}}}};
    CHECK(unplaceablePieces(plan, input, faces, 1.0) == std::vector<uint32_t>{2, 3});
    // At 2 mm voxels 20 voxel faces are 80 mm², still too small; at 3 mm, 180 mm²: 2 has a host.
    CHECK(unplaceablePieces(plan, input, faces, 2.0) == std::vector<uint32_t>{2, 3});
    CHECK(unplaceablePieces(plan, input, faces, 3.0) == std::vector<uint32_t>{3});
    // A piece placed (here glued into a group that pegs hold) is not one of them.
    plan.holeOfPiece = {kUp, -1, -1, kUp};
    CHECK(unplaceablePieces(plan, input, faces, 1.0) == std::vector<uint32_t>{2});
}
