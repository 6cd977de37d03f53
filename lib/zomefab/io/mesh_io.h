// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Mesh readers (STL ASCII/binary, OBJ, PLY ASCII/binary LE/BE, glTF/GLB) and writers
/// (binary STL, OBJ, binary PLY). Format from the extension, or given explicitly for "-" (stdin/stdout).
/// Details of each format: docs/io.md.
#pragma once

#include <optional>
#include <string>
#include <string_view>

#include "zomefab/core/tri_mesh.h"

namespace zomefab {

enum class MeshFormat { Stl, Obj, Ply, Gltf, Glb };

/// "stl", "obj", "ply", "gltf", "glb" (case-insensitive).
/// @throw Error(Usage) for anything else, naming @p sourceName (an option value is a usage error).
MeshFormat meshFormatFromName(const std::string& name, const std::string& sourceName = {});
/// The format of @p path from its extension. @throw Error(InvalidInput) for unknown extensions.
MeshFormat meshFormatFromPath(const std::string& path);
/// "stl", "obj", "ply", "gltf" or "glb".
const char* meshFormatName(MeshFormat format);

struct MeshReadOptions {
    std::optional<MeshFormat> format;  ///< required when reading "-"; otherwise from the extension
    /// Merge bit-identical positions into one vertex (-0 equals +0). Applies to STL, which stores
    /// three corners per facet, and glTF, whose primitives split vertices at normal/UV seams.
    bool weldVertices = true;
    /// Directory in which glTF external buffer URIs are looked up. Unset: external URIs are
    /// rejected (data: URIs and the GLB binary chunk always work). readMesh sets it to the file's
    /// directory, or the current directory for "-".
    std::optional<std::string> externalDir;
};

/// Reads a triangle mesh. Polygons are fan-triangulated; glTF node transforms are applied.
/// @throw Error(InvalidInput) naming the file for a missing, unreadable, malformed or empty input,
///        Error(Usage) for "-" without a format.
TriMesh readMesh(const std::string& path, const MeshReadOptions& options = {});

/// Parses @p bytes as @p format (options.format is ignored); @p sourceName only labels error
/// messages. Used by readMesh and the fuzz targets. @throw Error(InvalidInput) naming @p sourceName.
TriMesh parseMesh(std::string_view bytes, MeshFormat format, const std::string& sourceName,
                  const MeshReadOptions& options = {});

struct MeshWriteOptions {
    std::optional<MeshFormat> format;  ///< required when writing "-"; Stl, Obj or Ply
};

/// Writes binary STL (with real facet normals), OBJ or binary little-endian PLY, atomically.
/// @throw Error(WriteFailed) naming the file, Error(Usage) for glTF (not a writer format here).
void writeMesh(const TriMesh& mesh, const std::string& path, const MeshWriteOptions& options = {});
/// The bytes writeMesh would write. @throw Error(Usage) for glTF.
std::string serializeMesh(const TriMesh& mesh, MeshFormat format);

}  // namespace zomefab
