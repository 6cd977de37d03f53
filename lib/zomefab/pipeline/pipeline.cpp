// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/pipeline/pipeline.h"

#include <algorithm>
#include <filesystem>
#include <functional>

#include "zomefab/core/json_values.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/version.h"
#include "zomefab/frame/outermost.h"
#include "zomefab/io/file_io.h"
#include "zomefab/partition/partition_json.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/sdf/interior_field.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

namespace zomefab::pipeline {

namespace {

/// The file every zomefab output directory holds; its presence allows replacing the directory.
constexpr const char* kReportFile = "report.json";

/// Runs @p body as stage @p name: progress at its start and end, its wall time recorded.
template <class Body>
auto timedStage(const std::string& name, RunResult& result, RunContext& context, Body&& body) {
    context.throwIfCancelled();
    context.progress(name, 0.0);
    Stopwatch clock;
    auto value = body();
    result.timings.push_back({name, clock.seconds()});
    context.progress(name, 1.0);
    return value;
}

/// Errors that stages raise about the object itself belong to the input file.
[[noreturn]] void rethrowAboutInput(const Error& e, const std::string& sourceName) {
    if (e.code() == ErrorCode::Usage || e.code() == ErrorCode::Cancelled || e.code() == ErrorCode::Internal)
        throw e;
    throw e.withFile(sourceName);
}


}  // namespace

void checkRunOptions(const RunOptions& options) {
    mesh::checkScaleOptions(options.scale);
    sdf::checkObjectFieldOptions(options.field);
    sdf::checkShellOptions(options.shell);
    partition::checkPartitionOptions(options.partition, options.frame.lattice.scale);
    pieces::checkPiecesOptions(options.pieces);
    if (options.frame.chains < 1) throw Error(ErrorCode::Usage, "--chains must be at least 1");
    // The pieces stage would find this out only after the level sets; say it before any work.
    const double maxVoxelMm = pieces::maxVoxelForPegsMm(options.pieces.tenons);
    if (options.pieces.tenons.maxPerPiece > 0 && options.field.voxelMm > maxVoxelMm)
        throw Error(ErrorCode::Usage, "--voxel-mm " + formatNumbers("%g", options.field.voxelMm) + ": the tenon pegs (" +
                                          formatNumbers("%.2f", pieces::pegShortMm(options.pieces.tenons)) +
                                          " mm thick) need a voxel of at most " + formatNumbers("%.2f", maxVoxelMm) + " mm");
    report::checkCostOptions(options.cost);
}

RunResult runPipeline(const TriMesh& input, const std::string& sourceName, const RunOptions& options,
                      RunContext& context) {
    checkRunOptions(options);
    RunResult result;
    result.sourceName = sourceName;
    Stopwatch total;

    // Stage 1: validate and scale (paper §3: the input is a closed mesh at its target size).
    result.scaled = timedStage("input", result, context, [&] {
        result.inputReport = mesh::checkMesh(input);
        TriMesh valid = mesh::validateClosedMesh(input, options.validate, sourceName, context);
        return mesh::scaleToMillimetres(std::move(valid), options.scale);
    });

    // Stage 2: level sets. The object grid must be exact as deep as the shell is thick.
    sdf::ObjectFieldOptions fieldOptions = options.field;
    fieldOptions.shellDepthMm = std::max(fieldOptions.shellDepthMm, options.shell.shellMm);
    result.field = timedStage("level sets", result, context, [&] {
        try {
            sdf::ObjectField field = sdf::makeObjectField(result.scaled.mesh, fieldOptions, context);
            for (sdf::LevelSet* levelSet : {&field.object, &field.interior}) {
                levelSet->info().sourceFile = sourceName;
                levelSet->info().generator = generatorString();
                levelSet->info().transformMm = result.scaled.transformMm;
            }
            return field;
        } catch (const Error& e) {
            rethrowAboutInput(e, sourceName);
        }
    });
    result.shell = timedStage("shell", result, context, [&] {
        sdf::LevelSet shell = sdf::makeShell(result.field.object, options.shell, context);
        shell.info().generator = generatorString();
        return shell;
    });

    // Stage 4: the frame (paper §4), in the frame's millimetres (the lattice may be rotated).
    const sdf::InteriorField interior = sdf::makeInteriorField(result.field.interior, context);
    result.frame = timedStage("frame", result, context, [&] {
        try {
            return frame::buildFrame(interior, options.frame, context);
        } catch (const Error& e) {
            rethrowAboutInput(e, sourceName);
        }
    });
    result.frameTransformMm = frame::frameTransformMm(result.scaled.transformMm, result.frame.rotationDeg);
    {
        const frame::FrameField frameField(interior, result.frame.rotationDeg, result.frame.structure.scale(),
                                           options.frame.lattice.zone);
        result.frameMetrics =
            frame::measureFrame(result.frame.structure, frameField, options.frame.surfaceSampleSpacingMm);
    }

    // Stage 5: the surface partition (paper §5) of the outer surface, in frame coordinates.
    result.surfaceFrameMm = result.scaled.mesh;
    transformInPlace(result.surfaceFrameMm, frame::rotationAboutZ(-result.frame.rotationDeg));
    result.partition = timedStage("partition", result, context, [&] {
        partition::PartitionOptions partitionOptions = options.partition;
        partitionOptions.seed = options.frame.seed;
        try {
            return partition::partitionSurface(result.surfaceFrameMm, result.frame.structure,
                                               frame::outermostBalls(result.frame.structure), partitionOptions,
                                               context);
        } catch (const Error& e) {
            rethrowAboutInput(e, sourceName);
        }
    });

    // Stage 6: printable pieces (paper §6): the shell cut by the partition's cells, with tenons.
    result.pieces = timedStage("pieces", result, context, [&] {
        pieces::CellModel cells;
        cells.w = result.partition.cells.w;
        cells.b = result.partition.cells.b;
        std::vector<pieces::PieceRequest> requests;
        for (const partition::Piece& piece : result.partition.pieces) requests.push_back({piece.cells, piece.boundsMm});
        pieces::PiecesOptions piecesOptions = options.pieces;
        piecesOptions.printerMm = options.partition.printerMm;
        const Transform4d frameToGridMm = result.shell.info().transformMm * affineInverse(result.frameTransformMm);
        return pieces::makePieces(result.shell, result.frame.structure, frameToGridMm, cells, requests,
                                  piecesOptions, context);
    });

    // Stage 7: what the user reads (paper §7): the assembly guide and the cost report (Table 1).
    timedStage("report", result, context, [&] {
        std::vector<report::TenonLink> links;
        std::vector<std::string> names;
        std::vector<TriMesh> printed;
        for (size_t i = 0; i < result.pieces.pieces.size(); ++i) {
            const pieces::Piece& piece = result.pieces.pieces[i];
            names.push_back(pieces::pieceName(result.pieces, i));
            for (const pieces::Tenon& tenon : piece.tenons) links.push_back({names.back(), tenon.ball, tenon.hole});
            printed.push_back(piece.mesh);
        }
        result.assembly = report::assemblyGuide(result.frame.structure, links, names);
        report::CostOptions costOptions = options.cost;
        costOptions.printerMm = options.partition.printerMm;
        result.cost = report::costReport(result.scaled.mesh, printed, zome::partsList(result.frame.structure),
                                         costOptions, context);
        return 0;
    });

    result.totalSeconds = total.seconds();
    return result;
}

report::PreviewInput previewInput(const RunResult& result) {
    report::PreviewInput input;
    const Transform4d gridToFrameMm = affineInverse(result.pieces.frameToGridMm);
    for (size_t i = 0; i < result.pieces.pieces.size(); ++i) {
        const pieces::Piece& piece = result.pieces.pieces[i];
        input.pieces.push_back(piece.mesh);
        input.pieceNames.push_back(pieces::pieceName(result.pieces, i));
        input.pieceTransforms.push_back(gridToFrameMm * affineInverse(piece.gridToPrintMm));
    }
    input.frame = &result.frame.structure;
    input.extras = {{"source", result.sourceName}, {"size_mm", result.scaled.sizeMm}};
    return input;
}

std::vector<std::string> runSummaryLines(const RunResult& result) {
    std::vector<std::string> lines;
    const zome::PartsList& parts = result.cost.parts;
    size_t tenons = 0, fewTenons = 0;
    for (const pieces::Piece& piece : result.pieces.pieces) {
        tenons += piece.tenons.size();
        fewTenons += !piece.tenonShortfall.empty();
    }
    lines.push_back(formatNumbers("%.0f x %.0f x %.0f mm", result.scaled.sizeMm[0], result.scaled.sizeMm[1],
                           result.scaled.sizeMm[2]) +
                    ": frame of " + std::to_string(parts.balls) + " balls and " + std::to_string(parts.strutTotal()) +
                    " struts (" + std::to_string(result.assembly.layers) + " layers to build), " +
                    std::to_string(result.pieces.pieces.size()) + " printed pieces with " + std::to_string(tenons) +
                    " tenons" + (fewTenons ? " (" + std::to_string(fewTenons) + " pieces with fewer than planned)" : ""));
    for (const report::CostCase& c : result.cost.cases) {
        lines.push_back(c.name + formatNumbers(" (%.0f%% infill): ", c.infillPercent) +
                        formatNumbers("print %.1f h, %.2f kg, %.2f USD", c.zomefab.print.hours(), c.zomefab.filament.massG / 1000.0,
                               c.zomefab.filament.costUsd) +
                        formatNumbers(" + Zometool %.2f USD, %.1f h to build", c.zomefab.zomeUsd, c.zomefab.assemblyHours) +
                        formatNumbers("; whole object %.1f h, %.2f USD", c.baseline.print.hours(), c.baseline.totalUsd()) +
                        formatNumbers(": saves %.0f%% time, %.0f%% material", c.savedTimePercent, c.savedMaterialPercent));
    }
    return lines;
}

nlohmann::json runReportJson(const RunResult& result, const RunOptions& options, const RunContext& context) {
    nlohmann::json report;
    report["format"] = "zomefab.report";
    report["version"] = 1;
    report["generator"] = generatorString();
    report["input"] = {{"file", result.sourceName},
                       {"triangles", result.inputReport.triangleCount},
                       {"vertices", result.inputReport.vertexCount},
                       {"size_mm", result.scaled.sizeMm},
                       {"transform_mm", toJson(result.scaled.transformMm)}};
    report["level_sets"] = {
        {"object", {{"voxel_mm", result.field.object.info().voxelMm},
                    {"active_voxels", result.field.object.activeVoxelCount()}}},
        {"interior", {{"voxel_mm", result.field.interior.info().voxelMm},
                      {"active_voxels", result.field.interior.activeVoxelCount()}}},
        {"shell", {{"shell_mm", options.shell.shellMm}, {"active_voxels", result.shell.activeVoxelCount()}}}};
    const zome::PartsList parts = zome::partsList(result.frame.structure);
    report["frame"] = {{"balls", parts.balls},
                       {"struts", parts.strutTotal()},
                       {"parts", zome::partsListToJson(parts)},
                       {"energy_initial", result.frame.initialEnergy.total},
                       {"energy_final", result.frame.finalEnergy.total},
                       {"chains", options.frame.chains},
                       {"rotation_deg", result.frame.rotationDeg},
                       {"metrics", frame::metricsToJson(result.frameMetrics)}};
    report["partition"] = {{"pieces", result.partition.pieces.size()},
                           {"nearest_ball_partitions", result.partition.nearestPartitions},
                           {"graph_cut_partitions", result.partition.graphCutPartitions},
                           {"smoothness_weight", result.partition.smoothnessWeight},
                           {"energy_nearest", result.partition.energyNearest},
                           {"energy_graph_cut", result.partition.energyGraphCut},
                           {"printer_mm", result.partition.printerMm}};
    size_t tenons = 0;
    double piecesVolumeMm3 = 0;
    for (const pieces::Piece& piece : result.pieces.pieces) {
        tenons += piece.tenons.size();
        piecesVolumeMm3 += piece.volumeMm3;
    }
    report["pieces"] = {{"count", result.pieces.pieces.size()},
                        {"tenons", tenons},
                        {"volume_mm3", piecesVolumeMm3},
                        {"shell_volume_mm3", result.pieces.shellVolumeMm3},
                        {"slivers_merged", result.pieces.sliversMerged}};
    report["assembly"] = {{"layers", result.assembly.layers},
                          {"components", result.assembly.components},
                          {"file", "assembly.md"}};
    nlohmann::json cost = report::costReportToJson(result.cost);
    // The headline numbers (paper Table 1's "Efficiency (Saved)" columns), flat for batch summaries.
    for (const report::CostCase& c : result.cost.cases) {
        cost["time_saved_" + c.name + "_percent"] = c.savedTimePercent;
        cost["material_saved_" + c.name + "_percent"] = c.savedMaterialPercent;
        cost["filament_saved_" + c.name + "_percent"] = c.savedFilamentPercent;
    }
    report["cost"] = cost;
    nlohmann::json timings = nlohmann::json::array();
    for (const StageTiming& t : result.timings) timings.push_back({{"stage", t.stage}, {"seconds", t.seconds}});
    report["timings"] = timings;
    report["seconds"] = result.totalSeconds;
    report["peak_rss_bytes"] = peakRssBytes();
    report["warnings"] = context.warnings();
    return report;
}

std::vector<std::string> writeRunOutputs(const RunResult& result, const RunOptions& options,
                                         const nlohmann::json& report, const std::string& outDir) {
    StagedDirectory staged(outDir, kReportFile);
    std::vector<std::string> written;
    auto write = [&](const std::string& name, const std::function<void(std::ostream&)>& body) {
        writeOutputAtomic(staged.file(name), body);
        written.push_back(name);
    };
    write("frame.json", [&](std::ostream& out) {
        out << zome::structureToJson(result.frame.structure, result.frameTransformMm).dump(1) << '\n';
    });
    write("frame.vef", [&](std::ostream& out) { out << zome::structureToVef(result.frame.structure); });
    write("partition.json", [&](std::ostream& out) {
        partition::PartitionJsonInfo info;
        info.meshFile = result.sourceName;
        info.transformMm = result.frameTransformMm;
        info.vertexCount = result.surfaceFrameMm.vertexCount();
        out << partition::partitionToJson(result.partition, options.partition, info).dump(1) << '\n';
    });
    pieces::writePieces(result.pieces, staged.file("pieces"), {result.sourceName, "frame.json", "partition.json"});
    written.push_back("pieces/");
    // The 3MF holds every piece: one file to open in a slicer, next to the preview, not among the STLs.
    std::error_code ec;
    std::filesystem::rename(staged.file("pieces") + "/pieces.3mf", staged.file("pieces.3mf"), ec);
    if (ec) throw Error(ErrorCode::WriteFailed, "cannot move pieces.3mf: " + ec.message(), outDir);
    written.push_back("pieces.3mf");
    report::writePreview(previewInput(result), staged.file("preview.glb"), options.preview);
    written.push_back("preview.glb");
    write("assembly.md", [&](std::ostream& out) {
        out << report::assemblyGuideMarkdown(result.assembly, options.cost.prices);
    });
    write("cost.md", [&](std::ostream& out) {
        out << "# Cost and time: " << std::filesystem::path(result.sourceName).filename().string() << "\n\n";
        for (const std::string& line : runSummaryLines(result)) out << "- " << line << "\n";
        out << "\n" << report::costReportMarkdown(result.cost);
    });
    write(kReportFile, [&](std::ostream& out) { out << report.dump(2) << '\n'; });
    staged.commit();
    std::sort(written.begin(), written.end());
    return written;
}

}  // namespace zomefab::pipeline
