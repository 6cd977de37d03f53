// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Internal to lib/zomefab/verify: the printed pieces back in the grid's millimetres (where
/// the frame is), the surface samples the static checks test, and the checks themselves.
#pragma once

#include <vector>

#include "zomefab/verify/verify.h"

namespace zomefab::verify::detail {

/// One piece's triangles in the grid's mm (the inverse of its grid → printer transform).
struct PieceGeometry {
    std::vector<Vec3d> vertices;
    std::vector<std::array<uint32_t, 3>> triangles;
    Box3d bounds;
    /// The points the static checks test: every vertex and every triangle's centroid.
    std::vector<Vec3d> samples() const;
};
std::vector<PieceGeometry> pieceGeometries(const pieces::Pieces& pieces);

/// Where one ball's hole lies in the grid: the ball's centre, the hole's exact direction and
/// section axis rotated into the grid, its section and the distance to its face (mm).
struct HoleFrame {
    Vec3d centerMm, d, x, y;
    std::vector<std::array<double, 2>> section;
    double faceMm = 0.0;
};
HoleFrame holeFrame(const Assembly& a, zome::BallId ball, int hole);

/// Signed distance of the 2D point @p q to the convex polygon @p poly's boundary: positive inside.
double insideDistance(const std::vector<std::array<double, 2>>& poly, double qx, double qy);

/// The checks that need no motion: tenons against the plan and the frame, peg axes, peg fit and
/// material inside balls, material inside struts. Fill @p report's checks and piece results.
void checkTenons(const Assembly& a, VerifyReport& report);
void checkPegs(const Assembly& a, const std::vector<PieceGeometry>& geometry, const VerifyOptions& o,
               VerifyReport& report, const RunContext& context);
void checkStruts(const Assembly& a, const std::vector<PieceGeometry>& geometry, const VerifyOptions& o,
                 VerifyReport& report, const RunContext& context);

/// The checks of motion: every body's free path past the frame, and past the bodies mounted before it.
void checkPaths(const Assembly& a, const std::vector<PieceGeometry>& geometry, const VerifyOptions& o,
                VerifyReport& report, const RunContext& context);

}  // namespace zomefab::verify::detail
