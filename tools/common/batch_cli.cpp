// SPDX-License-Identifier: GPL-3.0-or-later
#include "batch_cli.h"

#include <filesystem>
#include <iostream>

#include "run_options.h"
#include "zomefab/core/error.h"

namespace zomefab::cli {

/// What workers inherit from this process: the seed, the thread limit, -q.
batch::WorkerCommand workerCommand(const Tool& tool) {
    batch::WorkerCommand command{"/proc/self/exe", {"--seed", std::to_string(tool.common().seed)}};
    if (tool.common().threads > 0)
        command.sharedArgs.insert(command.sharedArgs.end(),
                                  {"--threads", std::to_string(tool.common().threads)});
    if (tool.common().verbosity < 0) command.sharedArgs.push_back("-q");
    return command;
}

void BatchCli::addTo(CLI::App& app) {
    app.add_option("manifest", manifest, "Batch manifest (docs/batch.md)")->required();
    app.add_option("-o,--output", outDir, "Directory for one output directory per entry and the summary");
    app.add_option("--index", index, "Run entry I alone (for Slurm job arrays or GNU parallel)")
        ->check(CLI::NonNegativeNumber);
    app.add_flag("--merge", isMergeOnly, "Only join the per-entry summaries already in the output directory");
    app.add_flag("--count", isCountOnly,
                 "Only check the manifest and print its number of entries on stdout (a job array's size)");
}

int BatchCli::execute(Tool& tool, nlohmann::json& report) const {
    const std::vector<batch::BatchEntry> entries = batch::readManifest(manifest);
    for (size_t i = 0; i < entries.size(); ++i) {
        try {
            checkRunArguments(entries[i].runArgs);
        } catch (const Error& e) {
            throw Error(ErrorCode::InvalidInput, "entry " + std::to_string(i) + ": " + e.message(), manifest);
        }
    }
    if (isCountOnly) {
        std::cout << entries.size() << '\n';
        return 0;
    }
    if (outDir.empty()) throw Error(ErrorCode::Usage, "batch needs -o,--output DIR");
    std::error_code ec;
    std::filesystem::create_directories(outDir, ec);
    if (!std::filesystem::is_directory(outDir))
        throw Error(ErrorCode::WriteFailed, "cannot create the directory", outDir);
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
    for (const nlohmann::json& r : report["entries"]) failed += r["status"] != "ok";
    printInfo(tool, std::to_string(entries.size() - failed) + " of " + std::to_string(entries.size()) +
                        " inputs succeeded; summary in " + outDir + "/summary.md");
    return failed == 0 ? 0 : 3;
}

void BenchCli::addTo(CLI::App& app) {
    app.add_option("-o,--output", output, "Benchmark JSON (- = stdout)")->capture_default_str();
    app.add_option("--mesh", options.meshes, "Meshes under --data-dir to run (repeatable)")
        ->capture_default_str();
    app.add_option("--height-mm", options.heightsMm, "Object heights to run each mesh at (repeatable)")
        ->capture_default_str();
    app.add_option("--up", options.up, "Up axis of the meshes")->capture_default_str();
    app.add_option("--data-dir", options.dataDir, "Where the meshes are")->capture_default_str();
    app.add_option("--run-arg", options.extraArgs, "Extra option passed to every `zomefab run` (repeatable)");
}

int BenchCli::execute(Tool& tool, nlohmann::json& report) const {
    report = batch::runBench(workerCommand(tool), options, tool.context());
    report["threads"] = tool.common().threads;
    writeJsonFile(report, output);
    for (const nlohmann::json& c : report["cases"])
        if (c["exit_code"] != 0) return 3;
    return 0;
}

}  // namespace zomefab::cli
