// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include <cmath>

#include "frame_fixtures.h"
#include "zomefab/frame/energy.h"
#include "zomefab/frame/move_tables.h"
#include "zomefab/frame/outermost.h"

using namespace zomefab;

namespace {
constexpr double kHalfPi = 1.57079632679489661923;
uint64_t bit(int h) { return uint64_t(1) << h; }
int holeAlong(const zome::GoldenVector3& v) { return *zome::parallelHole(v); }
const zome::Golden kOne(1);
}  // namespace

TEST_CASE("move tables: every split and closing entry is exact") {
    const frame::MoveTables& t = frame::moveTables();
    size_t splits = 0;
    for (int h = 0; h < zome::kHoleCount; ++h)
        for (int s = 0; s < zome::kSizeCount; ++s)
            for (const frame::SplitEntry& e : t.splits[size_t(frame::strutKey(h, s))]) {
                ++splits;
                CHECK(zome::strutVector(e.hole1, e.size1) + zome::strutVector(e.hole2, e.size2) ==
                      zome::strutVector(h, s));
            }
    CHECK(splits > 0);
    // B0 along +x splits into two Y0 through the centre of a neighbouring cube (4 ways), among others.
    const int px = holeAlong({kOne, 0, 0});
    int yellowPairs = 0;
    for (const frame::SplitEntry& e : t.splits[size_t(frame::strutKey(px, 0))])
        if (zome::holeColor(e.hole1) == zome::Color::Yellow && e.size1 == 0 &&
            zome::holeColor(e.hole2) == zome::Color::Yellow && e.size2 == 0)
            ++yellowPairs;
    CHECK(yellowPairs == 4);
    // Closing: B0 + B1 along one axis is B2.
    CHECK(t.closing[size_t(frame::strutKey(px, 0))][size_t(frame::strutKey(px, 1))] == frame::strutKey(px, 2));
    const int py = holeAlong({0, kOne, 0});
    CHECK(t.closing[size_t(frame::strutKey(px, 0))][size_t(frame::strutKey(py, 0))] == -1);  // green
}

TEST_CASE("regularity: mean over strut ends of |nearest angle - 90 degrees|") {
    const int px = holeAlong({kOne, 0, 0}), mx = holeAlong({-kOne, 0, 0});
    const int py = holeAlong({0, kOne, 0}), pz = holeAlong({0, 0, kOne});
    CHECK(frame::regularityOfMask(bit(px) | bit(py) | bit(pz)) == 0.0);  // exactly, cube corner
    CHECK(frame::regularityOfMask(bit(px)) == 0.0);
    // Two opposite struts: each one's nearest neighbour is 180° away, deviation π/2 each.
    CHECK(frame::regularityOfMask(bit(px) | bit(mx)) == doctest::Approx(2 * kHalfPi));
    // A yellow next to +x: both struts' nearest angle is 54.7356°, deviation 35.26° each.
    const int y = holeAlong({kOne, kOne, kOne});
    const double dev = kHalfPi - std::acos(1.0 / std::sqrt(3.0));
    CHECK(frame::regularityOfMask(bit(px) | bit(y)) == doctest::Approx(2 * dev));
    // Adding the yellow to a cube corner: +x, +y, +z each now see it at 54.7°.
    CHECK(frame::regularityOfMask(bit(px) | bit(py) | bit(pz) | bit(y)) == doctest::Approx(4 * dev));
}

TEST_CASE("energy: terms of a 3x3x3 grid inside a 300 mm sphere, by hand") {
    const sdf::InteriorField& field = test::sphereField(300.0);
    zome::ZomeScale scale;
    scale.originMm = {-47.3, -47.3, -47.3};  // grid centred on the sphere's centre
    const zome::Structure s = test::cubeGrid(3, scale);
    const frame::FrameField ff(field, 0.0, scale, sdf::ForbiddenZoneOptions{});
    frame::EnergyOptions o;
    o.targetItemCount = 100.0;
    const frame::EnergyTerms e = frame::frameEnergy(s, ff, o);
    CHECK(e.balls == 27);
    CHECK(e.struts == 54);
    CHECK(e.outermostBalls == 26);
    CHECK(e.internalBalls == 1);
    CHECK(e.regularity == 0.0);  // a cube grid is perfectly regular
    // Valence over all balls: 8 corners (3), 12 edges (4), 6 faces (5), the centre (6).
    CHECK(e.valence == doctest::Approx((8 * 9 + 12 * 4 + 6 * 1) / 6.0));
    CHECK(e.simplicity == doctest::Approx((81.0 - 100.0) * (81.0 - 100.0) / 100.0));
    // Fidelity: mean over the 26 outermost balls of (depth/b0)² (1 + F(depth − ball radius)).
    double sum = 0;
    for (zome::BallId id : frame::outermostBalls(s)) {
        const double depth = 150.0 - std::sqrt(std::pow(s.ball(id).positionMm[0], 2) +
                                               std::pow(s.ball(id).positionMm[1], 2) +
                                               std::pow(s.ball(id).positionMm[2], 2));
        const double F = sdf::forbiddenZone(depth - scale.ballRadiusMm());
        sum += (depth / 47.3) * (depth / 47.3) * (1 + F);
    }
    // The 3 mm field of a 48×96 faceted sphere is within ~1 mm of the true sphere.
    CHECK(e.fidelity == doctest::Approx(sum / 26).epsilon(0.05));
    CHECK(e.total == doctest::Approx(e.fidelity + 100 * e.regularity + e.valence + e.simplicity));

    // The literal reading of Eq. 5 (internal balls only) leaves the 26 outer ones out.
    o.valenceOnInternalOnly = true;
    CHECK(frame::frameEnergy(s, ff, o).valence == 0.0);
}

TEST_CASE("energy: running sums add and subtract to the full value") {
    frame::EnergyOptions o;
    o.targetItemCount = 50;
    frame::EnergySums sums;
    const frame::BallEnergy a = frame::ballEnergy(0b111, 2.0, o);
    const frame::BallEnergy b = frame::ballEnergy(0b1, 3.0, o);
    sums.add(a);
    sums.add(b);
    sums.subtract(b);
    CHECK(sums.outermost == 1);
    CHECK(sums.fidelity == doctest::Approx(2.0));
}
