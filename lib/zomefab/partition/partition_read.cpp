// SPDX-License-Identifier: GPL-3.0-or-later
// PARTITION.json read back (the inverse of partitionToJson), for zf-pieces and the checks.
#include "zomefab/core/error.h"
#include "zomefab/core/json_values.h"
#include "zomefab/partition/partition_json.h"

namespace zomefab::partition {

using nlohmann::json;

namespace {

[[noreturn]] void fail(const std::string& what) { throw Error(ErrorCode::InvalidInput, what); }

uint32_t indexFromJson(const json& j, const std::string& what) {
    if (!j.is_number_unsigned() || j.get<uint64_t>() > 0xFFFFFFFEull) fail(what + " must be an index");
    return j.get<uint32_t>();
}

std::vector<uint32_t> indicesFromJson(const json& j, const std::string& what) {
    if (!j.is_array()) fail(what + " must be a list of indices");
    std::vector<uint32_t> out;
    out.reserve(j.size());
    for (const json& v : j) out.push_back(indexFromJson(v, what));
    return out;
}

void readCells(const json& cells, PartitionResult& r) {
    if (!cells.is_array() || cells.empty()) fail("no cells");
    for (size_t k = 0; k < cells.size(); ++k) {
        const json& c = cells[k];
        const std::string name = "cell " + std::to_string(k);
        if (!c.is_object() || !c.contains("w") || !c.contains("b") || !c["b"].is_number())
            fail(name + ": needs \"w\" and \"b\"");
        if (c.contains("cell") && (!c["cell"].is_number_unsigned() || c["cell"].get<size_t>() != k))
            fail(name + ": cells must be listed in order");
        r.cells.w.push_back(vec3FromJson(c["w"], name + " w"));
        r.cells.b.push_back(numberFromJson(c["b"], name + " b"));
        r.cells.classes.push_back(uint32_t(k));
        r.cellBalls.push_back(c.contains("ball") ? indexFromJson(c["ball"], name + " ball") : zome::kNoId);
    }
}

PrinterFit fitFromJson(const json& f, const std::string& what) {
    PrinterFit fit;
    fit.fits = f.value("fits", false);
    fit.ratio = numberFromJson(requireMember(f, "ratio", what), what + ".ratio");
    const json& axes = requireMember(f, "axes", what);
    if (!axes.is_array() || axes.size() != 3) fail(what + ".axes must be three vectors");
    for (size_t a = 0; a < 3; ++a) fit.axes[a] = vec3FromJson(axes[a], what + ".axes");
    fit.extentsMm = vec3FromJson(requireMember(f, "extents_mm", what), what + ".extents_mm");
    fit.centerMm = vec3FromJson(requireMember(f, "center_mm", what), what + ".center_mm");
    return fit;
}

void readPieces(const json& pieces, PartitionResult& r) {
    if (!pieces.is_array()) fail("no pieces");
    for (size_t p = 0; p < pieces.size(); ++p) {
        const json& j = pieces[p];
        const std::string name = "piece " + std::to_string(p);
        if (!j.is_object() || !j.contains("cells") || !j["cells"].is_array())
            fail(name + ": needs \"cells\"");
        Piece piece;
        for (const json& c : j["cells"]) {
            if (!c.is_number_unsigned() || c.get<size_t>() >= r.cells.cellCount())
                fail(name + ": cell " + c.dump() + " does not exist");
            piece.cells.push_back(c.get<uint32_t>());
        }
        if (j.contains("balls")) piece.balls = indicesFromJson(j["balls"], name + " balls");
        if (j.contains("faces")) piece.faceCount = indexFromJson(j["faces"], name + " faces");
        if (j.contains("area_mm2")) piece.areaMm2 = numberFromJson(j["area_mm2"], name + " area_mm2");
        if (j.contains("bbox_mm")) {
            const json& b = j["bbox_mm"];
            if (!b.is_object() || !b.contains("min") || !b.contains("max"))
                fail(name + ": bbox_mm needs min and max");
            piece.boundsMm.expand(vec3FromJson(b["min"], name + " bbox_mm.min"));
            piece.boundsMm.expand(vec3FromJson(b["max"], name + " bbox_mm.max"));
        }
        if (j.contains("fit")) piece.fit = fitFromJson(j["fit"], name + " fit");
        if (j.contains("patches")) {
            const json& list = j["patches"];
            if (!list.is_array()) fail(name + ": patches must be a list");
            for (size_t k = 0; k < list.size(); ++k) {
                const std::string what = name + " patch " + std::to_string(k);
                const json& c = list[k];
                if (!c.is_object() || !c.contains("cell") || !c.contains("bbox_mm") ||
                    !c["bbox_mm"].is_object() || !c["bbox_mm"].contains("min") ||
                    !c["bbox_mm"].contains("max"))
                    fail(what + ": needs cell and bbox_mm (min, max)");
                Piece::CellPatch patch;
                patch.cell = indexFromJson(c["cell"], what + " cell");
                if (patch.cell >= r.cells.cellCount()) fail(what + ": cell does not exist");
                patch.boundsMm.expand(vec3FromJson(c["bbox_mm"]["min"], what + " bbox_mm.min"));
                patch.boundsMm.expand(vec3FromJson(c["bbox_mm"]["max"], what + " bbox_mm.max"));
                piece.patches.push_back(patch);
            }
        }
        r.pieces.push_back(std::move(piece));
    }
}

/// The per-face arrays, when present; all of one length.
void readFaces(const json& j, PartitionResult& r) {
    const std::pair<const char*, std::vector<uint32_t>*> arrays[] = {
        {"face_nearest_labels", &r.nearestLabels},
        {"face_labels", &r.graphCutLabels},
        {"face_cells", &r.faceCells},
        {"face_pieces", &r.facePieces}};
    for (const auto& [key, target] : arrays)
        if (j.contains(key)) *target = indicesFromJson(j[key], key);
    for (uint32_t c : r.faceCells)
        if (c >= r.cells.cellCount()) fail("face_cells names a cell that does not exist");
    for (uint32_t p : r.facePieces)
        if (p >= r.pieces.size()) fail("face_pieces names a piece that does not exist");
    r.salientFaces.assign(r.faceCells.size(), 0);
    if (j.contains("salient_faces"))
        for (uint32_t f : indicesFromJson(j["salient_faces"], "salient_faces")) {
            if (f >= r.salientFaces.size()) fail("salient_faces names a face that does not exist");
            r.salientFaces[f] = 1;
        }
}

}  // namespace

PartitionFile partitionFromJson(const json& j) {
    if (!j.is_object()) fail("invalid JSON");
    if (j.value("format", "") != kPartitionFormatName)
        fail(std::string("not a partition file (format is not \"") + kPartitionFormatName + "\")");
    if (!j.contains("version") || !j["version"].is_number_integer() ||
        j["version"].get<int>() != kPartitionFormatVersion)
        fail("unsupported partition file version (expected " + std::to_string(kPartitionFormatVersion) + ")");
    PartitionFile file;
    PartitionResult& r = file.result;
    if (j.contains("transform_mm"))
        file.info.transformMm = transformFromJson(j["transform_mm"], "transform_mm");
    if (j.contains("mesh") && j["mesh"].is_object()) {
        file.info.meshFile = j["mesh"].value("file", "");
        file.info.vertexCount = countFromJson(j["mesh"], "vertices", 0);
    }
    if (j.contains("frame") && j["frame"].is_object()) {
        file.info.frameFile = j["frame"].value("file", "");
        if (j["frame"].contains("b0_mm")) r.b0Mm = numberFromJson(j["frame"]["b0_mm"], "frame.b0_mm");
    }
    if (j.contains("printer_mm")) r.printerMm = vec3FromJson(j["printer_mm"], "printer_mm");
    if (j.contains("fit_margin_mm")) r.fitMarginMm = numberFromJson(j["fit_margin_mm"], "fit_margin_mm");
    if (j.contains("labels") && j["labels"].is_array())
        for (const json& l : j["labels"])
            r.labelBalls.push_back(indexFromJson(requireMember(l, "ball", "labels"), "labels"));
    readCells(requireMember(j, "cells", "partition file"), r);
    readPieces(requireMember(j, "pieces", "partition file"), r);
    readFaces(j, r);
    return file;
}

PartitionFile parsePartitionFile(std::string_view bytes, const std::string& sourceName) {
    const json j = json::parse(bytes, nullptr, false);
    if (j.is_discarded()) throw Error(ErrorCode::InvalidInput, "invalid JSON", sourceName);
    try {
        return partitionFromJson(j);
    } catch (const Error& e) {
        throw e.withFile(sourceName);
    } catch (const json::exception& e) {
        throw Error(ErrorCode::InvalidInput, std::string("malformed partition file: ") + e.what(),
                    sourceName);
    }
}

}  // namespace zomefab::partition
