// SPDX-License-Identifier: GPL-3.0-or-later
// zf-pieces end to end: the files it writes, the same bytes whatever the thread count, and the real
// checkers on them: admesh (every STL loads without errors or repairs) and PrusaSlicer (a piece
// slices, the 3MF loads with every part manifold), each run when it is installed.
#include <doctest/doctest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <regex>

#include "pieces_fixtures.h"
#include "test_util.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/mesh_check.h"

using namespace zomefab;
namespace fs = std::filesystem;

namespace {

bool isInstalled(const std::string& program) {
    return test::runShell("command -v " + program + " > /dev/null") == 0;
}

/// The inputs and one zf-pieces run, shared by the cases (the run takes a few seconds).
struct Run {
    test::ScratchDir dir{"zomefab-pieces-tools"};
    int exitCode = -1;
    Run() {
        pieces::test::writeToolInputs(dir.path().string());
        exitCode = runInto("out", "--threads 2 --report " + dir.file("report.json"));
    }
    /// zf-pieces on the shared inputs into dir/@p outName with @p options; its exit code. The
    /// tilt is the paper's near-perpendicular 35° and glued groups are off, at which the sphere's
    /// four quadrants stay four pieces (at the 60° default two are printed as one with a neighbour,
    /// which pieces_test covers; with glued groups the quadrant glued onto its host is printed with
    /// it, the case below). @p defaults: only the tilt is set.
    int runInto(const std::string& outName, const std::string& options, bool isDefault = false) const {
        return test::runShell(test::toolPath("zf-pieces") + " " + dir.file("shell.vdb") + " " +
                              dir.file("frame.json") + " " + dir.file("partition.json") +
                              " -q --tenon-max-tilt-deg 35 " + (isDefault ? "" : "--no-glue-groups ") +
                              options + " -o " + dir.file(outName));
    }
    std::string out(const std::string& name) const { return dir.file("out/" + name); }
};

const Run& shared() {
    static const Run r;
    return r;
}

/// The value of "Label : value" in admesh's report.
std::string admeshField(const std::string& report, const std::string& label) {
    std::smatch m;
    if (std::regex_search(report, m, std::regex(label + R"(\s*:\s*([^\n]*))"))) return m[1];
    return "(missing)";
}

}  // namespace

TEST_CASE("zf-pieces: one closed STL per piece, a 3MF per plate and pieces.json") {
    const Run& r = shared();
    REQUIRE(r.exitCode == 0);
    const nlohmann::json j = nlohmann::json::parse(test::readFile(r.out("pieces.json")));
    CHECK(j["format"] == "zomefab.pieces");
    REQUIRE(j["pieces"].size() == 4);
    size_t tenons = 0;
    for (const nlohmann::json& p : j["pieces"]) {
        const std::string file = p["file"];
        INFO(file);
        const TriMesh m = readMesh(r.out(file));
        const mesh::MeshReport report = mesh::checkMesh(m);
        CHECK(report.boundaryEdges == 0);
        CHECK(report.nonManifoldEdges == 0);
        CHECK(report.volume == doctest::Approx(p["volume_mm3"].get<double>()).epsilon(1e-4));
        for (int a = 0; a < 3; ++a) CHECK(report.bounds.max[size_t(a)] <= 200.001);
        CHECK(p["bbox_mm"]["min"][2].get<double>() == doctest::Approx(0).epsilon(1e-4));
        CHECK(p["neighbors"].size() == 2);
        tenons += p["tenons"].size();
        REQUIRE(p["direction"].is_object());
        const int direction = p["direction"]["hole"];
        for (const nlohmann::json& t : p["tenons"]) {
            CHECK(t["ball"].is_number_unsigned());
            CHECK(t["hole"] == direction);  // every peg of a piece along its direction
        }
    }
    CHECK(tenons >= 3);
    CHECK(j["options"]["tenons"]["holes"] == "all");
    CHECK(j["installation"]["problems"].empty());
    CHECK(j["installation"]["steps"].size() >= 1);
    CHECK(test::readFile(r.out("plates/plate-01.3mf")).substr(0, 2) == "PK");
    const nlohmann::json report = nlohmann::json::parse(test::readFile(r.dir.file("report.json")));
    CHECK(report["pieces"] == 4);
    CHECK(report["tool"] == "zf-pieces");
}

TEST_CASE("zf-pieces: a piece glued onto its host is printed with it when the two fit the printer") {
    // Without glued groups one quadrant has no peg and is glued onto a neighbour after it; with
    // them (the default) the two are printed as one piece (docs/mounting.md, "Glued pairs printed
    // as one"), and nothing is glued on.
    const Run& r = shared();
    REQUIRE(r.exitCode == 0);
    const nlohmann::json apart = nlohmann::json::parse(test::readFile(r.out("pieces.json")));
    REQUIRE(r.runInto("glued", "", true) == 0);
    const nlohmann::json one = nlohmann::json::parse(test::readFile(r.dir.file("glued/pieces.json")));
    auto noPeg = [](const nlohmann::json& j) {
        size_t n = 0;
        for (const nlohmann::json& p : j["pieces"]) n += p["tenons"].empty() ? 1 : 0;
        return n;
    };
    REQUIRE(apart["installation"]["glued_on"].size() == 1);
    REQUIRE(noPeg(apart) == 1);
    CHECK(one["pieces"].size() == 3);
    CHECK(one["summary"]["merged_pieces"] == 1);
    CHECK(one["installation"]["glued_on"].empty());
    CHECK(one["installation"]["problems"].empty());
    CHECK(noPeg(one) == 0);
    // The shell is all there: the three pieces' shares of it sum to the four's (what each prints
    // depends on its wall: a glued pair keeps the shell's).
    double before = 0, after = 0;
    for (const nlohmann::json& p : apart["pieces"]) before += p["shell_volume_mm3"].get<double>();
    for (const nlohmann::json& p : one["pieces"]) after += p["shell_volume_mm3"].get<double>();
    CHECK(after == doctest::Approx(before).epsilon(0.01));
}

TEST_CASE("zf-pieces: --tenon-holes lattice keeps the tenons on the paper's six holes") {
    const Run& r = shared();
    REQUIRE(r.exitCode == 0);
    REQUIRE(r.runInto("lattice", "--tenon-holes lattice") == 0);
    const std::string out = r.dir.file("lattice");
    const nlohmann::json j = nlohmann::json::parse(test::readFile(out + "/pieces.json"));
    CHECK(j["options"]["tenons"]["holes"] == "lattice");
    size_t tenons = 0;
    for (const nlohmann::json& p : j["pieces"])
        for (const nlohmann::json& t : p["tenons"]) {
            ++tenons;
            const int hole = t["hole"];
            CHECK((hole == 0 || hole == 1 || hole == 2 || hole == 15 || hole == 16 || hole == 17));
        }
    CHECK(tenons >= 3);
}

TEST_CASE("zf-pieces: the same bytes with 1 and 2 threads") {
    const Run& r = shared();
    REQUIRE(r.exitCode == 0);
    REQUIRE(r.runInto("one-thread", "--threads 1") == 0);
    const std::string other = r.dir.file("one-thread");
    size_t files = 0;
    for (const auto& e : fs::recursive_directory_iterator(r.dir.file("out"))) {
        if (!e.is_regular_file()) continue;
        ++files;
        const std::string name = fs::relative(e.path(), r.dir.file("out")).string();
        INFO(name);
        CHECK(test::readFile(e.path().string()) == test::readFile(other + "/" + name));
    }
    const size_t plates = size_t(std::distance(fs::directory_iterator(r.out("plates")), {}));
    CHECK(plates >= 1);
    CHECK(files == 4 + plates + 2);  // 4 STL, the plates, JSON and the output manifest
}

TEST_CASE("zf-pieces: admesh loads every piece with no errors and nothing to repair") {
    if (!isInstalled("admesh")) {
        MESSAGE("admesh is not installed (apt-get install admesh): skipped");
        return;
    }
    const Run& r = shared();
    REQUIRE(r.exitCode == 0);
    for (int i = 0; i < 4; ++i) {
        const std::string file = r.out("piece-0" + std::to_string(i) + ".stl");
        const std::string log = r.dir.file("admesh.txt");
        REQUIRE(test::runShell("admesh " + file + " > " + log + " 2>&1") == 0);
        const std::string report = test::readFile(log);
        INFO(file << "\n" << report);
        CHECK(admeshField(report, "Total disconnected facets") == "0                   0");
        for (const char* field : {"Degenerate facets", "Edges fixed", "Facets removed", "Facets added",
                                  "Facets reversed", "Backwards edges", "Normals fixed"})
            CHECK(admeshField(report, field) == "0");
        CHECK(report.find("Binary STL file") != std::string::npos);
    }
}

TEST_CASE("zf-pieces: PrusaSlicer slices a piece and loads the 3MF") {
    if (!isInstalled("prusa-slicer")) {
        MESSAGE(
            "prusa-slicer is not installed (apt-get install --no-install-recommends prusa-slicer): skipped");
        return;
    }
    const Run& r = shared();
    REQUIRE(r.exitCode == 0);
    // The printer's own 200 mm bed: PrusaSlicer refuses parts that do not fit it
    // (../shared/docs/print-estimates.md). Coarse layers keep this quick.
    const std::string gcode = r.dir.file("piece.gcode");
    const int code = test::runShell(
        "prusa-slicer --loglevel 1 --export-gcode --layer-height 0.3 --first-layer-height 0.3 "
        "--nozzle-diameter 0.4 --filament-diameter 2.85 --fill-density 10% --perimeters 2 "
        "--gcode-flavor marlin2 --bed-shape 0x0,200x0,200x200,0x200 --max-print-height 200 -o " +
        gcode + " " + r.out("piece-00.stl") + " > " + r.dir.file("slicer.txt") + " 2>&1");
    INFO(test::readFile(r.dir.file("slicer.txt")));
    CHECK(code == 0);
    CHECK(test::readFile(gcode).find("; estimated printing time") != std::string::npos);

    std::string info;  // every plate's objects
    for (const fs::directory_entry& plate : fs::directory_iterator(r.out("plates"))) {
        REQUIRE(test::runShell("prusa-slicer --loglevel 1 --info " + plate.path().string() + " > " +
                               r.dir.file("info.txt") + " 2>&1") == 0);
        info += test::readFile(r.dir.file("info.txt"));
    }
    INFO(info);
    size_t manifold = 0;
    for (size_t at = info.find("manifold = yes"); at != std::string::npos;
         at = info.find("manifold = yes", at + 1))
        ++manifold;
    CHECK(manifold == 4);
    CHECK(info.find("manifold = no") == std::string::npos);
}

TEST_CASE("zf-pieces: the real chain zf-sdf, zf-shell, zf-frame, zf-partition, zf-pieces on the bunny") {
    for (const char* tool : {"zf-sdf", "zf-shell", "zf-frame", "zf-partition"})
        if (!fs::exists(test::toolPath(tool))) {
            MESSAGE(tool << " is not built: skipped");
            return;
        }
    test::ScratchDir dir("zomefab-pieces-chain");
    const std::string bunny = test::dataPath("bunny_npm_3674.stl");
    REQUIRE(test::runShell(test::toolPath("zf-sdf") + " " + bunny +
                           " --height-mm 250 --up y --shell-mm 10 -q -o " + dir.file("bunny.vdb")) == 0);
    REQUIRE(test::runShell(test::toolPath("zf-shell") + " " + dir.file("bunny.vdb") +
                           " --shell-mm 10 -q -o " + dir.file("shell.vdb")) == 0);
    REQUIRE(test::runShell(test::toolPath("zf-frame") + " " + dir.file("bunny.vdb") +
                           " --shell-mm 10 --frame-clearance-mm 10 -q -o " + dir.file("frame.json")) == 0);
    REQUIRE(test::runShell(test::toolPath("zf-partition") + " " + bunny + " " + dir.file("frame.json") +
                           " --shell-mm 10 -q -o " + dir.file("partition.json")) == 0);
    REQUIRE(test::runShell(test::toolPath("zf-pieces") + " " + dir.file("shell.vdb") + " " +
                           dir.file("frame.json") + " " + dir.file("partition.json") + " -q -o " +
                           dir.file("out")) == 0);
    const nlohmann::json j = nlohmann::json::parse(test::readFile(dir.file("out/pieces.json")));
    const nlohmann::json partition = nlohmann::json::parse(test::readFile(dir.file("partition.json")));
    REQUIRE(j["pieces"].size() >= 2);
    CHECK(j["pieces"].size() <= partition["pieces"].size() + j["summary"]["recut_pieces"].get<size_t>());
    double shell = 0;
    size_t thin = 0;
    for (const nlohmann::json& p : j["pieces"]) {
        const TriMesh m = readMesh(dir.file("out/" + p["file"].get<std::string>()));
        const mesh::MeshReport report = mesh::checkMesh(m);
        INFO(p["file"].get<std::string>());
        CHECK(report.boundaryEdges == 0);
        CHECK(report.nonManifoldEdges == 0);
        CHECK(report.degenerateTriangles == 0);
        CHECK(report.volume > 0);
        for (int a = 0; a < 3; ++a) CHECK(report.bounds.max[size_t(a)] <= 200.001);
        shell += p["shell_volume_mm3"].get<double>();
        // Printed with the shell's 10 mm, or (the default) 2.4 mm where its pegs reach through:
        // about that share of its part of the shell, stems through the hollow on top.
        const double share = p["wall_mm"].get<double>() / 10.0;
        thin += p["thin_wall"].get<bool>() ? 1 : 0;
        CHECK(report.volume >= 0.9 * share * p["shell_volume_mm3"].get<double>());
        CHECK(report.volume <=
              (p["thin_wall"].get<bool>() ? 0.5 : 1.05) * p["shell_volume_mm3"].get<double>());
    }
    CHECK(thin >= 1);
    CHECK(thin == j["summary"]["thin_pieces"].get<size_t>());
    // The pieces' parts of the shell are the shell.
    CHECK(shell == doctest::Approx(j["summary"]["shell_volume_mm3"].get<double>()).epsilon(0.01));
    CHECK(j["summary"]["tenons"].get<int>() >= 1);
}
