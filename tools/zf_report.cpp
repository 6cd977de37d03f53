// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-report: assembly.md and cost.md of `zomefab run` from separate files (paper §7): the
/// object mesh (scaled as for zf-sdf), the frame and the pieces directory of zf-pieces.
#include <filesystem>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/pieces/plates.h"
#include "zomefab/report/run_report.h"

using namespace zomefab;

int main(int argc, char** argv) {
    cli::Tool tool("zf-report",
                   "Write the assembly guide and the cost report of a frame and its printed pieces");
    CLI::App& app = tool.app();
    std::string meshPath, framePath, piecesPath, outDir;
    cli::ScaleCli scaleCli;
    cli::FabricationCli fabricationCli;
    cli::CostCli costCli;
    app.add_option("mesh", meshPath, "The object's mesh, as given to zf-sdf")->required();
    app.add_option("frame", framePath, "FRAME.json from zf-frame")->required();
    app.add_option("pieces", piecesPath, "The pieces directory (or its pieces.json) from zf-pieces")
        ->required();
    app.add_option("-o,--output", outDir,
                   "Directory to write assembly.md, assembly.html and cost.md into (must exist)")
        ->required();
    scaleCli.addTo(app);
    fabricationCli.addTo(app, cli::kPrinter);
    costCli.addTo(app);

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        // Checked before the work (with --slicer, half an hour), not when the files are written.
        for (const char* name : {"/assembly.md", "/assembly.html", "/cost.md"})
            checkOutputPath(outDir + name);
        const mesh::ScaleOptions scale = scaleCli.resolve();
        Fabrication fabrication = fabricationCli.resolve(tool.common().seed);
        const report::CostOptions costOptions = costCli.resolve();
        RunContext& context = tool.context();
        report::RunRecord run;
        run.sourceName = meshPath;
        run.scaled = mesh::scaleToMillimetres(
            mesh::validateClosedMesh(readMesh(meshPath), {}, meshPath, context), scale);
        run.frame.structure = cli::readFrame(framePath);
        run.pieces = pieces::readPieces(piecesPath);
        run.plates = pieces::packPlates(run.pieces);  // the same plates as zf-pieces wrote
        if (fabricationCli.printer.empty())
            fabrication.printerMm = run.pieces.printerMm;  // the pieces' printer
        report::RunReports reports = report::reportStage(run.frame.structure, run.pieces, run.scaled.mesh,
                                                         fabrication, costOptions, context);
        run.assembly = std::move(reports.assembly);
        run.cost = std::move(reports.cost);
        tool.writeOutput(outDir + "/assembly.md", [&](std::ostream& out) {
            out << report::assemblyGuideMarkdown(run.assembly, costOptions.prices);
        });
        tool.writeOutput(outDir + "/assembly.html",
                         [&](std::ostream& out) { out << report::assemblyPage(run, costOptions.prices); });
        tool.writeOutput(outDir + "/cost.md", [&](std::ostream& out) { out << report::costPage(run); });
        report = report::costReportToJson(run.cost);
        for (const std::string& line : report::runSummaryLines(run)) cli::printInfo(tool, line);
        return 0;
    });
}
