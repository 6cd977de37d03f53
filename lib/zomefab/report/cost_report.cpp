// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/cost_report.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/report/mesh_clip.h"

namespace zomefab::report {

namespace {

double savedPercent(double zomefab, double baseline) {
    return baseline > 0.0 ? 100.0 * (1.0 - zomefab / baseline) : 0.0;
}

nlohmann::json printJson(const PrintEstimate& e) {
    nlohmann::json j = {{"parts", e.parts},
                        {"hours", e.hours()},
                        {"filament_mm3", e.filamentMm3},
                        {"support_mm3", e.supportMm3}};
    if (e.partVolumeMm3 > 0.0)
        j["model"] = {{"part_volume_mm3", e.partVolumeMm3},
                      {"perimeter_mm3", e.perimeterMm3},
                      {"solid_layers_mm3", e.solidMm3},
                      {"infill_mm3", e.infillMm3},
                      {"layers", e.layers}};
    return j;
}

nlohmann::json makingCostJson(const MakingCost& f) {
    return {
        {"print", printJson(f.print)},
        {"filament",
         {{"length_m", f.filament.lengthM}, {"mass_g", f.filament.massG}, {"cost_usd", f.filament.costUsd}}},
        {"assembly_hours", f.assemblyHours},
        {"zometool_usd", f.zomeUsd},
        {"total_hours", f.totalHours()},
        {"total_usd", f.totalUsd()}};
}

}  // namespace

double assemblyHours(const zome::PartsList& parts, const AssemblyTimeOptions& options) {
    return (double(parts.strutTotal()) * options.secondsPerStrut +
            double(parts.balls) * options.secondsPerBall) /
           3600.0;
}

const char* estimateSourceName(EstimateSource source) {
    return source == EstimateSource::PrusaSlicer ? "prusa-slicer" : "estimator";
}

void checkCostOptions(const CostOptions& options) {
    options.print.validate();
    options.filament.validate();
    if (!(options.assembly.secondsPerStrut >= 0.0) || !(options.assembly.secondsPerBall >= 0.0))
        throw Error(ErrorCode::Usage, "assembly seconds per strut and per ball must not be negative");
    if (options.source == EstimateSource::PrusaSlicer && !isSlicerAvailable(options.slicer.executable))
        throw Error(ErrorCode::Usage, "--slicer " + options.slicer.executable +
                                          ": not installed or not executable (Debian package prusa-slicer)");
}

CostReport costReport(const TriMesh& objectMm, const std::vector<const TriMesh*>& piecesMm,
                      const zome::PartsList& parts, const Fabrication& fabrication,
                      const CostOptions& options, RunContext& context) {
    checkFabrication(fabrication);
    checkCostOptions(options);
    CostReport report;
    report.printerMm = fabrication.printerMm;
    report.options = options;
    report.options.print.overhangDeg = fabrication.overhangDeg;  // the printer's, for every part
    report.source = options.source;
    report.parts = parts;
    report.pieceCount = piecesMm.size();
    report.objectVolumeMm3 = signedVolume(objectMm);
    for (const TriMesh* p : piecesMm) report.piecesVolumeMm3 += signedVolume(*p);

    context.progress("report", 0.0);
    const std::vector<TriMesh> baselineParts = octreeParts(objectMm, fabrication.printerMm, 10, context);
    report.baselinePartCount = baselineParts.size();

    const double zomeUsd = zome::partsCostUsd(parts, options.prices);
    const double buildHours = assemblyHours(parts, options.assembly);
    const size_t total = 2 * (piecesMm.size() + baselineParts.size() + 1);
    size_t done = 0;
    std::vector<const TriMesh*> baselinePointers;
    for (const TriMesh& part : baselineParts) baselinePointers.push_back(&part);
    auto printAll = [&](const std::vector<const TriMesh*>& meshes, const PrintSettings& settings,
                        const std::string& what, std::vector<PieceCost>* each = nullptr) {
        PrintEstimate sum;
        for (size_t i = 0; i < meshes.size(); ++i) {
            context.throwIfCancelled();
            const std::string label =
                what + " " + std::to_string(i) + " at " + formatNumbers("%.0f", settings.infillPercent) + "%";
            PrintEstimate part;
            if (options.source == EstimateSource::PrusaSlicer) {
                try {
                    part = sliceWithPrusaSlicer(*meshes[i], settings, label, options.slicer, context);
                } catch (const Error& e) {
                    if (e.code() != ErrorCode::ProcessingFailed) throw;
                    // One odd part should not void the whole report: say so and estimate it.
                    context.warn(std::string(e.what()) + "; the estimator's numbers are used for it");
                    report.slicerFallbacks.push_back(label);
                    part = estimatePrint(*meshes[i], settings, options.rates);
                }
            } else {
                part = estimatePrint(*meshes[i], settings, options.rates);
            }
            sum += part;
            if (each) each->push_back({part, filamentUse(part.filamentMm3, options.filament)});
            context.progress("report", double(++done) / double(total));
        }
        return sum;
    };
    const std::pair<const char*, double> cases[] = {{"hollow", options.hollowInfillPercent},
                                                    {"solid", options.solidInfillPercent}};
    for (const auto& [name, infill] : cases) {
        PrintSettings settings = report.options.print;  // with the printer's overhang
        settings.infillPercent = infill;
        settings.supports = options.countSupports;
        settings.validate();
        CostCase c;
        c.name = name;
        c.infillPercent = infill;
        c.zomefab.print = printAll(piecesMm, settings, std::string(name) + " piece", &c.pieces);
        c.zomefab.filament = filamentUse(c.zomefab.print.filamentMm3, options.filament);
        c.zomefab.assemblyHours = buildHours;
        c.zomefab.zomeUsd = zomeUsd;
        c.baseline.print = printAll(baselinePointers, settings, std::string(name) + " baseline part");
        c.baseline.filament = filamentUse(c.baseline.print.filamentMm3, options.filament);
        c.savedTimePercent = savedPercent(c.zomefab.totalHours(), c.baseline.totalHours());
        c.savedMaterialPercent = savedPercent(c.zomefab.totalUsd(), c.baseline.totalUsd());
        c.savedFilamentPercent = savedPercent(c.zomefab.print.filamentMm3, c.baseline.print.filamentMm3);
        c.whole.print = printAll({&objectMm}, settings, std::string(name) + " whole object");
        c.whole.filament = filamentUse(c.whole.print.filamentMm3, options.filament);
        c.savedTimeVsWholePercent = savedPercent(c.zomefab.totalHours(), c.whole.totalHours());
        c.savedFilamentVsWholePercent = savedPercent(c.zomefab.print.filamentMm3, c.whole.print.filamentMm3);
        report.cases.push_back(std::move(c));
    }
    context.progress("report", 1.0);
    return report;
}

nlohmann::json costReportToJson(const CostReport& r) {
    const CostOptions& o = r.options;
    nlohmann::json cases = nlohmann::json::array();
    for (const CostCase& c : r.cases)
        cases.push_back({{"name", c.name},
                         {"infill_percent", c.infillPercent},
                         {"zomefab", makingCostJson(c.zomefab)},
                         {"baseline", makingCostJson(c.baseline)},
                         {"saved_time_percent", c.savedTimePercent},
                         {"saved_material_percent", c.savedMaterialPercent},
                         {"saved_filament_percent", c.savedFilamentPercent},
                         {"whole", makingCostJson(c.whole)},
                         {"saved_time_vs_whole_percent", c.savedTimeVsWholePercent},
                         {"saved_filament_vs_whole_percent", c.savedFilamentVsWholePercent}});
    return {{"source", estimateSourceName(r.source)},
            {"supports_counted", o.countSupports},
            {"slicer_fallbacks", r.slicerFallbacks},
            {"pieces", r.pieceCount},
            {"baseline_parts", r.baselinePartCount},
            {"object_volume_mm3", r.objectVolumeMm3},
            {"pieces_volume_mm3", r.piecesVolumeMm3},
            {"zometool", zome::partsListToJson(r.parts, o.prices)},
            {"cases", std::move(cases)},
            {"options",
             {{"printer_mm", r.printerMm},
              {"layer_height_mm", o.print.layerHeightMm},
              {"first_layer_height_mm", o.print.firstLayerHeightMm},
              {"nozzle_mm", o.print.nozzleMm},
              {"overhang_deg", o.print.overhangDeg},
              {"extrusion_width_mm", o.print.extrusionWidthMm},
              {"perimeters", o.print.perimeters},
              {"top_layers", o.print.topLayers},
              {"bottom_layers", o.print.bottomLayers},
              {"filament_mm", o.filament.diameterMm},
              {"filament_density_g_per_cm3", o.filament.densityGPerCm3},
              {"filament_usd_per_m", o.filament.usdPerM},
              {"assembly_seconds_per_strut", o.assembly.secondsPerStrut},
              {"assembly_seconds_per_ball", o.assembly.secondsPerBall}}}};
}

std::string costReportMarkdown(const CostReport& r) {
    std::string md =
        "| infill | method | printing (h) | Zometool assembly (h) | overall (h) | printing (USD) | "
        "Zometool (USD) | overall (USD) | time saved | material saved |\n"
        "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
    for (const CostCase& c : r.cases) {
        const std::string label = c.name + " (" + formatNumbers("%.0f", c.infillPercent) + "%)";
        md += "| " + label + " | ZomeFab | " + formatNumbers("%.2f", c.zomefab.print.hours()) + " | " +
              formatNumbers("%.2f", c.zomefab.assemblyHours) + " | " +
              formatNumbers("%.2f", c.zomefab.totalHours()) + " | " +
              formatNumbers("%.2f", c.zomefab.filament.costUsd) + " | " +
              formatNumbers("%.2f", c.zomefab.zomeUsd) + " | " + formatNumbers("%.2f", c.zomefab.totalUsd()) +
              " | " + formatNumbers("%.2f", c.savedTimePercent) + "% | " +
              formatNumbers("%.2f", c.savedMaterialPercent) + "% |\n";
        md += "| | baseline (" + std::to_string(c.baseline.print.parts) + " octree parts) | " +
              formatNumbers("%.2f", c.baseline.print.hours()) + " | | " +
              formatNumbers("%.2f", c.baseline.totalHours()) + " | " +
              formatNumbers("%.2f", c.baseline.filament.costUsd) + " | | " +
              formatNumbers("%.2f", c.baseline.totalUsd()) + " | | |\n";
        md += "| | whole object (1 part, large bed) | " + formatNumbers("%.2f", c.whole.print.hours()) +
              " | | " + formatNumbers("%.2f", c.whole.totalHours()) + " | " +
              formatNumbers("%.2f", c.whole.filament.costUsd) + " | | " +
              formatNumbers("%.2f", c.whole.totalUsd()) + " | " +
              formatNumbers("%.2f", c.savedTimeVsWholePercent) + "% | " +
              formatNumbers("%.2f", savedPercent(c.zomefab.totalUsd(), c.whole.totalUsd())) + "% |\n";
    }
    md +=
        "\nSaved is against the octree baseline (the paper's Table 1) on the ZomeFab row, against "
        "printing the object whole on the whole-object row.\n";
    md += "\nFilament (" + formatNumbers("%.2f", r.options.filament.diameterMm) + " mm, " +
          formatNumbers("%.2f", r.options.filament.usdPerM) + " USD/m): ";
    for (size_t i = 0; i < r.cases.size(); ++i) {
        const CostCase& c = r.cases[i];
        md += (i ? "; " : "") + c.name + " ZomeFab " + formatNumbers("%.1f", c.zomefab.filament.lengthM) +
              " m / " + formatNumbers("%.0f", c.zomefab.filament.massG) + " g, baseline " +
              formatNumbers("%.1f", c.baseline.filament.lengthM) + " m / " +
              formatNumbers("%.0f", c.baseline.filament.massG) + " g (" +
              formatNumbers("%.1f", c.savedFilamentPercent) + "% less plastic), whole object " +
              formatNumbers("%.1f", c.whole.filament.lengthM) + " m / " +
              formatNumbers("%.0f", c.whole.filament.massG) + " g (" +
              formatNumbers("%.1f", c.savedFilamentVsWholePercent) + "% less)";
    }
    md += ". Times and filament from the " + std::string(estimateSourceName(r.source)) + ".";
    if (r.options.countSupports && !r.cases.empty()) {
        const CostCase& c = r.cases[0];
        md += formatNumbers(
            " Automatic supports are counted on every side, where each part's overhangs (steeper than %.0f° "
            "from the vertical, `--overhang-deg`) need "
            "them: %.0f cm³ for the pieces, %.0f cm³ for the octree parts, %.0f cm³ for the object printed "
            "whole.",
            r.options.print.overhangDeg, c.zomefab.print.supportMm3 / 1000.0,
            c.baseline.print.supportMm3 / 1000.0, c.whole.print.supportMm3 / 1000.0);
    }
    md += "\n";
    return md;
}

}  // namespace zomefab::report
