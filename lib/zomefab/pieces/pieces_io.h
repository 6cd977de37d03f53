// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The output files of the pieces stage: piece-NN.stl, pieces.3mf and pieces.json
/// (format `zomefab.pieces`, docs/pieces.md), written into a staging directory that is renamed
/// into place only when everything was written.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces {

inline constexpr const char* kPiecesFormatName = "zomefab.pieces";
inline constexpr int kPiecesFormatVersion = 1;

/// Where the inputs came from, for provenance in pieces.json.
struct PiecesJsonInfo {
    std::string shellFile;
    std::string frameFile;
    std::string partitionFile;
};

/// "piece-07": the piece's name in files, the preview and the assembly guide; two digits at least,
/// more when there are over 100 pieces.
std::string pieceName(const Pieces& pieces, size_t index);
/// "piece-07.stl".
std::string pieceFileName(const Pieces& pieces, size_t index);

/// The pieces.json document: no timings, so equal inputs give equal bytes.
nlohmann::json piecesToJson(const Pieces& pieces, const PiecesJsonInfo& info);

/// Writes every piece-NN.stl (binary, real normals), pieces.3mf (all pieces, one bed-sized cell
/// each, mm) and pieces.json into @p directory. The files go to a temporary sibling first, which
/// replaces @p directory only when all were written; an existing @p directory is replaced only
/// when it is empty or an earlier output (it holds a pieces.json).
/// @throw Error(WriteFailed) naming the directory or file.
void writePieces(const Pieces& pieces, const std::string& directory, const PiecesJsonInfo& info);

}  // namespace zomefab::pieces
