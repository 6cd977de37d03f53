// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-partition: cut the shell's outer surface into printable pieces over the frame's
/// outermost balls (paper §5). MESH is in its own coordinates; the frame's transform_mm places it.
/// Parse, read, call, write; the stage lives in lib/zomefab/partition (docs/partition.md).
#include <cstdio>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/transform.h"
#include "zomefab/frame/outermost.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/partition/partition.h"
#include "zomefab/partition/partition_json.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
using nlohmann::json;

int main(int argc, char** argv) {
    cli::Tool tool("zf-partition",
                   "Partition the surface into printable pieces over the frame's outermost balls (paper §5): graph "
                   "cut, fit schedule, planar cuts from a multi-class linear SVM.");
    std::string meshPath, framePath, output, coloredPly, colorBy = "pieces", printer = "200x200x200", salientFile;
    std::string inFormat;
    std::vector<std::string> spheres;
    partition::PartitionOptions opt;
    bool oneVsRest = false;
    auto& app = tool.app();
    app.add_option("mesh", meshPath, "Surface mesh (.stl .obj .ply .gltf .glb) in its own coordinates")->required();
    app.add_option("frame", framePath, "Frame file (zomefab.structure JSON); its transform_mm places the mesh")->required();
    app.add_option("-o,--output", output, "PARTITION.json (- = stdout)")->required();
    app.add_option("--printer-mm", printer, "Printer build volume WxDxH in mm")->default_val(printer);
    app.add_option("--salient", spheres, "Keep faces within a sphere whole: x,y,z,r in the frame's mm (repeatable)");
    app.add_option("--salient-faces", salientFile, "JSON list of salient face indices (or {\"salient_faces\": [...]})");
    app.add_option("-k,--candidates", opt.candidateCount, "Candidate labels per triangle: its k nearest balls")
        ->default_val(opt.candidateCount)->check(CLI::PositiveNumber);
    app.add_option("--w-smoothness", opt.smoothnessStart, "First w_smoothness of the fit schedule")->default_val(opt.smoothnessStart);
    app.add_option("--w-smoothness-factor", opt.smoothnessFactor, "Multiply w_smoothness by this while a partition does not fit")
        ->default_val(opt.smoothnessFactor);
    app.add_option("--w-smoothness-min", opt.smoothnessMin, "The schedule bottoms out below this w_smoothness")
        ->default_val(opt.smoothnessMin);
    app.add_option("--w-saliency", opt.saliencyWeight, "w_saliency")->default_val(opt.saliencyWeight);
    app.add_option("--fit-margin-mm", opt.fitMarginMm, "Grow each side of a piece's box by this before the fit test")
        ->default_val(opt.fitMarginMm);
    app.add_option("--min-piece-area-mm2", opt.minPieceAreaMm2, "Merge smaller pieces into a neighbour when it fits")
        ->default_val(opt.minPieceAreaMm2);
    app.add_option("--svm-cost", opt.svm.cost, "liblinear C for the planar cuts")->default_val(opt.svm.cost);
    app.add_option("--svm-samples", opt.svmMaxSamples, "Train the planar cuts on at most this many faces")
        ->default_val(opt.svmMaxSamples)->check(CLI::PositiveNumber);
    app.add_flag("--one-vs-rest", oneVsRest, "One-vs-rest SVMs instead of Crammer-Singer (both give argmax cells)");
    app.add_option("--graph-nodes", opt.graphNodeTarget, "Cluster faces above this many graph-cut nodes (0 = never)")
        ->default_val(opt.graphNodeTarget);
    app.add_option("--colored-ply", coloredPly, "Also write the mesh (frame mm) with one colour per group");
    app.add_option("--color-by", colorBy, "Groups for --colored-ply")
        ->check(CLI::IsMember({"pieces", "cells", "labels", "nearest"}))->default_val(colorBy);
    tool.addFormatOption("--in-format", inFormat, {"stl", "obj", "ply", "gltf", "glb"}, "Mesh format (needed for -)");

    return tool.run(argc, argv, [&](json& report) {
        opt.printerMm = cli::parsePrinterMm(printer);
        for (const std::string& s : spheres) opt.salientSpheres.push_back(cli::parseSalientSphere(s));
        opt.svm.useCrammerSinger = !oneVsRest;
        opt.seed = tool.common().seed;
        partition::checkPartitionOptions(opt);  // bad options fail before any input is read

        MeshReadOptions readOptions;
        if (!inFormat.empty()) readOptions.format = meshFormatFromName(inFormat);
        TriMesh mesh = readMesh(meshPath, readOptions);
        Transform4d transformMm;
        const std::string frameBytes = readInputBytes(framePath);
        zome::Structure frame = [&] {
            try {
                return zome::structureFromJsonText(frameBytes, {}, {}, &transformMm);
            } catch (const Error& e) {
                throw e.withFile(framePath);
            }
        }();
        transformInPlace(mesh, transformMm);
        if (!salientFile.empty()) opt.salientFaceIndices = cli::readSalientFaceList(salientFile, mesh.triangles.size());

        const std::vector<zome::BallId> labels = frame::outermostBalls(frame);
        partition::PartitionResult r;
        try {
            r = partition::partitionSurface(mesh, frame, labels, opt, tool.context());
        } catch (const Error& e) {
            // Input problems here are the frame's, or the pair's: name the frame file (and the mesh).
            if (e.code() != ErrorCode::InvalidInput) throw;
            const bool isPair = e.message().rfind("frame and mesh", 0) == 0;
            throw Error(e.code(), e.message() + (isPair ? " (mesh " + meshPath + ")" : std::string()), framePath);
            throw;
        }
        partition::PartitionJsonInfo info{meshPath, framePath, transformMm, mesh.positions.size()};
        cli::writeJsonFile(partition::partitionToJson(r, opt, info), output);
        if (!coloredPly.empty()) {
            const std::vector<uint32_t>& groups = colorBy == "cells"    ? r.faceCells
                                                  : colorBy == "labels"  ? r.graphCutLabels
                                                  : colorBy == "nearest" ? r.nearestLabels
                                                                         : r.facePieces;
            const std::string bytes = partition::coloredPlyBytes(mesh, groups);
            writeOutputAtomic(coloredPly, [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); });
        }

        double worst = 0.0;
        for (const partition::Piece& p : r.pieces) worst = std::max(worst, p.fit.ratio);
        report = {{"faces", mesh.triangles.size()},
                  {"labels", labels.size()},
                  {"graph_nodes", r.graphNodes},
                  {"candidate_pairs", r.candidatePairs},
                  {"w_smoothness", r.smoothnessWeight},
                  {"energy_nearest_ball", r.energyNearest},
                  {"energy_graph_cut", r.energyGraphCut},
                  {"nearest_ball_partitions", r.nearestPartitions},
                  {"graph_cut_partitions", r.graphCutPartitions},
                  {"pieces", r.pieces.size()},
                  {"largest_fit_ratio", worst},
                  {"seconds", {{"graph_cut", r.secondsGraphCut}, {"svm_and_pieces", r.secondsSvm}, {"total", r.secondsTotal}}}};
        char line[320];
        std::snprintf(line, sizeof line,
                      "%s: %zu faces, %zu outermost balls: nearest ball %zu partitions, graph cut %zu (w_smoothness "
                      "%g), %zu pieces, all fit %s mm%s",
                      meshPath.c_str(), mesh.triangles.size(), labels.size(), r.nearestPartitions, r.graphCutPartitions,
                      r.smoothnessWeight, r.pieces.size(), printer.c_str(),
                      r.isScheduleBottomedOut ? " (schedule bottomed out: oversized partitions were split)" : "");
        cli::printInfo(tool, line);
        return 0;
    });
}
