// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Vec3d arithmetic shared by every module (the one copy: dot, cross, norms, the linear
/// part of a transform). Plain functions over std::array so the value types stay aggregates.
#pragma once

#include <cmath>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab {

/// π, for the angles the stages convert (degrees in options, radians in std::cos).
inline constexpr double kPi = 3.14159265358979323846;

inline Vec3d add(const Vec3d& a, const Vec3d& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
inline Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline Vec3d scale(const Vec3d& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
/// a + s·b
inline Vec3d madd(const Vec3d& a, double s, const Vec3d& b) {
    return {a[0] + s * b[0], a[1] + s * b[1], a[2] + s * b[2]};
}
inline double dot(const Vec3d& a, const Vec3d& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline Vec3d cross(const Vec3d& a, const Vec3d& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double norm(const Vec3d& a) { return std::sqrt(dot(a, a)); }
/// |a − b|²
inline double dist2(const Vec3d& a, const Vec3d& b) {
    const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}
/// a / |a|, or a itself when it is zero.
inline Vec3d normalized(const Vec3d& a) {
    const double n = norm(a);
    return n > 0 ? scale(a, 1.0 / n) : a;
}
inline Vec3d toD(const Vec3f& p) { return {double(p[0]), double(p[1]), double(p[2])}; }

/// The 3×3 part of @p t applied to the direction @p v (no translation).
inline Vec3d applyLinear(const Transform4d& t, const Vec3d& v) {
    return {t.at(0, 0) * v[0] + t.at(0, 1) * v[1] + t.at(0, 2) * v[2],
            t.at(1, 0) * v[0] + t.at(1, 1) * v[1] + t.at(1, 2) * v[2],
            t.at(2, 0) * v[0] + t.at(2, 1) * v[1] + t.at(2, 2) * v[2]};
}

}  // namespace zomefab
