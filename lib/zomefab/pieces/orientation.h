// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Print preparation: the planar cut faces of a piece mesh, and the rotation that puts the
/// largest cut face that allows it on the printer's bed with the piece inside the build volume.
/// No OpenVDB here. docs/pieces.md, "Orientation".
#pragma once

#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::pieces {

/// A plane the piece was cut along: {x : n·x + d = 0} with n the unit outward normal of the piece.
struct CutFace {
    Vec3d outwardNormal{0, 0, 1};
    double offsetMm = 0.0;
    double areaMm2 = 0.0;  ///< area of the piece's triangles lying on the plane
};

/// The planar faces of @p meshMm on the given planes: the triangles whose three vertices lie within
/// @p toleranceMm of a plane and whose normal agrees with its outward normal. @p planes holds
/// candidate planes (area ignored); the result keeps those with area, largest first.
std::vector<CutFace> measureCutFaces(const TriMesh& meshMm, const std::vector<CutFace>& planes, double toleranceMm);

/// How a piece sits in the printer.
struct PrintOrientation {
    bool fits = false;              ///< inside the build volume
    bool isCutFaceDown = false;     ///< a cut face lies on the bed
    Vec3d downNormal{0, 0, -1};     ///< the outward normal (input frame) that points down
    Transform4d transformMm;        ///< input mm → printer mm: on the bed (z = 0), centred in x and y
    Vec3d extentsMm{0, 0, 0};       ///< size along the printer's x, y, z
    double ratio = 0.0;             ///< max over axes of extent / printer size (≤ 1 fits)
};

/// The orientation of the points @p pointsMm (a piece's vertices) for a printer of @p printerMm
/// (x, y = bed, z = height). Tries the cut faces, largest first, that no point lies beyond by more
/// than @p flatToleranceMm, each turned about the vertical for the best fit on the bed; the first
/// that fits wins. Otherwise searches 6 axis and 250 sphere directions for the one with the most
/// room; fits = false when none fits. Deterministic.
PrintOrientation orientForPrinter(const std::vector<Vec3d>& pointsMm, const std::vector<CutFace>& cutFaces,
                                  const Vec3d& printerMm, double flatToleranceMm = 0.01);

}  // namespace zomefab::pieces
