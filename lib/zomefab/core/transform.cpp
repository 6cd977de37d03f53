// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/transform.h"

#include <algorithm>
#include <cmath>

#include "zomefab/core/error.h"

namespace zomefab {

Transform4d Transform4d::scaleTranslate(double scale, const Vec3d& t) {
    Transform4d r;
    r.m = {scale, 0, 0, t[0], 0, scale, 0, t[1], 0, 0, scale, t[2], 0, 0, 0, 1};
    return r;
}

Transform4d Transform4d::yUpToZUp() {
    Transform4d r;
    // (x, y, z) -> (x, -z, y): a proper rotation of +90 degrees about x.
    r.m = {1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1};
    return r;
}

Vec3d Transform4d::apply(const Vec3d& p) const {
    Vec3d r;
    for (int i = 0; i < 3; ++i)
        r[i] = m[i * 4] * p[0] + m[i * 4 + 1] * p[1] + m[i * 4 + 2] * p[2] + m[i * 4 + 3];
    return r;
}

Transform4d operator*(const Transform4d& a, const Transform4d& b) {
    Transform4d r;
    for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a.m[i * 4 + k] * b.m[k * 4 + j];
            r.m[i * 4 + j] = s;
        }
    return r;
}

Transform4d affineInverse(const Transform4d& t) {
    // Inverse of the 3×3 part A by cofactors, then the translation −A⁻¹·b.
    const auto a = [&](int i, int j) { return t.m[i * 4 + j]; };
    const double c00 = a(1, 1) * a(2, 2) - a(1, 2) * a(2, 1), c01 = a(1, 2) * a(2, 0) - a(1, 0) * a(2, 2),
                 c02 = a(1, 0) * a(2, 1) - a(1, 1) * a(2, 0);
    const double det = a(0, 0) * c00 + a(0, 1) * c01 + a(0, 2) * c02;
    if (!(std::abs(det) > 1e-300) || !std::isfinite(det))
        throw Error(ErrorCode::InvalidInput, "the transform is singular and has no inverse");
    double inv[3][3] = {{c00, a(0, 2) * a(2, 1) - a(0, 1) * a(2, 2), a(0, 1) * a(1, 2) - a(0, 2) * a(1, 1)},
                        {c01, a(0, 0) * a(2, 2) - a(0, 2) * a(2, 0), a(0, 2) * a(1, 0) - a(0, 0) * a(1, 2)},
                        {c02, a(0, 1) * a(2, 0) - a(0, 0) * a(2, 1), a(0, 0) * a(1, 1) - a(0, 1) * a(1, 0)}};
    Transform4d r;
    for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) r.m[i * 4 + j] = inv[i][j] / det;
        r.m[i * 4 + 3] = -(r.m[i * 4] * a(0, 3) + r.m[i * 4 + 1] * a(1, 3) + r.m[i * 4 + 2] * a(2, 3));
    }
    return r;
}

void transformInPlace(TriMesh& mesh, const Transform4d& t) {
    for (Vec3f& p : mesh.positions) {
        Vec3d q = t.apply({p[0], p[1], p[2]});
        p = {float(q[0]), float(q[1]), float(q[2])};
    }
}

bool isNearlyEqual(const Transform4d& a, const Transform4d& b, double relativeTolerance) {
    double scale = 1.0;
    for (double v : a.m) scale = std::max(scale, std::abs(v));
    for (size_t i = 0; i < 16; ++i)
        if (std::abs(a.m[i] - b.m[i]) > relativeTolerance * scale) return false;
    return true;
}

}  // namespace zomefab
