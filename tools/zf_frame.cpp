// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-frame: the Zometool frame of an object (paper §4). Reads the "interior" grid of a .vdb
/// written by zf-sdf, builds the B0 cube lattice, anneals it with parallel chains and writes the
/// frame file (zomefab.structure JSON, docs/formats.md) plus, with --report, the run's report.
#include <string>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/format.h"
#include "zomefab/frame/frame.h"
#include "zomefab/io/file_io.h"
#include "zomefab/sdf/vdb_file.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;

int main(int argc, char** argv) {
    cli::Tool tool("zf-frame", "Fill an object with a Zometool frame: B0 cube lattice + simulated annealing");
    CLI::App& app = tool.app();
    std::string input, output, gridName = "interior";
    cli::FabricationCli fabricationCli;
    cli::FrameCli frameCli;
    app.add_option("object", input, "OBJECT.vdb from zf-sdf (- reads stdin)")->required();
    app.add_option("-o,--output", output, "Output frame file FRAME.json (- writes stdout)")->required();
    app.add_option("--grid", gridName, "Level set to read")->capture_default_str();
    fabricationCli.addTo(app, cli::kFrameClearance | cli::kWall);
    frameCli.addTo(app);

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        const Fabrication fabrication = fabricationCli.resolve(tool.common().seed);
        const frame::FrameOptions& o = frameCli.options;
        RunContext& context = tool.context();
        const std::vector<sdf::LevelSet> grids = sdf::parseVdb(readInputBytes(input), input, context);
        const sdf::LevelSet& levelSet = sdf::findLevelSet(grids, gridName, input);
        const sdf::InteriorField field = sdf::makeInteriorField(levelSet, context);

        const frame::FrameResult result = frame::buildFrame(field, fabrication, o, context);
        const frame::FrameField ff(field, result.rotationDeg, result.lattice.structure.scale(), result.zone);
        const frame::FrameMetrics before =
            frame::measureFrame(result.lattice.structure, ff, o.surfaceSampleSpacingMm);
        const frame::FrameMetrics after = frame::measureFrame(result.structure, ff, o.surfaceSampleSpacingMm);
        report = frame::frameReportJson(result, o, before, after);
        report["input"] = input;
        report["output"] = output;
        const Transform4d transformMm =
            frame::frameTransformMm(levelSet.info().transformMm, result.rotationDeg);
        const nlohmann::json frameJson = zome::structureToJson(result.structure, transformMm);
        tool.writeOutput(output, [&](std::ostream& out) { out << frameJson.dump(1) << '\n'; });

        const zome::PartsList parts = zome::partsList(result.structure);
        cli::printInfo(tool, std::to_string(parts.balls) + " balls, " + std::to_string(parts.strutTotal()) +
                                 " struts; " +
                                 formatNumbers("E %.4f -> %.4f (tau %.0f); ", result.initialEnergy.total,
                                               result.finalEnergy.total, result.target.targetItemCount) +
                                 std::to_string(report["iterations"].get<uint64_t>()) + " iterations in " +
                                 formatNumbers("%.2f s", result.annealSeconds));
        return 0;
    });
}
