// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The output files of the pieces stage: piece-NN.stl, plates/plate-NN.3mf and pieces.json
/// (format `zomefab.pieces`, docs/pieces.md), written into a staging directory that is renamed
/// into place only when everything was written.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>

#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces {

inline constexpr const char* kPiecesFormatName = "zomefab.pieces";
inline constexpr int kPiecesFormatVersion = 1;
/// The file that names every piece of a directory, and marks it as a pieces output.
inline constexpr const char* kPiecesFile = "pieces.json";

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

/// Writes every piece-NN.stl (binary, real normals) and pieces.json into the existing
/// @p directory (a staging directory: nothing is replaced atomically as a whole).
/// @throw Error(WriteFailed) naming the file.
void writePieceFiles(const Pieces& pieces, const std::string& directory, const PiecesJsonInfo& info);

/// zf-pieces' output: writePieceFiles and the plates (plates/plate-NN.3mf, plates.h) into @p directory,
/// through a temporary sibling that replaces @p directory only when all were written; an existing @p
/// directory is replaced only when it is empty or an earlier output (it holds a pieces.json).
/// @throw Error(WriteFailed) naming the directory or file.
void writePieces(const Pieces& pieces, const std::string& directory, const PiecesJsonInfo& info);

/// pieces.json read back (the inverse of piecesToJson): every piece with its tenons, label,
/// orientation and neighbours, the options it was made with, and its mesh read from the STL
/// next to it (in @p directory, or not at all when @p directory is empty). Piece meshes are in
/// printer coordinates, as written. Pieces::options.tenons holds the peg dimensions of the file.
/// @throw Error(InvalidInput) naming the field (callers add the file) for a document that is not
/// `zomefab.pieces` version 1, a missing or malformed field, or a piece file that cannot be read.
Pieces piecesFromJson(const nlohmann::json& document, const std::string& directory);

/// piecesFromJson of the JSON text @p bytes. @throw Error(InvalidInput) naming @p sourceName for
/// invalid JSON or a malformed document.
Pieces parsePieces(std::string_view bytes, const std::string& sourceName, const std::string& directory);

/// Reads @p path (a pieces.json, or a directory holding one) with piecesFromJson, the meshes from
/// its directory. @throw Error(InvalidInput) naming the file.
Pieces readPieces(const std::string& path);

}  // namespace zomefab::pieces
