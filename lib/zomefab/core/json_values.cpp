// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/json_values.h"

#include <cmath>

#include "zomefab/core/error.h"

namespace zomefab {

using nlohmann::json;

json toJson(const Vec3d& v) { return json::array({v[0], v[1], v[2]}); }

json toJson(const Box3d& box) { return {{"min", toJson(box.min)}, {"max", toJson(box.max)}}; }

json toJson(const Transform4d& t) {
    json rows = json::array();
    for (int r = 0; r < 4; ++r) rows.push_back({t.at(r, 0), t.at(r, 1), t.at(r, 2), t.at(r, 3)});
    return rows;
}

double numberFromJson(const json& j, const std::string& what) {
    if (!j.is_number()) throw Error(ErrorCode::InvalidInput, what + " must be a finite number");
    const double x = j.get<double>();
    if (!std::isfinite(x)) throw Error(ErrorCode::InvalidInput, what + " must be a finite number");
    return x;
}

size_t countFromJson(const json& j, const char* key, size_t fallback) {
    if (!j.is_object() || !j.contains(key)) return fallback;
    const json& v = j[key];
    if (v.is_number_unsigned()) return v.get<size_t>();
    // Parsed text gives unsigned numbers; a json built in C++ from an int is signed.
    if (v.is_number_integer() && v.get<int64_t>() >= 0) return size_t(v.get<int64_t>());
    throw Error(ErrorCode::InvalidInput, std::string(key) + " must be a count");
}

Vec3d vec3FromJson(const json& j, const std::string& what) {
    if (!j.is_array() || j.size() != 3)
        throw Error(ErrorCode::InvalidInput, what + " must be an array of 3 numbers");
    return {numberFromJson(j[0], what), numberFromJson(j[1], what), numberFromJson(j[2], what)};
}

Box3d boxFromJson(const json& j, const std::string& what) {
    if (!j.is_object())
        throw Error(ErrorCode::InvalidInput, what + " must be an object with \"min\" and \"max\"");
    Box3d box;
    box.min = vec3FromJson(requireMember(j, "min", what), what + ".min");
    box.max = vec3FromJson(requireMember(j, "max", what), what + ".max");
    return box;
}

Transform4d transformFromJson(const json& j, const std::string& what) {
    if (!j.is_array() || j.size() != 4)
        throw Error(ErrorCode::InvalidInput, what + " must be a 4x4 array of rows");
    Transform4d t;
    for (size_t r = 0; r < 4; ++r) {
        if (!j[r].is_array() || j[r].size() != 4)
            throw Error(ErrorCode::InvalidInput, what + " must be a 4x4 array of rows");
        for (size_t c = 0; c < 4; ++c) t.m[r * 4 + c] = numberFromJson(j[r][c], what);
    }
    if (t.m[12] != 0.0 || t.m[13] != 0.0 || t.m[14] != 0.0 || t.m[15] != 1.0)
        throw Error(ErrorCode::InvalidInput, what + " must be affine (last row 0 0 0 1)");
    return t;
}

const json& requireMember(const json& j, const char* key, const std::string& what) {
    if (!j.is_object() || !j.contains(key))
        throw Error(ErrorCode::InvalidInput, what + ": needs \"" + std::string(key) + "\"");
    return j[key];
}

}  // namespace zomefab
