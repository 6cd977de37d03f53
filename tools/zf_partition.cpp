// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-partition: cut the shell's outer surface into printable pieces over the frame's
/// outermost balls (paper §5). MESH is in its own coordinates; the frame's transform_mm places it.
/// Parse, read, call, write; the stage lives in lib/zomefab/partition (docs/partition.md).
#include <filesystem>
#include <string>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/frame/outermost.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/partition/partition.h"
#include "zomefab/partition/partition_json.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
using nlohmann::json;

int main(int argc, char** argv) {
    cli::Tool tool(
        "zf-partition",
        "Partition the surface into printable pieces over the frame's outermost balls (paper §5): graph "
        "cut, fit schedule, planar cuts from a multi-class linear SVM.");
    std::string meshPath, framePath, output, coloredPly, colorBy = "pieces", inFormat;
    cli::FabricationCli fabricationCli;
    cli::PartitionCli partitionCli;
    auto& app = tool.app();
    app.add_option("mesh", meshPath, "Surface mesh (.stl .obj .ply .gltf .glb) in its own coordinates")
        ->required();
    app.add_option("frame", framePath,
                   "Frame file (zomefab.structure JSON); its transform_mm places the mesh")
        ->required();
    app.add_option("-o,--output", output, "PARTITION.json (- = stdout)")->required();
    fabricationCli.addTo(app, cli::kPrinter | cli::kWall);
    partitionCli.addTo(app);
    app.add_option("--colored-ply", coloredPly, "Also write the mesh (frame mm) with one colour per group");
    app.add_option("--color-by", colorBy, "Groups for --colored-ply")
        ->check(CLI::IsMember({"pieces", "cells", "labels", "nearest"}))
        ->capture_default_str();
    tool.addFormatOption("--in-format", inFormat, {"stl", "obj", "ply", "gltf", "glb"},
                         "Mesh format (needed for -)");

    return tool.run(argc, argv, [&](json& report) {
        const Fabrication fabrication = fabricationCli.resolve(tool.common().seed);
        partition::PartitionOptions opt = partitionCli.resolve();
        partition::checkPartitionOptions(opt, fabrication);    // bad options fail before any input is read
        if (!coloredPly.empty()) checkOutputPath(coloredPly);  // and an unwritable --colored-ply
        MeshReadOptions readOptions;
        if (!inFormat.empty()) readOptions.format = meshFormatFromName(inFormat);
        TriMesh mesh = readMesh(meshPath, readOptions);
        Transform4d transformMm;
        const zome::Structure frame = cli::readFrame(framePath, &transformMm);
        transformInPlace(mesh, transformMm);
        partitionCli.resolveSalientFaces(opt, mesh.triangles.size());

        const std::vector<zome::BallId> labels = frame::outermostBalls(frame);
        partition::PartitionResult r;
        try {
            r = partition::partitionSurface(mesh, frame, labels, fabrication, opt, tool.context());
        } catch (const Error& e) {
            // Input problems here are the frame's, or the pair's: name the frame file (and the mesh).
            if (e.code() != ErrorCode::InvalidInput) throw;
            const bool isPair = e.message().rfind("frame and mesh", 0) == 0;
            throw Error(e.code(), e.message() + (isPair ? " (mesh " + meshPath + ")" : std::string()),
                        framePath);
        }
        const partition::PartitionJsonInfo info{meshPath,
                                                std::filesystem::path(framePath).filename().string(),
                                                transformMm, mesh.positions.size()};
        const std::string text = partition::partitionToJson(r, opt, info).dump(1) + "\n";
        tool.writeOutput(output, [&](std::ostream& out) { out << text; });
        if (!coloredPly.empty()) {
            const std::string bytes = partition::coloredPlyBytes(mesh, partition::faceGroups(r, colorBy));
            tool.writeOutput(coloredPly, [&](std::ostream& out) {
                out.write(bytes.data(), std::streamsize(bytes.size()));
            });
        }
        report = partition::partitionSummaryJson(r);
        const Vec3d box = fabrication.pieceBoxMm();
        cli::printInfo(
            tool,
            meshPath + ": " + std::to_string(mesh.triangles.size()) + " faces, " +
                std::to_string(labels.size()) + " outermost balls: nearest ball " +
                std::to_string(r.nearestPartitions) + " partitions, graph cut " +
                std::to_string(r.graphCutPartitions) +
                formatNumbers(" (w_smoothness %g), ", r.smoothnessWeight) + std::to_string(r.pieces.size()) +
                " pieces, all fit " +
                formatNumbers("%gx%gx%g mm (the bed less its margins)", box[0], box[1], box[2]) +
                (r.isScheduleBottomedOut ? " (schedule bottomed out: oversized partitions were split)" : ""));
        return 0;
    });
}
