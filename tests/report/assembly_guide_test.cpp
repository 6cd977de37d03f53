// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Build order of the assembly guide, tenon checks and the Markdown/JSON forms.
#include "zomefab/report/assembly_guide.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <set>

#include "report_test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
using namespace zomefab::report;
using namespace zomefab::test;

namespace {

zome::Structure cubeFrame() {
    return zome::structureFromJsonText(readInputBytes(std::string(ZOMEFAB_ZOME_TEST_DATA) + "/cube.json"));
}

/// Checks the invariants every guide must satisfy.
void checkGuide(const zome::Structure& frame, const AssemblyGuide& g) {
    REQUIRE(g.steps.size() == frame.ballCount());
    std::set<zome::BallId> balls;
    std::set<zome::StrutId> struts;
    std::set<zome::BallId> present;
    size_t newBalls = 0;
    for (const BallStep& step : g.steps) {
        CHECK(balls.insert(step.ball).second);  // every ball once
        // A ball is reached before its step, except each component's start.
        if (step.layer == 0) present.insert(step.ball);
        CHECK(present.count(step.ball) == 1);
        for (const StrutStep& s : step.struts) {
            CHECK(struts.insert(s.strut).second);  // every strut once
            const zome::Strut& real = frame.strut(s.strut);
            CHECK(
                ((real.a == step.ball && real.b == s.toBall) || (real.b == step.ball && real.a == s.toBall)));
            CHECK(frame.ball(step.ball).holes[size_t(s.hole)] == s.strut);
            CHECK(frame.ball(s.toBall).holes[size_t(s.toHole)] == s.strut);
            CHECK(s.isNewBall == (present.count(s.toBall) == 0));
            if (s.isNewBall) ++newBalls;
            present.insert(s.toBall);
        }
    }
    CHECK(struts.size() == frame.strutCount());
    CHECK(newBalls == frame.ballCount() - g.components);
}

}  // namespace

TEST_CASE("assembly_guide: a cube frame, breadth-first from its lowest ball") {
    const zome::Structure cube = cubeFrame();
    const AssemblyGuide g = assemblyGuide(cube);
    checkGuide(cube, g);
    CHECK(g.components == 1);
    CHECK(g.layers == 4);         // corner, 3 neighbours, 3 face-diagonal corners, the far corner
    CHECK(g.steps[0].ball == 0);  // at z = 0, y = 0, x = 0
    CHECK(g.steps[0].struts.size() == 3);
    const std::vector<size_t> perLayer = {1, 3, 3, 1};
    for (size_t layer = 0; layer < 4; ++layer)
        CHECK(size_t(std::count_if(g.steps.begin(), g.steps.end(),
                                   [&](const BallStep& s) { return s.layer == layer; })) == perLayer[layer]);
    // Within a layer, bottom up: layer 1 holds the two z = 0 neighbours before the one above.
    CHECK(g.steps[1].positionMm[2] <= g.steps[2].positionMm[2]);
    CHECK(g.steps[2].positionMm[2] <= g.steps[3].positionMm[2]);
    CHECK(g.parts.balls == 8);
    CHECK(g.parts.strutTotal() == 12);
}

TEST_CASE("assembly_guide: colours, sizes and separate components") {
    zome::Structure s = colourFrame();
    // A second, unconnected pair of balls far below: a separate component that starts the list.
    const zome::GoldenVector3 down{zome::Golden(0), zome::Golden(0), zome::Golden(-40)};
    const zome::BallId lone = s.addBall(down);
    s.addBall(down + zome::strutVector(0, 0));
    s.addStrut(lone, 0, 0);
    const AssemblyGuide g = assemblyGuide(s);
    checkGuide(s, g);
    CHECK(g.components == 2);
    CHECK(g.steps[0].ball == lone);
    CHECK(g.steps[0].component == 0);
    // The colour frame's walk starts at ball 0: z = 0 is shared with the B0 and R0 ends (both
    // along the xy plane), and ball 0 has the smallest y, then x.
    CHECK(g.steps[2].component == 1);
    CHECK(g.steps[2].ball == 0);
    CHECK(g.steps[2].struts.size() == 4);
    const std::string md = assemblyGuideMarkdown(g);
    CHECK(md.find("## Frame part 2") != std::string::npos);
    CHECK(md.find("Y0 (yellow) in the yellow hole pointing") != std::string::npos);
    CHECK(md.find("(30)") != std::string::npos);
    CHECK(md.find("R0 (red) in the red hole pointing") != std::string::npos);
    CHECK(md.find("B1 (blue) in the blue hole pointing straight up (2)") != std::string::npos);
}

TEST_CASE("assembly_guide: the mounting steps, in order, and their checks") {
    const zome::Structure cube = cubeFrame();
    // Ball 0 uses the blue holes towards +x, +y, +z (0, 1, 2); the −z hole (17) is free.
    std::vector<MountingStep> steps(2);
    steps[0].pieces = {"piece-01"};
    steps[0].hole = 17;
    steps[0].tenons = {{"piece-01", 0, 17}, {"piece-01", 2, 17}};
    steps[1].pieces = {"piece-00", "piece-02", "piece-03"};
    steps[1].glue = {{"piece-00", "piece-02", 2}, {"piece-00", "piece-03", 0}};
    steps[1].hole = 17;
    steps[1].tenons = {{"piece-00", 1, 17}};
    const AssemblyGuide g = assemblyGuide(cube, steps);
    REQUIRE(g.mounting.size() == 2);
    const std::string md = assemblyGuideMarkdown(g);
    CHECK(md.find("### Step 1: piece-01") != std::string::npos);
    CHECK(md.find("Approach from: straight down. Push: straight up") != std::string::npos);
    CHECK(md.find("the blue hole pointing straight down (17) of ball-0, ball-2.") != std::string::npos);
    CHECK(md.find("### Step 2: piece-00 + piece-02 + piece-03") != std::string::npos);
    CHECK(md.find("First glue piece-00 to piece-03 along their common cut face (no room for alignment pins: "
                  "line the two up by eye)") != std::string::npos);
    CHECK(md.find("First glue piece-00 to piece-02 along their common cut face (2 alignment pins)") !=
          std::string::npos);
    CHECK(md.find("Blue") != std::string::npos);  // the parts table
    const nlohmann::json j = assemblyGuideToJson(g);
    CHECK(j["steps"].size() == 8);
    CHECK(j["mounting"][0]["pegs"][1]["ball"] == 2);
    CHECK(j["mounting"][1]["glue"][0]["pins"] == 2);
    CHECK(j["mounting"][0]["push"] == nlohmann::json::array({0.0, 0.0, 1.0}));
    CHECK(j["start_balls"] == nlohmann::json::array({0}));

    auto fails = [&](const MountingStep& step, const std::string& expected) {
        bool thrown = false;
        try {
            assemblyGuide(cube, {step});
        } catch (const Error& e) {
            thrown = true;
            CHECK(e.code() == ErrorCode::InvalidInput);
            CHECK(std::string(e.what()).find(expected) != std::string::npos);
        }
        CHECK(thrown);
    };
    MountingStep bad;
    bad.pieces = {"piece-07"};
    bad.hole = 3;
    bad.tenons = {{"piece-07", 99, 3}};
    fails(bad, "piece-07: peg into hole 3 of ball-99: no such ball");
    bad.tenons = {{"piece-07", 0, 5}};
    fails(bad, "not along its step's direction");
    bad.hole = 0;
    bad.tenons = {{"piece-07", 0, 0}};
    fails(bad, "the hole holds strut");
    bad.hole = -1;
    fails(bad, "has no direction");
}

TEST_CASE("assembly_guide: a piece no peg holds is glued onto a piece already on") {
    const zome::Structure cube = cubeFrame();
    std::vector<MountingStep> steps(2);
    steps[0].pieces = {"piece-01"};
    steps[0].hole = 17;
    steps[0].tenons = {{"piece-01", 0, 17}};
    steps[1].pieces = {"piece-04"};
    steps[1].hole = 2;
    steps[1].gluedOnto = {{"piece-04", "piece-01", 2}};
    const AssemblyGuide g = assemblyGuide(cube, steps);
    const std::string md = assemblyGuideMarkdown(g);
    CHECK(md.find("Put glue on the cut face of piece-04 that meets piece-01 (already on): piece-04 is glued "
                  "onto it as it goes on (2 alignment pins on piece-01 go into its sockets).") !=
          std::string::npos);
    CHECK(md.find("It has no pegs: the glue holds it.") != std::string::npos);
    const nlohmann::json j = assemblyGuideToJson(g);
    CHECK(j["mounting"][1]["glued_onto"][0]["onto"] == "piece-01");
    CHECK(j["mounting"][1]["glued_onto"][0]["pins"] == 2);
    CHECK(j["mounting"][1]["pegs"].empty());
}

TEST_CASE("assembly_guide: a stave slides in along its tunnel, then is pushed onto its pegs") {
    const zome::Structure cube = cubeFrame();
    std::vector<MountingStep> steps(2);
    steps[0].pieces = {"piece-01"};
    steps[0].hole = 17;  // blue, straight down: pushed on upward
    steps[0].tenons = {{"piece-01", 0, 17}};
    steps[0].slide = {1, 0, 0};  // slid off toward +x: in from the mouth on the right
    steps[0].liftMm = 12.0;
    steps[1].pieces = {"piece-02"};
    steps[1].hole = 17;
    steps[1].tenons = {{"piece-02", 1, 17}};
    const AssemblyGuide g = assemblyGuide(cube, steps);
    const std::string md = assemblyGuideMarkdown(g);
    CHECK(
        md.find("Slide it into the tunnel from its mouth on the side " + zome::directionName({1, 0, 0}) +
                " (direction -1.000, +0.000, +0.000), held 12 mm off its place toward the tunnel's middle") !=
        std::string::npos);
    CHECK(md.find("Push it on from: ") != std::string::npos);
    const nlohmann::json j = assemblyGuideToJson(g);
    CHECK(j["mounting"][0]["lift_mm"] == 12.0);
    CHECK(j["mounting"][0]["slide"][0] == -1.0);
    CHECK_FALSE(j["mounting"][1].contains("slide"));  // one straight push
}

TEST_CASE("assembly_guide: same frame, same text") {
    const zome::Structure a = cubeFrame(), b = cubeFrame();
    CHECK(assemblyGuideMarkdown(assemblyGuide(a)) == assemblyGuideMarkdown(assemblyGuide(b)));
}
