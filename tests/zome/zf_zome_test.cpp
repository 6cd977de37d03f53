// SPDX-License-Identifier: GPL-3.0-or-later
/// @file End to end: the zf-zome tool's outputs, checked for content (exit codes and messages of
/// the failure cases are ctest entries "cli.zome.*").
#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "test_util.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;

namespace {

std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string fixturePath(const std::string& name) { return std::string(ZOMEFAB_ZOME_TEST_DATA) + "/" + name; }

int run(const std::string& args) {
    const std::string cmd = test::toolPath("zf-zome") + " " + args + " 2>/dev/null";
    return WEXITSTATUS(std::system(cmd.c_str()));
}

}  // namespace

TEST_CASE("zf-zome: check, vef and parts produce the library's results") {
    test::ScratchDir dir("zf-zome");
    const std::string cube = fixturePath("cube.json");
    const zome::Structure frame = zome::structureFromJsonText(readText(cube));

    REQUIRE(run("check " + cube + " -o " + dir.file("check.json")) == 0);
    const nlohmann::json report = nlohmann::json::parse(readText(dir.file("check.json")));
    CHECK(report["valid"] == true);
    CHECK(report["collision_free"] == true);
    CHECK(report["balls"] == 8);
    CHECK(report["struts"] == 12);
    CHECK(report["parts"]["struts"]["B0"] == 12);
    CHECK(report["parts"]["cost_usd"].get<double>() == doctest::Approx(12 * 0.19 + 8 * 0.29));
    // Same input, same bytes.
    REQUIRE(run("check " + cube + " -o " + dir.file("check2.json")) == 0);
    CHECK(readText(dir.file("check.json")) == readText(dir.file("check2.json")));

    REQUIRE(run("vef " + cube + " -o " + dir.file("cube.vef")) == 0);
    CHECK(readText(dir.file("cube.vef")) == zome::structureToVef(frame));

    REQUIRE(run("parts " + cube + " --strut-usd 0.5 > " + dir.file("parts.txt")) == 0);
    zome::PriceOptions prices;
    prices.strutUsd = 0.5;
    CHECK(readText(dir.file("parts.txt")) == zome::partsTable(zome::partsList(frame), prices));

    // A colliding frame: exit 3, and the report lists the pair.
    CHECK(run("check " + fixturePath("collision.json") + " -o " + dir.file("bad.json")) == 3);
    const nlohmann::json bad = nlohmann::json::parse(readText(dir.file("bad.json")));
    CHECK(bad["collision_free"] == false);
    REQUIRE(bad["collisions"].size() == 1);
    CHECK(bad["collisions"][0]["kind"] == "ball-ball");

    // Invalid input: exit 2 and no output file.
    CHECK(run("vef " + fixturePath("hole_used_twice.json") + " -o " + dir.file("x.vef")) == 2);
    CHECK_FALSE(std::ifstream(dir.file("x.vef")).good());
}
