// SPDX-License-Identifier: GPL-3.0-or-later
// The chain of small tools and `zomefab run --no-frame-growth` write the same files, byte for byte
// (zf-pieces does not grow the frame toward pieces too few pegs hold: it has no object grid); every stage
// tool's option can be given to `zomefab run` and to a batch manifest.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>

#include "test_util.h"
#include "zomefab/io/file_io.h"

using namespace zomefab;
namespace fs = std::filesystem;

namespace {

std::string tool(const std::string& name) { return test::toolPath(name) + " "; }

/// The small bunny at 250 mm with a 1.5 mm voxel: the same options for both ways.
const std::string kMesh = test::dataPath("bunny_npm_3674.stl");
const std::string kScale = " --up y --height-mm 250";
const std::string kOptions = " --voxel-mm 1.5 --chains 2 --iterations 20000 --seed 3 -q";

/// The long option names ("--voxel-mm") in @p tool's --help.
std::set<std::string> helpOptions(const std::string& command) {
    std::string help;
    REQUIRE(test::runCapture(command + " --help", &help) == 0);
    std::set<std::string> names;
    const std::regex option(R"((?:^|[ ,])(--[a-z0-9][a-z0-9-]*))");
    for (auto it = std::sregex_iterator(help.begin(), help.end(), option); it != std::sregex_iterator(); ++it)
        names.insert((*it)[1]);
    return names;
}

}  // namespace

TEST_CASE("tools: the chain of small tools writes the same bytes as zomefab run --no-frame-growth") {
    test::ScratchDir dir("zomefab-chain");
    const std::string run = dir.file("run"), chain = dir.file("chain");
    // zf-pieces takes frame.json as it is (no object grid to grow it in): run without the growth.
    REQUIRE(test::runShell(tool("zomefab") + "run " + kMesh + kScale + kOptions + " --no-frame-growth -o " +
                           run) == 0);
    fs::create_directories(chain);
    const std::string c = chain + "/";
    // zf-shell and zf-frame take the shell and frame options; everything else is the default.
    REQUIRE(test::runShell(tool("zf-sdf") + kMesh + kScale + " --voxel-mm 1.5 -q -o " + c + "object.vdb") ==
            0);
    REQUIRE(test::runShell(tool("zf-shell") + c + "object.vdb -q -o " + c + "shell.vdb") == 0);
    REQUIRE(test::runShell(tool("zf-frame") + c + "object.vdb --chains 2 --iterations 20000 --seed 3 -q -o " +
                           c + "frame.json") == 0);
    REQUIRE(test::runShell(tool("zf-zome") + "vef " + c + "frame.json -q -o " + c + "frame.vef") == 0);
    REQUIRE(test::runShell(tool("zf-partition") + kMesh + " " + c + "frame.json --seed 3 -q -o " + c +
                           "partition.json") == 0);
    REQUIRE(test::runShell(tool("zf-pieces") + c + "shell.vdb " + c + "frame.json " + c +
                           "partition.json -q -o " + c + "pieces") == 0);
    REQUIRE(test::runShell(tool("zf-preview") + c + "frame.json --pieces " + c + "pieces --object " + kMesh +
                           kScale + " -q -o " + c + "preview.glb --viewer " + c + "viewer.html") == 0);
    REQUIRE(test::runShell(tool("zf-report") + kMesh + " " + c + "frame.json " + c + "pieces" + kScale +
                           " -q -o " + chain) == 0);
    // An output directory that does not exist is refused before any work: one line naming it, exit 4,
    // no progress of the report stage.
    const std::string said = dir.file("missing.txt");
    CHECK(test::runShell(tool("zf-report") + kMesh + " " + c + "frame.json " + c + "pieces" + kScale +
                         " -o " + dir.file("no-such-dir") + " 2> " + said) == 4);
    const std::string message = test::readFile(said);
    CHECK(message.find("no-such-dir/assembly.md: directory does not exist") != std::string::npos);
    CHECK(message.find("[report]") == std::string::npos);
    fs::rename(c + "pieces/plates", c + "plates");

    size_t compared = 0;
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(run)) {
        if (!e.is_regular_file()) continue;
        const std::string name = fs::relative(e.path(), run).string();
        if (name == "report.json") continue;  // zomefab run's own record (timings, peak memory)
        // Each tool's output manifest lists what that tool wrote (the chain's files come from several).
        if (e.path().filename() == kOutputManifestFile) continue;
        INFO(name);
        REQUIRE(fs::exists(chain + "/" + name));
        // Where the two differ, a short window around the first difference (pages are megabytes).
        const std::string mine = test::readFile(e.path().string()),
                          theirs = test::readFile(chain + "/" + name);
        const size_t at = size_t(
            std::mismatch(mine.begin(), mine.begin() + std::min(mine.size(), theirs.size()), theirs.begin())
                .first -
            mine.begin());
        INFO("sizes " << mine.size() << " / " << theirs.size() << "; first difference at byte " << at
                      << ": \"" << mine.substr(at > 40 ? at - 40 : 0, 120) << "\" / \""
                      << theirs.substr(at > 40 ? at - 40 : 0, 120) << "\"");
        CHECK(mine.size() == theirs.size());
        CHECK(at == std::min(mine.size(), theirs.size()));
        ++compared;
    }
    CHECK(compared >= 10);  // frame, vef, partition, plates, preview, viewer, guide, cost, pieces.json, STLs
}

TEST_CASE("tools: every option of a stage tool is an option of zomefab run") {
    std::set<std::string> run = helpOptions(tool("zomefab") + "run");
    for (const std::string& common : helpOptions(tool("zomefab")))
        run.insert(common);  // --seed, --threads, -v, -q
    // What only a stage tool has: the input grid's name, its own inputs and outputs.
    const std::set<std::string> own{"--grid",   "--colored-ply", "--color-by", "--pieces", "--object",
                                    "--output", "--help",        "--version",  "--report", "--viewer"};
    for (const char* stage :
         {"zf-sdf", "zf-shell", "zf-frame", "zf-partition", "zf-pieces", "zf-preview", "zf-report"}) {
        for (const std::string& option : helpOptions(tool(stage))) {
            if (own.count(option)) continue;
            const std::string where = std::string(stage) + " " + option;
            INFO(where);
            CHECK(run.count(option) == 1);
        }
    }
}

TEST_CASE("tools: a batch manifest can set any stage's option, and a bad one is refused before any run") {
    test::ScratchDir dir("zomefab-manifest");
    const nlohmann::json options = {{"up", "y"},
                                    {"height-mm", 250},
                                    {"voxel-mm", 1.5},
                                    {"field-voxel-mm", 2.5},
                                    {"frame-clearance-mm", 17},
                                    {"chains", 2},
                                    {"iterations", 20000},
                                    {"w-smoothness", 8},
                                    {"tenon-max-tilt-deg", 40},
                                    {"adaptivity", 0.25},
                                    {"filament-usd-per-m", 0.6},
                                    {"draco-bits", 12}};
    const nlohmann::json manifest = {
        {"format", "zomefab.batch"},
        {"version", 1},
        {"entries", {{{"mesh", kMesh}, {"name", "bunny"}, {"options", options}}}}};
    test::writeBytes(dir.file("manifest.json"), manifest.dump());
    REQUIRE(test::runShell(tool("zomefab") + "batch " + dir.file("manifest.json") + " --index 0 -q -o " +
                           dir.file("out")) == 0);
    const nlohmann::json pieces =
        nlohmann::json::parse(test::readFile(dir.file("out/bunny/pieces/pieces.json")));
    CHECK(pieces["options"]["tenons"]["max_tilt_deg"] == 40.0);
    CHECK(pieces["options"]["adaptivity"] == 0.25);
    const nlohmann::json report = nlohmann::json::parse(test::readFile(dir.file("out/bunny/report.json")));
    CHECK(report["level_sets"]["interior"]["voxel_mm"] == 2.5);
    CHECK(report["frame"]["chains"] == 2);
    CHECK(report["cost"]["options"]["filament_usd_per_m"] == 0.6);
    const nlohmann::json partition =
        nlohmann::json::parse(test::readFile(dir.file("out/bunny/partition.json")));
    CHECK(partition["energy"]["schedule"][0]["w_smoothness"] == 8.0);

    nlohmann::json bad = manifest;
    bad["entries"][0]["options"]["tenon-max-tilt-deg"] = 80;  // beyond the 60° limit
    test::writeBytes(dir.file("bad.json"), bad.dump());
    std::string err;
    CHECK(test::runCapture(
              tool("zomefab") + "batch " + dir.file("bad.json") + " -o " + dir.file("bad") + " 2>&1", &err) ==
          2);
    CHECK(err.find("bad.json: entry 0: the largest tenon tilt must be in [0, 60] degrees") !=
          std::string::npos);
    CHECK(!fs::exists(dir.file("bad/bunny")));
}
