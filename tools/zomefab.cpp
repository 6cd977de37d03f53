// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zomefab: the whole pipeline in one process (`zomefab run`), docs/cli.md and README.md.
#include <cstdio>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pipeline/pipeline.h"
#include "zomefab/zome/parts.h"

using namespace zomefab;

namespace {

struct RunCommand {
    std::string input, outDir, inFormat, printer = "200x200x200", salientFile;
    std::vector<std::string> salientSpheres;
    cli::ScaleCli scale;
    pipeline::RunOptions options;

    void addTo(cli::Tool& tool, CLI::App& run) {
        run.add_option("mesh", input, "Closed mesh (.stl .obj .ply .gltf .glb); - reads stdin")->required();
        run.add_option("-o,--output", outDir, "Output directory (created; a previous zomefab output is replaced)")
            ->required();
        scale.addTo(run);
        tool.addFormatOption("--in-format", inFormat, {"stl", "obj", "ply", "gltf", "glb"}, "Input format (for -)");
        run.add_option("--repair", options.validate.repair, "Close small holes of an open mesh");
        run.add_option("--voxel-mm", options.field.voxelMm, "Voxel of the object and shell level sets")
            ->capture_default_str();
        run.add_option("--shell-mm", options.shell.shellMm, "Shell wall thickness (paper: dMin = 16 mm)")
            ->capture_default_str();
        run.add_option("--chains", options.frame.chains, "Annealing chains run in parallel; the best is kept")
            ->capture_default_str()
            ->check(CLI::Range(1, 4096));
        run.add_option("--iterations", options.frame.anneal.maxIterations,
                       "Annealing iterations per chain (0 = until T < T_end)")
            ->capture_default_str();
        run.add_option("--printer-mm", printer, "Printer build volume WxDxH in mm")->capture_default_str();
        run.add_option("--salient", salientSpheres,
                       "Keep the surface within a sphere whole: x,y,z,r in the scaled object's mm (repeatable)");
        run.add_option("--salient-faces", salientFile, "JSON list of salient face indices of the input mesh");
    }

    int execute(cli::Tool& tool, nlohmann::json& report) {
        options.scale = scale.resolve();
        options.partition.printerMm = cli::parsePrinterMm(printer);
        for (const std::string& s : salientSpheres) options.partition.salientSpheres.push_back(cli::parseSalientSphere(s));
        options.frame.seed = tool.common().seed;
        pipeline::checkRunOptions(options);

        MeshReadOptions readOptions;
        if (!inFormat.empty()) readOptions.format = meshFormatFromName(inFormat);
        const TriMesh mesh = readMesh(input, readOptions);
        if (!salientFile.empty())
            options.partition.salientFaceIndices = cli::readSalientFaceList(salientFile, mesh.triangleCount());

        RunContext& context = tool.context();
        const pipeline::RunResult result = pipeline::runPipeline(mesh, input, options, context);
        report = pipeline::runReportJson(result, options, context);
        const std::vector<std::string> files = pipeline::writeRunOutputs(result, options, report, outDir);

        const zome::PartsList parts = zome::partsList(result.frame.structure);
        char line[256];
        std::snprintf(line, sizeof line, "%.0f x %.0f x %.0f mm: %zu balls, %zu struts, %zu pieces; %.1f s",
                      result.scaled.sizeMm[0], result.scaled.sizeMm[1], result.scaled.sizeMm[2], parts.balls,
                      parts.strutTotal(), result.partition.pieces.size(), result.totalSeconds);
        cli::printInfo(tool, line);
        std::string list;
        for (const std::string& f : files) list += (list.empty() ? "" : ", ") + f;
        cli::printInfo(tool, "wrote " + outDir + ": " + list);
        return 0;
    }
};

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zomefab", "Turn a closed mesh into a Zometool frame and printable shell pieces.");
    CLI::App& app = tool.app();
    app.require_subcommand(1);
    RunCommand runCommand;
    CLI::App* run = app.add_subcommand("run", "Run every stage on one mesh and write the outputs into a directory");
    run->fallthrough();
    runCommand.addTo(tool, *run);

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        if (run->parsed()) return runCommand.execute(tool, report);
        throw Error(ErrorCode::Usage, "no command given (see --help)");
    });
}
