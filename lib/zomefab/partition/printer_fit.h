// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Does a piece fit the printer's build volume in some orientation? An oriented bounding box
/// search: starts from the axis-aligned frame, the PCA frame, and the PCA frame with its major
/// axis along the printer's diagonal; scans rotations about each box axis, then refines by coordinate descent over rotations with shrinking steps (10°, 3°, 1°, 0.3°).
/// The objective is the fit ratio (below), ties broken by box volume.
#pragma once

#include <array>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::partition {

/// An oriented box around a point set and how it sits in the printer.
struct PrinterFit {
    bool fits = false;  ///< ratio ≤ 1: the box fits the build volume with its axes along the printer's
    /// Rows are the box axes as unit vectors in the input's mm frame (a rotation matrix R: box
    /// coordinates = R·x). Sorted so that extentsMm[0] ≤ extentsMm[1] ≤ extentsMm[2].
    std::array<Vec3d, 3> axes{Vec3d{1, 0, 0}, Vec3d{0, 1, 0}, Vec3d{0, 0, 1}};
    Vec3d extentsMm{0, 0, 0};  ///< box size along each axis, including 2 × margin
    Vec3d centerMm{0, 0, 0};   ///< box centre in the input's mm frame
    /// max_i e_(i) / p_(i) with box extents e and printer sizes p both sorted increasingly: the box
    /// fits in some axis-parallel placement exactly when this is ≤ 1.
    double ratio = 0.0;
};

/// The best orientation found for @p pointsMm in a printer of @p printerMm (x, y, z build sizes,
/// any order), every box side grown by @p marginMm. Deterministic. Empty input: fits, ratio 0.
PrinterFit fitInPrinter(const std::vector<Vec3d>& pointsMm, const Vec3d& printerMm, double marginMm = 0.0);

/// The fit ratio of the box with @p axes (rows of a rotation) around @p pointsMm (see PrinterFit).
PrinterFit evaluateFit(const std::vector<Vec3d>& pointsMm, const std::array<Vec3d, 3>& axes,
                       const Vec3d& printerMm, double marginMm = 0.0);

}  // namespace zomefab::partition
