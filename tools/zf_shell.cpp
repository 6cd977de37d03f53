// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-shell: OBJECT.vdb -> SHELL.vdb, the hollow shell {−T ≤ φ ≤ 0} (paper §6, docs/sdf.md).
#include <cstdio>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/version.h"
#include "zomefab/io/file_io.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/sdf/vdb_file.h"

using namespace zomefab;
using nlohmann::json;

int main(int argc, char** argv) {
    cli::Tool tool("zf-shell", "Hollow the object level set into a shell of the given wall thickness.");
    std::string input, output, gridName = "object";
    cli::FabricationCli fabricationCli;
    auto& app = tool.app();
    app.add_option("object", input, "OBJECT.vdb from zf-sdf; - reads stdin")->required();
    app.add_option("-o,--output", output, "Output .vdb with one grid, \"shell\"; - writes stdout")
        ->required();
    fabricationCli.addTo(app, cli::kWall);
    app.add_option("--grid", gridName, "Which level set of the input to hollow")->capture_default_str();

    return tool.run(argc, argv, [&](json& report) {
        const Fabrication fabrication =
            fabricationCli.resolve(tool.common().seed);  // fails before any input is read
        RunContext& context = tool.context();
        Stopwatch clock;
        const std::vector<sdf::LevelSet> grids = sdf::parseVdb(readInputBytes(input), input, context);
        const sdf::LevelSet& object = sdf::findLevelSet(grids, gridName, input);
        const double readSeconds = clock.seconds();
        sdf::LevelSet shell = sdf::makeShell(object, fabrication, context);
        shell.info().generator = generatorString();
        const double shellSeconds = clock.seconds() - readSeconds;
        tool.writeOutput(output, [&](std::ostream& out) { sdf::writeVdb({shell}, out); });

        report["input"] = input;
        report["output"] = output;
        report["shell_mm"] = fabrication.wallMm;
        report["voxel_mm"] = shell.info().voxelMm;
        report["active_voxels"] = shell.activeVoxelCount();
        report["seconds"] = {{"read", readSeconds}, {"shell", shellSeconds}, {"total", clock.seconds()}};
        report["peak_rss_bytes"] = peakRssBytes();
        char line[160];
        std::snprintf(line, sizeof(line), "%g mm shell: %zu voxels (%g mm); %.1f s", fabrication.wallMm,
                      shell.activeVoxelCount(), shell.info().voxelMm, clock.seconds());
        cli::printInfo(tool, line);
        return 0;
    });
}
