// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-preview end to end: pieces from a directory (an STL and a GLB: glTF read and Draco
/// written by the shipped binary), pieces.json placement back into frame coordinates, stdout, the
/// Khronos validator, determinism.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <set>

#include "glb_test_util.h"
#include "report_fixtures.h"
#include "test_util.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/transform.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"

using namespace zomefab;
using namespace zomefab::test;

namespace {

std::string preview() { return toolPath("zf-preview"); }
std::string cubeFrame() { return std::string(ZOMEFAB_ZOME_TEST_DATA) + "/cube.json"; }

nlohmann::json glbJson(const std::string& glb) { return parseGlb(glb).json; }

std::set<std::string> nodeNames(const nlohmann::json& j) {
    std::set<std::string> names;
    for (const nlohmann::json& n : j["nodes"])
        if (n.contains("name")) names.insert(n["name"].get<std::string>());
    return names;
}

}  // namespace

TEST_CASE("zf-preview: frame and a directory of pieces (STL and GLB)") {
    ScratchDir dir("zf-preview");
    std::filesystem::create_directories(dir.path() / "pieces");
    writeMesh(makeBox({-20, -20, -20}, {0, 0, 0}), dir.file("pieces/piece-00.stl"));
    std::filesystem::copy_file(std::string(ZOMEFAB_CLI_FIXTURES) + "/tetra.glb",
                               dir.file("pieces/piece-01.glb"));
    std::string err;
    REQUIRE(runCapture(preview() + " " + cubeFrame() + " --pieces " + dir.file("pieces") + " -o " +
                           dir.file("p.glb") + " 2>&1",
                       &err) == 0);
    CHECK(err.find("8 balls, 12 struts, 2 pieces -> ") != std::string::npos);
    const nlohmann::json j = glbJson(readInputBytes(dir.file("p.glb")));
    const std::set<std::string> names = nodeNames(j);
    for (const char* n : {"zomefab", "pieces", "balls", "struts", "piece-00", "piece-01", "ball-0", "ball-7",
                          "strut-0", "strut-11"})
        CHECK(names.count(n) == 1);
    size_t draco = 0;
    for (const nlohmann::json& m : j["meshes"])
        if (m["primitives"][0].contains("extensions")) ++draco;
    CHECK(draco == 2);
    CHECK(j["scenes"][0]["extras"]["parts"]["balls"] == 8);
    CHECK(j["scenes"][0]["extras"]["parts"]["struts"]["B0"] == 12);

    // Deterministic, and "-o -" puts exactly the same bytes on stdout.
    std::string stdoutBytes;
    REQUIRE(runCapture(preview() + " " + cubeFrame() + " --pieces " + dir.file("pieces") + " -o - -q",
                       &stdoutBytes) == 0);
    CHECK(stdoutBytes == readInputBytes(dir.file("p.glb")));

    if (!hasCommand("node")) {
        MESSAGE("node is not installed: the Khronos glTF-Validator check is skipped");
        return;
    }
    const nlohmann::json report = khronosValidate(dir.file("p.glb"));
    CHECK(report["errors"] == 0);
    CHECK(report["warnings"] == 0);
}

TEST_CASE("zf-preview: pieces.json pieces go back from the printer to the frame's coordinates") {
    ScratchDir dir("zf-preview-json");
    // A piece that sits at [10, 30] x [0, 20] x [0, 5] mm in frame coordinates; the grid is the
    // frame moved by (100, 0, 0); printing turns it 90° about z and moves it to the bed centre.
    Transform4d frameToGrid = Transform4d::scaleTranslate(1.0, {100, 0, 0});
    Transform4d gridToPrint;
    gridToPrint.m = {0, -1, 0, 50, 1, 0, 0, -110, 0, 0, 1, 0, 0, 0, 0, 1};
    TriMesh printed = makeBox({10, 0, 0}, {30, 20, 5});
    transformInPlace(printed, gridToPrint * frameToGrid);
    writeMesh(printed, dir.file("piece-00.stl"));
    auto matrix = [](const Transform4d& t) { return toJson(t); };
    const nlohmann::json pieces = {{"format", "zomefab.pieces"},
                                   {"version", 1},
                                   {"frame_to_grid_mm", matrix(frameToGrid)},
                                   {"pieces",
                                    {{{"piece", 0},
                                      {"file", "piece-00.stl"},
                                      {"orientation", {{"transform_mm", matrix(gridToPrint)}}}}}}};
    writeBytes(dir.file("pieces.json"), pieces.dump());
    REQUIRE(runCapture(preview() + " " + cubeFrame() + " --pieces " + dir.path().string() +
                       " --no-draco -o " + dir.file("p.glb") + " -q") == 0);
    const nlohmann::json j = glbJson(readInputBytes(dir.file("p.glb")));
    CHECK(!j.contains("extensionsUsed"));
    const nlohmann::json& accessor =
        j["accessors"][j["meshes"][0]["primitives"][0]["attributes"]["POSITION"].get<size_t>()];
    const std::vector<double> lo = accessor["min"], hi = accessor["max"];
    CHECK(lo[0] == doctest::Approx(10.0));
    CHECK(lo[1] == doctest::Approx(0.0));
    CHECK(hi[0] == doctest::Approx(30.0));
    CHECK(hi[1] == doctest::Approx(20.0));
    CHECK(hi[2] == doctest::Approx(5.0));

    writeBytes(dir.file("pieces.json"),
               R"({"format": "zomefab.pieces", "version": 1, "pieces": [{"piece": 0}]})");
    std::string err;
    CHECK(runCapture(preview() + " " + cubeFrame() + " --pieces " + dir.file("pieces.json") + " -o " +
                         dir.file("bad.glb") + " 2>&1",
                     &err) == 2);
    CHECK(err.find("pieces.json: pieces[0]: needs \"file\"") != std::string::npos);
    CHECK(!std::filesystem::exists(dir.file("bad.glb")));
}
