// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Helpers shared by the io tests: exception-message checks and mesh comparisons.
#pragma once

#include <doctest/doctest.h>

#include <cstring>
#include <functional>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::test {

/// Runs @p f, requires a zomefab::Error with @p code whose what() contains every one of @p parts.
inline void requireError(const std::function<void()>& f, ErrorCode code,
                         std::initializer_list<std::string> parts) {
    bool thrown = false;
    try {
        f();
    } catch (const Error& e) {
        thrown = true;
        const std::string message = e.what();
        INFO("message: " << message);
        CHECK(int(e.code()) == int(code));
        for (const std::string& p : parts) CHECK(std::string(e.what()).find(p) != std::string::npos);
        CHECK(std::string(e.what()).find('\n') == std::string::npos);  // one line
    }
    CHECK(thrown);
}

/// Same triangles with bit-identical corner positions, in the same order.
inline bool sameGeometry(const TriMesh& a, const TriMesh& b) {
    if (a.triangles.size() != b.triangles.size()) return false;
    for (size_t t = 0; t < a.triangles.size(); ++t)
        for (int c = 0; c < 3; ++c)
            if (std::memcmp(&a.positions[a.triangles[t][c]], &b.positions[b.triangles[t][c]],
                            sizeof(Vec3f)) != 0)
                return false;
    return true;
}

}  // namespace zomefab::test
