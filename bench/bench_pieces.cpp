// SPDX-License-Identifier: GPL-3.0-or-later
// Benchmark of the pieces stage (paper §6), from the shell and the partition to all piece files:
//   bench_pieces SHELL.vdb FRAME.json PARTITION.json [--threads N] [--out DIR]
// Prints the time of each phase, the peak RSS and the size of the files; docs/benchmarks.md
// ("Pieces") records the numbers with the commands that make the inputs.
#include <tbb/global_control.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/run_context.h"
#include "zomefab/io/file_io.h"
#include "zomefab/partition/partition_json.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/sdf/vdb_file.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
namespace fs = std::filesystem;

namespace {

uintmax_t directoryBytes(const std::string& dir, const std::string& extension) {
    uintmax_t total = 0;
    for (const auto& e : fs::directory_iterator(dir))
        if (e.path().extension() == extension) total += e.file_size();
    return total;
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 4) {
        std::fprintf(stderr,
                     "usage: bench_pieces SHELL.vdb FRAME.json PARTITION.json [--threads N] [--out DIR]\n");
        return 1;
    }
    const std::string shellPath = argv[1], framePath = argv[2], partitionPath = argv[3];
    int threads = 0;
    std::string outDir;
    for (int i = 4; i + 1 < argc; i += 2) {
        const std::string flag = argv[i];
        if (flag == "--threads")
            threads = std::atoi(argv[i + 1]);
        else if (flag == "--out")
            outDir = argv[i + 1];
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      size_t(threads));
    try {
        RunContext& context = RunContext::silent();
        Stopwatch clock;
        const auto grids = sdf::parseVdb(readInputBytes(shellPath), shellPath, context);
        const sdf::LevelSet& shell = sdf::findLevelSet(grids, "shell", shellPath);
        Transform4d frameTransform;
        const zome::Structure frame =
            zome::structureFromJsonText(readInputBytes(framePath), {}, {}, &frameTransform);
        const partition::PartitionFile partition =
            partition::partitionFromJson(nlohmann::json::parse(readInputBytes(partitionPath)));
        pieces::PiecesOptions options;
        Fabrication fabrication;
        fabrication.printerMm = partition.result.printerMm;
        if (!isNearlyEqual(partition.info.transformMm, frameTransform))
            std::fprintf(stderr,
                         "bench_pieces: warning: the partition's transform_mm differs from the frame's\n");
        const double readSeconds = clock.seconds();

        const Transform4d frameToGrid = shell.info().transformMm * affineInverse(frameTransform);
        const pieces::Pieces result =
            pieces::makePieces(shell, frame, frameToGrid, partition.result, fabrication, options, context);
        const double piecesSeconds = clock.seconds() - readSeconds;

        const bool isTemporary = outDir.empty();
        if (isTemporary)
            outDir = (fs::temp_directory_path() / ("bench_pieces." + std::to_string(::getpid()))).string();
        pieces::writePieces(result, outDir, {shellPath, framePath, partitionPath});
        const double writeSeconds = clock.seconds() - readSeconds - piecesSeconds;
        const uintmax_t stlBytes = directoryBytes(outDir, ".stl"),
                        threeMfBytes = directoryBytes(outDir, ".3mf");
        if (isTemporary) fs::remove_all(outDir);

        size_t tenons = 0, triangles = 0, few = 0, labelled = 0;
        for (const pieces::Piece& p : result.pieces) {
            tenons += p.tenons.size();
            triangles += p.mesh.triangles.size();
            few += p.tenons.size() < size_t(options.tenons.minPerPiece) ? 1 : 0;
            labelled += p.label ? 1 : 0;
        }
        std::printf(
            "pieces %zu (slivers merged %zu), tenons %zu (pieces with fewer than %d: %zu), numbered %zu\n",
            result.pieces.size(), result.sliversMerged, tenons, options.tenons.minPerPiece, few, labelled);
        std::printf("triangles %zu, STL %.1f MB, 3MF %.1f MB\n", triangles, double(stlBytes) / 1e6,
                    double(threeMfBytes) / 1e6);
        std::printf("read %.2f s, pieces %.2f s, write %.2f s, total %.2f s, peak RSS %.0f MB\n", readSeconds,
                    piecesSeconds, writeSeconds, clock.seconds(), double(peakRssBytes()) / 1e6);
    } catch (const Error& e) {
        std::fprintf(stderr, "bench_pieces: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "bench_pieces: %s\n", e.what());
        return 1;
    }
    return 0;
}
