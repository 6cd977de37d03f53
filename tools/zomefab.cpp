// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zomefab: `run` (every stage in one process), `batch` (a manifest, one worker each) and
/// `bench` (timed runs of the bundled meshes); docs/cli.md, docs/batch.md, README.md.
#include <filesystem>
#include <iostream>

#include "common/batch_cli.h"
#include "common/cli.h"
#include "common/run_options.h"
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

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zomefab", "Turn a closed mesh into a Zometool frame and printable shell pieces.");
    CLI::App& app = tool.app();
    app.require_subcommand(1);
    cli::RunCli runCli;
    cli::BatchCli batchCli;
    cli::BenchCli benchCli;
    CLI::App* run =
        app.add_subcommand("run", "Run every stage on one mesh and write the outputs into a directory");
    CLI::App* batch = app.add_subcommand("batch", "Run many inputs from a manifest, one worker process each");
    CLI::App* bench =
        app.add_subcommand("bench", "Time every stage on bundled meshes at several sizes; JSON out");
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
