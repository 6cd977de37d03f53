// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/run_report.h"

#include <filesystem>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/version.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/report/assembly_page.h"
#include "zomefab/zome/parts.h"

namespace zomefab::report {

using nlohmann::json;

namespace {

std::string frameLine(const RunRecord& run) {
    const zome::PartsList& parts = run.cost.parts;
    size_t tenons = 0, fewTenons = 0;
    for (const pieces::Piece& piece : run.pieces.pieces) {
        tenons += piece.tenons.size();
        fewTenons += !piece.tenonShortfall.empty();
    }
    const Vec3d& size = run.scaled.sizeMm;
    return formatNumbers("%.0f x %.0f x %.0f mm", size[0], size[1], size[2]) + ": frame of " +
           std::to_string(parts.balls) + " balls and " + std::to_string(parts.strutTotal()) + " struts (" +
           std::to_string(run.assembly.layers) + " layers to build), " +
           std::to_string(run.pieces.pieces.size()) + " printed pieces with " + std::to_string(tenons) +
           " tenons" +
           (fewTenons ? " (" + std::to_string(fewTenons) + (fewTenons == 1 ? " piece" : " pieces") +
                            " with fewer than planned)"
                      : "");
}

std::string costLine(const CostCase& c) {
    return c.name + formatNumbers(" (%.0f%% infill): ", c.infillPercent) +
           formatNumbers("print %.1f h, %.2f kg, %.2f USD", c.zomefab.print.hours(),
                         c.zomefab.filament.massG / 1000.0, c.zomefab.filament.costUsd) +
           formatNumbers(" + Zometool %.2f USD, %.1f h to build", c.zomefab.zomeUsd,
                         c.zomefab.assemblyHours) +
           formatNumbers("; octree baseline %.1f h, %.2f USD", c.baseline.print.hours(),
                         c.baseline.totalUsd()) +
           formatNumbers(": saves %.0f%% time, %.0f%% material", c.savedTimePercent, c.savedMaterialPercent) +
           formatNumbers("; printed whole %.1f h: saves %.0f%% time, %.0f%% filament", c.whole.print.hours(),
                         c.savedTimeVsWholePercent, c.savedFilamentVsWholePercent);
}

json levelSetsJson(const RunRecord& run) {
    return {
        {"object",
         {{"voxel_mm", run.field.object.info().voxelMm},
          {"active_voxels", run.field.object.activeVoxelCount()}}},
        {"interior",
         {{"voxel_mm", run.field.interior.info().voxelMm},
          {"active_voxels", run.field.interior.activeVoxelCount()}}},
        {"shell", {{"shell_mm", run.fabrication.wallMm}, {"active_voxels", run.shell.activeVoxelCount()}}}};
}

json frameJson(const RunRecord& run) {
    const zome::PartsList parts = zome::partsList(run.frame.structure);
    return {{"balls", parts.balls},
            {"struts", parts.strutTotal()},
            {"parts", zome::partsListToJson(parts)},
            {"energy_initial", run.frame.initialEnergy.total},
            {"energy_final", run.frame.finalEnergy.total},
            {"chains", run.frame.chains.size()},
            {"rotation_deg", run.frame.rotationDeg},
            {"metrics", frame::metricsToJson(run.frameMetrics)}};
}

json partitionJson(const RunRecord& run) {
    const partition::PartitionResult& p = run.partition;
    return {{"pieces", p.pieces.size()},
            {"nearest_ball_partitions", p.nearestPartitions},
            {"graph_cut_partitions", p.graphCutPartitions},
            {"smoothness_weight", p.smoothnessWeight},
            {"energy_nearest", p.energyNearest},
            {"energy_graph_cut", p.energyGraphCut},
            {"printer_mm", p.printerMm}};
}

json piecesJson(const RunRecord& run) {
    size_t tenons = 0;
    double volumeMm3 = 0;
    for (const pieces::Piece& piece : run.pieces.pieces) {
        tenons += piece.tenons.size();
        volumeMm3 += piece.volumeMm3;
    }
    return {{"count", run.pieces.pieces.size()},
            {"tenons", tenons},
            {"volume_mm3", volumeMm3},
            {"shell_volume_mm3", run.pieces.shellVolumeMm3},
            {"slivers_merged", run.pieces.sliversMerged}};
}

/// Grams of support filament in a piece's print @p cost (the estimator's or the slicer's).
double supportGrams(const PieceCost& cost) {
    const double gPerMm3 = cost.print.filamentMm3 > 0 ? cost.filament.massG / cost.print.filamentMm3 : 0.0;
    return cost.print.supportMm3 * gPerMm3;
}

json costJson(const RunRecord& run) {
    json cost = costReportToJson(run.cost);
    // Per piece, per infill case: what the maker plans prints with.
    json perPiece = json::array();
    for (size_t i = 0; i < run.pieces.pieces.size(); ++i) {
        const pieces::Piece& piece = run.pieces.pieces[i];
        json row{{"piece", pieces::pieceName(run.pieces, i)},
                 {"support_area_mm2", piece.supportAreaMm2},
                 {"support_volume_mm3", piece.supportVolumeMm3},
                 {"brim_advised", piece.isBrimAdvised}};
        for (const CostCase& c : run.cost.cases)
            if (i < c.pieces.size())
                row[c.name] = {{"hours", c.pieces[i].print.hours()},
                               {"filament_mm3", c.pieces[i].print.filamentMm3},
                               {"grams", c.pieces[i].filament.massG},
                               {"support_mm3", c.pieces[i].print.supportMm3},
                               {"support_grams", supportGrams(c.pieces[i])}};
        perPiece.push_back(row);
    }
    cost["per_piece"] = perPiece;
    // The headline numbers (paper Table 1's "Efficiency (Saved)" columns), flat for batch summaries.
    for (const CostCase& c : run.cost.cases) {
        cost["time_saved_" + c.name + "_percent"] = c.savedTimePercent;
        cost["material_saved_" + c.name + "_percent"] = c.savedMaterialPercent;
        cost["filament_saved_" + c.name + "_percent"] = c.savedFilamentPercent;
    }
    return cost;
}

}  // namespace

std::vector<MountingStep> mountingSteps(const pieces::Pieces& all) {
    std::vector<MountingStep> steps;
    for (const mount::MountStep& plan : all.plan.steps) {
        MountingStep step;
        step.hole = plan.hole;
        step.slide = plan.slide;
        step.liftMm = plan.liftMm;
        for (uint32_t p : plan.pieces) {
            step.pieces.push_back(pieces::pieceName(all, p));
            for (const pieces::Tenon& t : all.pieces[p].tenons)
                step.tenons.push_back({step.pieces.back(), t.ball, t.hole});
        }
        for (const auto& [a, b] : all.plan.glued) {
            if (std::find(plan.pieces.begin(), plan.pieces.end(), a) == plan.pieces.end()) continue;
            size_t pins = 0;
            for (const pieces::AlignmentPin& pin : all.pieces[a].pins) pins += pin.partner == b ? 1 : 0;
            step.glue.push_back({pieces::pieceName(all, a), pieces::pieceName(all, b), pins});
        }
        for (const auto& [host, piece] : all.plan.gluedOn) {
            if (std::find(plan.pieces.begin(), plan.pieces.end(), piece) == plan.pieces.end()) continue;
            size_t pins = 0;
            for (const pieces::AlignmentPin& pin : all.pieces[host].pins)
                pins += pin.partner == piece && !pin.isSocket ? 1 : 0;
            step.gluedOnto.push_back({pieces::pieceName(all, piece), pieces::pieceName(all, host), pins});
        }
        steps.push_back(std::move(step));
    }
    return steps;
}

RunReports reportStage(const zome::Structure& frame, const pieces::Pieces& all, const TriMesh& objectMm,
                       const Fabrication& fabrication, const CostOptions& options, RunContext& context) {
    std::vector<const TriMesh*> printed;
    for (const pieces::Piece& piece : all.pieces) printed.push_back(&piece.mesh);
    RunReports reports;
    reports.assembly = assemblyGuide(frame, mountingSteps(all));
    reports.cost = costReport(objectMm, printed, zome::partsList(frame), fabrication, options, context);
    return reports;
}

std::vector<std::string> runSummaryLines(const RunRecord& run) {
    std::vector<std::string> lines{frameLine(run)};
    for (const CostCase& c : run.cost.cases) lines.push_back(costLine(c));
    return lines;
}

json runReportJson(const RunRecord& run, const RunContext& context) {
    json report;
    report["format"] = kReportFormatName;
    report["version"] = kReportFormatVersion;
    report["generator"] = generatorString();
    report["input"] = {{"file", run.sourceName},
                       {"triangles", run.inputReport.triangleCount},
                       {"vertices", run.inputReport.vertexCount},
                       {"size_mm", run.scaled.sizeMm},
                       {"transform_mm", toJson(run.scaled.transformMm)}};
    report["level_sets"] = levelSetsJson(run);
    report["frame"] = frameJson(run);
    report["partition"] = partitionJson(run);
    report["pieces"] = piecesJson(run);
    report["plates"] = pieces::platesToJson(run.pieces, run.plates);
    report["assembly"] = {{"layers", run.assembly.layers},
                          {"components", run.assembly.components},
                          {"mounting", assemblyGuideToJson(run.assembly)["mounting"]},
                          {"file", "assembly.md"}};
    report["cost"] = costJson(run);
    json timings = json::array();
    for (const StageTiming& t : run.timings) timings.push_back({{"stage", t.stage}, {"seconds", t.seconds}});
    report["timings"] = timings;
    report["seconds"] = run.totalSeconds;
    report["peak_rss_bytes"] = peakRssBytes();
    report["warnings"] = context.warnings();
    return report;
}

namespace {

/// The plate (1-based) each piece is printed on; 0 when the run has no plates.
std::vector<size_t> plateOfPiece(const RunRecord& run) {
    std::vector<size_t> plate(run.pieces.pieces.size(), 0);
    for (size_t k = 0; k < run.plates.size(); ++k)
        for (const pieces::PlacedPiece& p : run.plates[k].items) plate[p.piece] = k + 1;
    return plate;
}

/// Per piece and per plate: hours and grams in each infill case (the estimator's, or the slicer's).
std::string perPieceMarkdown(const RunRecord& run) {
    if (run.cost.cases.empty() || run.cost.cases[0].pieces.size() != run.pieces.pieces.size()) return "";
    const std::vector<size_t> plate = plateOfPiece(run);
    std::string columns, rule;  // hours and grams per infill case
    for (const CostCase& c : run.cost.cases) {
        columns += formatNumbers(" h at %.0f%% | g at %.0f%% |", c.infillPercent, c.infillPercent);
        rule += "---:|---:|";
    }
    const CostCase& first = run.cost.cases[0];
    const std::string supportNote =
        !run.cost.options.countSupports ? "no supports counted"
        : run.cost.source == EstimateSource::PrusaSlicer
            ? "with PrusaSlicer's automatic supports where the overhangs need them; support: the "
              "filament PrusaSlicer lays down as support"
            : std::string(
                  "with automatic supports where the overhangs need them; support: the "
                  "estimator's, from the columns under the overhangs, their footprint and its edge "
                  "(fitted to PrusaSlicer on 32 pieces and 3 objects printed whole, docs/report.md)");
    std::string md =
        "\n## Per piece\n\nEach piece's print on its own, " + supportNote +
        formatNumbers(
            ". Overhang: the area facing down more than %.0f° from the vertical as the "
            "piece lies. ",
            run.cost.options.print.overhangDeg) +
        "Brim: the first layer is under 4 cm²; \"on supports\": no first layer of its own, it stands on its "
        "supports (print it with them).\n\n| piece | plate |" +
        columns + " overhang cm² | support g | brim |\n|---|---:|" + rule + "---:|---:|---|\n";
    double supportG = 0;
    for (size_t i = 0; i < run.pieces.pieces.size(); ++i) {
        md += "| " + pieces::pieceName(run.pieces, i) + " | " + std::to_string(plate[i]) + " |";
        for (const CostCase& c : run.cost.cases)
            md += formatNumbers(" %.1f | %.0f |", c.pieces[i].print.hours(), c.pieces[i].filament.massG);
        const pieces::Piece& piece = run.pieces.pieces[i];
        const double grams = supportGrams(first.pieces[i]);
        supportG += grams;
        md += formatNumbers(" %.0f | %.0f | ", piece.supportAreaMm2 / 100.0, grams) +
              (piece.isOnSupports    ? "on supports"
               : piece.isBrimAdvised ? "yes"
                                     : "no") +
              " |\n";
    }
    md += formatNumbers("\nSupport filament in all: %.0f g.\n", supportG);
    md += "\n## Per plate (print job)\n\n" + std::to_string(run.plates.size()) +
          " print jobs, one per file in plates/.\n\n| plate | pieces |" + columns + "\n|---|---|" + rule +
          "\n";
    for (size_t k = 0; k < run.plates.size(); ++k) {
        std::string names;
        for (const pieces::PlacedPiece& p : run.plates[k].items)
            names += (names.empty() ? "" : ", ") + pieces::pieceName(run.pieces, p.piece);
        md += "| " + pieces::plateFileName(k) + " | " + names + " |";
        for (const CostCase& c : run.cost.cases) {
            double hours = 0, grams = 0;
            for (const pieces::PlacedPiece& p : run.plates[k].items)
                hours += c.pieces[p.piece].print.hours(), grams += c.pieces[p.piece].filament.massG;
            md += formatNumbers(" %.1f | %.0f |", hours, grams);
        }
        md += "\n";
    }
    return md;
}

}  // namespace

std::string costPage(const RunRecord& run) {
    std::string page =
        "# Cost and time: " + std::filesystem::path(run.sourceName).filename().string() + "\n\n";
    for (const std::string& line : runSummaryLines(run)) page += "- " + line + "\n";
    return page + "\n" + costReportMarkdown(run.cost) + perPieceMarkdown(run);
}

json previewExtras(const std::string& sourceName, const Vec3d& sizeMm) {
    return {{"source", sourceName}, {"size_mm", sizeMm}};
}

PreviewInput previewInput(const pieces::Pieces& all, const zome::Structure& frame) {
    PreviewInput input;
    const Transform4d gridToFrameMm = affineInverse(all.frameToGridMm);
    for (size_t i = 0; i < all.pieces.size(); ++i) {
        const pieces::Piece& piece = all.pieces[i];
        input.pieces.push_back(&piece.mesh);
        input.pieceNames.push_back(pieces::pieceName(all, i));
        input.pieceTransforms.push_back(gridToFrameMm * affineInverse(piece.gridToPrintMm));
        const int step = all.plan.stepOf(uint32_t(i));
        json extras = {{"step", step < 0 ? json(nullptr) : json(step + 1)}};
        if (piece.hole >= 0) {
            const Vec3d& d = zome::holeDirection(piece.hole);
            extras["hole"] = piece.hole;
            extras["push"] = {0.0 - d[0], 0.0 - d[1],
                              0.0 - d[2]};  // frame mm: the way it moves onto the frame
        }
        if (step >= 0 && all.plan.steps[size_t(step)].pieces.size() > 1) {
            json group = json::array();
            for (uint32_t p : all.plan.steps[size_t(step)].pieces) group.push_back(pieces::pieceName(all, p));
            extras["glued_group"] = group;
        }
        input.pieceExtras.push_back(std::move(extras));
    }
    input.frame = &frame;
    return input;
}

PreviewInput previewInput(const RunRecord& run) {
    PreviewInput input = previewInput(run.pieces, run.frame.structure);
    input.extras = previewExtras(run.sourceName, run.scaled.sizeMm);
    return input;
}

std::string assemblyPage(const RunRecord& run, const zome::PriceOptions& prices) {
    return assemblyGuideHtml(run.assembly, previewInput(run),
                             std::filesystem::path(run.sourceName).filename().string(), prices);
}

RunSummary runSummaryFromJson(const json& report) {
    if (!report.is_object() || report.value("format", "") != kReportFormatName)
        throw Error(ErrorCode::InvalidInput,
                    std::string("not a run report (format is not \"") + kReportFormatName + "\")");
    RunSummary s;
    s.peakRssBytes = countFromJson(report, "peak_rss_bytes", 0);
    const json frame = report.value("frame", json::object());
    s.balls = countFromJson(frame, "balls", 0);
    s.struts = countFromJson(frame, "struts", 0);
    // The printed pieces, after the pieces stage's re-cuts (the partition's regions can be fewer).
    const json pieces = report.value("pieces", json::object());
    s.pieces = pieces.is_object() ? countFromJson(pieces, "count", 0) : 0;
    const json cost = report.value("cost", json::object());
    if (cost.contains("material_saved_hollow_percent") && cost["material_saved_hollow_percent"].is_number()) {
        s.hasMaterialSaved = true;
        s.materialSavedPercent = cost["material_saved_hollow_percent"].get<double>();
    }
    return s;
}

}  // namespace zomefab::report
