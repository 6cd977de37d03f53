// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/partition_json.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "zomefab/core/error.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/version.h"

namespace zomefab::partition {

using nlohmann::json;

namespace {

template <class T>
void append(std::string& out, T value) {
    char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));  // x86-64 and aarch64 are little-endian
    out.append(bytes, sizeof(T));
}

}  // namespace

json partitionToJson(const PartitionResult& r, const PartitionOptions& o, const PartitionJsonInfo& info) {
    json j;
    j["format"] = kPartitionFormatName;
    j["version"] = kPartitionFormatVersion;
    j["generator"] = generatorString();
    j["mesh"] = {{"file", info.meshFile}, {"faces", r.faceCells.size()}, {"vertices", info.vertexCount}};
    j["frame"] = {{"file", info.frameFile}, {"b0_mm", r.b0Mm}};
    j["transform_mm"] = toJson(info.transformMm);
    j["printer_mm"] = toJson(r.printerMm);
    j["fit_margin_mm"] = r.fitMarginMm;

    json labels = json::array();
    for (size_t l = 0; l < r.labelBalls.size(); ++l)
        labels.push_back({{"label", l}, {"ball", r.labelBalls[l]}});
    j["labels"] = labels;

    json cells = json::array();
    for (size_t c = 0; c < r.cells.cellCount(); ++c)
        cells.push_back(
            {{"cell", c}, {"ball", r.cellBalls[c]}, {"w", toJson(r.cells.w[c])}, {"b", r.cells.b[c]}});
    j["cells"] = cells;

    json pieces = json::array();
    for (size_t p = 0; p < r.pieces.size(); ++p) {
        const Piece& piece = r.pieces[p];
        json axes =
            json::array({toJson(piece.fit.axes[0]), toJson(piece.fit.axes[1]), toJson(piece.fit.axes[2])});
        json patches = json::array();
        for (const Piece::CellPatch& c : piece.patches)
            patches.push_back(
                {{"cell", c.cell},
                 {"bbox_mm", {{"min", toJson(c.boundsMm.min)}, {"max", toJson(c.boundsMm.max)}}}});
        pieces.push_back(
            {{"piece", p},
             {"cells", piece.cells},
             {"balls", piece.balls},
             {"faces", piece.faceCount},
             {"area_mm2", piece.areaMm2},
             {"bbox_mm", {{"min", toJson(piece.boundsMm.min)}, {"max", toJson(piece.boundsMm.max)}}},
             {"patches", std::move(patches)},
             {"fit",
              {{"fits", piece.fit.fits},
               {"ratio", piece.fit.ratio},
               {"axes", axes},
               {"extents_mm", toJson(piece.fit.extentsMm)},
               {"center_mm", toJson(piece.fit.centerMm)}}}});
    }
    j["pieces"] = pieces;

    json schedule = json::array();
    for (const ScheduleStep& s : r.schedule)
        schedule.push_back({{"w_smoothness", s.smoothnessWeight},
                            {"energy_nearest_ball", s.energyNearest},
                            {"energy_graph_cut", s.energyGraphCut},
                            {"partitions", s.partitions},
                            {"oversized", s.oversized},
                            {"faces", s.faces},
                            {"kept", s.kept},
                            {"sweeps", s.sweeps},
                            {"expansions", s.expansions}});
    j["energy"] = {{"w_data", o.dataWeight},
                   {"w_saliency", o.saliencyWeight},
                   {"w_smoothness", r.smoothnessWeight},
                   {"k", o.candidateCount},
                   {"nearest_ball", r.energyNearest},
                   {"graph_cut", r.energyGraphCut},
                   {"sweep_energies", r.sweepEnergies},
                   {"schedule", schedule},
                   {"schedule_bottomed_out", r.isScheduleBottomedOut}};
    j["counts"] = {{"nearest_ball_partitions", r.nearestPartitions},
                   {"graph_cut_partitions", r.graphCutPartitions},
                   {"cells", r.cells.cellCount()},
                   {"pieces", r.pieces.size()},
                   {"splits", r.splits},
                   {"merges", r.merges},
                   {"region_merges", r.regionMerges},
                   {"salient_faces", std::count(r.salientFaces.begin(), r.salientFaces.end(), uint8_t(1))},
                   {"salient_regions", r.salientRegions},
                   {"salient_regions_crossed", r.salientRegionsSplit},
                   {"graph_nodes", r.graphNodes},
                   {"candidate_pairs", r.candidatePairs}};
    j["svm"] = {{"solver", o.svm.useCrammerSinger ? "MCSVM_CS" : "L2R_L2LOSS_SVC_DUAL"},
                {"cost", o.svm.cost},
                {"samples", r.svmSamples},
                {"agreement", r.svmAgreement}};

    json salient = json::array();
    for (size_t f = 0; f < r.salientFaces.size(); ++f)
        if (r.salientFaces[f]) salient.push_back(f);
    j["salient_faces"] = salient;
    j["face_nearest_labels"] = r.nearestLabels;
    j["face_labels"] = r.graphCutLabels;
    j["face_cells"] = r.faceCells;
    j["face_pieces"] = r.facePieces;
    return j;
}

json partitionSummaryJson(const PartitionResult& r) {
    double worst = 0.0;
    for (const Piece& p : r.pieces) worst = std::max(worst, p.fit.ratio);
    return {
        {"faces", r.faceCells.size()},
        {"labels", r.labelBalls.size()},
        {"graph_nodes", r.graphNodes},
        {"candidate_pairs", r.candidatePairs},
        {"w_smoothness", r.smoothnessWeight},
        {"energy_nearest_ball", r.energyNearest},
        {"energy_graph_cut", r.energyGraphCut},
        {"nearest_ball_partitions", r.nearestPartitions},
        {"graph_cut_partitions", r.graphCutPartitions},
        {"pieces", r.pieces.size()},
        {"largest_fit_ratio", worst},
        {"seconds",
         {{"graph_cut", r.secondsGraphCut}, {"svm_and_pieces", r.secondsSvm}, {"total", r.secondsTotal}}}};
}

const std::vector<uint32_t>& faceGroups(const PartitionResult& r, const std::string& groups) {
    if (groups == "pieces") return r.facePieces;
    if (groups == "cells") return r.faceCells;
    if (groups == "labels") return r.graphCutLabels;
    if (groups == "nearest") return r.nearestLabels;
    throw Error(ErrorCode::Usage,
                "face groups must be pieces, cells, labels or nearest, got \"" + groups + "\"");
}

std::string coloredPlyBytes(const TriMesh& mesh, const std::vector<uint32_t>& groups) {
    if (groups.size() != mesh.triangles.size())
        throw Error(ErrorCode::Usage, "coloured PLY: " + std::to_string(groups.size()) + " face groups for " +
                                          std::to_string(mesh.triangles.size()) + " faces");
    std::string out =
        "ply\nformat binary_little_endian 1.0\ncomment zomefab partition: one colour per group\n"
        "element vertex " +
        std::to_string(mesh.positions.size()) +
        "\nproperty float x\nproperty float y\nproperty float z\n"
        "element face " +
        std::to_string(mesh.triangles.size()) +
        "\nproperty list uchar int vertex_indices\nproperty uchar red\nproperty uchar green\nproperty uchar "
        "blue\n"
        "property int group\nend_header\n";
    out.reserve(out.size() + mesh.positions.size() * 12 + mesh.triangles.size() * 20);
    for (const Vec3f& p : mesh.positions)
        for (float x : p) append(out, x);
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
        append<uint8_t>(out, 3);
        for (uint32_t v : mesh.triangles[f]) append<int32_t>(out, int32_t(v));
        // Hue h = frac(id·0.618…) walks the colour wheel so consecutive ids differ; HSV → RGB.
        const double h = std::fmod(double(groups[f]) * 0.6180339887498949, 1.0) * 6.0;
        const double s = 0.65, v = 0.95;
        const int i = int(h) % 6;
        const double fr = h - std::floor(h);
        const double p = v * (1 - s), q = v * (1 - s * fr), t = v * (1 - s * (1 - fr));
        double rgb[3];
        switch (i) {
            case 0:
                rgb[0] = v, rgb[1] = t, rgb[2] = p;
                break;
            case 1:
                rgb[0] = q, rgb[1] = v, rgb[2] = p;
                break;
            case 2:
                rgb[0] = p, rgb[1] = v, rgb[2] = t;
                break;
            case 3:
                rgb[0] = p, rgb[1] = q, rgb[2] = v;
                break;
            case 4:
                rgb[0] = t, rgb[1] = p, rgb[2] = v;
                break;
            default:
                rgb[0] = v, rgb[1] = p, rgb[2] = q;
                break;
        }
        for (double c : rgb) append<uint8_t>(out, uint8_t(std::lround(c * 255.0)));
        append<int32_t>(out, int32_t(groups[f]));
    }
    return out;
}

}  // namespace zomefab::partition
