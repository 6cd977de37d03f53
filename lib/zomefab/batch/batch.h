// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Many inputs, one worker process each (`zomefab batch`, docs/batch.md) and the benchmark
/// cases of `zomefab bench`: the manifest, the per-entry summaries and their merge, and the runs of
/// `zomefab run` as child processes (so a crash or a memory peak stays in its own process).
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "zomefab/core/run_context.h"

namespace zomefab::batch {

inline constexpr const char* kManifestFormatName = "zomefab.batch";
inline constexpr const char* kSummaryFormatName = "zomefab.batch-summary";

/// One entry of a manifest: a mesh, a name for its output directory, and the `zomefab run`
/// arguments its options stand for ({"height-mm": 400, "up": "y"} → --height-mm 400 --up y).
struct BatchEntry {
    std::string name;
    std::string mesh;  ///< relative paths are taken from the manifest's directory
    std::vector<std::string> runArgs;
};

/// Reads a `zomefab.batch` manifest (docs/batch.md): its "defaults", then per entry "mesh", "name"
/// and "options" (merged over the defaults). Booleans become flags, lists repeat the option.
/// @throw Error(InvalidInput) naming @p path and the entry.
std::vector<BatchEntry> readManifest(const std::string& path);

/// readManifest of the JSON text @p bytes; relative mesh paths are taken from @p path's directory.
std::vector<BatchEntry> parseManifest(std::string_view bytes, const std::string& path);

/// What every worker gets besides its entry: the executable to run (`zomefab`) and the options
/// the batch itself was given that workers inherit (--seed, --threads, -q).
struct WorkerCommand {
    std::string executable;
    std::vector<std::string> sharedArgs;
};

/// Runs entry @p index as `executable run MESH -o DIR/NAME ARGS...` and writes its summary row to
/// DIR/NAME.summary.json (so concurrent entries never write the same file). Returns the row.
/// @throw Error(ProcessingFailed) when the worker cannot start; Error(Cancelled) (the worker is
/// ended) when @p context is cancelled.
nlohmann::json runEntry(const WorkerCommand& command, const std::vector<BatchEntry>& entries, size_t index,
                        const std::string& outDir, RunContext& context);

/// Joins the per-entry summaries in @p outDir into summary.json and summary.md; entries with no
/// summary are "missing". Returns the summary document.
nlohmann::json mergeSummaries(const std::vector<BatchEntry>& entries, const std::string& outDir);

/// The Markdown table of the summary rows.
std::string summaryTable(const nlohmann::json& rows);

/// `zomefab bench`: every mesh at every height, one worker each, per-stage seconds and peak
/// memory from each run's report.json.
struct BenchOptions {
    std::vector<std::string> meshes{"bunny_cgal_75k.stl"};
    std::vector<double> heightsMm{300, 400, 800};
    std::string up = "y";
    std::string dataDir = "data";
    std::vector<std::string> extraArgs;  ///< passed to every `zomefab run`
};
nlohmann::json runBench(const WorkerCommand& command, const BenchOptions& options, RunContext& context);

}  // namespace zomefab::batch
