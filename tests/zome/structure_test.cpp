// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/structure.h"

#include <doctest/doctest.h>

#include <functional>
#include <random>
#include <string>
#include <vector>

#include "zome_fixtures.h"
#include "zomefab/core/error.h"

using namespace zomefab;
using namespace zomefab::zome;
using zomefab::zome::test::latticePoint;
using zomefab::zome::test::makeCubeLattice;

namespace {

std::string errorMessage(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.message();
    }
    return "(no error)";
}

/// Every invariant of a structure, checked by brute force.
void checkInvariants(const Structure& s) {
    size_t balls = 0, struts = 0;
    for (BallId id = 0; id < s.ballIdBound(); ++id) {
        if (!s.hasBall(id)) continue;
        ++balls;
        const Ball& b = s.ball(id);
        REQUIRE(s.findBall(b.position) == id);
        int valence = 0;
        for (int h = 0; h < kHoleCount; ++h) {
            const StrutId t = b.holes[size_t(h)];
            if (t == kNoId) continue;
            ++valence;
            REQUIRE(s.hasStrut(t));
            const Strut& st = s.strut(t);
            REQUIRE(((st.a == id && st.holeA == h) || (st.b == id && st.holeB == h)));
        }
        REQUIRE(valence == b.valence);
    }
    for (StrutId id = 0; id < s.strutIdBound(); ++id) {
        if (!s.hasStrut(id)) continue;
        ++struts;
        const Strut& st = s.strut(id);
        REQUIRE(s.hasBall(st.a));
        REQUIRE(s.hasBall(st.b));
        REQUIRE(s.ball(st.b).position - s.ball(st.a).position == strutVector(st.holeA, st.size));
        REQUIRE(st.holeB == oppositeHole(st.holeA));
        REQUIRE(st.color == holeColor(st.holeA));
        REQUIRE(s.ball(st.a).holes[st.holeA] == id);
        REQUIRE(s.ball(st.b).holes[st.holeB] == id);
    }
    REQUIRE(balls == s.ballCount());
    REQUIRE(struts == s.strutCount());
}

}  // namespace

TEST_CASE("structure: a B0 cube lattice") {
    const Structure s = makeCubeLattice(3);
    CHECK(s.ballCount() == 64);
    CHECK(s.strutCount() == 3 * 3 * 16);
    checkInvariants(s);
    const BallId corner = s.findBall(latticePoint(0, 0, 0));
    const BallId inner = s.findBall(latticePoint(1, 1, 1));
    CHECK(corner == 0);
    CHECK(s.ball(corner).valence == 3);
    CHECK(s.ball(inner).valence == 6);
    CHECK(s.neighbor(corner, 0) == s.findBall(latticePoint(1, 0, 0)));
    CHECK(s.neighbor(inner, oppositeHole(2)) == s.findBall(latticePoint(1, 1, 0)));
    CHECK(s.neighbor(corner, 3) == kNoId);
    CHECK(s.findBall(latticePoint(7, 0, 0)) == kNoId);
    CHECK(s.ball(inner).positionMm[0] == doctest::Approx(47.3).epsilon(1e-12));
    CHECK(s.strutBetween(corner, s.findBall(latticePoint(1, 1, 0))) == std::nullopt);  // face diagonal
    CHECK(s.strutBetween(corner, s.findBall(latticePoint(1, 0, 0))) == std::nullopt);  // hole taken
}

TEST_CASE("structure: adding a strut checks the vector and both holes") {
    Structure s;
    const BallId a = s.addBall(latticePoint(0, 0, 0));
    const BallId b = s.addBall(latticePoint(1, 0, 0));
    const BallId c = s.addBall(latticePoint(1, 1, 0));
    const BallId far = s.addBall(GoldenVector3{Golden{2, 4}, Golden{}, Golden{}});  // B1 along +x
    CHECK(errorMessage([&] { s.addStrut(a, c); }).find("is not a Zome strut") != std::string::npos);
    CHECK(errorMessage([&] { s.addStrut(a, a); }).find("to itself") != std::string::npos);
    const StrutId ab = s.addStrut(a, b);
    CHECK(s.strut(ab).holeA == 0);
    CHECK(s.strut(ab).holeB == 15);
    CHECK(s.strut(ab).color == Color::Blue);
    CHECK(s.strut(ab).size == 0);
    // B1 from a to far would use hole 0 of a again.
    const std::string busy = errorMessage([&] { s.addStrut(a, far); });
    CHECK(busy == "strut from ball 0 to ball 3: hole 0 of ball 0 is already used by strut 0");
    CHECK(errorMessage([&] { s.addStrut(b, 0, 2); }).find("no ball at") != std::string::npos);
    CHECK(errorMessage([&] { s.addBall(latticePoint(1, 0, 0)); }).find("already holds ball 1") !=
          std::string::npos);
    CHECK(errorMessage([&] { s.removeBall(a); }).find("1 struts attached") != std::string::npos);
    s.removeStrut(ab);
    CHECK(s.isHoleFree(a, 0));
    CHECK(s.isHoleFree(b, 15));
    const StrutId af = s.addStrut(a, far);
    CHECK(s.strut(af).size == 1);
    CHECK(af == ab);  // freed id reused
    checkInvariants(s);
    try {
        s.addStrut(a, c);
        FAIL("expected an error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::InvalidInput);
    }
}

TEST_CASE("structure: ids are deterministic and freed ids are reused last-in first-out") {
    Structure s = makeCubeLattice(2);
    const BallId n = s.ballIdBound();
    const BallId corner = s.findBall(latticePoint(2, 2, 2));
    std::vector<StrutId> attached;
    for (int h = 0; h < kHoleCount; ++h)
        if (!s.isHoleFree(corner, h)) attached.push_back(s.ball(corner).holes[size_t(h)]);
    for (StrutId t : attached) s.removeStrut(t);
    s.removeBall(corner);
    CHECK(s.ballCount() == size_t(n) - 1);
    CHECK(s.ballIdBound() == n);  // tombstone
    CHECK_FALSE(s.hasBall(corner));
    CHECK(s.addBall(latticePoint(5, 5, 5)) == corner);
    CHECK(s.addBall(latticePoint(6, 5, 5)) == n);
    // Two identical edit sequences give identical ids.
    Structure x = makeCubeLattice(2), y = makeCubeLattice(2);
    std::mt19937_64 rx(9), ry(9);
    for (Structure* st : {&x, &y}) {
        std::mt19937_64& rng = st == &x ? rx : ry;
        for (int i = 0; i < 200; ++i) {
            const StrutId t = StrutId(rng() % st->strutIdBound());
            if (st->hasStrut(t)) {
                const Strut copy = st->strut(t);
                st->removeStrut(t);
                if (rng() % 2) st->addStrut(copy.a, copy.holeA, copy.size);
            }
        }
    }
    REQUIRE(x.strutIdBound() == y.strutIdBound());
    for (StrutId t = 0; t < x.strutIdBound(); ++t) {
        REQUIRE(x.hasStrut(t) == y.hasStrut(t));
        if (x.hasStrut(t)) CHECK(x.strut(t).a == y.strut(t).a);
    }
}

TEST_CASE("structure: random edits keep every invariant, including across grid growth") {
    Structure s;
    std::mt19937_64 rng(21);
    s.addBall(GoldenVector3{});
    for (int step = 0; step < 4000; ++step) {
        const int action = int(rng() % 10);
        const BallId id = BallId(rng() % s.ballIdBound());
        if (!s.hasBall(id)) continue;
        const int hole = int(rng() % kHoleCount);
        const int size = int(rng() % kSizeCount);
        const GoldenVector3 end = s.ball(id).position + strutVector(hole, size);
        if (action < 5) {  // grow: a new ball and a strut to it
            if (s.findBall(end) == kNoId && s.isHoleFree(id, hole)) {
                s.addBall(end);
                s.addStrut(id, hole, size);
            }
        } else if (action < 7) {  // close a strut between existing balls
            const BallId other = s.findBall(end);
            if (other != kNoId && s.strutBetween(id, other)) s.addStrut(id, other);
        } else if (action < 9) {  // remove a strut
            const StrutId t = s.ball(id).holes[size_t(hole)];
            if (t != kNoId) s.removeStrut(t);
        } else if (s.ball(id).valence == 0 && s.ballCount() > 1) {
            s.removeBall(id);
        }
    }
    CHECK(s.ballCount() > 500);
    checkInvariants(s);
    const Structure c = s.compacted();
    CHECK(c.ballCount() == s.ballCount());
    CHECK(c.strutCount() == s.strutCount());
    CHECK(c.ballIdBound() == c.ballCount());
    CHECK(c.strutIdBound() == c.strutCount());
    checkInvariants(c);
    for (BallId id : s.ballIds()) CHECK(c.findBall(s.ball(id).position) != kNoId);
}

TEST_CASE("structure: addBallWithId keeps ids, then reuses the gaps lowest first") {
    Structure s;
    s.addBallWithId(5, latticePoint(0, 0, 0));
    s.addBallWithId(2, latticePoint(1, 0, 0));
    CHECK(errorMessage([&] { s.addBallWithId(5, latticePoint(2, 0, 0)); }) == "ball 5: duplicate id");
    CHECK(errorMessage([&] { s.addBallWithId(7, latticePoint(1, 0, 0)); }).find("ball 7: same position") !=
          std::string::npos);
    CHECK(s.ballIdBound() == 6);
    CHECK(s.addBall(latticePoint(3, 0, 0)) == 0);
    CHECK(s.addBall(latticePoint(4, 0, 0)) == 1);
    CHECK(s.addBall(latticePoint(5, 0, 0)) == 3);
}

TEST_CASE("structure: invalid options are usage errors") {
    CollisionOptions bad;
    bad.clearanceMm = -1.0;
    CHECK_THROWS_AS(Structure(ZomeScale{}, bad), Error);
    ZomeScale scale;
    scale.b0Mm = 0.0;
    try {
        Structure s(scale);
        FAIL("expected an error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::Usage);
    }
}
