// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The verifier (issue 17, docs/mounting.md "The verifier") on a real output and on broken
/// copies of it: a peg turned 10°, a ball put in a piece's path, two pieces mounted in an order
/// where one blocks the other, printed material inside a ball, a piece with no tenon left; each
/// must fail the check that names it, and `zomefab check` must exit 3 on a broken directory.
#include "zomefab/verify/verify.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>

#include "test_util.h"
#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/tenons.h"
#include "zomefab/pipeline/pipeline.h"
#include "zomefab/report/run_report.h"
#include "zomefab/zome/zome_system.h"

using namespace zomefab;
using nlohmann::json;

namespace {

/// The small bunny end to end (as tests/pipeline), written once and read back as the verifier sees it.
struct GoodRun {
    test::ScratchDir dir{"zomefab-verify"};
    std::string out;
    verify::Assembly assembly;

    GoodRun() {
        pipeline::RunOptions o;
        o.scale.heightMm = 250;
        o.scale.up = mesh::UpAxis::Y;
        o.field.voxelMm = 1.5;
        o.frame.anneal.maxIterations = 20000;
        o.frame.chains = 2;
        o.fabrication.seed = 7;
        const TriMesh mesh = readMesh(test::dataPath("bunny_npm_3674.stl"));
        const report::RunRecord run = pipeline::runPipeline(mesh, "bunny", o, RunContext::silent());
        out = dir.file("run");
        const json report = report::runReportJson(run, RunContext::silent());
        const pipeline::RunOutputs written =
            pipeline::writeRunOutputs(run, o, report, out, RunContext::silent());
        REQUIRE(written.verification.passed());
        assembly = verify::readAssembly(out);
    }
};

const GoodRun& good() {
    static const GoodRun g;
    return g;
}

verify::VerifyReport check(const verify::Assembly& a) {
    return verify::verifyAssembly(a, {}, RunContext::silent());
}

/// The names of the checks that failed, and every failure line (for the test log).
std::set<std::string> failed(const verify::VerifyReport& r) {
    std::set<std::string> names;
    for (const verify::CheckResult& c : r.checks)
        if (!c.passed()) names.insert(c.name);
    for (const std::string& line : verify::verifySummaryLines(r)) MESSAGE(line);
    return names;
}

/// The first piece mounted alone (not glued) that has a tenon.
uint32_t loneHeldPiece(const verify::Assembly& a) {
    for (const mount::MountStep& s : a.pieces.plan.steps)
        if (s.pieces.size() == 1 && !a.pieces.pieces[s.pieces[0]].tenons.empty()) return s.pieces[0];
    FAIL("no piece is mounted alone with a tenon");
    return 0;
}

/// Rodrigues: @p p turned by @p angleRad about the line through @p origin along unit @p k.
Vec3d turned(const Vec3d& p, const Vec3d& origin, const Vec3d& k, double angleRad) {
    const Vec3d r = sub(p, origin);
    const double c = std::cos(angleRad), s = std::sin(angleRad);
    Vec3d out = add(scale(r, c), scale(cross(k, r), s));
    out = madd(out, dot(k, r) * (1 - c), k);
    return add(origin, out);
}

/// Appends an axis-aligned closed cube (outward triangles) of half-size @p h at @p c.
void appendCube(TriMesh& m, const Vec3d& c, double h) {
    const uint32_t base = uint32_t(m.positions.size());
    for (int i = 0; i < 8; ++i)
        m.positions.push_back({float(c[0] + ((i & 1) ? h : -h)), float(c[1] + ((i & 2) ? h : -h)),
                               float(c[2] + ((i & 4) ? h : -h))});
    const uint32_t f[12][3] = {{0, 2, 1}, {1, 2, 3}, {4, 5, 6}, {5, 7, 6}, {0, 1, 4}, {1, 5, 4},
                               {2, 6, 3}, {3, 6, 7}, {0, 4, 2}, {2, 4, 6}, {1, 3, 5}, {3, 7, 5}};
    for (const auto& t : f) m.triangles.push_back({base + t[0], base + t[1], base + t[2]});
}

}  // namespace

TEST_CASE("verify: the pipeline's own output passes every check") {
    const verify::VerifyReport r = check(good().assembly);
    CHECK(failed(r).empty());
    CHECK(r.bodies == good().assembly.pieces.plan.steps.size());
    CHECK(r.tenons > 0);
    for (const verify::PieceResult& p : r.pieces) {
        CHECK(p.worstAxisDeg <= 1.0);
        CHECK(p.step >= 0);
    }
}

TEST_CASE("verify: a peg turned 10 degrees fails the peg axes") {
    verify::Assembly a = good().assembly;
    const uint32_t id = loneHeldPiece(a);
    pieces::Piece& p = a.pieces.pieces[id];
    const pieces::Tenon& t = p.tenons[0];
    const Vec3d pivot = p.gridToPrintMm.apply(t.pointAt(t.shoulderMm));
    const Vec3d axis = normalized(applyLinear(p.gridToPrintMm, t.axisGrid));
    const Vec3d ball = p.gridToPrintMm.apply(t.ballCenterGridMm);
    // The peg is what lies on the tenon's axis between its tip and the ball's face (the body stops
    // outside the ball): turn those vertices about the shoulder's centre.
    const Vec3d k = normalized(cross(axis, std::abs(axis[0]) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}));
    size_t moved = 0;
    for (Vec3f& v : p.mesh.positions) {
        const Vec3d r = sub(toD(v), ball);
        const double along = dot(r, axis);
        if (along < t.pegTipMm - 0.5 || along > t.shoulderMm + 0.2 || norm(madd(r, -along, axis)) > 5.0)
            continue;
        const Vec3d q = turned(toD(v), pivot, k, 10.0 * M_PI / 180.0);
        v = {float(q[0]), float(q[1]), float(q[2])};
        ++moved;
    }
    REQUIRE(moved > 0);
    REQUIRE(moved < p.mesh.positions.size() / 4);  // the peg, not the body
    const verify::VerifyReport r = check(a);
    CHECK(failed(r).count("peg axes") == 1);
    CHECK(r.pieces[id].worstAxisDeg > 5.0);
}

namespace {

/// The failure lines of check @p name.
std::vector<std::string> failuresOf(const verify::VerifyReport& r, const std::string& name) {
    for (const verify::CheckResult& c : r.checks)
        if (c.name == name) return c.failures;
    return {};
}

/// @p a with a ball put on piece @p id's first tenon's axis, 30 mm past the piece's reach along its
/// direction: in the way of its straight path off the frame.
zome::BallId addBallInPath(verify::Assembly& a, uint32_t id) {
    const pieces::Piece& p = a.pieces.pieces[id];
    const pieces::Tenon& t = p.tenons[0];
    const Transform4d printToFrame = affineInverse(a.frameToGridMm) * affineInverse(p.gridToPrintMm);
    const Vec3d d = zome::holeDirection(p.hole);
    const Vec3d ballMm = a.frame.ball(t.ball).positionMm;
    double reachMm = 0;
    for (const Vec3f& v : p.mesh.positions)
        reachMm = std::max(reachMm, dot(sub(printToFrame.apply(toD(v)), ballMm), d));
    zome::GoldenVector3 at = a.frame.ball(t.ball).position;
    const zome::GoldenVector3 step = zome::strutVector(p.hole, 0);
    for (int i = 0; i < 1000; ++i) {
        at += step;
        const Vec3d mm = a.frame.scale().toMm(at);
        if (dot(sub(mm, ballMm), d) > reachMm + 30 && a.frame.findBall(at) == zome::kNoId) break;
    }
    return a.frame.addBall(at);
}

mount::MountStep& stepOf(verify::Assembly& a, uint32_t piece) {
    return a.pieces.plan.steps[size_t(a.pieces.plan.stepOf(piece))];
}

}  // namespace

TEST_CASE("verify: a ball in a piece's path fails the free path") {
    verify::Assembly a = good().assembly;
    const uint32_t id = loneHeldPiece(a);
    addBallInPath(a, id);
    const verify::VerifyReport r = check(a);
    CHECK(failed(r).count("free path") == 1);
    bool named = false;
    for (const std::string& f : failuresOf(r, "free path"))
        named = named || f.find("piece " + std::to_string(id)) != std::string::npos;
    CHECK(named);
}

TEST_CASE("verify: a step of two legs is lifted only as far as its lift, then slid along its slide") {
    const uint32_t id = loneHeldPiece(good().assembly);
    const Vec3d d = zome::holeDirection(good().assembly.pieces.pieces[id].hole);
    // Lifted 8 mm, then slid on the same way: the straight path in two legs, and it passes.
    verify::Assembly same = good().assembly;
    stepOf(same, id).slide = d;
    stepOf(same, id).liftMm = 8.0;
    CHECK(failed(check(same)).empty());
    // A ball 30 mm past the piece along its direction: in the way of the slide on, not of the lift.
    verify::Assembly blocked = same;
    const zome::BallId added = addBallInPath(blocked, id);
    const verify::VerifyReport r = check(blocked);
    CHECK(failed(r).count("free path") == 1);
    bool isSlideNamed = false;
    for (const std::string& f : failuresOf(r, "free path")) {
        CHECK(f.find("lifted off its pegs") == std::string::npos);
        isSlideNamed =
            isSlideNamed || (f.find("piece " + std::to_string(id)) != std::string::npos &&
                             f.find("slid off along its tunnel it meets ball") != std::string::npos);
    }
    CHECK(isSlideNamed);
    // Slid off sideways instead, the ball is passed by: no leg of this step meets it.
    verify::Assembly aside = blocked;
    const Vec3d side = normalized(cross(d, std::abs(d[0]) < 0.9 ? Vec3d{1, 0, 0} : Vec3d{0, 1, 0}));
    stepOf(aside, id).slide = side;
    for (const std::string& f : failuresOf(check(aside), "free path"))
        CHECK(f.find("ball " + std::to_string(added) + " ") == std::string::npos);
}

TEST_CASE("verify: two pieces mounted with the blocked one first fail the order") {
    verify::Assembly a = good().assembly;
    mount::InstallationPlan& plan = a.pieces.plan;
    REQUIRE(!plan.before.empty());
    // Every constraint reversed: each piece that must go first now comes after the one it blocks.
    std::reverse(plan.steps.begin(), plan.steps.end());
    CHECK(failed(check(a)).count("order") == 1);
}

TEST_CASE("verify: printed material inside a ball fails the peg fit") {
    verify::Assembly a = good().assembly;
    const uint32_t id = loneHeldPiece(a);
    pieces::Piece& p = a.pieces.pieces[id];
    const pieces::Tenon& t = p.tenons[0];
    appendCube(p.mesh, p.gridToPrintMm.apply(t.ballCenterGridMm), 2.0);
    CHECK(failed(check(a)).count("peg fit") == 1);
}

TEST_CASE("verify: a piece left with no tenon fails held") {
    verify::Assembly a = good().assembly;
    const uint32_t id = loneHeldPiece(a);
    a.pieces.pieces[id].tenons.clear();
    CHECK(failed(check(a)).count("held") == 1);
}

TEST_CASE("verify: zomefab check passes the output, exits 3 on a broken copy and 2 on a missing one") {
    const std::string zf = test::toolPath("zomefab");
    CHECK(test::runShell(zf + " check '" + good().out + "' 2>/dev/null") == 0);
    // The same files with the mounting order reversed in pieces.json.
    test::ScratchDir dir{"zomefab-verify-cli"};
    const std::string broken = dir.file("broken");
    REQUIRE(test::runShell("cp -r '" + good().out + "' '" + broken + "'") == 0);
    const std::string piecesJson = broken + "/pieces/pieces.json";
    json j = json::parse(readInputBytes(piecesJson));
    json& steps = j["installation"]["steps"];
    std::reverse(steps.begin(), steps.end());
    test::writeBytes(piecesJson, j.dump(1));
    std::string err;
    CHECK(test::runCapture(zf + " check '" + broken + "' 2>&1", &err) == 3);
    CHECK(err.find("order") != std::string::npos);
    CHECK(test::runShell(zf + " check '" + dir.file("none") + "' 2>/dev/null") == 2);
}

TEST_CASE(
    "verify: a piece with no peg glued onto a piece put on before it is held; onto a later one it is not") {
    verify::Assembly a = good().assembly;
    const mount::InstallationPlan& plan = a.pieces.plan;
    // A piece mounted alone, with a neighbour put on in an earlier step and one in a later step.
    uint32_t id = 0, earlier = 0, later = 0;
    bool isFound = false;
    for (uint32_t p = 0; p < a.pieces.pieces.size() && !isFound; ++p) {
        const int step = plan.stepOf(p);
        if (step < 0 || plan.steps[size_t(step)].pieces.size() != 1) continue;
        bool hasEarlier = false, hasLater = false;
        for (const auto& [q, area] : a.pieces.pieces[p].neighbors) {
            if (plan.stepOf(q) < step && !hasEarlier) hasEarlier = true, earlier = q;
            if (plan.stepOf(q) > step && !hasLater) hasLater = true, later = q;
        }
        if (hasEarlier && hasLater) id = p, isFound = true;
    }
    REQUIRE(isFound);
    a.pieces.pieces[id].tenons.clear();  // its pegs were in the balls: "peg fit" fails too
    const auto gluedBefore = a.pieces.plan.gluedOn;
    a.pieces.plan.gluedOn.push_back({earlier, id});
    std::set<std::string> names = failed(check(a));
    CHECK(names.count("held") == 0);
    CHECK(names.count("plan") == 0);
    a.pieces.plan.gluedOn = gluedBefore;
    a.pieces.plan.gluedOn.push_back({later, id});
    names = failed(check(a));
    CHECK(names.count("held") == 0);
    CHECK(names.count("plan") == 1);  // "glued onto piece N, which is not put on before it"
}
