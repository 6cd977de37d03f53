// SPDX-License-Identifier: GPL-3.0-or-later
// End to end through the built tools: the piped chain zf-sdf | zf-shell | zf-mesh, and the same
// bytes whatever the thread count.
#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>
#include <iterator>

#include "mesh_distance.h"
#include "test_util.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/sdf/vdb_file.h"

using namespace zomefab;

namespace {

const std::string kBunny = test::dataPath("bunny_npm_3674.stl");
const std::string kScale = " --height-mm 150 --up y --shell-mm 8 -q";

}  // namespace

TEST_CASE("tools: zf-sdf | zf-shell | zf-mesh through pipes gives the closed shell the files give") {
    test::ScratchDir dir("zomefab-sdf-tools");
    const std::string sdf = test::toolPath("zf-sdf"), shell = test::toolPath("zf-shell"),
                      mesh = test::toolPath("zf-mesh");
    const std::string piped = dir.file("piped.stl");
    REQUIRE(test::runShell(sdf + " " + kBunny + kScale + " -o - | " + shell + " - --shell-mm 8 -q -o - | " +
                           mesh + " - -q -o " + piped) == 0);
    // The same through files.
    REQUIRE(test::runShell(sdf + " " + kBunny + kScale + " -o " + dir.file("object.vdb")) == 0);
    REQUIRE(test::runShell(shell + " " + dir.file("object.vdb") + " --shell-mm 8 -q -o " +
                           dir.file("shell.vdb")) == 0);
    REQUIRE(test::runShell(mesh + " " + dir.file("shell.vdb") + " -q -o " + dir.file("files.stl")) == 0);
    CHECK(test::readFile(piped) == test::readFile(dir.file("files.stl")));

    const TriMesh result = readMesh(piped);
    const test::EdgeReport edges = test::edgeReport(result);
    CHECK(edges.boundaryEdges == 0);
    CHECK(edges.misorientedEdges == 0);
    CHECK(edges.components == 2);  // outer wall and cavity
    CHECK(signedVolume(result) > 0);

    // The grids carry where they came from.
    const auto grids =
        sdf::parseVdb(test::readFile(dir.file("shell.vdb")), "shell.vdb", RunContext::silent());
    REQUIRE(grids.size() == 1);
    CHECK(grids[0].info().name == "shell");
    CHECK(grids[0].info().shellMm == 8.0);
    CHECK(grids[0].info().sourceFile == kBunny);
    CHECK(grids[0].info().transformMm.at(0, 0) != 1.0);  // scaled
    const auto objects =
        sdf::parseVdb(test::readFile(dir.file("object.vdb")), "object.vdb", RunContext::silent());
    REQUIRE(objects.size() == 2);
    CHECK(objects[1].info().name == "interior");
}

TEST_CASE("tools: the same input gives the same .vdb and mesh bytes with 1 or 2 threads") {
    test::ScratchDir dir("zomefab-sdf-threads");
    const std::string sdf = test::toolPath("zf-sdf"), mesh = test::toolPath("zf-mesh");
    for (const char* threads : {"1", "2"}) {
        const std::string object = dir.file(std::string("object") + threads + ".vdb");
        REQUIRE(test::runShell(sdf + " " + kBunny + kScale + " --threads " + threads + " -o " + object) == 0);
        REQUIRE(test::runShell(mesh + " " + object + " --grid object -q --threads " + threads + " -o " +
                               dir.file(std::string("object") + threads + ".stl")) == 0);
    }
    CHECK(test::readFile(dir.file("object1.vdb")).size() > 1000);
    CHECK(test::readFile(dir.file("object1.vdb")) == test::readFile(dir.file("object2.vdb")));
    CHECK(test::readFile(dir.file("object1.stl")) == test::readFile(dir.file("object2.stl")));
}
