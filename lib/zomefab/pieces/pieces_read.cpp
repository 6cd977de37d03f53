// SPDX-License-Identifier: GPL-3.0-or-later
// pieces.json read back: the inverse of piecesToJson (pieces_io.cpp), for zf-preview, the
// installation checks and anything else that starts from a pieces directory.
#include <algorithm>
#include <cmath>
#include <filesystem>

#include "zomefab/core/error.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pieces/pieces_io.h"

namespace zomefab::pieces {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const std::string& what) { throw Error(ErrorCode::InvalidInput, what); }

/// @p j[@p key] read by @p read when present, else @p fallback: the reader is strict on what a
/// file means and lenient on what it can do without (a hand-written pieces.json for zf-preview).
template <class T, class Read>
T optionalField(const json& j, const char* key, T fallback, Read&& read) {
    return j.is_object() && j.contains(key) ? read(j[key]) : fallback;
}

uint32_t indexFromJson(const json& j, const std::string& what) {
    if (!j.is_number_unsigned() || j.get<uint64_t>() > 0xFFFFFFFEull) fail(what + " must be an index");
    return j.get<uint32_t>();
}

int intFromJson(const json& j, const std::string& what) {
    if (!j.is_number_integer() || j.get<int64_t>() < -1000000 || j.get<int64_t>() > 1000000)
        fail(what + " must be an integer");
    return j.get<int>();
}

std::vector<uint32_t> indicesFromJson(const json& j, const std::string& what) {
    if (!j.is_array()) fail(what + " must be a list of indices");
    std::vector<uint32_t> out;
    for (size_t i = 0; i < j.size(); ++i) out.push_back(indexFromJson(j[i], what));
    return out;
}

void readOptions(const json& o, PiecesOptions& options) {
    const std::string what = "options";
    options.minPieceVolumeMm3 = numberFromJson(requireMember(o, "min_piece_volume_mm3", what), what);
    options.adaptivity = numberFromJson(requireMember(o, "adaptivity", what), what);
    const json& t = requireMember(o, "tenons", what);
    TenonOptions& to = options.tenons;
    to.minPerPiece = intFromJson(requireMember(t, "min_per_piece", "tenons"), "tenons.min_per_piece");
    to.maxPerPiece = intFromJson(requireMember(t, "max_per_piece", "tenons"), "tenons.max_per_piece");
    to.clearanceMm = numberFromJson(requireMember(t, "clearance_mm", "tenons"), "tenons.clearance_mm");
    to.pegDepthMm = numberFromJson(requireMember(t, "peg_depth_mm", "tenons"), "tenons.peg_depth_mm");
    to.bodyWidthMm = numberFromJson(requireMember(t, "width_mm", "tenons"), "tenons.width_mm");
    to.taperDeg = numberFromJson(requireMember(t, "taper_deg", "tenons"), "tenons.taper_deg");
    to.maxLengthMm = numberFromJson(requireMember(t, "max_length_mm", "tenons"), "tenons.max_length_mm");
    to.maxTiltDeg = numberFromJson(requireMember(t, "max_tilt_deg", "tenons"), "tenons.max_tilt_deg");
    to.embedMm = numberFromJson(requireMember(t, "embed_mm", "tenons"), "tenons.embed_mm");
    to.frameClearanceMm =
        numberFromJson(requireMember(t, "frame_clearance_mm", "tenons"), "tenons.frame_clearance_mm");
    const std::string holes = t.value("holes", "all");
    const auto parsed = tenonHolesFromName(holes);
    if (!parsed) fail("tenons.holes must be lattice, blue or all, not \"" + holes + "\"");
    to.holes = *parsed;
    options.printWallMm = optionalField(
        o, "print_wall_mm", 0.0, [&](const json& v) { return numberFromJson(v, what + ".print_wall_mm"); });
}

Tenon tenonFromJson(const json& j, uint32_t piece, const std::string& what) {
    Tenon t;
    t.piece = piece;
    t.ball = indexFromJson(requireMember(j, "ball", what), what + ".ball");
    t.hole = intFromJson(requireMember(j, "hole", what), what + ".hole");
    if (t.hole < 0 || t.hole >= 62) fail(what + ".hole must be in 0..61");
    t.axisFrame = vec3FromJson(requireMember(j, "axis_frame", what), what + ".axis_frame");
    t.axisGrid = vec3FromJson(requireMember(j, "axis_mm", what), what + ".axis_mm");
    t.longSideGrid = vec3FromJson(requireMember(j, "peg_long_side_mm", what), what + ".peg_long_side_mm");
    t.ballCenterGridMm = vec3FromJson(requireMember(j, "ball_center_mm", what), what + ".ball_center_mm");
    // The distances along the axis, from the points written.
    auto along = [&](const char* key) {
        return dot(sub(vec3FromJson(requireMember(j, key, what), what + "." + key), t.ballCenterGridMm),
                   t.axisGrid);
    };
    t.pegTipMm = along("peg_tip_mm");
    t.shoulderMm = along("shoulder_mm");
    t.baseMm = along("base_mm");
    t.endMm = along("end_mm");
    t.tiltDeg = numberFromJson(requireMember(j, "tilt_deg", what), what + ".tilt_deg");
    if (j.contains("cut_plane"))  // written before stems were cut along the outer surface
        fail(what + ".cut_plane is from an older zomefab (a stem cut by a plane): make the pieces again");
    if (j.contains("cut_mm")) {
        // The 5 × 5 points where the stem's lines are cut: only how far along the axis each lies
        // is kept (the line fixes the rest).
        const json& c = j.at("cut_mm");
        const std::string where = what + ".cut_mm";
        if (!c.is_array() || c.size() != size_t(kCutLines))
            fail(where + " must be an array of " + std::to_string(kCutLines) + " points");
        for (size_t k = 0; k < c.size(); ++k) {
            const std::string at = where + "[" + std::to_string(k) + "]";
            t.cutAlongMm[k] = dot(sub(vec3FromJson(c[k], at), t.ballCenterGridMm), t.axisGrid);
            if (!(t.cutAlongMm[k] >= t.shoulderMm && t.cutAlongMm[k] <= t.endMm))
                fail(at + " must lie on the stem, between its shoulder and its end");
        }
        t.isCut = true;
    }
    return t;
}

void readOrientation(const json& o, Piece& piece, const std::string& what) {
    auto vec = [&](const char* key) {
        return [&, key](const json& v) { return vec3FromJson(v, what + "." + key); };
    };
    piece.gridToPrintMm = optionalField(o, "transform_mm", Transform4d::identity(), [&](const json& v) {
        return transformFromJson(v, what + ".transform_mm");
    });
    piece.isCutFaceDown = o.value("cut_face_down", false);
    piece.isOnSupports = o.value("on_supports", false);
    piece.downNormalGridMm = optionalField(o, "down_normal", Vec3d{0, 0, -1}, vec("down_normal"));
    auto number = [&](const char* key) {
        return [&, key](const json& v) { return numberFromJson(v, what + "." + key); };
    };
    piece.baseAreaMm2 = optionalField(o, "base_area_mm2", 0.0, number("base_area_mm2"));
    piece.supportAreaMm2 = optionalField(o, "support_area_mm2", 0.0, number("support_area_mm2"));
    piece.supportVolumeMm3 = optionalField(o, "support_volume_mm3", 0.0, number("support_volume_mm3"));
    piece.isBrimAdvised = o.value("brim_advised", false);
    piece.extentsMm = optionalField(o, "extents_mm", Vec3d{0, 0, 0}, vec("extents_mm"));
}

Piece pieceFromJson(const json& j, size_t index, const std::string& directory) {
    const std::string what = "pieces[" + std::to_string(index) + "]";
    if (!j.is_object()) fail(what + " must be an object");
    Piece piece;
    auto number = [&](const char* key) {
        return [&, key](const json& v) { return numberFromJson(v, what + "." + key); };
    };
    auto indices = [&](const char* key) {
        return [&, key](const json& v) { return indicesFromJson(v, what + "." + key); };
    };
    piece.id = optionalField(j, "piece", uint32_t(index),
                             [&](const json& v) { return indexFromJson(v, what + ".piece"); });
    piece.volumeMm3 = optionalField(j, "volume_mm3", 0.0, number("volume_mm3"));
    piece.shellVolumeMm3 = optionalField(j, "shell_volume_mm3", 0.0, number("shell_volume_mm3"));
    piece.wallMm = optionalField(j, "wall_mm", 0.0, number("wall_mm"));
    piece.isThinWall = optionalField(j, "thin_wall", false, [&](const json& v) {
        if (!v.is_boolean()) fail(what + ".thin_wall must be true or false");
        return v.get<bool>();
    });
    piece.gridBoundsMm = optionalField(j, "grid_bbox_mm", Box3d{},
                                       [&](const json& v) { return boxFromJson(v, what + ".grid_bbox_mm"); });
    readOrientation(j.value("orientation", json::object()), piece, what + ".orientation");
    piece.cells = optionalField(j, "cells", std::vector<uint32_t>{}, indices("cells"));
    piece.requests =
        optionalField(j, "partition_pieces", std::vector<uint32_t>{}, indices("partition_pieces"));
    for (const json& n : j.value("neighbors", json::array()))
        piece.neighbors.push_back(
            {indexFromJson(requireMember(n, "piece", what), what + ".neighbors"),
             numberFromJson(requireMember(n, "contact_mm2", what), what + ".neighbors")});
    piece.sliversMerged = optionalField(j, "slivers_merged", uint32_t(0), [&](const json& v) {
        return indexFromJson(v, what + ".slivers_merged");
    });
    const json tenons = j.value("tenons", json::array());
    if (!tenons.is_array()) fail(what + ".tenons must be a list");
    for (size_t t = 0; t < tenons.size(); ++t)
        piece.tenons.push_back(
            tenonFromJson(tenons[t], piece.id, what + ".tenons[" + std::to_string(t) + "]"));
    const json& shortfall = j.value("tenon_shortfall", json());
    if (shortfall.is_object() && shortfall.contains("reasons") && shortfall["reasons"].is_object())
        for (const auto& [why, count] : shortfall["reasons"].items())
            piece.tenonShortfall[why] = intFromJson(count, what + ".tenon_shortfall");
    const json& label = j.value("label", json());
    if (label.is_object()) {
        PieceLabel l;
        l.text = label.value("text", "");
        l.centerGridMm = vec3FromJson(requireMember(label, "center_mm", what), what + ".label.center_mm");
        l.normalGrid = vec3FromJson(requireMember(label, "normal", what), what + ".label.normal");
        l.upGrid = vec3FromJson(requireMember(label, "up", what), what + ".label.up");
        const json& size = requireMember(label, "size_mm", what);
        if (!size.is_array() || size.size() != 2) fail(what + ".label.size_mm must be [width, height]");
        l.widthMm = numberFromJson(size[0], what + ".label.size_mm");
        l.heightMm = numberFromJson(size[1], what + ".label.size_mm");
        piece.label = l;
    }
    if (j.contains("label_note") && j["label_note"].is_string())
        piece.labelNote = j["label_note"].get<std::string>();
    for (const json& pin : j.value("pins", json::array())) {
        const std::string w = what + ".pins";
        AlignmentPin a;
        a.partner = indexFromJson(requireMember(pin, "partner", w), w + ".partner");
        const std::string kind =
            requireMember(pin, "kind", w).is_string() ? pin["kind"].get<std::string>() : "";
        if (kind != "pin" && kind != "socket") fail(w + ".kind must be \"pin\" or \"socket\"");
        a.isSocket = kind == "socket";
        a.centerGridMm = vec3FromJson(requireMember(pin, "center_mm", w), w + ".center_mm");
        a.axisGrid = vec3FromJson(requireMember(pin, "axis", w), w + ".axis");
        a.radiusMm = numberFromJson(requireMember(pin, "radius_mm", w), w + ".radius_mm");
        a.lengthMm = numberFromJson(requireMember(pin, "length_mm", w), w + ".length_mm");
        piece.pins.push_back(a);
    }
    const json& direction = j.value("direction", json());
    if (direction.is_object()) {
        piece.hole = intFromJson(requireMember(direction, "hole", what), what + ".direction.hole");
        if (piece.hole < 0 || piece.hole >= zome::kHoleCount) fail(what + ".direction.hole must be in 0..61");
    }
    const json& file = requireMember(j, "file", what);
    if (!file.is_string() || file.get<std::string>().find('/') != std::string::npos)
        fail(what + ".file must be a file name next to pieces.json");
    if (!directory.empty()) piece.mesh = readMesh((fs::path(directory) / file.get<std::string>()).string());
    return piece;
}

std::pair<uint32_t, uint32_t> indexPair(const json& j, size_t pieceCount, const std::string& what) {
    if (!j.is_array() || j.size() != 2) fail(what + " must be a pair of piece indices");
    const uint32_t a = indexFromJson(j[0], what), b = indexFromJson(j[1], what);
    if (a >= pieceCount || b >= pieceCount) fail(what + " names a piece that does not exist");
    return {a, b};
}

/// The installation plan of pieces.json ("installation"): its steps, order, glued pairs and
/// problems; every piece's direction and group from the steps.
mount::InstallationPlan planFromJson(const json& j, const std::vector<Piece>& pieces) {
    mount::InstallationPlan plan;
    const size_t n = pieces.size();
    plan.holeOfPiece.assign(n, -1);
    plan.groupOf.resize(n);
    for (uint32_t p = 0; p < n; ++p) plan.groupOf[p] = p, plan.holeOfPiece[p] = pieces[p].hole;
    const json& steps = requireMember(j, "steps", "installation");
    if (!steps.is_array()) fail("installation.steps must be a list");
    std::vector<uint8_t> isPlaced(n, 0);
    for (size_t s = 0; s < steps.size(); ++s) {
        const std::string what = "installation.steps[" + std::to_string(s) + "]";
        mount::MountStep step;
        step.pieces = indicesFromJson(requireMember(steps[s], "pieces", what), what + ".pieces");
        step.hole = intFromJson(requireMember(steps[s], "hole", what), what + ".hole");
        if (step.pieces.empty()) fail(what + ".pieces must not be empty");
        if (step.hole < -1 || step.hole >= zome::kHoleCount) fail(what + ".hole must be in -1..61");
        if (const auto slide = steps[s].find("slide"); slide != steps[s].end()) {
            const std::string where = what + ".slide";
            if (!slide->is_object()) fail(where + " must be an object");
            step.slide = vec3FromJson(requireMember(*slide, "frame", where), where + ".frame");
            step.liftMm = numberFromJson(requireMember(*slide, "lift_mm", where), where + ".lift_mm");
            // A lift of more than a tunnel across is no stave's: such a file was not written by zomefab.
            if (!(step.liftMm > 0.0 && step.liftMm <= 100.0)) fail(where + ".lift_mm must be in (0, 100] mm");
            if (std::abs(norm(step.slide) - 1.0) > 1e-3) fail(where + ".frame must be a unit vector");
            if (step.hole < 0) fail(what + " slides but has no direction to be pushed on along");
        }
        for (uint32_t p : step.pieces) {
            if (p >= n) fail(what + " names piece " + std::to_string(p) + ", which does not exist");
            if (isPlaced[p]) fail(what + " mounts piece " + std::to_string(p) + " a second time");
            isPlaced[p] = 1;
            plan.groupOf[p] = *std::min_element(step.pieces.begin(), step.pieces.end());
        }
        plan.steps.push_back(step);
    }
    for (const json& pair : j.value("before", json::array()))
        plan.before.push_back(indexPair(pair, n, "installation.before"));
    for (const json& pair : j.value("glued", json::array()))
        plan.glued.push_back(indexPair(pair, n, "installation.glued"));
    for (const json& pair : j.value("glued_on", json::array()))
        plan.gluedOn.push_back(indexPair(pair, n, "installation.glued_on"));
    for (const json& problem : j.value("problems", json::array()))
        plan.problems.push_back(problem.is_string() ? problem.get<std::string>() : problem.dump());
    return plan;
}

}  // namespace

Pieces piecesFromJson(const json& j, const std::string& directory) {
    if (!j.is_object() || j.value("format", "") != kPiecesFormatName)
        fail(std::string("not a pieces file (format is not \"") + kPiecesFormatName + "\")");
    if (!j.contains("version") || !j["version"].is_number_integer() ||
        j["version"].get<int>() != kPiecesFormatVersion)
        fail("unsupported pieces file version (expected " + std::to_string(kPiecesFormatVersion) + ")");
    Pieces out;
    out.printerMm = optionalField(j, "printer_mm", out.printerMm,
                                  [](const json& v) { return vec3FromJson(v, "printer_mm"); });
    out.bedMarginMm = optionalField(j, "bed_margin_mm", out.bedMarginMm,
                                    [](const json& v) { return numberFromJson(v, "bed_margin_mm"); });
    if (!(out.bedMarginMm >= 0.0 && out.bedMarginMm <= 100.0)) fail("bed_margin_mm out of range [0, 100]");
    out.voxelMm =
        optionalField(j, "voxel_mm", 0.0, [](const json& v) { return numberFromJson(v, "voxel_mm"); });
    auto transform = [](const char* key) {
        return [key](const json& v) { return transformFromJson(v, key); };
    };
    out.gridTransformMm =
        optionalField(j, "grid_transform_mm", Transform4d::identity(), transform("grid_transform_mm"));
    out.frameToGridMm =
        optionalField(j, "frame_to_grid_mm", Transform4d::identity(), transform("frame_to_grid_mm"));
    if (j.contains("options")) readOptions(j["options"], out.options);
    const json& pieces = requireMember(j, "pieces", "pieces file");
    if (!pieces.is_array()) fail("pieces must be a list");
    for (size_t i = 0; i < pieces.size(); ++i) {
        out.pieces.push_back(pieceFromJson(pieces[i], i, directory));
        if (out.pieces.back().id != i)
            fail("pieces[" + std::to_string(i) + "].piece must be " + std::to_string(i));
    }
    if (j.contains("installation")) out.plan = planFromJson(j["installation"], out.pieces);
    const json& summary = j.value("summary", json::object());
    out.shellVolumeMm3 = summary.value("shell_volume_mm3", 0.0);
    out.outsideCellsVolumeMm3 = summary.value("outside_cells_volume_mm3", 0.0);
    out.sliversMerged = countFromJson(summary, "slivers_merged", 0);
    out.isolatedSlivers = countFromJson(summary, "isolated_slivers", 0);
    out.recutPieces = countFromJson(summary, "recut_pieces", 0);
    out.mergedPieces = countFromJson(summary, "merged_pieces", 0);
    out.recutPairs = countFromJson(summary, "recut_pairs", 0);
    out.supportCuts = countFromJson(summary, "support_cuts", 0);
    out.printSplits = countFromJson(summary, "print_splits", 0);
    out.gluedForPegs = countFromJson(summary, "glued_for_pegs", 0);
    out.frameStrutsGrown = countFromJson(summary, "frame_struts_grown", 0);
    return out;
}

Pieces parsePieces(std::string_view bytes, const std::string& sourceName, const std::string& directory) {
    const json j = json::parse(bytes, nullptr, false);
    if (j.is_discarded()) throw Error(ErrorCode::InvalidInput, "invalid JSON", sourceName);
    try {
        return piecesFromJson(j, directory);
    } catch (const Error& e) {
        throw e.withFile(sourceName);
    } catch (const json::exception& e) {
        throw Error(ErrorCode::InvalidInput, std::string("malformed pieces file: ") + e.what(), sourceName);
    }
}

Pieces readPieces(const std::string& path) {
    std::error_code ec;
    const std::string file = fs::is_directory(path, ec) ? (fs::path(path) / kPiecesFile).string() : path;
    const std::string directory = fs::path(file).parent_path().string();
    return parsePieces(readInputBytes(file), file, directory.empty() ? "." : directory);
}

}  // namespace zomefab::pieces
