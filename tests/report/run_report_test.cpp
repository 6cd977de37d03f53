// SPDX-License-Identifier: GPL-3.0-or-later
// The batch summary row read back from a run's report.json.
#include "zomefab/report/run_report.h"

#include <doctest/doctest.h>

#include "zomefab/core/error.h"

using namespace zomefab;
using nlohmann::json;

TEST_CASE("runSummaryFromJson counts the printed pieces, not the partition's regions") {
    // The pieces stage re-cuts regions the frame blocks: 2 regions became 3 pieces.
    const json report{
        {"format", report::kReportFormatName},      {"peak_rss_bytes", 1000},
        {"frame", {{"balls", 14}, {"struts", 18}}}, {"partition", {{"pieces", 2}}},
        {"pieces", {{"count", 3}, {"tenons", 7}}},  {"cost", {{"material_saved_hollow_percent", 25.5}}}};
    const report::RunSummary s = report::runSummaryFromJson(report);
    CHECK(s.peakRssBytes == 1000);
    CHECK(s.balls == 14);
    CHECK(s.struts == 18);
    CHECK(s.pieces == 3);
    CHECK(s.hasMaterialSaved);
    CHECK(s.materialSavedPercent == doctest::Approx(25.5));
}

TEST_CASE("runSummaryFromJson refuses what is not a run report") {
    CHECK_THROWS_AS(report::runSummaryFromJson(json{{"format", "zomefab.pieces"}}), Error);
    CHECK_THROWS_AS(report::runSummaryFromJson(json::array()), Error);
    // A report without pieces (the frame alone) has 0 pieces and no saving.
    const report::RunSummary s = report::runSummaryFromJson(json{{"format", report::kReportFormatName}});
    CHECK(s.pieces == 0);
    CHECK_FALSE(s.hasMaterialSaved);
}

TEST_CASE("runSummaryLines counts the pieces short of tenons in the right number") {
    report::RunRecord run;
    run.pieces.pieces.resize(3);
    run.pieces.pieces[1].tenonShortfall["hole holds a strut"] = 1;
    CHECK(report::runSummaryLines(run).front().find("(1 piece with fewer than planned)") !=
          std::string::npos);
    run.pieces.pieces[2].tenonShortfall["no ball in reach"] = 2;
    CHECK(report::runSummaryLines(run).front().find("(2 pieces with fewer than planned)") !=
          std::string::npos);
    run.pieces.pieces[1].tenonShortfall.clear();
    run.pieces.pieces[2].tenonShortfall.clear();
    CHECK(report::runSummaryLines(run).front().find("fewer than planned") == std::string::npos);
}
