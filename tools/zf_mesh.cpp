// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-mesh: GRID.vdb -> a closed, outward triangle mesh in millimetres (docs/sdf.md).
#include <cstdio>

#include "common/cli.h"
#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/sdf/vdb_file.h"

using namespace zomefab;
using nlohmann::json;

int main(int argc, char** argv) {
    cli::Tool tool("zf-mesh", "Extract the surface of a level set as a closed triangle mesh (millimetres).");
    std::string input, output, gridName, outFormat;
    sdf::LevelSetToMeshOptions options;
    auto& app = tool.app();
    app.add_option("grid", input, ".vdb from zf-sdf or zf-shell; - reads stdin")->required();
    app.add_option("-o,--output", output, "Output mesh (.stl .obj .ply); - writes stdout")->required();
    app.add_option("--grid", gridName,
                   "Which level set to mesh (default: \"shell\" if present, else the first)");
    app.add_option("--adaptivity", options.adaptivity, "0 = uniform triangles; up to 1 merges flat regions")
        ->capture_default_str();
    app.add_option("--iso-mm", options.isoMm, "Extract {φ = iso} instead of the surface (negative = inside)")
        ->capture_default_str();
    tool.addFormatOption("--out-format", outFormat, {"stl", "obj", "ply"},
                         "Output format (default for -: stl)");

    return tool.run(argc, argv, [&](json& report) {
        sdf::checkMeshingOptions(options);  // bad options fail before any input is read
        MeshWriteOptions writeOptions;
        if (!outFormat.empty())
            writeOptions.format = meshFormatFromName(outFormat);
        else if (output == "-")
            writeOptions.format = MeshFormat::Stl;
        else if (fileExtension(output) != "stl" && fileExtension(output) != "obj" &&
                 fileExtension(output) != "ply")
            throw Error(ErrorCode::Usage, "cannot tell the mesh format from '" + output +
                                              "': use .stl, .obj, .ply or --out-format");
        RunContext& context = tool.context();
        Stopwatch clock;
        const std::vector<sdf::LevelSet> grids = sdf::parseVdb(readInputBytes(input), input, context);
        std::string name = gridName;
        if (name.empty()) {
            for (const sdf::LevelSet& g : grids)
                if (g.info().name == "shell") name = "shell";
        }
        const sdf::LevelSet& levelSet = sdf::findLevelSet(grids, name, input);
        const double readSeconds = clock.seconds();
        const TriMesh mesh = sdf::levelSetToMesh(levelSet, options, context);
        const double meshSeconds = clock.seconds() - readSeconds;
        writeMesh(mesh, output, writeOptions);

        report["input"] = input;
        report["output"] = output;
        report["grid"] = levelSet.info().name;
        report["triangles"] = mesh.triangleCount();
        report["vertices"] = mesh.vertexCount();
        report["seconds"] = {{"read", readSeconds}, {"mesh", meshSeconds}, {"total", clock.seconds()}};
        report["peak_rss_bytes"] = peakRssBytes();
        char line[160];
        std::snprintf(line, sizeof(line), "'%s': %zu triangles, %zu vertices; %.1f s",
                      levelSet.info().name.c_str(), mesh.triangleCount(), mesh.vertexCount(),
                      clock.seconds());
        cli::printInfo(tool, line);
        return 0;
    });
}
