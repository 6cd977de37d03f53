// SPDX-License-Identifier: GPL-3.0-or-later
/// @file `zomefab run`: every stage in one process, in order, on in-memory values. This module only
/// composes stages (no geometry here); each stage's options struct keeps its own defaults.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/frame/frame.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/mesh/scale.h"
#include "zomefab/partition/partition.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/report/assembly_guide.h"
#include "zomefab/report/cost_report.h"
#include "zomefab/report/preview_scene.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::pipeline {

struct RunOptions {
    mesh::ValidateOptions validate;
    mesh::ScaleOptions scale;
    sdf::ObjectFieldOptions field;   ///< its shellDepthMm is raised to the shell thickness if needed
    sdf::ShellOptions shell;         ///< wall thickness (paper §6: dMin = 16 mm)
    frame::FrameOptions frame;       ///< chains, seed, annealing budget (paper §4)
    partition::PartitionOptions partition;  ///< printer size, saliency (paper §5)
    pieces::PiecesOptions pieces;    ///< tenons, slivers, meshing; printer size from partition
    /// Cost and time report (paper §7.2, Table 1): print profile, filament, Zometool prices,
    /// estimator or PrusaSlicer; its printer size comes from the partition's.
    report::CostOptions cost;
    report::PreviewOptions preview;  ///< preview.glb: Draco settings
};

/// Seconds spent in each stage, in run order.
struct StageTiming {
    std::string stage;
    double seconds = 0;
};

/// Everything the stages produced, in memory; writeRunOutputs() turns it into files.
struct RunResult {
    std::string sourceName;
    mesh::MeshReport inputReport;      ///< checks of the input as read (file units)
    mesh::ScaledMesh scaled;           ///< the object in mm, z up, with transform_mm
    sdf::ObjectField field;            ///< "object" and "interior" level sets
    sdf::LevelSet shell;               ///< the hollow shell
    frame::FrameResult frame;          ///< the frame (structure in frame mm)
    Transform4d frameTransformMm;      ///< input coordinates → frame mm
    frame::FrameMetrics frameMetrics;
    TriMesh surfaceFrameMm;            ///< the scaled surface in the frame's coordinates
    partition::PartitionResult partition;
    pieces::Pieces pieces;             ///< printable pieces, in printer coordinates
    report::AssemblyGuide assembly;    ///< build order of the frame and the pieces' tenons
    report::CostReport cost;           ///< Table 1: ZomeFab against the octree baseline
    std::vector<StageTiming> timings;
    double totalSeconds = 0;
};

/// @throw Error(Usage) for inconsistent options, before any work (tools call it before reading).
void checkRunOptions(const RunOptions& options);

/// Runs every stage on @p input (file units, as read from @p sourceName). Progress is reported on
/// @p context once per stage (stage name, fraction, as the stages report it).
/// @throw Error from the failing stage, attributed to @p sourceName where it is about the input.
RunResult runPipeline(const TriMesh& input, const std::string& sourceName, const RunOptions& options,
                      RunContext& context);

/// The preview scene's input for @p result: every piece placed back into the frame's mm, the frame.
report::PreviewInput previewInput(const RunResult& result);

/// One line per fact a user wants first: size, parts, pieces, print hours and material, savings.
std::vector<std::string> runSummaryLines(const RunResult& result);

/// The run's report.json: input, options, per-stage numbers and timings, cost, warnings.
nlohmann::json runReportJson(const RunResult& result, const RunOptions& options, const RunContext& context);

/// Writes every output file of @p result into @p outDir (frame.json, frame.vef, partition.json,
/// pieces/ with piece-NN.stl and pieces.json, pieces.3mf, preview.glb, assembly.md, cost.md,
/// report.json) through a staging directory, so a failure
/// leaves no half-written directory (an existing output directory of zomefab is replaced; any
/// other existing non-empty directory is refused). Returns the file names written, sorted.
/// @throw Error(WriteFailed)
std::vector<std::string> writeRunOutputs(const RunResult& result, const RunOptions& options,
                                         const nlohmann::json& report, const std::string& outDir);

}  // namespace zomefab::pipeline
