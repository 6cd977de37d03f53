// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Mesh readers (STL ASCII/binary, OBJ, PLY ASCII/binary LE/BE, glTF/GLB) and writers
/// (binary STL, OBJ, PLY). Format from the extension, or given explicitly for "-" (stdin/stdout).
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "zomefab/core/tri_mesh.h"

namespace zomefab {

enum class MeshFormat { Stl, Obj, Ply, Gltf, Glb };

/// "stl", "obj", "ply", "gltf", "glb" (case-insensitive).
/// @throw Error(InvalidInput) for anything else, naming @p sourceName.
MeshFormat meshFormatFromName(const std::string& name, const std::string& sourceName = {});
/// The format of @p path from its extension. @throw Error(InvalidInput) for unknown extensions.
MeshFormat meshFormatFromPath(const std::string& path);
const char* meshFormatName(MeshFormat format);

struct MeshReadOptions {
    std::optional<MeshFormat> format;  ///< required when reading "-"; otherwise from the extension
    bool weldStlVertices = true;       ///< merge bit-identical STL corners into shared vertices
};

/// Reads a triangle mesh. Polygons are fan-triangulated; glTF node transforms are applied.
/// @throw Error(InvalidInput) with the file name for unreadable, malformed or empty input.
TriMesh readMesh(const std::string& path, const MeshReadOptions& options = {});

/// Parses @p bytes as @p format; @p sourceName only labels error messages. Used by readMesh and
/// the fuzz targets. @throw Error(InvalidInput).
TriMesh parseMesh(std::string_view bytes, MeshFormat format, const std::string& sourceName,
                  bool weldStlVertices = true);

struct MeshWriteOptions {
    std::optional<MeshFormat> format;  ///< required when writing "-"; Stl, Obj or Ply
};

/// Writes binary STL (with real facet normals), OBJ or binary little-endian PLY, atomically.
/// @throw Error(WriteFailed) naming the file, Error(Usage) for glTF (not a writer format here).
void writeMesh(const TriMesh& mesh, const std::string& path, const MeshWriteOptions& options = {});
/// The bytes writeMesh would write.
std::string serializeMesh(const TriMesh& mesh, MeshFormat format);

}  // namespace zomefab
