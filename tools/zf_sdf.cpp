// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-sdf: mesh -> OBJECT.vdb with the object's distance fields (docs/sdf.md): "object"
/// (fine, exact as deep as --shell-mm, for zf-shell) and "interior" (coarse, the whole
/// inside, for the frame optimisation), in millimetres, z up, with the input->mm transform.
#include <cstdio>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/version.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/mesh/scale.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/sdf/vdb_file.h"

using namespace zomefab;
using nlohmann::json;

int main(int argc, char** argv) {
    cli::Tool tool("zf-sdf",
                   "Turn a closed mesh into signed distance level sets (OpenVDB .vdb, millimetres).");
    std::string input, output, inFormat;
    cli::ScaleCli scaleCli;
    cli::FabricationCli fabricationCli;
    cli::FieldCli fieldCli;
    auto& app = tool.app();
    app.add_option("mesh", input, "Closed mesh (.stl .obj .ply .gltf .glb); - reads stdin")->required();
    app.add_option("-o,--output", output, "Output .vdb; - writes stdout")->required();
    scaleCli.addTo(app);
    tool.addFormatOption("--in-format", inFormat, {"stl", "obj", "ply", "gltf", "glb"},
                         "Input format (needed for -)");
    fabricationCli.addTo(app, cli::kWall);
    fieldCli.addTo(app);

    return tool.run(argc, argv, [&](json& report) {
        const mesh::ScaleOptions scaleOptions =
            scaleCli.resolve();  // bad options fail before any input is read
        const Fabrication fabrication = fabricationCli.resolve(tool.common().seed);
        sdf::checkObjectFieldOptions(fieldCli.options);
        MeshReadOptions readOptions;
        if (!inFormat.empty()) readOptions.format = meshFormatFromName(inFormat);
        RunContext& context = tool.context();
        Stopwatch clock;
        TriMesh valid = mesh::validateClosedMesh(readMesh(input, readOptions), {}, input, context);
        const mesh::ScaledMesh scaled = mesh::scaleToMillimetres(std::move(valid), scaleOptions);
        const double readSeconds = clock.seconds();
        sdf::ObjectField field;
        try {
            field = sdf::makeObjectField(scaled.mesh, fabrication, fieldCli.options, context);
        } catch (const Error& e) {
            // Input problems found only now (no inside, a leaking inside) are about this file.
            if (e.code() == ErrorCode::Usage || e.code() == ErrorCode::Cancelled) throw;
            throw e.withFile(input);
        }
        const double fieldSeconds = clock.seconds() - readSeconds;
        for (sdf::LevelSet* levelSet : {&field.object, &field.interior}) {
            levelSet->info().sourceFile = input;
            levelSet->info().generator = generatorString();
            levelSet->info().transformMm = scaled.transformMm;
        }
        tool.writeOutput(output, [&](std::ostream& out) {
            sdf::writeVdb({field.object, field.interior}, out);
        });
        const double totalSeconds = clock.seconds();

        report["input"] = input;
        report["output"] = output;
        report["size_mm"] = {scaled.sizeMm[0], scaled.sizeMm[1], scaled.sizeMm[2]};
        for (const sdf::LevelSet* levelSet : {&field.object, &field.interior}) {
            report["grids"][levelSet->info().name] = {{"voxel_mm", levelSet->info().voxelMm},
                                                      {"active_voxels", levelSet->activeVoxelCount()},
                                                      {"memory_bytes", levelSet->memoryBytes()}};
        }
        report["seconds"] = {{"read", readSeconds}, {"level_sets", fieldSeconds}, {"total", totalSeconds}};
        report["peak_rss_bytes"] = peakRssBytes();
        char line[256];
        std::snprintf(line, sizeof(line),
                      "%.1f x %.1f x %.1f mm; object %zu voxels (%g mm), interior %zu voxels (%g mm); %.1f s",
                      scaled.sizeMm[0], scaled.sizeMm[1], scaled.sizeMm[2], field.object.activeVoxelCount(),
                      field.object.info().voxelMm, field.interior.activeVoxelCount(),
                      field.interior.info().voxelMm, totalSeconds);
        cli::printInfo(tool, line);
        return 0;
    });
}
