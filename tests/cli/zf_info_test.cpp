// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-info end to end: the JSON on stdout and in --report, and silence on stdout on failure.
#include <doctest/doctest.h>

#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "test_util.h"

using namespace zomefab::test;
using nlohmann::json;

namespace {

struct Run {
    int exitCode = -1;
    std::string out;
};

/// Runs zf-info with @p args (shell words), stderr discarded.
Run runZfInfo(const std::string& args) {
    Run r;
    const std::string command = "'" + toolPath("zf-info") + "' " + args + " 2>/dev/null";
    FILE* pipe = popen(command.c_str(), "r");
    REQUIRE(pipe != nullptr);
    char buf[4096];
    size_t n;
    while ((n = fread(buf, 1, sizeof(buf), pipe)) > 0) r.out.append(buf, n);
    const int status = pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

}  // namespace

TEST_CASE("zf-info: JSON report of a scaled y-up mesh, on stdout and in --report") {
    ScratchDir dir;
    const std::string report = dir.file("info.json");
    const Run r = runZfInfo("'" + dataPath("bunny_npm_3674.stl") + "' --up y --height-mm 400 --report '" +
                            report + "'");
    REQUIRE(r.exitCode == 0);
    const json j = json::parse(r.out);
    CHECK(j["format"] == "zomefab.info");
    REQUIRE(j["meshes"].size() == 1);
    const json& m = j["meshes"][0];
    CHECK(m["valid"] == true);
    CHECK(m["format"] == "stl");
    CHECK(m["input"]["triangles"] == 3674);
    CHECK(m["mesh"]["triangles"] == 3674);
    CHECK(m["mesh"]["vertices"] == 1839);
    CHECK(m["mesh"]["closed"] == true);
    CHECK(m["mesh"]["components"] == 1);
    CHECK(m["mesh"]["boundary_edges"] == 0);
    CHECK(m["mesh"]["bbox_mm"]["size"][2].get<double>() == doctest::Approx(400.0));
    CHECK(m["mesh"]["bbox_mm"]["min"][2].get<double>() == doctest::Approx(0.0));
    CHECK(m["mesh"]["volume_mm3"].get<double>() > 0);
    // y up -> z up: the input's y extent became the height.
    const double s = m["transform_mm"][2][1].get<double>();
    CHECK(s * m["input"]["bbox"]["size"][1].get<double>() == doctest::Approx(400.0));

    std::ifstream in(report);
    const json file = json::parse(in);
    CHECK(file["meshes"] == j["meshes"]);
    CHECK(file["tool"] == "zf-info");
    CHECK(file["warnings"].is_array());
}

TEST_CASE("zf-info: --allow-invalid reports an open mesh instead of failing") {
    const Run r = runZfInfo("'" + dataPath("bunny_stanford_open_69k.stl") + "' '" +
                            dataPath("bunny_npm_3674.stl") + "' --allow-invalid");
    REQUIRE(r.exitCode == 0);
    const json j = json::parse(r.out);
    REQUIRE(j["meshes"].size() == 2);
    const json& open = j["meshes"][0];
    CHECK(open["valid"] == false);
    CHECK(open["input"]["closed"] == false);
    CHECK(open["input"]["boundary_edges"] == 223);
    CHECK(open["input"]["boundary_loops"] == 5);
    CHECK(open["error"].get<std::string>().rfind("open mesh: 223 boundary edges in 5 loops", 0) == 0);
    CHECK(!open.contains("mesh"));
    CHECK(j["meshes"][1]["valid"] == true);
}

TEST_CASE("zf-info: an inside-out mesh is reported flipped, with the warning in the report") {
    ScratchDir dir;
    // The fixture tetrahedron with every face reversed.
    writeBytes(dir.file("inv.obj"),
               "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 4 2\nf 2 4 3\nf 3 4 1\n");
    const Run r = runZfInfo("'" + dir.file("inv.obj") + "' --report '" + dir.file("r.json") + "'");
    REQUIRE(r.exitCode == 0);
    const json j = json::parse(r.out);
    CHECK(j["meshes"][0]["input"]["volume"].get<double>() < 0);
    CHECK(j["meshes"][0]["mesh"]["volume_mm3"].get<double>() == doctest::Approx(1.0 / 6.0));
    std::ifstream in(dir.file("r.json"));
    const json file = json::parse(in);
    REQUIRE(file["warnings"].size() == 1);
    CHECK(file["warnings"][0].get<std::string>().find("inside out") != std::string::npos);
}

TEST_CASE("zf-info: nothing on stdout when a mesh fails") {
    const Run r = runZfInfo("'" + dataPath("bunny_npm_3674.stl") + "' '" + std::string(ZOMEFAB_CLI_FIXTURES) +
                            "/flat_pillow.obj'");
    CHECK(r.exitCode == 2);
    CHECK(r.out.empty());
}

TEST_CASE("zf-info: --help lists the options, --version the generator") {
    Run r = runZfInfo("--help");
    CHECK(r.exitCode == 0);
    for (const char* option :
         {"--height-mm", "--scale", "--up", "--in-format", "--report", "--threads", "--seed"})
        CHECK(r.out.find(option) != std::string::npos);
    r = runZfInfo("--version");
    CHECK(r.exitCode == 0);
    CHECK(r.out.find("zomefab ") == 0);
}
