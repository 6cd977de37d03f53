// SPDX-License-Identifier: GPL-3.0-or-later
// pieces.json, and the pieces' files written through a staging directory.
#include "zomefab/pieces/pieces_io.h"

#include <cmath>

#include "zomefab/core/error.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/vec.h"
#include "zomefab/core/version.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/pieces/plates.h"
#include "zomefab/zome/holes.h"

namespace zomefab::pieces {

using nlohmann::json;

namespace {

/// A piece's direction as pieces.json writes it: the hole, its colour, the unit vector in frame
/// and grid coordinates, and its name in words; null when it has none.
json directionToJson(int hole, const Transform4d& frameToGridMm) {
    if (hole < 0) return nullptr;
    const Vec3d& d = zome::holeDirection(hole);
    return {{"hole", hole},
            {"color", zome::colorName(zome::holeColor(hole))},
            {"frame", toJson(d)},
            {"grid", toJson(normalized(applyLinear(frameToGridMm, d)))},
            {"name", zome::directionName(d)}};
}

json installationToJson(const mount::InstallationPlan& plan, const Transform4d& frameToGridMm) {
    json steps = json::array();
    for (const mount::MountStep& s : plan.steps) {
        json step = {{"pieces", s.pieces}, {"hole", s.hole}};
        if (s.hasTwoLegs())  // slid in along −slide first, then pushed on by lift_mm
            step["slide"] = {{"frame", toJson(s.slide)},
                             {"grid", toJson(normalized(applyLinear(frameToGridMm, s.slide)))},
                             {"lift_mm", s.liftMm}};
        steps.push_back(std::move(step));
    }
    json before = json::array();
    for (const auto& [a, b] : plan.before) before.push_back({a, b});
    json glued = json::array();
    for (const auto& [a, b] : plan.glued) glued.push_back({a, b});
    json gluedOn = json::array();
    for (const auto& [host, piece] : plan.gluedOn) gluedOn.push_back({host, piece});
    return {{"steps", steps},
            {"before", before},
            {"glued", glued},
            {"glued_on", gluedOn},
            {"problems", plan.problems}};
}

/// One tenon of pieces.json: its axis, ball and the points along it; a stem cut through a thin
/// wall adds where its 5 × 5 lines are cut (tenons.h, Tenon::cutAlongMm), as points.
json tenonToJson(const Tenon& t, const TenonOptions& o) {
    json j = {{"ball", t.ball},
              {"hole", t.hole},
              {"axis_frame", toJson(t.axisFrame)},
              {"axis_mm", toJson(t.axisGrid)},
              {"peg_long_side_mm", toJson(t.longSideGrid)},
              {"ball_center_mm", toJson(t.ballCenterGridMm)},
              {"peg_tip_mm", toJson(t.pointAt(t.pegTipMm))},
              {"shoulder_mm", toJson(t.pointAt(t.shoulderMm))},
              {"base_mm", toJson(t.pointAt(t.baseMm))},
              {"end_mm", toJson(t.pointAt(t.endMm))},
              {"length_mm", t.lengthMm()},
              {"tilt_deg", t.tiltDeg}};
    if (t.isClipped()) {
        json points = json::array();
        for (int i = 0; i < kCutSide; ++i)
            for (int k = 0; k < kCutSide; ++k)
                points.push_back(toJson(stemPointMm(t, o, t.cutAlongMm[size_t(i * kCutSide + k)],
                                                    cutLineFraction(i), cutLineFraction(k))));
        j["cut_mm"] = std::move(points);
    }
    return j;
}

}  // namespace

std::string pieceName(const Pieces& pieces, size_t index) {
    size_t width = 2;
    for (size_t n = pieces.pieces.size(); n > 100; n /= 10) ++width;
    std::string digits = std::to_string(index);
    if (digits.size() < width) digits.insert(0, width - digits.size(), '0');
    return "piece-" + digits;
}

std::string pieceFileName(const Pieces& pieces, size_t index) { return pieceName(pieces, index) + ".stl"; }

json piecesToJson(const Pieces& all, const PiecesJsonInfo& info) {
    const PiecesOptions& o = all.options;
    json j;
    j["format"] = kPiecesFormatName;
    j["version"] = kPiecesFormatVersion;
    j["generator"] = generatorString();
    j["units"] = "mm";
    j["inputs"] = {{"shell", info.shellFile}, {"frame", info.frameFile}, {"partition", info.partitionFile}};
    j["printer_mm"] = toJson(all.printerMm);
    j["bed_margin_mm"] = all.bedMarginMm;
    j["voxel_mm"] = all.voxelMm;
    j["grid_transform_mm"] = toJson(all.gridTransformMm);
    j["frame_to_grid_mm"] = toJson(all.frameToGridMm);
    j["options"] = {{"min_piece_volume_mm3", o.minPieceVolumeMm3},
                    {"adaptivity", o.adaptivity},
                    {"tenons",
                     {{"min_per_piece", o.tenons.minPerPiece},
                      {"max_per_piece", o.tenons.maxPerPiece},
                      {"clearance_mm", o.tenons.clearanceMm},
                      {"hole_mm",
                       {2 * zome::holeSectionMm(zome::Color::Blue)[2][0],
                        2 * zome::holeSectionMm(zome::Color::Blue)[2][1]}},
                      {"peg_mm", {pegLongMm(o.tenons), pegShortMm(o.tenons)}},
                      {"peg_depth_mm", o.tenons.pegDepthMm},
                      {"width_mm", o.tenons.bodyWidthMm},
                      {"taper_deg", o.tenons.taperDeg},
                      {"max_length_mm", o.tenons.maxLengthMm},
                      {"max_tilt_deg", o.tenons.maxTiltDeg},
                      {"embed_mm", o.tenons.embedMm},
                      {"frame_clearance_mm", o.tenons.frameClearanceMm},
                      {"holes", tenonHolesName(o.tenons.holes)}}},
                    {"seam_gap_mm", o.seamGapMm},
                    {"recut_pairs", o.isRecuttingPairs},
                    {"cut_for_support", o.isCuttingForSupport},
                    {"glue_under_held", o.isGluingUnderHeld},
                    {"grow_frame", o.isGrowingFrame},
                    {"print_wall_mm", o.printWallMm},
                    {"pins",
                     {{"diameter_mm", o.pins.diameterMm},
                      {"length_mm", o.pins.lengthMm},
                      {"clearance_mm", o.pins.clearanceMm},
                      {"per_pair", o.pins.perPair}}},
                    {"label",
                     {{"enabled", o.label.isEnabled},
                      {"height_mm", o.label.heightMm},
                      {"stroke_mm", o.label.strokeMm},
                      {"depth_mm", o.label.depthMm}}}};
    double total = 0;
    size_t tenonCount = 0, fewTenons = 0, labelled = 0;
    json pieces = json::array();
    for (size_t i = 0; i < all.pieces.size(); ++i) {
        const Piece& p = all.pieces[i];
        total += p.volumeMm3;
        tenonCount += p.tenons.size();
        if (p.tenons.size() < size_t(o.tenons.minPerPiece)) ++fewTenons;
        if (p.label) ++labelled;
        json neighbors = json::array();
        for (const auto& [id, area] : p.neighbors)
            neighbors.push_back({{"piece", id}, {"contact_mm2", area}});
        json tenons = json::array();
        for (const Tenon& t : p.tenons) tenons.push_back(tenonToJson(t, o.tenons));
        json pins = json::array();
        for (const AlignmentPin& pin : p.pins)
            pins.push_back({{"partner", pin.partner},
                            {"kind", pin.isSocket ? "socket" : "pin"},
                            {"center_mm", toJson(pin.centerGridMm)},
                            {"axis", toJson(pin.axisGrid)},
                            {"radius_mm", pin.radiusMm},
                            {"length_mm", pin.lengthMm}});
        json shortfall = nullptr;
        if (p.tenons.size() < size_t(o.tenons.minPerPiece)) {
            shortfall = {
                {"found", p.tenons.size()}, {"wanted", o.tenons.minPerPiece}, {"reasons", json::object()}};
            for (const auto& [why, count] : p.tenonShortfall) shortfall["reasons"][why] = count;
        }
        json label = nullptr;
        if (p.label)
            label = {{"text", p.label->text},
                     {"center_mm", toJson(p.label->centerGridMm)},
                     {"normal", toJson(p.label->normalGrid)},
                     {"up", toJson(p.label->upGrid)},
                     {"size_mm", {p.label->widthMm, p.label->heightMm}}};
        Box3d printed = boundingBox(p.mesh);
        pieces.push_back({{"piece", p.id},
                          {"file", pieceFileName(all, i)},
                          {"volume_mm3", p.volumeMm3},
                          {"shell_volume_mm3", p.shellVolumeMm3},
                          {"wall_mm", p.wallMm},
                          {"thin_wall", p.isThinWall},
                          {"triangles", p.mesh.triangles.size()},
                          {"bbox_mm", toJson(printed)},
                          {"grid_bbox_mm", toJson(p.gridBoundsMm)},
                          {"orientation",
                           {{"transform_mm", toJson(p.gridToPrintMm)},
                            {"cut_face_down", p.isCutFaceDown},
                            {"on_supports", p.isOnSupports},
                            {"down_normal", toJson(p.downNormalGridMm)},
                            {"base_area_mm2", p.baseAreaMm2},
                            {"support_area_mm2", p.supportAreaMm2},
                            {"support_volume_mm3", p.supportVolumeMm3},
                            {"brim_advised", p.isBrimAdvised},
                            {"extents_mm", toJson(p.extentsMm)},
                            {"fits", true}}},
                          {"direction", directionToJson(p.hole, all.frameToGridMm)},
                          {"cells", p.cells},
                          {"partition_pieces", p.requests},
                          {"neighbors", neighbors},
                          {"slivers_merged", p.sliversMerged},
                          {"tenons", tenons},
                          {"tenon_shortfall", shortfall},
                          {"pins", pins},
                          {"label", label},
                          {"label_note", p.label ? json(nullptr) : json(p.labelNote)}});
    }
    j["pieces"] = pieces;
    j["installation"] = installationToJson(all.plan, all.frameToGridMm);
    j["summary"] = {{"pieces", all.pieces.size()},
                    {"volume_mm3", total},
                    {"shell_volume_mm3", all.shellVolumeMm3},
                    {"outside_cells_volume_mm3", all.outsideCellsVolumeMm3},
                    {"slivers_merged", all.sliversMerged},
                    {"isolated_slivers", all.isolatedSlivers},
                    {"recut_pieces", all.recutPieces},
                    {"merged_pieces", all.mergedPieces},
                    {"recut_pairs", all.recutPairs},
                    {"support_cuts", all.supportCuts},
                    {"print_splits", all.printSplits},
                    {"glued_for_pegs", all.gluedForPegs},
                    {"thin_pieces", all.thinPieces},
                    {"frame_struts_grown", all.frameStrutsGrown},
                    {"tenons", tenonCount},
                    {"pieces_with_few_tenons", fewTenons},
                    {"labelled", labelled}};
    return j;
}

void writePieceFiles(const Pieces& all, const std::string& directory, const PiecesJsonInfo& info) {
    for (size_t i = 0; i < all.pieces.size(); ++i)
        writeMesh(all.pieces[i].mesh, directory + "/" + pieceFileName(all, i));
    const std::string text = piecesToJson(all, info).dump(2) + "\n";
    writeOutputAtomic(directory + "/" + kPiecesFile,
                      [&](std::ostream& out) { out.write(text.data(), std::streamsize(text.size())); });
}

void writePieces(const Pieces& all, const std::string& directory, const PiecesJsonInfo& info) {
    StagedDirectory staging(directory);
    writePieceFiles(all, staging.path(), info);
    writePlates(all, packPlates(all), staging.path());
    staging.commit();
}

}  // namespace zomefab::pieces
