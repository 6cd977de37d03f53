// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/zome_system.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "zomefab/core/error.h"

using namespace zomefab;
using namespace zomefab::zome;

namespace {

/// Exact squared size-0 lengths in vZome units: B0² = 4φ⁴ = 8+12φ, Y0² = 3φ⁴ = 6+9φ,
/// R0² = φ⁴(2+φ) = 7+11φ.
Golden squaredLength0(Color c) {
    switch (c) {
        case Color::Blue:
            return {8, 12};
        case Color::Yellow:
            return {6, 9};
        case Color::Red:
            return {7, 11};
    }
    return {};
}

/// Angles in degrees, rounded to 0.01, between the axes (lines) of two colours.
std::set<double> axisAngles(Color x, Color y) {
    std::set<double> out;
    for (int i = 0; i < kHoleCount; ++i)
        for (int j = 0; j < kHoleCount; ++j) {
            if (holeColor(i) != x || holeColor(j) != y || holeInfo(i).axis == holeInfo(j).axis) continue;
            const double c = std::abs(holeCosine(i, j));
            out.insert(std::round(std::acos(std::min(1.0, c)) * 180.0 / M_PI * 100.0) / 100.0);
        }
    return out;
}

/// The definition the matcher must agree with: parallel to a hole axis (exact cross product) and
/// of a catalogue length (exact squared length φ^{2n}·size-0²).
std::optional<StrutMatch> matchByDefinition(const GoldenVector3& v) {
    const std::optional<int> hole = parallelHole(v);
    if (!hole) return std::nullopt;
    const Golden len2 = dot(v, v);
    const Color c = holeColor(*hole);
    for (int size = 0; size < kSizeCount; ++size)
        if (len2 == Golden::phiPower(2 * size) * squaredLength0(c)) return StrutMatch{*hole, c, size};
    return std::nullopt;
}

GoldenVector3 permute(const GoldenVector3& v) { return {v[1], v[2], v[0]}; }

}  // namespace

TEST_CASE("zome system: 31 axes, 62 holes, colours and opposite holes") {
    std::map<Color, int> holesOf;
    std::set<int> axes;
    for (int h = 0; h < kHoleCount; ++h) {
        const HoleInfo& info = holeInfo(h);
        ++holesOf[info.color];
        axes.insert(info.axis);
        CHECK(oppositeHole(oppositeHole(h)) == h);
        CHECK(oppositeHole(h) != h);
        CHECK(holeInfo(oppositeHole(h)).axis == info.axis);
        CHECK(holeColor(oppositeHole(h)) == info.color);
        for (int size = 0; size < kSizeCount; ++size)
            CHECK(strutVector(oppositeHole(h), size) == -strutVector(h, size));
        const auto [first, last] = holeRange(info.color);
        CHECK(h >= first);
        CHECK(h < last);
    }
    CHECK(axes.size() == size_t(kAxisCount));
    CHECK(holesOf[Color::Blue] == 30);    // rectangular holes
    CHECK(holesOf[Color::Yellow] == 20);  // triangular
    CHECK(holesOf[Color::Red] == 12);     // pentagonal
    CHECK(oppositeHole(0) == 15);         // the numbering of formats.md's example strut
    CHECK(oppositeHole(30) == 40);
    CHECK(oppositeHole(50) == 56);
}

TEST_CASE("zome system: exact lengths, unit directions and size ratios") {
    for (int h = 0; h < kHoleCount; ++h) {
        const Color c = holeColor(h);
        for (int size = 0; size < kSizeCount; ++size) {
            const GoldenVector3& v = strutVector(h, size);
            CHECK(dot(v, v) == Golden::phiPower(2 * size) * squaredLength0(c));
            if (size > 0) CHECK(v == Golden::phi() * strutVector(h, size - 1));
        }
        const Vec3d& d = holeDirection(h);
        CHECK(std::abs(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]) - 1.0) < 1e-15);
        CHECK(holeCosine(h, h) == doctest::Approx(1.0).epsilon(1e-15));
        CHECK(holeCosine(h, oppositeHole(h)) == doctest::Approx(-1.0).epsilon(1e-15));
    }
    // Length ratios of the paper §4.1: y = (√3/2)·b, r = (√(2+φ)/2)·b, size n+1 = φ·size n.
    const ZomeTables& t = zomeTables();
    for (int size = 0; size < kSizeCount; ++size) {
        const double b = t.lengthUnits[0][size];
        CHECK(t.lengthUnits[1][size] == doctest::Approx(std::sqrt(3.0) / 2.0 * b).epsilon(1e-14));
        CHECK(t.lengthUnits[2][size] == doctest::Approx(std::sqrt(2.0 + kPhi) / 2.0 * b).epsilon(1e-14));
        CHECK(b == doctest::Approx(2.0 * std::pow(kPhi, 2 + size)).epsilon(1e-14));
    }
}

TEST_CASE("zome system: icosahedral angle sets between the axes") {
    using S = std::set<double>;
    CHECK(axisAngles(Color::Blue, Color::Blue) == S{36.0, 60.0, 72.0, 90.0});
    CHECK(axisAngles(Color::Yellow, Color::Yellow) == S{41.81, 70.53});
    CHECK(axisAngles(Color::Red, Color::Red) == S{63.43});
    CHECK(axisAngles(Color::Blue, Color::Yellow) == S{20.91, 54.74, 69.09, 90.0});
    CHECK(axisAngles(Color::Blue, Color::Red) == S{31.72, 58.28, 90.0});
    CHECK(axisAngles(Color::Red, Color::Yellow) == S{37.38, 79.19});
}

TEST_CASE("zome system: the hole set is closed under the pyritohedral symmetries, exactly") {
    std::set<std::string> vectors;
    for (int h = 0; h < kHoleCount; ++h) vectors.insert(strutVector(h, 0).toString());
    for (int h = 0; h < kHoleCount; ++h) {
        const GoldenVector3& v = strutVector(h, 0);
        CHECK(vectors.count(permute(v).toString()) == 1);  // 3-fold rotation about (1,1,1)
        for (int axis = 0; axis < 3; ++axis) {             // the three coordinate mirrors
            GoldenVector3 m = v;
            m[axis] = -m[axis];
            CHECK(vectors.count(m.toString()) == 1);
        }
        const std::optional<StrutMatch> m = matchStrut(permute(v));
        REQUIRE(m);
        CHECK(m->color == holeColor(h));  // symmetries preserve colours
    }
}

TEST_CASE("zome system: hole sections follow the ball's faces") {
    auto dot3 = [](const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; };
    // zome-geometry.md §2: the +z blue hole has its long side along x, +x along y, +y along z.
    CHECK(std::abs(holeSectionAxis(2)[0]) == doctest::Approx(1.0));
    CHECK(std::abs(holeSectionAxis(0)[1]) == doctest::Approx(1.0));
    CHECK(std::abs(holeSectionAxis(1)[2]) == doctest::Approx(1.0));
    for (int hole = 0; hole < kHoleCount; ++hole) {
        const Vec3d& u = holeSectionAxis(hole);
        CHECK(dot3(u, holeDirection(hole)) == doctest::Approx(0.0).epsilon(1e-12));
        CHECK(dot3(u, u) == doctest::Approx(1.0));
    }
    // Every blue hole is a 2-fold axis between two red (5-fold) neighbours at the same angle; the
    // rectangle's long side runs from one to the other, so it is along their difference.
    for (int hole = 0; hole < 30; ++hole) {
        std::vector<std::pair<double, int>> reds;
        for (int r = 50; r < 62; ++r) reds.push_back({holeCosine(hole, r), r});
        std::sort(reds.rbegin(), reds.rend());
        CHECK(reds[0].first == doctest::Approx(reds[1].first));
        CHECK(reds[1].first > reds[2].first + 0.1);
        const Vec3d &a = holeDirection(reds[0].second), &b = holeDirection(reds[1].second);
        const Vec3d diff{a[0] - b[0], a[1] - b[1], a[2] - b[2]};
        CHECK(std::abs(dot3(diff, holeSectionAxis(hole))) == doctest::Approx(std::sqrt(dot3(diff, diff))));
    }
    // A yellow triangle's corner points at the nearest red hole: the corner direction is that red
    // direction's projection on the face plane.
    const Vec3d &d = holeDirection(30), &u = holeSectionAxis(30);
    double best = -2.0;
    for (int h = 50; h < 62; ++h) {
        const Vec3d& r = holeDirection(h);
        best = std::max(best, dot3(r, u) / std::sqrt(1.0 - std::pow(dot3(r, d), 2)));
    }
    CHECK(best == doctest::Approx(1.0));
}

TEST_CASE("zome system: the B0 cube") {
    // Holes 0, 1, 2 are +x, +y, +z: three orthogonal blue axes.
    const GoldenVector3 &x = strutVector(0, 0), &y = strutVector(1, 0), &z = strutVector(2, 0);
    CHECK(holeColor(0) == Color::Blue);
    CHECK(dot(x, y).isZero());
    CHECK(dot(y, z).isZero());
    CHECK(dot(z, x).isZero());
    CHECK(cross(x, y) == Golden{2, 2} * z);  // right-handed, |x| = B0 = 2φ² = 2+2φ
    CHECK(x == GoldenVector3{Golden{2, 2}, Golden{}, Golden{}});

    // The body diagonal is not one strut but two Y0 struts end to end.
    const GoldenVector3 diagonal = x + y + z;
    CHECK_FALSE(matchStrut(diagonal));
    const std::optional<int> along = parallelHole(diagonal);
    REQUIRE(along);
    CHECK(holeColor(*along) == Color::Yellow);
    const GoldenVector3 half{Golden{1, 1}, Golden{1, 1}, Golden{1, 1}};
    CHECK(half + half == diagonal);
    const std::optional<StrutMatch> y0 = matchStrut(half);
    REQUIRE(y0);
    CHECK(y0->color == Color::Yellow);
    CHECK(y0->size == 0);
    CHECK(y0->hole == *along);

    // Face diagonals are not Zome vectors at all (green directions).
    for (const GoldenVector3& face : {x + y, y + z, z + x, x - y}) {
        CHECK_FALSE(matchStrut(face));
        CHECK_FALSE(parallelHole(face));
    }
}

TEST_CASE("zome system: matchStrut accepts every catalogue strut and rejects perturbed and scaled ones") {
    for (int h = 0; h < kHoleCount; ++h) {
        for (int size = 0; size < kSizeCount; ++size) {
            const GoldenVector3& v = strutVector(h, size);
            const std::optional<StrutMatch> m = matchStrut(v);
            REQUIRE(m);
            CHECK(*m == StrutMatch{h, holeColor(h), size});
            CHECK(matchByDefinition(v) == m);
            // perturbed by the smallest steps of Z[φ] in any coordinate
            for (int axis = 0; axis < 3; ++axis)
                for (const Golden& eps :
                     {Golden{1}, Golden{-1}, Golden{0, 1}, Golden{0, -1}, Golden{1, -1}}) {
                    GoldenVector3 p = v;
                    p[axis] += eps;
                    CHECK_FALSE(matchStrut(p));
                }
            // scaled: parallel but not a catalogue length
            CHECK_FALSE(matchStrut(Golden{2} * v));
            CHECK_FALSE(matchStrut(Golden{3} * v));
            CHECK(parallelHole(Golden{2} * v) == h);
        }
        CHECK_FALSE(matchStrut(Golden::phiPower(3) * strutVector(h, 0)));  // "size 3" (B3 is discontinued)
        CHECK_FALSE(
            matchStrut(Golden::phiPower(-1) * strutVector(h, 0)));  // R00 and smaller are not modelled
    }
    CHECK_FALSE(matchStrut(GoldenVector3{}));
    // Random small vectors: the hash lookup agrees with "cross product zero + catalogue length".
    std::mt19937_64 rng(17);
    std::uniform_int_distribution<int64_t> coef(-7, 7);
    int matched = 0;
    for (int i = 0; i < 20000; ++i) {
        GoldenVector3 v;
        if (i % 4 == 0) {
            v = strutVector(int(rng() % kHoleCount), int(rng() % kSizeCount));
            v[int(rng() % 3)] += Golden{coef(rng) / 4, coef(rng) / 4};
        } else {
            for (int k = 0; k < 3; ++k) v[k] = Golden{coef(rng), coef(rng)};
        }
        const std::optional<StrutMatch> m = matchStrut(v);
        CHECK(m == matchByDefinition(v));
        matched += m ? 1 : 0;
    }
    CHECK(matched > 100);
}

TEST_CASE("zome system: names and the physical scale") {
    CHECK(partName(Color::Blue, 0) == "B0");
    CHECK(partName(Color::Yellow, 2) == "Y2");
    CHECK(partName(Color::Red, 1) == "R1");
    CHECK(std::string(colorName(Color::Yellow)) == "yellow");
    CHECK(colorFromName("red") == Color::Red);
    CHECK_FALSE(colorFromName("green"));

    ZomeScale scale;  // paper: b0 = 47.3 mm
    CHECK(scale.unitMm() == doctest::Approx(9.03350).epsilon(1e-5));
    CHECK(scale.strutLengthMm(Color::Blue, 0) == doctest::Approx(47.3).epsilon(1e-12));
    CHECK(scale.strutLengthMm(Color::Blue, 1) == doctest::Approx(76.53).epsilon(1e-3));
    CHECK(scale.strutLengthMm(Color::Blue, 2) == doctest::Approx(123.83).epsilon(1e-3));
    CHECK(scale.strutLengthMm(Color::Yellow, 0) == doctest::Approx(40.96).epsilon(1e-3));
    CHECK(scale.strutLengthMm(Color::Red, 0) == doctest::Approx(44.99).epsilon(1e-3));
    scale.b0Mm = kVzomeNominalB0Mm;  // vZome: 1 unit = 8.8365 mm
    CHECK(scale.unitMm() == doctest::Approx(8.8365).epsilon(1e-4));
    CHECK(scale.strutLengthMm(Color::Yellow, 1) == doctest::Approx(64.83).epsilon(1e-3));
    CHECK(scale.strutLengthMm(Color::Red, 2) == doctest::Approx(115.20).epsilon(1e-3));

    ZomeScale bad;
    bad.b0Mm = -1.0;
    CHECK_THROWS_AS(bad.validate(), Error);
    bad = ZomeScale{};
    bad.ballDiameterMm = std::nan("");
    CHECK_THROWS_AS(bad.validate(), Error);
}
