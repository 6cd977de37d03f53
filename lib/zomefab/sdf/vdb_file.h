// SPDX-License-Identifier: GPL-3.0-or-later
/// @file .vdb streams of level sets with zomefab's metadata (docs/sdf.md, "Metadata"). Works on
/// bytes and streams so the tools can read stdin and write stdout (OpenVDB io::Stream); the tools
/// do the file handling with readInputBytes / writeOutputAtomic.
#pragma once

#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::sdf {

/// Writes @p levelSets (non-empty, distinct names) as one .vdb stream: Blosc-compressed, every
/// LevelSetInfo field as grid metadata. The same grids give the same bytes (the archive UUID,
/// random in OpenVDB, is replaced by a hash of the content).
/// @throw Error(Internal) for an empty level set or a duplicate name; Error(WriteFailed) when
///        @p out fails.
void writeVdb(const std::vector<LevelSet>& levelSets, std::ostream& out);

/// The bytes writeVdb writes.
std::string serializeVdb(const std::vector<LevelSet>& levelSets);

/// Every float level-set grid in the .vdb @p bytes, in file order. Grids written by other programs
/// are accepted when they are float level sets with a uniform voxel; missing metadata is derived
/// (voxel from the transform, bands from the background, identity transform_mm) with a warning on
/// @p context for missing units.
/// @throw Error(InvalidInput) naming @p sourceName when the bytes are not a .vdb stream, hold no
///        float level set, use units other than "mm", or a non-uniform or non-linear transform.
std::vector<LevelSet> parseVdb(std::string_view bytes, const std::string& sourceName, RunContext& context);

/// The level set named @p name in @p levelSets; when @p name is empty, the first one.
/// @throw Error(InvalidInput) naming @p sourceName and listing the grids present.
const LevelSet& findLevelSet(const std::vector<LevelSet>& levelSets, const std::string& name,
                             const std::string& sourceName);

}  // namespace zomefab::sdf
