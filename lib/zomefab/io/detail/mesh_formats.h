// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Internal to zomefab_io: one parser/serializer per format, plus the byte helpers they share.
/// Other modules use mesh_io.h.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <type_traits>
#include <utility>

#include "zomefab/core/error.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/io/mesh_io.h"

namespace zomefab::detail {

TriMesh parseStl(std::string_view bytes, const std::string& source, bool weld);
TriMesh parseObj(std::string_view bytes, const std::string& source);
TriMesh parsePly(std::string_view bytes, const std::string& source);
/// @p isBinary: GLB container rather than JSON text.
TriMesh parseGltf(std::string_view bytes, bool isBinary, const std::string& source,
                  const MeshReadOptions& options);

std::string serializeStl(const TriMesh& mesh);
std::string serializeObj(const TriMesh& mesh);
std::string serializePly(const TriMesh& mesh);

/// Error(InvalidInput) for @p source.
[[noreturn]] inline void fail(const std::string& source, const std::string& message) {
    throw Error(ErrorCode::InvalidInput, message, source);
}

inline bool isFinite(const Vec3f& p) {
    return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

/// Little-endian load of a trivially copyable value; @p swap reverses the bytes (big-endian data).
template <typename T>
T loadScalar(const char* p, bool swap) {
    static_assert(std::is_trivially_copyable_v<T>);
    char buf[sizeof(T)];
    std::memcpy(buf, p, sizeof(T));
    if (swap)
        for (size_t i = 0; i < sizeof(T) / 2; ++i) std::swap(buf[i], buf[sizeof(T) - 1 - i]);
    T value;
    std::memcpy(&value, buf, sizeof(T));
    return value;
}

/// Appends @p value's bytes (little-endian host assumed, checked in mesh_io.cpp).
template <typename T>
void appendScalar(std::string& out, T value) {
    static_assert(std::is_trivially_copyable_v<T>);
    char buf[sizeof(T)];
    std::memcpy(buf, &value, sizeof(T));
    out.append(buf, sizeof(T));
}

}  // namespace zomefab::detail
