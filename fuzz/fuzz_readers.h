// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The readers of the files the stages hand each other, as the fuzz targets and their
/// regression test call them: frame.json, partition.json, pieces.json, batch manifests and .vdb
/// level sets, each given bytes the way the tools give them what they read from disk. A
/// zomefab::Error is the expected answer to bad input; anything else (a crash, a sanitizer report,
/// another exception, a broken promise of the result) is a bug.
#pragma once

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <stdexcept>
#include <string>
#include <string_view>

#include "zomefab/batch/batch.h"
#include "zomefab/core/error.h"
#include "zomefab/core/run_context.h"
#include "zomefab/partition/partition_json.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/sdf/vdb_file.h"
#include "zomefab/zome/structure_json.h"

namespace zomefab::fuzz {

/// The document readers, by fuzz target name (fuzz_<name>, fuzz/corpus/<name>).
inline constexpr const char* kDocumentReaders[] = {"frame", "partition", "pieces", "manifest", "vdb"};

/// A promise of a reader that did not hold: abort, so the fuzzer records the input.
inline void require(bool condition, const char* what) {
    if (!condition) {
        std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
        std::abort();
    }
}

/// Reads @p bytes with reader @p name and checks what it promises of a result.
/// @throw Error for bad input (the expected answer); std::invalid_argument for an unknown name.
inline void readDocument(std::string_view name, std::string_view bytes) {
    if (name == "frame") {
        const zome::Structure frame = zome::structureFromJsonText(std::string(bytes));
        for (zome::StrutId id : frame.strutIds()) {
            const zome::Strut& s = frame.strut(id);
            require(frame.hasBall(s.a) && frame.hasBall(s.b), "a strut names a missing ball");
        }
    } else if (name == "partition") {
        const partition::PartitionFile file = partition::parsePartitionFile(bytes, "fuzz-input");
        for (const auto& piece : file.result.pieces)
            for (uint32_t cell : piece.cells)
                require(cell < file.result.cells.cellCount(), "piece cell out of range");
    } else if (name == "pieces") {
        const pieces::Pieces all = pieces::parsePieces(bytes, "fuzz-input", /*directory=*/"");
        for (const auto& step : all.plan.steps)
            for (uint32_t p : step.pieces) require(p < all.pieces.size(), "a step names a missing piece");
    } else if (name == "manifest") {
        const auto entries = batch::parseManifest(bytes, "/nonexistent/fuzz-input.json");
        require(!entries.empty(), "a manifest without entries was accepted");
    } else if (name == "vdb") {
        const auto grids = sdf::parseVdb(bytes, "fuzz-input", RunContext::silent());
        require(!grids.empty(), "no level set returned");
        for (const sdf::LevelSet& g : grids) {
            require(g.info().voxelMm > 0 && std::isfinite(g.info().voxelMm), "voxel size");
            require(std::isfinite(g.valueMm({0, 0, 0})), "non-finite distance");
        }
    } else {
        throw std::invalid_argument("no fuzz reader named " + std::string(name));
    }
}

}  // namespace zomefab::fuzz
