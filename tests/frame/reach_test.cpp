// SPDX-License-Identifier: GPL-3.0-or-later
// Growing the frame toward the surface it does not reach (frame/reach.h).
#include "zomefab/frame/reach.h"

#include <doctest/doctest.h>

#include "frame_fixtures.h"
#include "zomefab/frame/frame.h"
#include "zomefab/frame/target_count.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;

namespace {

/// One ball at the centre of the 300 mm sphere, in the frame stage's zone.
struct OneBall {
    sdf::ForbiddenZoneOptions zone;
    zome::Structure structure;
    frame::FrameField field;
    OneBall() : zone(zoneOf()), structure(), field(test::sphereField(300.0), 0.0, structure.scale(), zone) {
        structure.addBall(zome::GoldenVector3());
    }
    static sdf::ForbiddenZoneOptions zoneOf() {
        sdf::ForbiddenZoneOptions z;
        z.dMinMm = 19.0;
        z.dMaxMm = 47.3;
        return z;
    }
};

}  // namespace

TEST_CASE("reach: from one ball the frame grows toward the surface, valid after every addition") {
    OneBall a;
    const double before = frame::coveredFraction(a.structure, a.field, frame::sampleSurface(a.field, 8.0));
    frame::ReachOptions o;
    const frame::ReachResult r = frame::growForReach(a.structure, a.field, o, RunContext::silent());
    CHECK(r.coverageBefore == doctest::Approx(before));
    CHECK(r.strutsAdded > 5);
    CHECK(r.coverageAfter > r.coverageBefore + 0.5);
    CHECK(a.structure.strutCount() == r.strutsAdded);
    CHECK(a.structure.ballCount() == r.strutsAdded + 1);  // every strut to a new ball
    // Exact struts, clearance, no collisions, connected.
    CHECK(frame::verifyFrame(a.structure, a.field).empty());
    CHECK(r.coverageAfter ==
          doctest::Approx(frame::coveredFraction(a.structure, a.field, frame::sampleSurface(a.field, 8.0))));
}

TEST_CASE("reach: deterministic; off, or a gain no strut reaches, leaves the frame as it is") {
    OneBall a, b;
    frame::growForReach(a.structure, a.field, {}, RunContext::silent());
    frame::growForReach(b.structure, b.field, {}, RunContext::silent());
    CHECK(zome::structureToJson(a.structure).dump() == zome::structureToJson(b.structure).dump());

    OneBall off;
    frame::ReachOptions none;
    none.isEnabled = false;
    CHECK(frame::growForReach(off.structure, off.field, none, RunContext::silent()).strutsAdded == 0);
    CHECK(off.structure.ballCount() == 1);
    frame::ReachOptions greedy;
    greedy.minGainSamples = 100000;
    CHECK(frame::growForReach(off.structure, off.field, greedy, RunContext::silent()).strutsAdded == 0);

    frame::ReachOptions capped;
    capped.maxStruts = 3;
    OneBall c;
    CHECK(frame::growForReach(c.structure, c.field, capped, RunContext::silent()).strutsAdded == 3);
    frame::ReachOptions bad;
    bad.minGainSamples = 0;
    CHECK_THROWS_AS(frame::growForReach(c.structure, c.field, bad, RunContext::silent()), Error);
}

TEST_CASE("reach: the frame stage grows the annealed frame and reports it") {
    frame::FrameOptions o;
    o.anneal.maxIterations = 2000;
    o.anneal.finalTemperature = 0;
    o.chains = 1;
    Fabrication f;
    f.seed = 3;
    const frame::FrameResult r = frame::buildFrame(test::sphereField(300.0), f, o, RunContext::silent());
    CHECK(r.reach.coverageAfter >= r.reach.coverageBefore);
    CHECK(r.structure.ballCount() + r.structure.strutCount() >= r.lattice.structure.ballCount());
    const frame::FrameField ff(test::sphereField(300.0), r.rotationDeg, r.structure.scale(), r.zone);
    CHECK(frame::verifyFrame(r.structure, ff).empty());
    o.reach.isEnabled = false;
    const frame::FrameResult paper = frame::buildFrame(test::sphereField(300.0), f, o, RunContext::silent());
    CHECK(paper.reach.strutsAdded == 0);
    CHECK(paper.finalEnergy.total == paper.annealedEnergy.total);
}
