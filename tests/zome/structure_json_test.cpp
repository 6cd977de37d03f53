// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/structure_json.h"

#include <doctest/doctest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "zome_fixtures.h"
#include "zomefab/core/error.h"

using namespace zomefab;
using namespace zomefab::zome;
using nlohmann::json;
using zomefab::zome::test::latticePoint;
using zomefab::zome::test::makeCubeLattice;

namespace {

std::string fixture(const std::string& name) {
    std::ifstream in(std::string(ZOMEFAB_ZOME_TEST_DATA) + "/" + name, std::ios::binary);
    REQUIRE(in.good());
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

/// The InvalidInput message of reading @p text, or "(no error)".
std::string readError(const std::string& text) {
    try {
        structureFromJsonText(text);
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::InvalidInput);
        return e.message();
    }
    return "(no error)";
}

std::string readError(const json& j) { return readError(j.dump()); }

json cubeJson() { return json::parse(fixture("cube.json")); }

std::vector<std::string> lines(const std::string& text) {
    std::vector<std::string> out;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) out.push_back(line);
    return out;
}

}  // namespace

TEST_CASE("structure json: round trip keeps ids, exact positions, struts, scale, origin and transform") {
    ZomeScale scale;
    scale.b0Mm = kVzomeNominalB0Mm;
    scale.originMm = {10.0, -5.0, 3.25};
    Structure s = makeCubeLattice(2, scale);
    // A Y0 to the centre of the first cube and an R0 beyond it.
    const GoldenVector3 centre{Golden{1, 1}, Golden{1, 1}, Golden{1, 1}};
    const BallId c = s.addBall(centre);
    s.addStrut(0, c);
    const BallId r = s.addBall(centre + strutVector(50, 0));
    s.addStrut(c, r);
    // A gap in the ball ids and in the strut ids.
    const BallId corner = s.findBall(latticePoint(2, 2, 2));
    for (int h = 0; h < kHoleCount; ++h)
        if (!s.isHoleFree(corner, h)) s.removeStrut(s.ball(corner).holes[size_t(h)]);
    s.removeBall(corner);

    const Transform4d transform = Transform4d::scaleTranslate(2.5, {1.0, 2.0, 3.0});
    const json j = structureToJson(s, transform);
    CHECK(j["format"] == "zomefab.structure");
    CHECK(j["version"] == 1);
    CHECK(j["unit_mm"].get<double>() == doctest::Approx(8.8365).epsilon(1e-4));
    CHECK(j["balls"].size() == s.ballCount());
    CHECK(j["struts"].size() == s.strutCount());

    Transform4d readTransform;
    const Structure t = structureFromJsonText(j.dump(), ZomeScale{}, CollisionOptions{}, &readTransform);
    CHECK(readTransform == transform);
    CHECK(t.scale().b0Mm == scale.b0Mm);
    for (int i = 0; i < 3; ++i)
        CHECK(t.scale().originMm[size_t(i)] == doctest::Approx(scale.originMm[size_t(i)]));
    REQUIRE(t.ballIds() == s.ballIds());
    for (BallId id : s.ballIds()) {
        CHECK(t.ball(id).position == s.ball(id).position);
        for (int i = 0; i < 3; ++i)
            CHECK(t.ball(id).positionMm[size_t(i)] == doctest::Approx(s.ball(id).positionMm[size_t(i)]));
    }
    const std::vector<StrutId> sIds = s.strutIds();
    REQUIRE(t.strutCount() == sIds.size());
    for (size_t k = 0; k < sIds.size(); ++k) {
        const Strut &x = s.strut(sIds[k]), &y = t.strut(StrutId(k));
        CHECK(x.a == y.a);
        CHECK(x.b == y.b);
        CHECK(x.holeA == y.holeA);
        CHECK(x.holeB == y.holeB);
        CHECK(x.color == y.color);
        CHECK(x.size == y.size);
    }
    // Writing the read structure gives the same document (up to float noise in mm).
    json again = structureToJson(t, readTransform);
    for (json* doc : {&again}) (*doc)["balls"].clear();
    json first = j;
    first["balls"].clear();
    CHECK(again == first);
}

TEST_CASE("structure json: the fixtures") {
    const Structure cube = structureFromJsonText(fixture("cube.json"));
    CHECK(cube.ballCount() == 8);
    CHECK(cube.strutCount() == 12);
    CHECK(readError(fixture("bad_json.json")).rfind("invalid JSON: ", 0) == 0);
    CHECK(readError(fixture("wrong_version.json")) == "unsupported version 2 (this build reads version 1)");
    CHECK(readError(fixture("not_zome_strut.json")) ==
          "strut 12 (ball 0 to ball 3): vector (2+2phi, 2+2phi, 0) is not a Zome strut");
    CHECK(readError(fixture("hole_used_twice.json")) ==
          "strut 1 (ball 0 to ball 2): hole 0 of ball 0 is already used by strut 0");
    CHECK(readError(fixture("duplicate_id.json")) == "ball 0: duplicate id");
    CHECK(readError(fixture("unknown_ball.json")) == "strut 12: unknown ball id 99");
    CHECK(readError(fixture("color_contradiction.json")) ==
          "strut 0 (ball 0 to ball 1): color is red but the vector is a blue B0 strut");
    const Structure close = structureFromJsonText(fixture("collision.json"));  // valid, but collides
    CHECK(close.ballCount() == 2);
}

TEST_CASE("structure json: the reader rejects every contradiction with a message naming the culprit") {
    CHECK(readError(json::array()) == "not a zomefab.structure file: the top level is not a JSON object");
    json j = cubeJson();
    j.erase("format");
    CHECK(readError(j) == "not a zomefab.structure file: no \"format\"");
    j = cubeJson();
    j["format"] = "zomefab.report";
    CHECK(readError(j) == "not a zomefab.structure file: format is \"zomefab.report\"");
    j = cubeJson();
    j["version"] = "1";
    CHECK(readError(j) == "version must be an integer");
    j = cubeJson();
    j["unit_mm"] = 9.5;
    CHECK(readError(j).rfind("unit_mm 9.5 contradicts b0_mm 47.3", 0) == 0);
    j = cubeJson();
    j["balls"][3]["mm"][0] = 50.0;
    CHECK(readError(j).rfind("ball 3: mm [50, 47.3, 0] does not match", 0) == 0);
    j = cubeJson();
    j["balls"][2]["exact"][1][0] = int64_t(1) << 41;
    CHECK(readError(j) == "ball 2: exact coefficient out of range (|a|, |b| <= 2^40)");
    j = cubeJson();
    j["balls"][2]["exact"] = {{0, 0}, {0, 0}};
    CHECK(readError(j) == "ball 2: \"exact\" must be 3 pairs [a, b]");
    j = cubeJson();
    j["balls"][1]["id"] = 1.5;
    CHECK(readError(j) == "balls[1]: id must be an integer");
    j = cubeJson();
    j["balls"][1]["id"] = 100000;
    CHECK(readError(j) == "ball 100000: id too large for 8 balls (ids must be below 2 x count + 1024)");
    j = cubeJson();
    j["transform_mm"][3][0] = 1.0;
    CHECK(readError(j) == "transform_mm must be affine (last row 0 0 0 1)");
    j = cubeJson();
    j["struts"][0]["size"] = 1;
    CHECK(readError(j) == "strut 0 (ball 0 to ball 1): size is 1 but the vector is a blue B0 strut");
    j = cubeJson();
    j["struts"][0]["hole_b"] = 0;
    CHECK(readError(j) ==
          "strut 0 (ball 0 to ball 1): hole_b is 0 but the vector enters ball 1 through hole 15");
    j = cubeJson();
    j["struts"][0]["hole_a"] = 3;
    CHECK(readError(j) ==
          "strut 0 (ball 0 to ball 1): hole_a is 3 but the vector leaves ball 0 through hole 0");
    j = cubeJson();
    j["struts"][0]["color"] = "green";
    CHECK(readError(j) == "strut 0 (ball 0 to ball 1): color must be \"blue\", \"yellow\" or \"red\"");
    j = cubeJson();
    j["struts"][0]["b"] = 0;
    CHECK(readError(j) == "strut 0 (ball 0 to ball 0): both ends are the same ball");
    j = cubeJson();
    j["struts"].push_back({{"a", 0}});
    CHECK(readError(j) == "strut 12: needs ball ids \"a\" and \"b\"");
    j = cubeJson();
    j.erase("struts");
    CHECK(readError(j) == "\"struts\" must be an array");
    // A scaled strut: parallel to a hole, but not a catalogue length.
    j = json{{"format", "zomefab.structure"},
             {"version", 1},
             {"balls",
              {{{"id", 0}, {"exact", {{0, 0}, {0, 0}, {0, 0}}}},
               {{"id", 1}, {"exact", {{4, 4}, {0, 0}, {0, 0}}}}}},
             {"struts", {{{"a", 0}, {"b", 1}}}}};
    CHECK(readError(j) ==
          "strut 0 (ball 0 to ball 1): vector (4+4phi, 0, 0) is not a Zome strut "
          "(parallel to hole 0 but not a blue catalogue length)");
}

TEST_CASE("structure json: lenient on redundancy") {
    // Only the required keys; colour, size, holes, mm, unit_mm and the transform are derived.
    json j = {{"format", "zomefab.structure"},
              {"version", 1},
              {"unit_mm", 47.3 / (2.0 * kPhi * kPhi)},
              {"balls",
               {{{"id", 4}, {"exact", {{0, 0}, {0, 0}, {0, 0}}}},
                {{"id", 9}, {"exact", {{1, 2}, {1, 1}, {0, 0}}}}}},
              {"struts", {{{"a", 9}, {"b", 4}}}},
              {"comment", "unknown keys are ignored"}};
    Transform4d t = Transform4d::scaleTranslate(3.0, {1, 1, 1});
    const Structure s = structureFromJson(j, ZomeScale{}, CollisionOptions{}, &t);
    CHECK(t == Transform4d::identity());
    CHECK(s.scale().b0Mm == doctest::Approx(47.3));
    CHECK(s.hasBall(4));
    CHECK(s.hasBall(9));
    REQUIRE(s.strutCount() == 1);
    CHECK(s.strut(0).color == Color::Red);
    CHECK(s.strut(0).a == 9);
    CHECK(s.strut(0).holeA == 56);  // −(φ³, φ², 0) is the negative end of red axis 25
}

TEST_CASE("vef: a single B0 cube, line by line") {
    const Structure cube = makeCubeLattice(1);
    const std::vector<std::string> expected = {
        "vZome VEF 6 field golden",
        "",
        "8",  // vertices: w x y z, each number (phis,ones)
        "(0,0) (0,0) (0,0) (0,0)",
        "(0,0) (2,2) (0,0) (0,0)",
        "(0,0) (0,0) (2,2) (0,0)",
        "(0,0) (2,2) (2,2) (0,0)",
        "(0,0) (0,0) (0,0) (2,2)",
        "(0,0) (2,2) (0,0) (2,2)",
        "(0,0) (0,0) (2,2) (2,2)",
        "(0,0) (2,2) (2,2) (2,2)",
        "",
        "",
        "",
        "12",  // edges as vertex index pairs
        "0 1",
        "0 2",
        "0 4",
        "1 3",
        "1 5",
        "2 3",
        "2 6",
        "3 7",
        "4 5",
        "4 6",
        "5 7",
        "6 7",
        "",
        "",
        "",
        "0",  // no panels
        "",
        "",
        "",
        "8",  // balls: every vertex
        "0 1 2 3 4 5 6 7 ",
        "",
    };
    CHECK(lines(structureToVef(cube)) == expected);
}

TEST_CASE("vef: numbers are (phis,ones), tokens parse like vZome's VefParser") {
    Structure s;
    const BallId a = s.addBall(GoldenVector3{Golden{-1, 1}, Golden{}, Golden{3}});
    s.addBall(GoldenVector3{Golden{-1, 1}, Golden{}, Golden{3}} + strutVector(0, 1));  // + B1 = 2+4φ
    s.addStrut(a, 0, 1);
    const std::string vef = structureToVef(s);
    // Whitespace-separated tokens, as VefParser reads them.
    std::istringstream in(vef);
    std::vector<std::string> tok;
    for (std::string t; in >> t;) tok.push_back(t);
    const std::vector<std::string> expected = {
        "vZome", "VEF",   "6",     "field", "golden", "2", "(0,0)", "(1,-1)", "(0,0)", "(0,3)", "(0,0)",
        "(5,1)", "(0,0)", "(0,3)", "1",     "0",      "1", "0",     "2",      "0",     "1"};
    CHECK(tok == expected);
    // More than ten balls wrap the ball list every ten entries.
    const std::string big = structureToVef(makeCubeLattice(2));
    const std::vector<std::string> l = lines(big);
    CHECK(std::find(l.begin(), l.end(), "0 1 2 3 4 5 6 7 8 9 ") != l.end());
    CHECK(std::find(l.begin(), l.end(), "20 21 22 23 24 25 26 ") != l.end());
}
