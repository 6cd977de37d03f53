// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <tuple>
#include <vector>

#include "zome_fixtures.h"
#include "zomefab/zome/structure.h"

using namespace zomefab;
using namespace zomefab::zome;
using zomefab::zome::test::latticePoint;
using zomefab::zome::test::makeCubeLattice;

namespace {

GoldenVector3 vec(Golden x, Golden y, Golden z) { return {x, y, z}; }

bool hasKind(const std::vector<Collision>& cs, CollisionKind kind) {
    return std::any_of(cs.begin(), cs.end(), [&](const Collision& c) { return c.kind == kind; });
}

/// The collision rules written out naively over all pairs: the reference for the spatial hash.
std::vector<std::tuple<int, uint32_t, uint32_t>> bruteForceCollisions(const Structure& s) {
    std::vector<std::tuple<int, uint32_t, uint32_t>> out;
    const std::vector<BallId> balls = s.ballIds();
    const std::vector<StrutId> struts = s.strutIds();
    for (size_t i = 0; i < balls.size(); ++i)
        for (size_t j = i + 1; j < balls.size(); ++j) {
            const Vec3d &p = s.ball(balls[i]).positionMm, &q = s.ball(balls[j]).positionMm;
            const double d =
                std::sqrt(std::pow(p[0] - q[0], 2) + std::pow(p[1] - q[1], 2) + std::pow(p[2] - q[2], 2));
            if (d < s.ballBallLimitMm()) out.emplace_back(int(CollisionKind::BallBall), balls[i], balls[j]);
        }
    for (StrutId t : struts)
        for (BallId b : balls) {
            const Strut& st = s.strut(t);
            if (st.a == b || st.b == b) continue;
            const double d2 = pointSegmentDistanceSq(s.ball(b).positionMm, st.startMm, st.endMm);
            if (d2 < std::pow(s.strutBallLimitMm(st.color), 2))
                out.emplace_back(int(CollisionKind::StrutBall), t, b);
        }
    for (size_t i = 0; i < struts.size(); ++i)
        for (size_t j = i + 1; j < struts.size(); ++j) {
            const Strut &x = s.strut(struts[i]), &y = s.strut(struts[j]);
            if (x.a == y.a || x.a == y.b || x.b == y.a || x.b == y.b) continue;
            const double d2 = segmentSegmentDistanceSq(x.startMm, x.endMm, y.startMm, y.endMm);
            if (d2 < std::pow(s.strutStrutLimitMm(x.color, y.color), 2))
                out.emplace_back(int(CollisionKind::StrutStrut), struts[i], struts[j]);
        }
    std::sort(out.begin(), out.end());
    return out;
}

/// Naive version of Structure::strutCollides.
bool bruteForceStrutCollides(const Structure& s, const GoldenVector3& start, int hole, int size) {
    const GoldenVector3 end = start + strutVector(hole, size);
    const BallId a = s.findBall(start), b = s.findBall(end);
    const Vec3d& d = holeDirection(hole);
    const double r = s.scale().ballRadiusMm();
    const Vec3d pa = s.scale().toMm(start), pb = s.scale().toMm(end);
    const Vec3d p0{pa[0] + r * d[0], pa[1] + r * d[1], pa[2] + r * d[2]};
    const Vec3d p1{pb[0] - r * d[0], pb[1] - r * d[1], pb[2] - r * d[2]};
    const Color color = holeColor(hole);
    for (BallId id : s.ballIds()) {
        if (id == a || id == b) continue;
        if (pointSegmentDistanceSq(s.ball(id).positionMm, p0, p1) < std::pow(s.strutBallLimitMm(color), 2))
            return true;
    }
    for (StrutId t : s.strutIds()) {
        const Strut& st = s.strut(t);
        bool shares = false;
        for (const auto& [ball, h] : {std::pair<BallId, int>{a, hole}, {b, oppositeHole(hole)}}) {
            if (ball == kNoId || (st.a != ball && st.b != ball)) continue;
            if ((st.a == ball ? st.holeA : st.holeB) == h) return true;
            shares = true;
        }
        if (shares) continue;
        if (segmentSegmentDistanceSq(p0, p1, st.startMm, st.endMm) <
            std::pow(s.strutStrutLimitMm(color, st.color), 2))
            return true;
    }
    return false;
}

bool bruteForceBallCollides(const Structure& s, const GoldenVector3& p) {
    if (s.findBall(p) != kNoId) return true;
    const Vec3d mm = s.scale().toMm(p);
    for (BallId id : s.ballIds()) {
        const Vec3d& q = s.ball(id).positionMm;
        if (std::pow(mm[0] - q[0], 2) + std::pow(mm[1] - q[1], 2) + std::pow(mm[2] - q[2], 2) <
            std::pow(s.ballBallLimitMm(), 2))
            return true;
    }
    for (StrutId t : s.strutIds()) {
        const Strut& st = s.strut(t);
        if (pointSegmentDistanceSq(mm, st.startMm, st.endMm) < std::pow(s.strutBallLimitMm(st.color), 2))
            return true;
    }
    return false;
}

std::vector<std::tuple<int, uint32_t, uint32_t>> asTuples(const std::vector<Collision>& cs) {
    std::vector<std::tuple<int, uint32_t, uint32_t>> out;
    for (const Collision& c : cs) out.emplace_back(int(c.kind), c.first, c.second);
    return out;
}

}  // namespace

TEST_CASE("collisions: segment distances") {
    CHECK(segmentSegmentDistanceSq({0, 0, 0}, {10, 0, 0}, {5, -5, 3}, {5, 5, 3}) == doctest::Approx(9.0));
    CHECK(segmentSegmentDistanceSq({0, 0, 0}, {10, 0, 0}, {2, 4, 0}, {8, 4, 0}) ==
          doctest::Approx(16.0));  // parallel
    CHECK(segmentSegmentDistanceSq({0, 0, 0}, {10, 0, 0}, {13, 4, 0}, {20, 4, 0}) == doctest::Approx(25.0));
    CHECK(segmentSegmentDistanceSq({0, 0, 0}, {0, 0, 0}, {1, 1, 0}, {1, 1, 0}) == doctest::Approx(2.0));
    CHECK(pointSegmentDistanceSq({5, 3, 0}, {0, 0, 0}, {10, 0, 0}) == doctest::Approx(9.0));
    CHECK(pointSegmentDistanceSq({-4, 3, 0}, {0, 0, 0}, {10, 0, 0}) == doctest::Approx(25.0));
}

TEST_CASE("collisions: two balls too close, and not") {
    Structure s;
    s.addBall(GoldenVector3{});
    // One vZome unit = 9.03 mm < 17.7 mm ball diameter.
    const GoldenVector3 near = vec(Golden{1}, Golden{}, Golden{});
    CHECK(s.ballCollides(near));
    CHECK(s.ballCollides(GoldenVector3{}));  // an occupied position
    s.addBall(near);
    const std::vector<Collision> cs = findCollisions(s);
    REQUIRE(cs.size() == 1);
    CHECK(cs[0].kind == CollisionKind::BallBall);
    CHECK(cs[0].distanceMm == doctest::Approx(s.scale().unitMm()));
    CHECK(cs[0].limitMm == doctest::Approx(17.7));
    // Non-case: unconnected balls one B0 apart.
    Structure t;
    t.addBall(GoldenVector3{});
    CHECK_FALSE(t.ballCollides(latticePoint(1, 0, 0)));
    t.addBall(latticePoint(1, 0, 0));
    CHECK(findCollisions(t).empty());
    // Two units = 18.07 mm: clear at the default, colliding with 1 mm clearance.
    const GoldenVector3 two = vec(Golden{2}, Golden{}, Golden{});
    CHECK_FALSE(t.ballCollides(two + latticePoint(3, 0, 0)));
    Structure u;
    u.addBall(GoldenVector3{});
    CHECK_FALSE(u.ballCollides(two));
    CollisionOptions clearance;
    clearance.clearanceMm = 1.0;
    Structure v(ZomeScale{}, clearance);
    v.addBall(GoldenVector3{});
    CHECK(v.ballCollides(two));
}

TEST_CASE("collisions: a strut passing through a ball it does not end at") {
    Structure s;
    const BallId a = s.addBall(GoldenVector3{});
    s.addBall(GoldenVector3{Golden{2, 4}, Golden{}, Golden{}});  // B1 along +x
    const GoldenVector3 onAxis = latticePoint(1, 0, 0);          // B0 along +x: on the B1 strut
    CHECK_FALSE(s.strutCollides(s.ball(a).position, 0, 1));
    const StrutId t = s.addStrut(a, 0, 1);
    CHECK(s.ballCollides(onAxis));
    const BallId c = s.addBall(onAxis);
    std::vector<Collision> cs = findCollisions(s);
    REQUIRE(cs.size() == 1);
    CHECK(cs[0].kind == CollisionKind::StrutBall);
    CHECK(cs[0].first == t);
    CHECK(cs[0].second == c);
    CHECK(cs[0].distanceMm == doctest::Approx(0.0).epsilon(1e-9));
    // Querying the strut with the ball already there collides too.
    s.removeStrut(t);
    CHECK(s.strutCollides(s.ball(a).position, 0, 1));
    // Non-case: the same ball moved one B0 off the axis.
    s.removeBall(c);
    s.addStrut(a, 0, 1);
    CHECK_FALSE(s.ballCollides(latticePoint(1, 1, 0)));
    s.addBall(latticePoint(1, 1, 0));
    CHECK(findCollisions(s).empty());
}

TEST_CASE("collisions: crossing struts, and struts that pass at a distance") {
    // Strut 1: B1 along +x from the origin. Strut 2: B1 along +y crossing it at x = 1+2φ units.
    const Golden x0{1, 2};
    for (const bool offset : {false, true}) {
        Structure s;
        const Golden z = offset ? Golden{2, 2} : Golden{};  // B0 = 47.3 mm above, or in the plane
        const BallId a = s.addBall(GoldenVector3{});
        s.addBall(vec(Golden{2, 4}, Golden{}, Golden{}));
        const BallId c = s.addBall(vec(x0, Golden{-1, -2}, z));
        s.addBall(vec(x0, Golden{1, 2}, z));
        s.addStrut(a, 0, 1);
        CHECK(s.strutCollides(s.ball(c).position, 1, 1) == !offset);
        s.addStrut(c, 1, 1);
        const std::vector<Collision> cs = findCollisions(s);
        if (offset) {
            CHECK(cs.empty());
        } else {
            REQUIRE(cs.size() == 1);
            CHECK(cs[0].kind == CollisionKind::StrutStrut);
            CHECK(cs[0].distanceMm == doctest::Approx(0.0).epsilon(1e-9));
            CHECK(cs[0].limitMm == doctest::Approx(6.6));
        }
    }
}

TEST_CASE("collisions: parallel struts close together, and a cube lattice's parallel edges") {
    // Strut 1: B1 along +x. Strut 2: B1 along +x, shifted (1+φ) along x and (φ−1) = 5.58 mm along y.
    Structure s;
    const BallId a = s.addBall(GoldenVector3{});
    s.addBall(vec(Golden{2, 4}, Golden{}, Golden{}));
    const BallId c = s.addBall(vec(Golden{1, 1}, Golden{-1, 1}, Golden{}));
    s.addBall(vec(Golden{3, 5}, Golden{-1, 1}, Golden{}));
    s.addStrut(a, 0, 1);
    CHECK(s.strutCollides(s.ball(c).position, 0, 1));
    s.addStrut(c, 0, 1);
    const std::vector<Collision> cs = findCollisions(s);
    CHECK(hasKind(cs, CollisionKind::StrutStrut));
    for (const Collision& col : cs)
        if (col.kind == CollisionKind::StrutStrut)
            CHECK(col.distanceMm == doctest::Approx(s.scale().unitMm() * (kPhi - 1.0)));
    // Non-case: a 4x4x4 lattice of B0 cubes has many parallel edges 47.3 mm apart.
    CHECK(findCollisions(makeCubeLattice(4)).empty());
}

TEST_CASE("collisions: struts sharing a ball in different holes are exempt, the same hole is not") {
    // A ball with a size-1 strut in every one of its 62 holes is buildable.
    Structure s;
    const BallId centre = s.addBall(GoldenVector3{});
    for (int h = 0; h < kHoleCount; ++h) {
        const GoldenVector3 end = strutVector(h, 1);
        CHECK_FALSE(s.ballCollides(end));
        CHECK_FALSE(s.strutCollides(GoldenVector3{}, h, 1));
        s.addBall(end);
        s.addStrut(centre, h, 1);
    }
    CHECK(s.ball(centre).valence == 62);
    CHECK(findCollisions(s).empty());
    // A second strut in a used hole (here a B2 through hole 0) overlaps the first.
    CHECK(s.strutCollides(GoldenVector3{}, 0, 2));
}

TEST_CASE("collisions: the spatial hash agrees with brute force on random structures") {
    for (uint64_t seed : {1u, 2u, 3u}) {
        Structure s;
        std::mt19937_64 rng(seed);
        s.addBall(GoldenVector3{});
        // Random walks of struts: balls land close to each other and struts cross, so there are
        // collisions of every kind.
        for (int step = 0; step < 600; ++step) {
            const BallId id = BallId(rng() % s.ballIdBound());
            const int hole = int(rng() % kHoleCount), size = int(rng() % kSizeCount);
            const GoldenVector3 end = s.ball(id).position + strutVector(hole, size);
            if (s.findBall(end) == kNoId) s.addBall(end);
            if (s.strutBetween(id, s.findBall(end))) s.addStrut(id, hole, size);
            if (step % 7 == 0 && s.strutCount() > 0) {  // removals exercise the hash updates
                const StrutId t = StrutId(rng() % s.strutIdBound());
                if (s.hasStrut(t)) s.removeStrut(t);
            }
        }
        const auto expected = bruteForceCollisions(s);
        CHECK(expected.size() > 10);
        bool sawKind[3] = {false, false, false};
        for (const auto& c : expected) sawKind[std::get<0>(c)] = true;
        CHECK((sawKind[0] && sawKind[1] && sawKind[2]));
        CHECK(asTuples(findCollisions(s)) == expected);
        // Queries, at random places near and far.
        int hits = 0;
        for (int q = 0; q < 3000; ++q) {
            const BallId id = BallId(rng() % s.ballIdBound());
            if (!s.hasBall(id)) continue;
            const int hole = int(rng() % kHoleCount), size = int(rng() % kSizeCount);
            const GoldenVector3& p = s.ball(id).position;
            const bool strutHit = s.strutCollides(p, hole, size);
            REQUIRE(strutHit == bruteForceStrutCollides(s, p, hole, size));
            const GoldenVector3 target =
                p + strutVector(hole, size) + strutVector(int(rng() % kHoleCount), 0);
            REQUIRE(s.ballCollides(target) == bruteForceBallCollides(s, target));
            hits += strutHit ? 1 : 0;
        }
        CHECK(hits > 100);
    }
}

TEST_CASE("collisions: a small grid cell and a large one give the same answers") {
    CollisionOptions small, large;
    small.gridCellMm = 5.0;
    large.gridCellMm = 400.0;
    const Structure a = makeCubeLattice(3, ZomeScale{}, small);
    const Structure b = makeCubeLattice(3, ZomeScale{}, large);
    CHECK(a.gridCellMm() == 5.0);
    for (int h = 0; h < kHoleCount; ++h)
        for (int size = 0; size < kSizeCount; ++size) {
            const GoldenVector3 p = latticePoint(1, 1, 1);
            CHECK(a.strutCollides(p, h, size) == b.strutCollides(p, h, size));
            CHECK(a.ballCollides(p + strutVector(h, size)) == b.ballCollides(p + strutVector(h, size)));
        }
}
