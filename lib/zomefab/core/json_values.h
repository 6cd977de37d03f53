// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The JSON spelling of the core value types, shared by every file format the library reads
/// and writes (frame.json, partition.json, pieces.json, report.json): a Vec3d is [x, y, z], a Box3d
/// {"min": [...], "max": [...]}, a Transform4d four rows of four numbers. Readers check the shape
/// and that every number is finite, and throw Error(InvalidInput) naming the field; callers add
/// the file with Error::withFile.
#pragma once

#include <nlohmann/json.hpp>
#include <string>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab {

nlohmann::json toJson(const Vec3d& v);
nlohmann::json toJson(const Box3d& box);
/// Row-major, four rows.
nlohmann::json toJson(const Transform4d& t);

/// A finite number. @throw Error(InvalidInput) "<what> must be a finite number".
double numberFromJson(const nlohmann::json& j, const std::string& what);
/// The count @p key of the object @p j, or @p fallback when absent. Counts are unsigned integers:
/// nlohmann would cast a float or a negative number (5.6e99, found by fuzz_partition) to size_t,
/// undefined behaviour. @throw Error(InvalidInput) "<key> must be a count".
size_t countFromJson(const nlohmann::json& j, const char* key, size_t fallback);
/// [x, y, z]. @throw Error(InvalidInput) "<what> must be an array of 3 numbers".
Vec3d vec3FromJson(const nlohmann::json& j, const std::string& what);
/// {"min": [...], "max": [...]}.
Box3d boxFromJson(const nlohmann::json& j, const std::string& what);
/// Four rows of four numbers whose last row is 0 0 0 1 (every transform zomefab writes is affine).
Transform4d transformFromJson(const nlohmann::json& j, const std::string& what);

/// The member @p key of the object @p j, or an error "<what>: needs \"<key>\"".
const nlohmann::json& requireMember(const nlohmann::json& j, const char* key, const std::string& what);

}  // namespace zomefab
