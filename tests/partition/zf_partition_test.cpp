// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-partition end to end: a bunny in its own file coordinates, a frame file whose
/// transform_mm places it, the PARTITION.json and the coloured PLY.
#include <doctest/doctest.h>

#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "partition_fixtures.h"
#include "test_util.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
using nlohmann::json;

namespace {

int runTool(const std::string& args, const std::string& errFile) {
    const std::string cmd = zomefab::test::toolPath("zf-partition") + " " + args + " 2> " + errFile;
    const int status = std::system(cmd.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

}  // namespace

TEST_CASE("zf-partition: bunny in file coordinates, frame with transform_mm") {
    zomefab::test::ScratchDir dir("zf-partition");
    const std::string meshPath = zomefab::test::dataPath("bunny_npm_3674.stl");
    const partition::test::MeshMm bunny = partition::test::loadMeshMm(meshPath, 300.0, true);
    const partition::test::LatticeFrame frame = partition::test::makeLatticeFrame(bunny.mesh, 12.0);
    const std::string framePath = dir.file("frame.json");
    zomefab::test::writeBytes(framePath, zome::structureToJson(frame.structure, bunny.transformMm).dump());
    // Salient: the first 30 faces of one ear (faces near the highest vertex).
    const std::string facesPath = dir.file("salient.json");
    std::vector<uint32_t> salient;
    {
        size_t top = 0;
        for (size_t v = 0; v < bunny.mesh.positions.size(); ++v)
            if (bunny.mesh.positions[v][2] > bunny.mesh.positions[top][2]) top = v;
        for (uint32_t f = 0; f < bunny.mesh.triangles.size() && salient.size() < 30; ++f)
            for (uint32_t v : bunny.mesh.triangles[f]) {
                const auto& p = bunny.mesh.positions[v];
                const auto& q = bunny.mesh.positions[top];
                if ((p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) + (p[2] - q[2]) * (p[2] - q[2]) < 400.0) {
                    salient.push_back(f);
                    break;
                }
            }
        zomefab::test::writeBytes(facesPath, json(salient).dump());
    }
    const std::string common = meshPath + " " + framePath + " --printer-mm 150x150x150 --salient-faces " + facesPath;
    REQUIRE(runTool(common + " -o " + dir.file("p1.json") + " --colored-ply " + dir.file("p.ply") + " --threads 1",
                    dir.file("err1.txt")) == 0);
    REQUIRE(runTool(common + " -o " + dir.file("p2.json") + " --threads 2 -q", dir.file("err2.txt")) == 0);
    const std::string bytes = readInputBytes(dir.file("p1.json"));
    CHECK(bytes == readInputBytes(dir.file("p2.json")));  // whatever the thread count
    CHECK(readInputBytes(dir.file("err2.txt")).empty());   // -q
    CHECK(readInputBytes(dir.file("err1.txt"))
              .find("pieces, all fit 132x132x150 mm (the bed less its margins)") != std::string::npos);

    const json j = json::parse(bytes);
    CHECK(j["format"] == "zomefab.partition");
    CHECK(j["version"] == 1);
    const size_t faces = bunny.mesh.triangles.size();
    CHECK(j["mesh"]["faces"] == faces);
    CHECK(j["face_labels"].size() == faces);
    CHECK(j["face_cells"].size() == faces);
    CHECK(j["face_pieces"].size() == faces);
    CHECK(j["printer_mm"] == json::array({150.0, 150.0, 150.0}));
    // Labels are the frame's outermost balls (frame::outermostBalls = the lattice's boundary layer).
    std::vector<uint32_t> labelBalls;
    for (const json& l : j["labels"]) labelBalls.push_back(l["ball"]);
    CHECK(labelBalls == frame.outermost);
    CHECK(j["counts"]["graph_cut_partitions"] < j["counts"]["nearest_ball_partitions"]);
    CHECK(j["energy"]["graph_cut"] < j["energy"]["nearest_ball"]);
    CHECK(j["counts"]["pieces"] == j["pieces"].size());
    for (const json& p : j["pieces"]) {
        CHECK(p["fit"]["fits"] == true);
        CHECK(p["fit"]["ratio"] <= 1.0);
        CHECK(p["cells"].size() >= 1);
    }
    for (const json& c : j["cells"]) CHECK(c["w"].size() == 3);
    std::set<uint32_t> salientPieces;
    for (uint32_t f : salient) salientPieces.insert(j["face_pieces"][f].get<uint32_t>());
    CHECK(salientPieces.size() == 1);
    CHECK(j["salient_faces"].size() == salient.size());

    // The coloured PLY: the same faces, in frame millimetres.
    const TriMesh ply = readMesh(dir.file("p.ply"));
    CHECK(ply.triangles.size() == faces);
    CHECK(ply.positions[0][0] == doctest::Approx(bunny.mesh.positions[0][0]));

    // The same salient faces as a PLY `salient` face property (mesh in file coordinates), plus a
    // salient sphere around the highest point (frame mm).
    TriMesh marked = readMesh(meshPath);
    marked.salientFaces.assign(marked.triangles.size(), 0);
    for (uint32_t f : salient) marked.salientFaces[f] = 1;
    writeMesh(marked, dir.file("marked.ply"));
    size_t top = 0;
    for (size_t v = 0; v < bunny.mesh.positions.size(); ++v)
        if (bunny.mesh.positions[v][2] > bunny.mesh.positions[top][2]) top = v;
    const auto& q = bunny.mesh.positions[top];
    std::ostringstream sphere;
    sphere << q[0] << "," << q[1] << "," << q[2] << ",15";
    REQUIRE(runTool(dir.file("marked.ply") + " " + framePath + " --printer-mm 150x150x150 -q -o " + dir.file("p3.json") +
                        " --salient " + sphere.str(),
                    dir.file("err3.txt")) == 0);
    const json k = json::parse(readInputBytes(dir.file("p3.json")));
    std::set<uint32_t> markedFaces(salient.begin(), salient.end());
    size_t inSphere = 0;
    for (const json& f : k["salient_faces"]) inSphere += markedFaces.count(f.get<uint32_t>()) ? 0 : 1;
    CHECK(inSphere > 0);                                          // the sphere added faces
    CHECK(k["salient_faces"].size() == markedFaces.size() + inSphere);  // and the PLY flags are all there
    std::set<uint32_t> pieces;
    for (uint32_t f : salient) pieces.insert(k["face_pieces"][f].get<uint32_t>());
    CHECK(pieces.size() == 1);
    CHECK(k["counts"]["salient_regions_crossed"] == 0);
}

TEST_CASE("zf-partition: bad inputs exit with the documented codes and write nothing") {
    zomefab::test::ScratchDir dir("zf-partition-bad");
    const std::string mesh = zomefab::test::dataPath("bunny_npm_3674.stl");
    const std::string fix = ZOMEFAB_PARTITION_TEST_DATA;
    const std::string out = dir.file("out.json");
    CHECK(runTool(mesh + " " + fix + "/no_balls_frame.json -o " + out, dir.file("e")) == 2);
    CHECK(readInputBytes(dir.file("e")).find("no_balls_frame.json: the frame has no outermost balls") != std::string::npos);
    CHECK(runTool(mesh + " " + fix + "/far_frame.json -o " + out, dir.file("e")) == 2);
    CHECK(readInputBytes(dir.file("e")).find("frame and mesh do not match") != std::string::npos);
    CHECK(
        runTool(mesh + " " + fix + "/far_frame.json -o " + out + " --printer-mm 15x200x200 --bed-margin-mm 0",
                dir.file("e")) == 1);
    CHECK(readInputBytes(dir.file("e")).find("smaller than a Zome ball") != std::string::npos);
    // A margin that leaves no bed is refused before anything is read.
    CHECK(runTool(mesh + " " + fix + "/far_frame.json -o " + out + " --printer-mm 15x200x200",
                  dir.file("e")) == 1);
    CHECK(readInputBytes(dir.file("e")).find("--bed-margin-mm 9 leaves nothing of the 15 x 200 mm bed") !=
          std::string::npos);
    CHECK_FALSE(std::ifstream(out).good());
}
