// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zomefab: `run` (every stage in one process), `check` (can an output be built?), `batch` (a
/// manifest, one worker each) and `bench` (timed runs of the bundled meshes); docs/cli.md,
/// docs/batch.md, docs/mounting.md, README.md.
#include <filesystem>
#include <iostream>

#include "common/batch_cli.h"
#include "common/cli.h"
#include "common/run_options.h"
#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/report/run_report.h"
#include "zomefab/verify/verify.h"

using namespace zomefab;
using nlohmann::json;

namespace {

int runCommand(cli::Tool& tool, const cli::RunCli& cli, json& report) {
    pipeline::RunOptions options = cli.resolve(tool.common().seed);
    checkOutputDirectory(cli.outDir);  // a mistyped -o fails now, not after the whole run
    MeshReadOptions readOptions;
    if (!cli.inFormat.empty()) readOptions.format = meshFormatFromName(cli.inFormat);
    const TriMesh mesh = readMesh(cli.input, readOptions);
    cli.partition.resolveSalientFaces(options.partition, mesh.triangleCount());
    RunContext& context = tool.context();
    const report::RunRecord run = pipeline::runPipeline(mesh, cli.input, options, context);
    report = report::runReportJson(run, context);
    const pipeline::RunOutputs outputs = pipeline::writeRunOutputs(run, options, report, cli.outDir, context);
    report["verify"] = verify::verifyReportJson(outputs.verification);
    for (const std::string& line : report::runSummaryLines(run)) cli::printInfo(tool, line);
    std::string list;
    for (const std::string& f : outputs.files) list += (list.empty() ? "" : ", ") + f;
    if (!outputs.verification.passed()) {
        for (const std::string& line : verify::verifySummaryLines(outputs.verification)) context.warn(line);
        throw Error(
            ErrorCode::ProcessingFailed,
            "the object cannot be built as planned (see above); the outputs are kept for inspection in " +
                outputs.directory,
            cli.input);
    }
    cli::printInfo(tool, verify::verifySummaryLines(outputs.verification).front());
    cli::printInfo(tool, "done in " + std::to_string(int(run.totalSeconds + 0.5)) + " s");
    cli::printInfo(tool, "wrote " + cli.outDir + ": " + list);
    return 0;
}

/// `zomefab check OUTDIR`: the verifier on a written output; exit 3 when it cannot be built.
int checkCommand(cli::Tool& tool, const std::string& outDir, const std::string& jsonPath, json& report) {
    const verify::Assembly assembly = verify::readAssembly(outDir);
    const verify::VerifyReport result = verify::verifyAssembly(assembly, {}, tool.context());
    report = verify::verifyReportJson(result);
    if (!jsonPath.empty()) cli::writeJsonFile(report, jsonPath);
    const std::vector<std::string> lines = verify::verifySummaryLines(result);
    for (const std::string& line : lines)
        if (result.passed()) cli::printInfo(tool, line);
    if (result.passed()) return 0;
    for (const std::string& line : lines) tool.context().warn(line);
    throw Error(ErrorCode::ProcessingFailed, "the object cannot be built as planned (see above)", outDir);
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
    CLI::App* check = app.add_subcommand(
        "check",
        "Verify that an output directory can be built: pegs, holes, free paths, order (exit 3 if not)");
    std::string checkDir, checkJson;
    check->add_option("output", checkDir, "Output directory of zomefab run (frame.json, pieces/)")
        ->required();
    check->add_option("--json", checkJson, "Also write the verifier's findings as JSON here (- = stdout)");
    CLI::App* batch = app.add_subcommand("batch", "Run many inputs from a manifest, one worker process each");
    CLI::App* bench =
        app.add_subcommand("bench", "Time every stage on bundled meshes at several sizes; JSON out");
    for (CLI::App* sub : {run, check, batch, bench}) sub->fallthrough();
    runCli.addTo(*run);
    batchCli.addTo(*batch);
    benchCli.addTo(*bench);
    return tool.run(argc, argv, [&](json& report) {
        if (run->parsed()) return runCommand(tool, runCli, report);
        if (check->parsed()) return checkCommand(tool, checkDir, checkJson, report);
        if (batch->parsed()) return batchCli.execute(tool, report);
        return benchCli.execute(tool, report);
    });
}
