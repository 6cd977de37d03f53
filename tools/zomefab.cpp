// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zomefab: `run` (every stage in one process), `batch` (a manifest, one worker each) and
/// `bench` (timed runs of the bundled meshes); docs/cli.md, docs/batch.md, README.md.
#include <filesystem>
#include <iostream>

#include "common/cli.h"
#include "common/run_options.h"
#include "zomefab/batch/batch.h"
#include "zomefab/core/error.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/report/run_report.h"

using namespace zomefab;
using nlohmann::json;

namespace {

int runCommand(cli::Tool& tool, const cli::RunCli& cli, json& report) {
    pipeline::RunOptions options = cli.resolve(tool.common().seed);
    MeshReadOptions readOptions;
    if (!cli.inFormat.empty()) readOptions.format = meshFormatFromName(cli.inFormat);
    const TriMesh mesh = readMesh(cli.input, readOptions);
    cli.partition.resolveSalientFaces(options.partition, mesh.triangleCount());
    RunContext& context = tool.context();
    const report::RunRecord run = pipeline::runPipeline(mesh, cli.input, options, context);
    report = report::runReportJson(run, context);
    const std::vector<std::string> files = pipeline::writeRunOutputs(run, options, report, cli.outDir);
    for (const std::string& line : report::runSummaryLines(run)) cli::printInfo(tool, line);
    cli::printInfo(tool, "done in " + std::to_string(int(run.totalSeconds + 0.5)) + " s");
    std::string list;
    for (const std::string& f : files) list += (list.empty() ? "" : ", ") + f;
    cli::printInfo(tool, "wrote " + cli.outDir + ": " + list);
    return 0;
}

/// What workers inherit from this process: the seed, the thread limit, -q.
batch::WorkerCommand workerCommand(const cli::Tool& tool) {
    batch::WorkerCommand command{"/proc/self/exe", {"--seed", std::to_string(tool.common().seed)}};
    if (tool.common().threads > 0) command.sharedArgs.insert(command.sharedArgs.end(), {"--threads", std::to_string(tool.common().threads)});
    if (tool.common().verbosity < 0) command.sharedArgs.push_back("-q");
    return command;
}

struct BatchCli {
    std::string manifest, outDir;
    int index = -1;
    bool isMergeOnly = false;

    void addTo(CLI::App& app) {
        app.add_option("manifest", manifest, "Batch manifest (docs/batch.md)")->required();
        app.add_option("-o,--output", outDir, "Directory for one output directory per entry and the summary")->required();
        app.add_option("--index", index, "Run entry I alone (for Slurm job arrays or GNU parallel)")->check(CLI::NonNegativeNumber);
        app.add_flag("--merge", isMergeOnly, "Only join the per-entry summaries already in the output directory");
    }

    int execute(cli::Tool& tool, json& report) const {
        const std::vector<batch::BatchEntry> entries = batch::readManifest(manifest);
        for (size_t i = 0; i < entries.size(); ++i) {
            try {
                cli::checkRunArguments(entries[i].runArgs);
            } catch (const Error& e) {
                throw Error(ErrorCode::InvalidInput, "entry " + std::to_string(i) + ": " + e.message(), manifest);
            }
        }
        std::error_code ec;
        std::filesystem::create_directories(outDir, ec);
        if (!std::filesystem::is_directory(outDir)) throw Error(ErrorCode::WriteFailed, "cannot create the directory", outDir);
        if (index >= 0) {
            if (size_t(index) >= entries.size())
                throw Error(ErrorCode::Usage, "--index " + std::to_string(index) + " is past the last entry (" +
                                                  std::to_string(entries.size() - 1) + ")");
            report = batch::runEntry(workerCommand(tool), entries, size_t(index), outDir, tool.context());
            return report["exit_code"] == 0 ? 0 : 3;
        }
        if (!isMergeOnly)
            for (size_t i = 0; i < entries.size(); ++i)
                if (batch::runEntry(workerCommand(tool), entries, i, outDir, tool.context())["exit_code"] == 5)
                    throw Error(ErrorCode::Cancelled, "interrupted");
        report = batch::mergeSummaries(entries, outDir);
        std::cerr << batch::summaryTable(report["entries"]);
        size_t failed = 0;
        for (const json& r : report["entries"]) failed += r["status"] != "ok";
        cli::printInfo(tool, std::to_string(entries.size() - failed) + " of " + std::to_string(entries.size()) +
                                 " inputs succeeded; summary in " + outDir + "/summary.md");
        return failed == 0 ? 0 : 3;
    }
};

struct BenchCli {
    std::string output = "-";
    batch::BenchOptions options;

    void addTo(CLI::App& app) {
        app.add_option("-o,--output", output, "Benchmark JSON (- = stdout)")->capture_default_str();
        app.add_option("--mesh", options.meshes, "Meshes under --data-dir to run (repeatable)")->capture_default_str();
        app.add_option("--height-mm", options.heightsMm, "Object heights to run each mesh at (repeatable)")->capture_default_str();
        app.add_option("--up", options.up, "Up axis of the meshes")->capture_default_str();
        app.add_option("--data-dir", options.dataDir, "Where the meshes are")->capture_default_str();
        app.add_option("--run-arg", options.extraArgs, "Extra option passed to every `zomefab run` (repeatable)");
    }

    int execute(cli::Tool& tool, json& report) const {
        report = batch::runBench(workerCommand(tool), options, tool.context());
        report["threads"] = tool.common().threads;
        cli::writeJsonFile(report, output);
        for (const json& c : report["cases"])
            if (c["exit_code"] != 0) return 3;
        return 0;
    }
};

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zomefab", "Turn a closed mesh into a Zometool frame and printable shell pieces.");
    CLI::App& app = tool.app();
    app.require_subcommand(1);
    cli::RunCli runCli;
    BatchCli batchCli;
    BenchCli benchCli;
    CLI::App* run = app.add_subcommand("run", "Run every stage on one mesh and write the outputs into a directory");
    CLI::App* batch = app.add_subcommand("batch", "Run many inputs from a manifest, one worker process each");
    CLI::App* bench = app.add_subcommand("bench", "Time every stage on bundled meshes at several sizes; JSON out");
    for (CLI::App* sub : {run, batch, bench}) sub->fallthrough();
    runCli.addTo(*run);
    batchCli.addTo(*batch);
    benchCli.addTo(*bench);
    return tool.run(argc, argv, [&](json& report) {
        if (run->parsed()) return runCommand(tool, runCli, report);
        if (batch->parsed()) return batchCli.execute(tool, report);
        return benchCli.execute(tool, report);
    });
}
