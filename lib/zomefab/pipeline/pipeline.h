// SPDX-License-Identifier: GPL-3.0-or-later
/// @file `zomefab run`: every stage in one process, in order, each handing its result to the next
/// as it is. This module only composes stages and writers (no geometry here): what the user is
/// making is one Fabrication, each stage's own options are its options struct.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/frame/frame.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/mesh/scale.h"
#include "zomefab/partition/partition.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/report/cost_report.h"
#include "zomefab/report/preview_scene.h"
#include "zomefab/report/run_record.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/verify/verify.h"

namespace zomefab::pipeline {

struct RunOptions {
    Fabrication fabrication;  ///< printer, wall, frame clearance, b0, seed
    mesh::ValidateOptions validate;
    mesh::ScaleOptions scale;
    sdf::ObjectFieldOptions field;          ///< voxel sizes of the level sets
    frame::FrameOptions frame;              ///< chains, annealing budget (paper §4)
    partition::PartitionOptions partition;  ///< energy, schedule, saliency (paper §5)
    pieces::PiecesOptions pieces;           ///< tenons, slivers, meshing (paper §6)
    report::CostOptions cost;               ///< print profile, filament, prices, estimator or slicer (§7.2)
    report::PreviewOptions preview;         ///< preview.glb: Draco settings
};

/// How often the partition runs again, for smaller pieces, when its pieces have no mounting order.
inline constexpr int kMaxReplans = 2;

/// Whether `zomefab run` partitions again, for smaller pieces, after a plan with no mounting order
/// that recorded @p problemsNow problems, when @p replansDone runs again came before it and the
/// plan that started the last of them recorded @p problemsBefore: at most kMaxReplans times, and
/// not when the last run again left clearly more problems than the plan before it (5 more, and
/// half as many again). Smaller pieces free pieces that interlock; pieces the
/// frame blocks along every straight path (the cheese's tunnel linings) they do not: at 700 mm the
/// cheese went from 16 to 26 problems at the first run again, each run taking about 20 minutes
/// (docs/benchmarks.md).
bool shouldPartitionAgain(int replansDone, size_t problemsBefore, size_t problemsNow);

/// @throw Error(Usage) for inconsistent options, before any work (tools call it before reading).
void checkRunOptions(const RunOptions& options);

/// Runs every stage on @p input (file units, as read from @p sourceName). Progress is reported on
/// @p context once per stage (stage name, fraction, as the stages report it).
/// @throw Error from the failing stage, attributed to @p sourceName where it is about the input.
report::RunRecord runPipeline(const TriMesh& input, const std::string& sourceName, const RunOptions& options,
                              RunContext& context);

/// The file every zomefab run directory holds; its presence allows replacing the directory.
inline constexpr const char* kRunMarkerFile = "report.json";

/// What writeRunOutputs did: the files, the verifier's findings on them, and where they went.
struct RunOutputs {
    std::vector<std::string> files;  ///< names written, sorted
    verify::VerifyReport verification;
    std::string directory;  ///< outDir, or outDir + ".failed" when the verification failed
};

/// Writes every output file of @p run (frame.json, frame.vef, partition.json, pieces/ with
/// piece-NN.stl and pieces.json, plates/plate-NN.3mf, preview.glb, assembly.md, cost.md, report.json =
/// @p report, report::runReportJson, with the verifier's findings added as "verify") into a staging
/// directory, runs the verifier on the files written (docs/mounting.md) and moves the directory
/// to @p outDir when they pass, else to @p outDir + ".failed" for inspection. A failure to write
/// leaves no half-written directory (an existing output directory of zomefab is replaced; any
/// other existing non-empty directory is refused). The same writers as the stage tools, so a
/// chain of them writes the same bytes. @throw Error(WriteFailed)
RunOutputs writeRunOutputs(const report::RunRecord& run, const RunOptions& options, nlohmann::json report,
                           const std::string& outDir, const RunContext& context);

}  // namespace zomefab::pipeline
