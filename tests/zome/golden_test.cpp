// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/golden.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/zome/zome_system.h"

using namespace zomefab;
using namespace zomefab::zome;

namespace {

Golden randomGolden(std::mt19937_64& rng, int64_t range) {
    std::uniform_int_distribution<int64_t> d(-range, range);
    return Golden{d(rng), d(rng)};
}

/// Fibonacci numbers F(0..92) (F(92) is the largest that fits int64).
std::vector<int64_t> fibonacci() {
    std::vector<int64_t> f{0, 1};
    while (f.size() < 93) f.push_back(f[f.size() - 1] + f[f.size() - 2]);
    return f;
}

}  // namespace

TEST_CASE("golden: phi squared is phi plus one") {
    const Golden phi = Golden::phi();
    CHECK(phi * phi == phi + 1);
    CHECK(phi * phi == Golden{1, 1});
    CHECK(phi.timesPhi() == phi * phi);
    CHECK(phi.dividedByPhi() == Golden{1});
    CHECK(Golden::phiPower(-1) == Golden{-1, 1});  // 1/φ = φ − 1
    CHECK(Golden::phiPower(3) == Golden{1, 2});    // φ³ = 1 + 2φ
    CHECK(std::abs(Golden::phiPower(5).toDouble() - std::pow(kPhi, 5)) < 1e-12);
}

TEST_CASE("golden: ring laws hold exactly on random values") {
    std::mt19937_64 rng(7);
    for (int i = 0; i < 2000; ++i) {
        const Golden x = randomGolden(rng, 1000), y = randomGolden(rng, 1000), z = randomGolden(rng, 1000);
        CHECK(x + y == y + x);
        CHECK(x * y == y * x);
        CHECK((x + y) + z == x + (y + z));
        CHECK((x * y) * z == x * (y * z));
        CHECK(x * (y + z) == x * y + x * z);
        CHECK(x - x == Golden{});
        CHECK(-(-x) == x);
        CHECK(x * x.conjugate() == Golden{x.norm()});
        CHECK(x.timesPhi().dividedByPhi() == x);
        // the exact value agrees with double arithmetic where doubles are reliable
        CHECK(std::abs((x * y).toDouble() - x.toDouble() * y.toDouble()) <
              1e-6 * (1 + std::abs((x * y).toDouble())));
    }
}

TEST_CASE("golden: inverse exists exactly for the units plus or minus phi^n") {
    for (int n = -20; n <= 20; ++n) {
        for (int sign : {1, -1}) {
            const Golden u = Golden{sign} * Golden::phiPower(n);
            const std::optional<Golden> inv = u.inverse();
            REQUIRE(inv);
            CHECK(u * *inv == Golden{1});
            CHECK(*inv == Golden{sign} * Golden::phiPower(-n));
        }
    }
    CHECK_FALSE(Golden{2}.inverse());
    CHECK_FALSE(Golden{3, 1}.inverse());  // norm 9 + 3 − 1 = 11
    CHECK_FALSE(Golden{}.inverse());
    std::mt19937_64 rng(11);
    for (int i = 0; i < 1000; ++i) {
        const Golden x = randomGolden(rng, 500), y = randomGolden(rng, 500);
        if (y.isZero()) continue;
        const std::optional<Golden> q = (x * y).dividedExactlyBy(y);
        REQUIRE(q);
        CHECK(*q == x);
    }
    CHECK_FALSE(Golden{1}.dividedExactlyBy(Golden{2}));
}

TEST_CASE("golden: long chains stay exact and overflow is reported, never wrapped") {
    const std::vector<int64_t> f = fibonacci();
    Golden x{1};
    for (int n = 1; n <= 92; ++n) {
        x = x.timesPhi();  // φⁿ = F(n−1) + F(n)·φ
        REQUIRE(x == Golden{f[size_t(n - 1)], f[size_t(n)]});
    }
    CHECK_THROWS_AS(x.timesPhi(), Error);  // F(93) > 2^63
    try {
        (void)x.timesPhi();
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::ProcessingFailed);
    }
    CHECK_THROWS_AS(Golden(int64_t(1) << 40) * Golden(int64_t(1) << 40), Error);
    CHECK_THROWS_AS(Golden(std::numeric_limits<int64_t>::max()) + Golden(1), Error);
    CHECK_THROWS_AS(Golden(std::numeric_limits<int64_t>::min()) - Golden(1), Error);

    // A million strut steps out and back return exactly to the origin.
    GoldenVector3 p;
    std::mt19937_64 rng(3);
    std::vector<std::pair<int, int>> steps;
    for (int i = 0; i < 1000000; ++i) {
        steps.push_back({int(rng() % kHoleCount), int(rng() % kSizeCount)});
        p += strutVector(steps.back().first, steps.back().second);
    }
    CHECK_FALSE(p.isZero());
    for (auto it = steps.rbegin(); it != steps.rend(); ++it) p -= strutVector(it->first, it->second);
    CHECK(p.isZero());
}

TEST_CASE("golden: the sign of values within 1e-12 of zero is decided exactly") {
    const std::vector<int64_t> f = fibonacci();
    // F(n+1) − F(n)·φ = (−1)ⁿ φ⁻ⁿ: tiny, alternating, with huge cancelling coefficients.
    int wrongInDouble = 0;
    for (int n = 20; n <= 91; ++n) {
        const Golden x{f[size_t(n + 1)], -f[size_t(n)]};
        const int expected = n % 2 == 0 ? 1 : -1;
        CHECK(x.sign() == expected);
        CHECK((-x).sign() == -expected);
        CHECK(x == Golden{expected} * Golden::phiPower(-n));
        if (n >= 58) CHECK(std::abs(std::pow(kPhi, -n)) < 1e-12);
        const double approx = x.toDouble();
        if ((approx > 0 ? 1 : approx < 0 ? -1 : 0) != expected) ++wrongInDouble;
    }
    CHECK(wrongInDouble > 0);  // double evaluation gets some of these wrong; sign() never does
    CHECK(Golden{}.sign() == 0);
    CHECK(Golden{std::numeric_limits<int64_t>::min(), 1}.sign() == -1);
    CHECK(Golden{std::numeric_limits<int64_t>::min(), std::numeric_limits<int64_t>::max()}.sign() == 1);
    CHECK(Golden{std::numeric_limits<int64_t>::max(), std::numeric_limits<int64_t>::min()}.sign() == -1);
    CHECK(Golden{0, -1} < Golden{-1});  // −φ < −1
    CHECK(Golden{-1, 1} < Golden{1});   // 1/φ < 1
    CHECK(Golden{2, -1} > Golden{});    // 2 − φ > 0
    // Random values: the exact order agrees with doubles wherever the gap is large.
    std::mt19937_64 rng(5);
    for (int i = 0; i < 5000; ++i) {
        const Golden x = randomGolden(rng, 1000000);
        const double v = x.toDouble();
        if (std::abs(v) > 1e-6) CHECK(x.sign() == (v > 0 ? 1 : -1));
    }
}

TEST_CASE("golden: vectors, cross products and hashing") {
    const GoldenVector3 x{Golden{1}, Golden{}, Golden{}};
    const GoldenVector3 y{Golden{}, Golden{1}, Golden{}};
    CHECK(cross(x, y) == GoldenVector3{Golden{}, Golden{}, Golden{1}});
    CHECK(dot(x, y).isZero());
    CHECK(areParallel(x, Golden::phi() * x));
    CHECK(areParallel(x, -x));
    CHECK_FALSE(areParallel(x, x + y));
    CHECK(GoldenVector3Hash{}(x) == GoldenVector3Hash{}(GoldenVector3{Golden{1}, Golden{}, Golden{}}));
    CHECK(GoldenVector3Hash{}(x) != GoldenVector3Hash{}(y));
    CHECK(Golden{2, 2}.toString() == "2+2phi");
    CHECK(Golden{0, -3}.toString() == "-3phi");
    CHECK(Golden{-1}.toString() == "-1");
}
