// SPDX-License-Identifier: GPL-3.0-or-later
/// @file In-memory conversions of a PartitionResult: the versioned `zomefab.partition` JSON that
/// the pieces stage reads (docs/partition.md, "PARTITION.json"), and a PLY with one colour per face
/// to look at labellings. No file access: tools write the bytes atomically.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/partition/partition.h"

namespace zomefab::partition {

inline constexpr const char* kPartitionFormatName = "zomefab.partition";
inline constexpr int kPartitionFormatVersion = 1;

/// What the JSON records about the run besides the result.
struct PartitionJsonInfo {
    std::string meshFile;
    std::string frameFile;
    Transform4d transformMm;  ///< the frame's transform_mm (mesh file coordinates → mm)
    size_t vertexCount = 0;
};

/// The PARTITION.json document. Contains no timings, so equal inputs give equal bytes; every
/// writer dumps it with an indent of 1 and a final newline.
nlohmann::json partitionToJson(const PartitionResult& result, const PartitionOptions& options,
                               const PartitionJsonInfo& info);

/// The headline numbers of a result (zf-partition's --report): faces, labels, graph sizes,
/// energies, partitions, pieces, the largest fit ratio and the timings.
nlohmann::json partitionSummaryJson(const PartitionResult& result);

/// The per-face groups to colour a mesh by: "pieces", "cells", "labels" (after the graph cut) or
/// "nearest" (the nearest-ball labelling). @throw Error(Usage) for another name.
const std::vector<uint32_t>& faceGroups(const PartitionResult& result, const std::string& groups);

/// A partition file read back: the result (what the pieces stage needs and the numbers reports
/// show; the per-face arrays when present) and the record of where it came from.
struct PartitionFile {
    PartitionResult result;
    PartitionJsonInfo info;
};

/// The inverse of partitionToJson. Checks the format and version, that every cell and piece is
/// complete, every index in range (cells of pieces, balls of cells) and every number finite.
/// @throw Error(InvalidInput) naming the field (callers add the file).
PartitionFile partitionFromJson(const nlohmann::json& document);

/// partitionFromJson of the JSON text @p bytes (a partition.json as read from disk).
/// @throw Error(InvalidInput) naming @p sourceName for invalid JSON or a malformed document.
PartitionFile parsePartitionFile(std::string_view bytes, const std::string& sourceName);

/// Binary little-endian PLY of @p meshMm with `uchar red, green, blue` and `int group` per face:
/// @p faceGroups (piece, cell or label ids) coloured by a golden-ratio hue walk, so neighbouring
/// ids get distinct colours. @throw Error(Usage) when the sizes differ.
std::string coloredPlyBytes(const TriMesh& meshMm, const std::vector<uint32_t>& faceGroups);

}  // namespace zomefab::partition
