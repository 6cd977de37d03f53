// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/parts.h"

#include <doctest/doctest.h>

#include <string>

#include "zome_fixtures.h"

using namespace zomefab;
using namespace zomefab::zome;
using zomefab::zome::test::makeCubeLattice;

TEST_CASE("parts: counts by Zometool name and the paper's prices") {
    Structure s = makeCubeLattice(2);  // 27 balls, 54 B0
    const GoldenVector3 centre{Golden{1, 1}, Golden{1, 1}, Golden{1, 1}};
    const BallId c = s.addBall(centre);
    s.addStrut(0, c);                                         // Y0
    const BallId r = s.addBall(centre + strutVector(50, 1));  // R1
    s.addStrut(c, 50, 1);
    (void)r;
    const PartsList p = partsList(s);
    CHECK(p.balls == 29);
    CHECK(p.count(Color::Blue, 0) == 54);
    CHECK(p.count(Color::Yellow, 0) == 1);
    CHECK(p.count(Color::Red, 1) == 1);
    CHECK(p.count(Color::Red, 0) == 0);
    CHECK(p.strutTotal() == 56);
    CHECK(partsCostUsd(p) == doctest::Approx(56 * 0.19 + 29 * 0.29));
    PriceOptions prices;
    prices.strutUsd = 0.5;
    prices.ballUsd = 1.0;
    CHECK(partsCostUsd(p, prices) == doctest::Approx(56 * 0.5 + 29.0));

    const nlohmann::json j = partsListToJson(p);
    CHECK(j["balls"] == 29);
    CHECK(j["struts"]["B0"] == 54);
    CHECK(j["struts"]["Y0"] == 1);
    CHECK(j["struts"]["R1"] == 1);
    CHECK(j["struts"]["B2"] == 0);
    CHECK(j["strut_total"] == 56);
    CHECK(j["cost_usd"].get<double>() == doctest::Approx(19.05));
}

TEST_CASE("parts: the table follows the paper's Table 2 layout") {
    PartsList p;  // the paper's Moai row: 112 B0, 140 Y0, 73 balls
    p.balls = 73;
    p.struts[size_t(Color::Blue)][0] = 112;
    p.struts[size_t(Color::Yellow)][0] = 140;
    const std::string expected =
        "Blue            Red             Yellow          Total   Total\n"
        "B0   B1   B2    R0   R1   R2    Y0   Y1   Y2    struts  balls\n"
        "112  0    0     0    0    0     140  0    0     252     73\n"
        "\n"
        "Cost: 252 struts x 0.19 USD + 73 balls x 0.29 USD = 69.05 USD\n";
    CHECK(partsTable(p) == expected);

    // Five-digit counts widen the columns instead of running into each other.
    PartsList big;
    big.balls = 4096;
    big.struts[size_t(Color::Blue)][0] = 11520;
    const std::string wide =
        "Blue               Red                Yellow             Total   Total\n"
        "B0    B1    B2     R0    R1    R2     Y0    Y1    Y2     struts  balls\n"
        "11520 0     0      0     0     0      0     0     0      11520   4096\n"
        "\n"
        "Cost: 11520 struts x 0.19 USD + 4096 balls x 0.29 USD = 3376.64 USD\n";
    CHECK(partsTable(big) == wide);
}
