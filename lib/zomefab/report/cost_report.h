// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Cost and time report like the paper's Table 1 (§7.2): printing the pieces plus building
/// the Zometool frame, against printing the whole object cut by an octree until every part fits
/// the printer (the paper's baseline) and against printing it whole in one part, at 20 % infill
/// ("hollow") and 100 % ("solid"), with the time and material saved.
/// Models and calibration: docs/report.md.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/report/print_estimate.h"
#include "zomefab/report/slicer.h"
#include "zomefab/zome/parts.h"

namespace zomefab::report {

/// Assembly time of the frame: a fixed time per strut and per ball. One rate, 32 s per element,
/// is the least-squares fit of the paper's Table 1 assembly hours against its Table 2 part counts
/// (docs/report.md; a separate ball rate fits with a negative strut time, so it is not used).
struct AssemblyTimeOptions {
    double secondsPerStrut = 32.0;
    double secondsPerBall = 32.0;
};

/// Hours to build @p parts.
double assemblyHours(const zome::PartsList& parts, const AssemblyTimeOptions& options = {});

/// Where print times and filament come from.
enum class EstimateSource { Estimator, PrusaSlicer };

struct CostOptions {
    PrintSettings print;                ///< profile; its infillPercent is replaced by the two cases
    double hollowInfillPercent = 20.0;  ///< the paper's "hollow" case (§7.2)
    double solidInfillPercent = 100.0;  ///< the paper's "solid" case
    PrintRates rates;
    FilamentOptions filament;
    zome::PriceOptions prices;  ///< Zometool prices (0.19 USD a strut, 0.29 USD a ball)
    AssemblyTimeOptions assembly;
    EstimateSource source = EstimateSource::Estimator;
    SlicerOptions slicer;  ///< used when source == PrusaSlicer
    /// Every part printed with automatic supports where its overhangs need them (pieces, octree
    /// parts and the whole object alike): the estimator's support model or PrusaSlicer's.
    bool countSupports = true;
};

/// One way of making the object: what it costs.
struct MakingCost {
    PrintEstimate print;         ///< summed over the printed parts
    FilamentUse filament;        ///< of print.filamentMm3
    double assemblyHours = 0.0;  ///< building the frame (0 for the baseline)
    double zomeUsd = 0.0;        ///< Zometool parts (0 for the baseline)

    double totalHours() const { return print.hours() + assemblyHours; }
    double totalUsd() const { return filament.costUsd + zomeUsd; }
};

/// One printed piece's print (its support in print.supportMm3).
struct PieceCost {
    PrintEstimate print;
    FilamentUse filament;  ///< of print.filamentMm3
};

/// One infill case: ZomeFab against the baseline, and the savings as in Table 1
/// (saved = 1 − zomefab/baseline, in percent; "material" compares total cost in USD as the paper
/// does, "filament" compares the plastic alone).
struct CostCase {
    std::string name;  ///< "hollow" or "solid"
    double infillPercent = 0.0;
    MakingCost zomefab;
    MakingCost baseline;
    /// The object printed whole, in one part on a bed large enough for it: what a maker with a
    /// big printer compares against (the honest saving; the octree baseline is the paper's).
    MakingCost whole;
    /// Each printed piece on its own (in piece order; their sum is zomefab.print): hours and
    /// filament per piece for the maker's plan.
    std::vector<PieceCost> pieces;
    double savedTimePercent = 0.0;
    double savedMaterialPercent = 0.0;
    double savedFilamentPercent = 0.0;
    double savedTimeVsWholePercent = 0.0;      ///< 1 − ZomeFab overall hours / whole print hours
    double savedFilamentVsWholePercent = 0.0;  ///< 1 − pieces' filament / whole print's filament
};

struct CostReport {
    std::vector<CostCase> cases;  ///< hollow, then solid
    size_t pieceCount = 0;
    size_t baselinePartCount = 0;
    double objectVolumeMm3 = 0.0;
    double piecesVolumeMm3 = 0.0;
    zome::PartsList parts;
    Vec3d printerMm = Fabrication{}.printerMm;  ///< the printer the baseline was cut for
    EstimateSource source = EstimateSource::Estimator;
    /// Parts the slicer failed on (e.g. "baseline part 3 at 20%"), estimated instead, each with a
    /// warning on the run context.
    std::vector<std::string> slicerFallbacks;
    CostOptions options;  ///< the options used, echoed into the JSON
};

/// @throw Error(Usage) naming the option for invalid print, filament or assembly options, or a
/// PrusaSlicer source whose executable is not installed. costReport() calls it; callers call it
/// before long work so a bad option fails fast.
void checkCostOptions(const CostOptions& options);

/// Builds the report. @p objectMm is the closed input object in mm as it would be printed whole
/// (z up); @p piecesMm the closed pieces as they will be printed (print orientation); @p parts the
/// frame's parts list; the baseline is cut for the Fabrication's printer. With EstimateSource::PrusaSlicer
/// every piece and baseline part is sliced (2 × (pieces + parts) slicer runs; progress through @p context); a
/// part the slicer fails on is estimated instead, with a warning, and listed in CostReport::slicerFallbacks.
/// @throw Error(Usage) for invalid options or a slicer that is not installed, as octreeParts(),
///   Error(Cancelled).
CostReport costReport(const TriMesh& objectMm, const std::vector<const TriMesh*>& piecesMm,
                      const zome::PartsList& parts, const Fabrication& fabrication,
                      const CostOptions& options = {}, RunContext& context = RunContext::silent());

/// The report as JSON (report.json's "cost" block): every number with its unit in the key.
nlohmann::json costReportToJson(const CostReport& report);

/// The report as a Markdown table in the layout of the paper's Table 1.
std::string costReportMarkdown(const CostReport& report);

/// "estimator" or "prusa-slicer".
const char* estimateSourceName(EstimateSource source);

}  // namespace zomefab::report
