// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-pieces: SHELL.vdb FRAME.json PARTITION.json -> DIR/ with piece-NN.stl, plates/plate-NN.3mf and
/// pieces.json (paper §6, docs/pieces.md). Parse, read, call makePieces, write.
#include <filesystem>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/io/file_io.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/sdf/vdb_file.h"

using namespace zomefab;
using nlohmann::json;
namespace fs = std::filesystem;

namespace {

/// The shell grid: --grid, else the one named "shell", else the first; it must be a shell (a wall
/// thickness in its metadata): cutting the solid object would print it solid.
const sdf::LevelSet& shellGrid(const std::vector<sdf::LevelSet>& grids, std::string name,
                               const std::string& path) {
    if (name.empty())
        for (const sdf::LevelSet& g : grids)
            if (g.info().name == "shell") name = "shell";
    const sdf::LevelSet& grid = sdf::findLevelSet(grids, name, path);
    if (!(grid.info().shellMm > 0))
        throw Error(
            ErrorCode::InvalidInput,
            "grid \"" + grid.info().name + "\" is not a shell (no wall thickness): give zf-shell's output",
            path);
    return grid;
}

/// Cuts, with errors attributed: input mismatches are between the files, a piece that fits
/// nowhere is the partition's.
pieces::Pieces cut(const sdf::LevelSet& shell, const zome::Structure& frame, const Transform4d& frameToGrid,
                   const partition::PartitionResult& partition, const Fabrication& fabrication,
                   const pieces::PiecesOptions& options, RunContext& context, const std::string (&paths)[3]) {
    try {
        return pieces::makePieces(shell, frame, frameToGrid, partition, fabrication, options, context);
    } catch (const Error& e) {
        if (e.code() == ErrorCode::InvalidInput && e.message().find("frame") != std::string::npos)
            throw Error(e.code(), paths[0] + " and " + paths[1] + ": " + e.message(), paths[1]);
        if (e.code() == ErrorCode::InvalidInput || e.code() == ErrorCode::ProcessingFailed)
            throw e.withFile(paths[2]);
        throw;
    }
}

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool(
        "zf-pieces",
        "Cut the shell into printable pieces along the partition's cells, plan how each goes onto the frame "
        "(one Zome direction per piece, an order), grow its tenons into the frame's holes along that "
        "direction, "
        "engrave piece numbers, orient each piece for the printer (paper §6, docs/mounting.md).");
    std::string shellPath, framePath, partitionPath, output, gridName;
    cli::FabricationCli fabricationCli;
    cli::PiecesCli piecesCli;
    auto& app = tool.app();
    app.add_option("shell", shellPath, "SHELL.vdb from zf-shell (- reads stdin)")->required();
    app.add_option("frame", framePath, "FRAME.json from zf-frame")->required();
    app.add_option("partition", partitionPath, "PARTITION.json from zf-partition")->required();
    app.add_option("-o,--output", output, "Output directory (piece-NN.stl, plates/plate-NN.3mf, pieces.json)")
        ->required();
    app.add_option("--grid", gridName, "Level set to cut (default: \"shell\" if present, else the first)");
    fabricationCli.addTo(app, cli::kPrinter);
    piecesCli.addTo(app);

    return tool.run(argc, argv, [&](json& report) {
        Fabrication fabrication = fabricationCli.resolve(tool.common().seed);
        pieces::PiecesOptions options = piecesCli.resolve();  // bad options fail before any input is read
        // No object grid here to keep new struts clear of the surface in: the frame is frame.json's.
        options.isGrowingFrame = false;
        RunContext& context = tool.context();
        const std::vector<sdf::LevelSet> grids = sdf::parseVdb(readInputBytes(shellPath), shellPath, context);
        const sdf::LevelSet& shell = shellGrid(grids, gridName, shellPath);
        Transform4d frameTransform;
        const zome::Structure frame = cli::readFrame(framePath, &frameTransform);
        const partition::PartitionFile partition = cli::readPartition(partitionPath);
        if (!isNearlyEqual(partition.info.transformMm, frameTransform))
            throw Error(ErrorCode::InvalidInput,
                        "was made with another frame: its transform_mm differs from " + framePath + "'s",
                        partitionPath);
        if (fabricationCli.printer.empty())
            fabrication.printerMm = partition.result.printerMm;  // the partition's printer
        fabrication.wallMm = shell.info().shellMm;               // the wall the shell was hollowed with
        const Transform4d frameToGrid = [&] {
            try {
                return shell.info().transformMm * affineInverse(frameTransform);
            } catch (const Error& e) {
                throw e.withFile(framePath);
            }
        }();
        const pieces::Pieces result = cut(shell, frame, frameToGrid, partition.result, fabrication, options,
                                          context, {shellPath, framePath, partitionPath});
        pieces::requireBuildable(result);  // never write pieces that cannot be put on the frame
        pieces::writePieces(result, output,
                            {shell.info().sourceFile, fs::path(framePath).filename().string(),
                             fs::path(partitionPath).filename().string()});
        report = pieces::piecesToJson(result, {})["summary"];
        report["output"] = output;
        report["peak_rss_bytes"] = peakRssBytes();
        cli::printInfo(tool, std::to_string(result.pieces.size()) + " pieces, " + report["tenons"].dump() +
                                 " tenons (" + report["pieces_with_few_tenons"].dump() +
                                 " pieces with fewer than " + std::to_string(options.tenons.minPerPiece) +
                                 "), " + report["labelled"].dump() + " numbered" +
                                 formatNumbers("; %.1f s", result.seconds));
        return 0;
    });
}
