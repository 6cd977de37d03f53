// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/pipeline/pipeline.h"

#include <doctest/doctest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/pieces/plates.h"
#include "zomefab/report/run_report.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
namespace fs = std::filesystem;

namespace {

pipeline::RunOptions smallRunOptions() {
    pipeline::RunOptions o;
    o.scale.heightMm = 250;
    o.scale.up = mesh::UpAxis::Y;
    o.field.voxelMm = 1.5;  // coarse for speed, fine enough for the tenon prisms (≤ 3.5 mm)
    o.frame.anneal.maxIterations = 20000;
    o.frame.chains = 2;
    o.fabrication.seed = 7;
    return o;
}

}  // namespace

TEST_CASE("pipeline: the small bunny end to end, outputs consistent with each other") {
    const TriMesh mesh = readMesh(test::dataPath("bunny_npm_3674.stl"));
    const pipeline::RunOptions options = smallRunOptions();
    const report::RunRecord result = pipeline::runPipeline(mesh, "bunny", options, RunContext::silent());
    CHECK(result.scaled.sizeMm[2] == doctest::Approx(250).epsilon(1e-4));
    REQUIRE(result.frame.structure.ballCount() > 0);
    CHECK(!result.partition.pieces.empty());

    test::ScratchDir dir;
    const std::string out = dir.file("run");
    const nlohmann::json report = report::runReportJson(result, RunContext::silent());
    const pipeline::RunOutputs outputs =
        pipeline::writeRunOutputs(result, options, report, out, RunContext::silent());
    // The verifier passed on what was written, so the outputs are where they were asked for.
    for (const std::string& line : verify::verifySummaryLines(outputs.verification)) INFO(line);
    REQUIRE(outputs.verification.passed());
    CHECK(outputs.directory == out);
    const std::vector<std::string>& files = outputs.files;
    for (const std::string& f : files) CHECK(fs::exists(fs::path(out) / f));
    CHECK(files == std::vector<std::string>{"assembly.html", "assembly.md", "cost.md", "frame.json",
                                            "frame.vef", "partition.json", "pieces/", "plates/",
                                            "preview.glb", "report.json", "viewer.html"});
    CHECK(!fs::exists(out + "/pieces/plates"));  // moved up, next to the preview
    CHECK(fs::exists(out + "/" + pieces::plateFileName(0)));
    CHECK(report["plates"].size() == result.plates.size());
    // cost.md and report.json list every piece's hours and grams, and every plate's.
    const std::string costPage = test::readFile(out + "/cost.md");
    for (size_t i = 0; i < result.pieces.pieces.size(); ++i)
        CHECK(costPage.find("| " + pieces::pieceName(result.pieces, i) + " | ") != std::string::npos);
    CHECK(costPage.find("| " + pieces::plateFileName(0) + " | ") != std::string::npos);
    CHECK(report["cost"]["per_piece"].size() == result.pieces.pieces.size());
    CHECK(report["cost"]["per_piece"][0]["hollow"]["grams"].get<double>() > 0);
    // The cost report prices exactly the pieces written and the frame's parts.
    CHECK(report["cost"]["pieces"] == result.pieces.pieces.size());
    CHECK(report["cost"]["pieces_volume_mm3"].get<double>() ==
          doctest::Approx(report["pieces"]["volume_mm3"].get<double>()).epsilon(1e-6));
    CHECK(report["cost"]["zometool"]["balls"] == report["frame"]["balls"]);
    for (const char* key :
         {"material_saved_hollow_percent", "time_saved_hollow_percent", "material_saved_solid_percent"})
        CHECK(report["cost"][key].is_number());
    CHECK(report["cost"]["source"] == "estimator");
    const std::string costMd = readInputBytes(out + "/cost.md");
    CHECK(costMd.find("| hollow (20%) | ZomeFab |") != std::string::npos);
    CHECK(readInputBytes(out + "/assembly.md").find("## Parts list") != std::string::npos);
    CHECK(readInputBytes(out + "/preview.glb").substr(0, 4) == "glTF");
    // The frame file reads back to the same parts list the report states.
    const zome::Structure back = zome::structureFromJsonText(readInputBytes(out + "/frame.json"));
    const zome::PartsList parts = zome::partsList(back);
    CHECK(parts.balls == report["frame"]["balls"].get<size_t>());
    CHECK(parts.strutTotal() == report["frame"]["struts"].get<size_t>());
    // No staging directory is left next to the output.
    for (const auto& entry : fs::directory_iterator(dir.path()))
        CHECK(entry.path().filename().string().find(".tmp") == std::string::npos);
}

TEST_CASE("pipeline: same seed gives byte-identical frame and partition files") {
    const TriMesh mesh = readMesh(test::dataPath("bunny_npm_3674.stl"));
    const pipeline::RunOptions options = smallRunOptions();
    test::ScratchDir dir;
    std::string frames[2], partitions[2];
    for (int i = 0; i < 2; ++i) {
        const report::RunRecord r = pipeline::runPipeline(mesh, "bunny", options, RunContext::silent());
        const std::string out = dir.file("run" + std::to_string(i));
        pipeline::writeRunOutputs(r, options, report::runReportJson(r, RunContext::silent()), out,
                                  RunContext::silent());
        frames[i] = readInputBytes(out + "/frame.json");
        partitions[i] = readInputBytes(out + "/partition.json");
    }
    CHECK(frames[0] == frames[1]);
    CHECK(partitions[0] == partitions[1]);
}

TEST_CASE("staged directory: refuses to replace a directory that is not a zomefab output") {
    test::ScratchDir dir;
    const std::string target = dir.file("precious");
    fs::create_directories(target);
    test::writeBytes(target + "/thesis.tex", "do not delete");
    {
        StagedDirectory staged(target);
        test::writeBytes(staged.file("report.json"), "{}");
        CHECK_THROWS_AS(staged.commit(), Error);
    }
    CHECK(fs::exists(target + "/thesis.tex"));
    CHECK(!fs::exists(target + "/report.json"));
    // A directory that merely holds a report.json next to other work is not an output either.
    fs::create_directories(target + "/src");
    test::writeBytes(target + "/report.json", "{}");
    {
        StagedDirectory staged(target);
        test::writeBytes(staged.file("report.json"), "{}");
        CHECK_THROWS_WITH_AS(staged.commit(), doctest::Contains(".zomefab-output"), Error);
    }
    CHECK(fs::exists(target + "/thesis.tex"));
    // An earlier output (its manifest lists all it holds) is replaced; nothing else is left behind.
    const std::string previous = dir.file("previous");
    {
        StagedDirectory staged(previous);
        test::writeBytes(staged.file("report.json"), "old");
        test::writeBytes(staged.file("stale.stl"), "old");
        staged.commit();
    }
    CHECK(readInputBytes(previous + "/.zomefab-output") == "report.json\nstale.stl\n");
    {
        StagedDirectory staged(previous);
        test::writeBytes(staged.file("report.json"), "new");
        staged.commit();
    }
    CHECK(readInputBytes(previous + "/report.json") == "new");
    CHECK(!fs::exists(previous + "/stale.stl"));
    // A staging directory left by a run that was killed (its process is gone) goes with the next run.
    const std::string stale = dir.file(".previous.tmp4194303");  // above Linux's largest pid
    fs::create_directories(stale);
    test::writeBytes(stale + "/half.stl", "x");
    { StagedDirectory staged(previous); }
    CHECK(!fs::exists(stale));
    size_t entries = 0;
    for (const auto& e : fs::directory_iterator(dir.path())) entries += e.is_directory() ? 1 : 0;
    CHECK(entries == 2);
}

TEST_CASE("pipeline: the partition runs again for smaller pieces only while that can help") {
    using pipeline::shouldPartitionAgain;
    // The first plan with no order always gets a run again, whatever its count.
    CHECK(shouldPartitionAgain(0, 0, 1));
    CHECK(shouldPartitionAgain(0, 0, 400));
    // A few problems more come and go with the cuts (the armadillo at 600 mm needs the third run).
    CHECK(shouldPartitionAgain(1, 2, 2));
    CHECK(shouldPartitionAgain(1, 2, 6));
    CHECK(shouldPartitionAgain(1, 16, 23));
    // A clear rise ends it: the cheese at 700 mm went from 16 to 26 problems.
    CHECK_FALSE(shouldPartitionAgain(1, 2, 7));
    CHECK_FALSE(shouldPartitionAgain(1, 16, 26));
    CHECK_FALSE(shouldPartitionAgain(1, 100, 150));
    CHECK(shouldPartitionAgain(1, 100, 149));
    // Never more than kMaxReplans runs again.
    CHECK_FALSE(shouldPartitionAgain(pipeline::kMaxReplans, 10, 1));
}
