// SPDX-License-Identifier: GPL-3.0-or-later
/// @file In-memory conversions of a Structure: the versioned `zomefab.structure` JSON of
/// ../shared/docs/formats.md (strict reader, every error naming the ball or strut) and vZome's VEF
/// text. No file access here: tools read and write the bytes (io/file_io.h).
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "zomefab/core/transform.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure.h"

namespace zomefab::zome {

/// `format` value of a frame file.
inline constexpr const char* kStructureFormatName = "zomefab.structure";
/// Major version written and accepted.
inline constexpr int kStructureFormatVersion = 1;
/// Largest |a| or |b| accepted in `exact` (2^40: far beyond any physical frame, and sums of two
/// coordinates stay far inside int64).
inline constexpr int64_t kMaxExactCoefficient = int64_t(1) << 40;
/// Tolerance of the informative `mm` coordinates against exact × unit_mm + origin, mm.
inline constexpr double kMmCheckToleranceMm = 0.01;

/// The frame file: live balls and struts in id order (ball ids written as they are, struts in id
/// order), `b0_mm`, `unit_mm`, `transform_mm`, `mm` = exact × unit_mm + scale().originMm.
nlohmann::json structureToJson(const Structure& structure,
                               const Transform4d& transformMm = Transform4d::identity());

/// Reads a frame file. `b0_mm` (default 47.3) and the mm origin come from the file; the other
/// physical sizes from @p physical. Ball ids are kept; struts get ids 0..n−1 in file order.
/// @param transformMm receives `transform_mm` (identity when absent), may be null
/// @throw Error(InvalidInput) with a one-line message naming the ball or strut: wrong format or
///   major version, a vector that is not a Zome strut, a hole used twice, an unknown or duplicate
///   ball id, a declared colour/size/hole that contradicts the vector, inconsistent mm or unit_mm.
Structure structureFromJson(const nlohmann::json& json, const ZomeScale& physical = {},
                            const CollisionOptions& collision = {}, Transform4d* transformMm = nullptr);

/// Parses @p text as JSON, then structureFromJson().
/// @throw Error(InvalidInput) "invalid JSON: ..." or as structureFromJson().
Structure structureFromJsonText(const std::string& text, const ZomeScale& physical = {},
                                const CollisionOptions& collision = {}, Transform4d* transformMm = nullptr);

/// vZome VEF (version 6, field golden) as vZome's own exporter writes it: every ball is a vertex
/// `(0,0) x y z` (w first, each coordinate "(b,a)" for a + bφ, vZome units), every strut an edge
/// "i j" of vertex indices, no panels, every vertex a ball. Vertices are the live balls in id order.
std::string structureToVef(const Structure& structure);

/// One collision as JSON: kind, the two ids, distance and limit (mm).
nlohmann::json collisionToJson(const Collision& collision);
/// "strut 3 and ball 7 (strut–ball, 10.02 mm < 12.15 mm)".
std::string describeCollision(const Collision& collision);
/// zf-zome check's report of @p frame read from @p file: validity, collisions, parts and prices,
/// the scale and the collision clearance used.
nlohmann::json checkReportJson(const Structure& frame, const std::string& file,
                               const std::vector<Collision>& collisions, const PriceOptions& prices);

}  // namespace zomefab::zome
