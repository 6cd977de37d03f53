// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Row-major 4x4 affine transform, used as `transform_mm`: input-mesh coordinates to millimetres.
#pragma once

#include <array>

#include "zomefab/core/tri_mesh.h"

namespace zomefab {

/// Row-major 4x4 matrix; only affine matrices (last row 0 0 0 1) are produced by zomefab.
struct Transform4d {
    std::array<double, 16> m{1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};

    static Transform4d identity() { return {}; }
    /// x ↦ scale·x + translation.
    static Transform4d scaleTranslate(double scale, const Vec3d& translation);
    /// A rotation that maps the +y axis to +z (x stays, y→z, z→−y): used for `--up y` inputs.
    static Transform4d yUpToZUp();

    double at(int row, int col) const { return m[row * 4 + col]; }
    Vec3d apply(const Vec3d& p) const;
    /// The composition: (a * b)(x) = a(b(x)).
    friend Transform4d operator*(const Transform4d& a, const Transform4d& b);
    bool operator==(const Transform4d& o) const { return m == o.m; }
};

/// The inverse of the affine transform @p t (last row 0 0 0 1); the identity's inverse is exact.
/// @throw Error(InvalidInput) when the 3×3 part is singular.
Transform4d affineInverse(const Transform4d& t);

/// Every entry of @p a within @p relativeTolerance · max(1, largest |entry| of a) of @p b's: the
/// same transform written out and read back, or computed twice.
bool isNearlyEqual(const Transform4d& a, const Transform4d& b, double relativeTolerance = 1e-6);

/// Applies @p t to every vertex of @p mesh in place.
void transformInPlace(TriMesh& mesh, const Transform4d& t);

}  // namespace zomefab
