// SPDX-License-Identifier: GPL-3.0-or-later
/// @file What a run tells its user, from its RunRecord: report.json (format `zomefab.report`,
/// docs/report.md), the page cost.md, the summary lines on stderr, and the preview's input. The
/// batch summary reads report.json back with runSummaryFromJson.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/report/preview_scene.h"
#include "zomefab/report/run_record.h"

namespace zomefab::report {

inline constexpr const char* kReportFormatName = "zomefab.report";
inline constexpr int kReportFormatVersion = 1;

/// The installation plan of @p pieces as the guide's mounting steps (names, glue, pegs).
std::vector<MountingStep> mountingSteps(const pieces::Pieces& pieces);

/// The report stage (paper §7): the assembly guide of @p frame with @p pieces' tenons, and the
/// cost report of printing @p pieces against printing @p objectMm whole (Table 1).
struct RunReports {
    AssemblyGuide assembly;
    CostReport cost;
};
RunReports reportStage(const zome::Structure& frame, const pieces::Pieces& pieces, const TriMesh& objectMm,
                       const Fabrication& fabrication, const CostOptions& options, RunContext& context);

/// One line per fact a user wants first: size, parts, pieces, print hours and material, savings.
std::vector<std::string> runSummaryLines(const RunRecord& run);

/// report.json: input, fabrication, per-stage numbers and timings, cost, the warnings of @p context.
nlohmann::json runReportJson(const RunRecord& run, const RunContext& context);

/// cost.md: the summary lines, then the cost table (paper Table 1 layout).
std::string costPage(const RunRecord& run);

/// The preview scene's input: every piece of @p pieces (printer mm) placed back into the frame's
/// mm, and @p frame. The meshes are referenced, not copied.
PreviewInput previewInput(const pieces::Pieces& pieces, const zome::Structure& frame);
/// The same for a run, with its source and size as the scene's extras.
PreviewInput previewInput(const RunRecord& run);
/// assembly.html of the run (assembly_page.h): its guide, drawn with the preview's scene, titled
/// with the input file's name.
std::string assemblyPage(const RunRecord& run, const zome::PriceOptions& prices);
/// The preview's scene extras for an object read from @p sourceName at @p sizeMm.
nlohmann::json previewExtras(const std::string& sourceName, const Vec3d& sizeMm);

/// The headline numbers of a report.json, for batch summaries.
struct RunSummary {
    size_t peakRssBytes = 0;
    size_t balls = 0;
    size_t struts = 0;
    size_t pieces = 0;
    bool hasMaterialSaved = false;
    double materialSavedPercent = 0.0;  ///< hollow case, paper Table 1
};
/// @throw Error(InvalidInput) when @p report is not a `zomefab.report` document.
RunSummary runSummaryFromJson(const nlohmann::json& report);

}  // namespace zomefab::report
