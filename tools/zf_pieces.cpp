// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-pieces: SHELL.vdb FRAME.json PARTITION.json -> DIR/ with piece-NN.stl, pieces.3mf and
/// pieces.json (paper §6, docs/pieces.md). Parse, read, call makePieces, write.
#include <cmath>
#include <cstdio>
#include <optional>
#include <sstream>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/transform.h"
#include "zomefab/io/file_io.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/sdf/vdb_file.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
using nlohmann::json;

namespace {

Vec3d vec3(const json& j, const std::string& what) {
    if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() || !j[2].is_number())
        throw Error(ErrorCode::InvalidInput, what + ": expected three numbers");
    return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

Transform4d matrix(const json& j, const std::string& what) {
    Transform4d t;
    if (!j.is_array() || j.size() != 4) throw Error(ErrorCode::InvalidInput, what + ": expected a 4×4 matrix");
    for (int r = 0; r < 4; ++r) {
        if (!j[size_t(r)].is_array() || j[size_t(r)].size() != 4)
            throw Error(ErrorCode::InvalidInput, what + ": expected a 4×4 matrix");
        for (int c = 0; c < 4; ++c) {
            if (!j[size_t(r)][size_t(c)].is_number()) throw Error(ErrorCode::InvalidInput, what + ": not a number");
            t.m[size_t(r * 4 + c)] = j[size_t(r)][size_t(c)].get<double>();
        }
    }
    return t;
}

/// What zf-pieces needs of a `zomefab.partition` file (docs/partition.md): the cells (w, b in the
/// frame's mm), the pieces (their cells and surface boxes), the frame's transform_mm, the printer.
struct PartitionInput {
    pieces::CellModel cells;
    std::vector<pieces::PieceRequest> requests;
    Transform4d transformMm;
    std::optional<Vec3d> printerMm;
};

/// @throw Error(InvalidInput) naming @p path and what is wrong.
PartitionInput readPartition(const std::string& path) {
    const json j = json::parse(readInputBytes(path), nullptr, false);
    try {
        if (j.is_discarded() || !j.is_object()) throw Error(ErrorCode::InvalidInput, "invalid JSON");
        if (j.value("format", "") != "zomefab.partition")
            throw Error(ErrorCode::InvalidInput, "not a partition file (format is not \"zomefab.partition\")");
        if (!j.contains("version") || !j["version"].is_number_integer() || j["version"].get<int>() != 1)
            throw Error(ErrorCode::InvalidInput, "unsupported partition file version (expected 1)");
        PartitionInput in;
        if (j.contains("transform_mm")) in.transformMm = matrix(j["transform_mm"], "transform_mm");
        if (j.contains("printer_mm")) in.printerMm = vec3(j["printer_mm"], "printer_mm");
        if (!j.contains("cells") || !j["cells"].is_array() || j["cells"].empty())
            throw Error(ErrorCode::InvalidInput, "no cells");
        for (size_t k = 0; k < j["cells"].size(); ++k) {
            const json& c = j["cells"][k];
            const std::string name = "cell " + std::to_string(k);
            if (!c.is_object() || !c.contains("w") || !c.contains("b") || !c["b"].is_number())
                throw Error(ErrorCode::InvalidInput, name + ": needs \"w\" and \"b\"");
            if (c.contains("cell") && (!c["cell"].is_number_unsigned() || c["cell"].get<size_t>() != k))
                throw Error(ErrorCode::InvalidInput, name + ": cells must be listed in order");
            in.cells.w.push_back(vec3(c["w"], name + " w"));
            in.cells.b.push_back(c["b"].get<double>());
        }
        if (!j.contains("pieces") || !j["pieces"].is_array())
            throw Error(ErrorCode::InvalidInput, "no pieces");
        for (size_t p = 0; p < j["pieces"].size(); ++p) {
            const json& piece = j["pieces"][p];
            const std::string name = "piece " + std::to_string(p);
            if (!piece.is_object() || !piece.contains("cells") || !piece["cells"].is_array())
                throw Error(ErrorCode::InvalidInput, name + ": needs \"cells\"");
            pieces::PieceRequest r;
            for (const json& c : piece["cells"]) {
                if (!c.is_number_unsigned() || c.get<size_t>() >= in.cells.cellCount())
                    throw Error(ErrorCode::InvalidInput, name + ": cell " + c.dump() + " does not exist");
                r.cells.push_back(c.get<uint32_t>());
            }
            if (piece.contains("bbox_mm")) {
                const json& b = piece["bbox_mm"];
                if (!b.is_object() || !b.contains("min") || !b.contains("max"))
                    throw Error(ErrorCode::InvalidInput, name + ": bbox_mm needs min and max");
                r.boundsMm.expand(vec3(b["min"], name + " bbox_mm.min"));
                r.boundsMm.expand(vec3(b["max"], name + " bbox_mm.max"));
            }
            in.requests.push_back(std::move(r));
        }
        return in;
    } catch (const Error& e) {
        throw e.withFile(path);
    } catch (const json::exception& e) {
        throw Error(ErrorCode::InvalidInput, std::string("malformed partition file: ") + e.what(), path);
    }
}

bool isNear(const Transform4d& a, const Transform4d& b) {
    double scale = 0;
    for (double v : a.m) scale = std::max(scale, std::abs(v));
    for (size_t i = 0; i < 16; ++i)
        if (std::abs(a.m[i] - b.m[i]) > 1e-6 * std::max(1.0, scale)) return false;
    return true;
}

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zf-pieces",
                   "Cut the shell into printable pieces along the partition's cells, grow tenons into the frame's "
                   "free blue holes, engrave piece numbers, orient each piece for the printer (paper §6).");
    std::string shellPath, framePath, partitionPath, output, gridName, printer;
    pieces::PiecesOptions opt;
    bool isUnlabelled = false;
    auto& app = tool.app();
    app.add_option("shell", shellPath, "SHELL.vdb from zf-shell (- reads stdin)")->required();
    app.add_option("frame", framePath, "FRAME.json from zf-frame")->required();
    app.add_option("partition", partitionPath, "PARTITION.json from zf-partition")->required();
    app.add_option("-o,--output", output, "Output directory (piece-NN.stl, pieces.3mf, pieces.json)")->required();
    app.add_option("--grid", gridName, "Level set to cut (default: \"shell\" if present, else the first)");
    app.add_option("--printer-mm", printer, "Printer build volume WxDxH in mm (default: the partition's)");
    app.add_option("--min-piece-volume-mm3", opt.minPieceVolumeMm3, "Merge smaller pieces into a neighbour")
        ->capture_default_str();
    app.add_option("--adaptivity", opt.adaptivity, "Meshing: 0 = uniform triangles; up to 1 merges flat regions")
        ->capture_default_str();
    app.add_option("--min-tenons", opt.tenons.minPerPiece, "Tenons wanted per piece (fewer are reported)")
        ->capture_default_str();
    app.add_option("--max-tenons", opt.tenons.maxPerPiece, "Most tenons per piece (0 = none)")->capture_default_str();
    app.add_option("--tenon-clearance-mm", opt.tenons.clearanceMm, "Gap between peg and hole on every side")
        ->capture_default_str();
    app.add_option("--tenon-width-mm", opt.tenons.bodyWidthMm, "Side of the square prism")->capture_default_str();
    app.add_option("--peg-depth-mm", opt.tenons.pegDepthMm, "How far the peg enters the blue hole")
        ->capture_default_str();
    app.add_option("--tenon-max-length-mm", opt.tenons.maxLengthMm, "Longest prism, ball face to inner surface")
        ->capture_default_str();
    app.add_option("--tenon-max-tilt-deg", opt.tenons.maxTiltDeg, "Largest angle between hole axis and surface normal")
        ->capture_default_str();
    app.add_flag("--tenon-lattice-holes-only", opt.tenons.latticeHolesOnly,
                 "Tenons only along the lattice axes (+-x +-y +-z), as the paper; default: all 30 blue holes");
    app.add_flag("--no-label", isUnlabelled, "Do not engrave piece numbers");
    app.add_option("--label-height-mm", opt.label.heightMm, "Height of the engraved digits")->capture_default_str();
    app.add_option("--label-depth-mm", opt.label.depthMm, "Engraving depth")->capture_default_str();

    return tool.run(argc, argv, [&](json& report) {
        if (!printer.empty()) opt.printerMm = cli::parsePrinterMm(printer);
        opt.label.isEnabled = !isUnlabelled;
        pieces::checkPiecesOptions(opt);  // bad options fail before any input is read
        RunContext& context = tool.context();
        Stopwatch clock;

        const std::vector<sdf::LevelSet> grids = sdf::parseVdb(readInputBytes(shellPath), shellPath, context);
        std::string name = gridName;
        if (name.empty())
            for (const sdf::LevelSet& g : grids)
                if (g.info().name == "shell") name = "shell";
        const sdf::LevelSet& shell = sdf::findLevelSet(grids, name, shellPath);
        Transform4d frameTransform;
        const zome::Structure frame = [&] {
            try {
                return zome::structureFromJsonText(readInputBytes(framePath), {}, {}, &frameTransform);
            } catch (const Error& e) {
                throw e.withFile(framePath);
            }
        }();
        const PartitionInput partition = readPartition(partitionPath);
        if (!isNear(partition.transformMm, frameTransform))
            throw Error(ErrorCode::InvalidInput, "was made with another frame: its transform_mm differs from " + framePath + "'s",
                        partitionPath);
        if (printer.empty() && partition.printerMm) {
            opt.printerMm = *partition.printerMm;
            pieces::checkPiecesOptions(opt);
        }
        const double readSeconds = clock.seconds();

        Transform4d frameToGrid;
        try {
            frameToGrid = shell.info().transformMm * affineInverse(frameTransform);
        } catch (const Error& e) {
            throw e.withFile(framePath);
        }
        pieces::Pieces result;
        try {
            result = pieces::makePieces(shell, frame, frameToGrid, partition.cells, partition.requests, opt, context);
        } catch (const Error& e) {
            // Input mismatches are between the files; a piece that fits nowhere is the partition's.
            if (e.code() == ErrorCode::InvalidInput && e.message().find("frame") != std::string::npos)
                throw Error(e.code(), shellPath + " and " + framePath + ": " + e.message(), framePath);
            if (e.code() == ErrorCode::InvalidInput || e.code() == ErrorCode::ProcessingFailed)
                throw e.withFile(partitionPath);
            throw;
        }
        const double piecesSeconds = clock.seconds() - readSeconds;
        pieces::writePieces(result, output, {shellPath, framePath, partitionPath});

        size_t tenons = 0, few = 0, labelled = 0, triangles = 0;
        double volume = 0;
        for (const pieces::Piece& p : result.pieces) {
            tenons += p.tenons.size();
            few += p.tenons.size() < size_t(opt.tenons.minPerPiece) ? 1 : 0;
            labelled += p.label ? 1 : 0;
            triangles += p.mesh.triangles.size();
            volume += p.volumeMm3;
        }
        report["output"] = output;
        report["pieces"] = result.pieces.size();
        report["tenons"] = tenons;
        report["pieces_with_few_tenons"] = few;
        report["labelled"] = labelled;
        report["triangles"] = triangles;
        report["volume_mm3"] = volume;
        report["shell_volume_mm3"] = result.shellVolumeMm3;
        report["slivers_merged"] = result.sliversMerged;
        report["seconds"] = {{"read", readSeconds}, {"pieces", piecesSeconds}, {"total", clock.seconds()}};
        report["peak_rss_bytes"] = peakRssBytes();
        char line[240];
        std::snprintf(line, sizeof(line), "%zu pieces, %zu tenons (%zu pieces with fewer than %d), %zu numbered, %zu triangles; %.1f s",
                      result.pieces.size(), tenons, few, opt.tenons.minPerPiece, labelled, triangles, clock.seconds());
        cli::printInfo(tool, line);
        return 0;
    });
}
