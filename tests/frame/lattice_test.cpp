// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/lattice.h"

#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "frame_fixtures.h"
#include "zomefab/core/error.h"
#include "zomefab/frame/frame.h"

using namespace zomefab;

TEST_CASE("lattice: B0 cubes in a 300 mm sphere keep dMin and are connected") {
    const sdf::InteriorField& field = test::sphereField(300.0);
    frame::LatticeOptions o;
    const frame::LatticeResult r = frame::initialLattice(field, o, RunContext::silent());
    CHECK(r.cubes > 0);
    CHECK(r.keptCubes == r.cubes);  // a sphere's cubes form one part
    CHECK(r.placementsTried == 216);
    CHECK(r.cubes >= r.firstPlacementCubes);  // the search never loses
    const zome::Structure& s = r.structure;
    // Every strut is B0 along x, y or z; each ball has the three cube directions only.
    const zome::PartsList parts = zome::partsList(s);
    CHECK(parts.count(zome::Color::Blue, 0) == s.strutCount());
    const frame::FrameField ff(field, r.rotationDeg, s.scale(), o.zone);
    CHECK(frame::verifyFrame(s, ff).empty());
    for (zome::BallId id : s.ballIds())
        CHECK(ff.depthMm(s.ball(id).positionMm) >= o.zone.dMinMm + s.scale().ballRadiusMm());
    // Deterministic whatever the thread count (the placement search runs in parallel).
    const frame::LatticeResult again = frame::initialLattice(field, o, RunContext::silent());
    CHECK(again.offsetMm == r.offsetMm);
    CHECK(again.structure.ballCount() == s.ballCount());
}

TEST_CASE("lattice: the rotation search is an option and goes into the frame transform") {
    const sdf::InteriorField& field = test::sphereField(300.0);
    frame::LatticeOptions o;
    o.offsetSteps = 2;
    o.searchRotation = true;
    o.rotationStepDeg = 30.0;
    const frame::LatticeResult r = frame::initialLattice(field, o, RunContext::silent());
    CHECK(r.placementsTried == 3 * 8);
    CHECK(r.cubes > 0);
    // transform_mm composes the field's transform with R(−rotation): a field point maps to the
    // frame point the lattice sees.
    const Transform4d t = frame::frameTransformMm(Transform4d::identity(), 30.0);
    const frame::FrameField ff(field, 30.0, zome::ZomeScale{}, o.zone);
    const Vec3d p{10.0, 20.0, 5.0};
    const Vec3d q = t.apply(p);
    const Vec3d back = ff.toFieldMm(q);
    for (int a = 0; a < 3; ++a) CHECK(back[a] == doctest::Approx(p[a]));
}

TEST_CASE("lattice: an object thinner than a cube gets balls joined by struts in its middle") {
    // A 400 × 400 × 80 mm slab: 40 mm deep at most; a cube needs 24.85 mm clearance around a 47.3 mm
    // cube, a ball only 24.85 mm. The frame is a grid of balls in the slab's mid-plane.
    const sdf::InteriorField field =
        test::interiorFieldOf(test::makeBox({-200, -200, -40}, {200, 200, 40}), 4.0);
    const frame::LatticeResult r = frame::initialLattice(field, {}, RunContext::silent());
    CHECK(r.cubes == 0);
    CHECK(r.structure.ballCount() >= 9);
    CHECK(r.structure.strutCount() >= 12);
    for (zome::BallId id : r.structure.ballIds()) {
        const Vec3d p = r.structure.ball(id).positionMm;
        CHECK(std::abs(p[2]) <= 40.0 - 24.85 + 1e-6);  // every ball deep enough
    }
}

TEST_CASE("lattice: an object too thin for one ball fails with the sizes involved") {
    // A 400 × 400 × 40 mm slab: 20 mm deep at most, a ball needs 24.85 mm (dMin 16 + radius 8.85).
    const sdf::InteriorField field =
        test::interiorFieldOf(test::makeBox({-200, -200, -20}, {200, 200, 20}), 4.0);
    try {
        frame::initialLattice(field, {}, RunContext::silent());
        FAIL("expected an error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::ProcessingFailed);
        const std::string m = e.message();
        CHECK(m.find("too thin for a Zome frame") != std::string::npos);
        CHECK(m.find("has a ball at least 24.9 mm inside") != std::string::npos);
        CHECK(m.find("deepest point is 20.0 mm inside") != std::string::npos);  // half the slab
        CHECK(m.find("needs 31.7 mm") != std::string::npos);                    // 24.85 + 47.3·√3/12
        CHECK(m.find("scaled up 1.58 times") != std::string::npos);
    }
}

TEST_CASE("lattice: a sphere as deep as cubeDepthMm holds a whole cube") {
    // The worst case of the bound: a sphere is as deep as cubeDepthMm only at its centre. dMin 16 +
    // radius 8.85, half a cube's diagonal 47.3·√3/2, half an offset step's diagonal 47.3·√3/12.
    frame::LatticeOptions o;
    const double depthMm = frame::cubeDepthMm(o);
    CHECK(frame::ballDepthLimitMm(o.zone, o.scale) == doctest::Approx(24.85));
    CHECK(depthMm == doctest::Approx(24.85 + 47.3 * std::sqrt(3.0) * (0.5 + 1.0 / 12.0)));
    // 2 mm voxels: the field's depth may be off by a voxel, so the sphere is 2 mm deeper.
    const frame::LatticeResult r =
        frame::initialLattice(test::sphereField(2.0 * (depthMm + 2.0)), o, RunContext::silent());
    CHECK(r.cubes >= 1);
    // Only a sufficient depth: a cube's own half diagonal is what a sphere needs at the least, so
    // a sphere much shallower than cubeDepthMm holds none.
    const double tooShallowMm = frame::ballDepthLimitMm(o.zone, o.scale) + 0.5 * std::sqrt(3.0) * 47.3 - 2.0;
    CHECK(frame::initialLattice(test::sphereField(2.0 * tooShallowMm), o, RunContext::silent()).cubes == 0);
}

TEST_CASE("lattice: bad options are usage errors") {
    const sdf::InteriorField& field = test::sphereField(300.0);
    frame::LatticeOptions o;
    o.offsetSteps = 0;
    CHECK_THROWS_AS(frame::initialLattice(field, o, RunContext::silent()), Error);
}
