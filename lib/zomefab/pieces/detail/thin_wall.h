// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Pieces printed with a wall thinner than the shell's (PiecesOptions::printWallMm; internal
/// to lib/zomefab/pieces; docs/pieces.md, "A thinner printed wall"). The installation plan is made
/// with the shell's wall (the forbidden zone's d_min, 16 mm by default); a piece then keeps only
/// the outer printWallMm of it where every one of its planned pegs can be grown again through the
/// thin wall. The thin piece lies inside the thick one (its stems run where the thick wall was, in
/// its own cells), so every path, order and peg of the plan still holds.
#pragma once

#include <vector>

#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/tenons.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces::detail {

/// @throw Error(Usage) naming --print-wall-mm when @p printWallMm (0 = off) cannot be cut from a
/// shell of @p shellWallMm with a band of @p backgroundMm: the thin wall must lie inside the band
/// (half a voxel to spare), and the shell's two bands must be apart (wall ≥ 2 bands + a voxel).
void checkPrintWall(double printWallMm, double shellWallMm, double backgroundMm, double voxelMm);

/// The printed wall makePieces uses for PiecesOptions::printWallMm = @p requested: kPrintWallAuto
/// gives kDefaultPrintWallMm where checkPrintWall passes it, else 0 (the shell's wall); any other
/// value is checked (checkPrintWall throws) and returned.
double resolvePrintWallMm(double requested, double shellWallMm, double backgroundMm, double voxelMm);

/// Per slot of @p field: φ of the thin wall, max(φ, −φ − W) near the outer surface (wall voxels
/// 6-connected through the band to exteriorBand), positive (background − W) deeper in the wall
/// and in the hollow's band, φ outside the material. W = @p printWallMm < field.background.
std::vector<float> thinWallPhi(const VoxelField& field, double printWallMm);

/// A ShellProbe of @p field's thinPhi (trilinear; +background where the field has no voxel), the
/// owners of the field's voxels, wall @p printWallMm.
ShellProbe thinWallProbe(const VoxelField& field, double printWallMm);

/// The tenon options a stem grown again through a thin wall is held to: @p o with maxLengthMm
/// longer by how much deeper the thin wall's inner surface lies along a stem at the steepest tilt,
/// (shell − print) / cos(maxTiltDeg). The planned stem kept its limit; what it gains runs inside
/// its own piece's thick wall (thinPieces checks that), so the limit's reason, reaching the wall
/// across the forbidden zone, is met as it was.
TenonOptions thinTenonOptions(const TenonOptions& o, double shellWallMm, double printWallMm);

/// Each piece of @p out that can be printed thin: it is in no glued pair and carries no pin, each
/// of its tenons (same ball and hole) is a candidate again through @p thin's wall that meets this
/// piece, whose stem beyond the thick wall's inner surface crosses no other piece's wall, and the
/// thin wall keeps a plausible share (of @p shellWallMm's) of its voxels. Such pieces get the new
/// tenons, wallMm = printWallMm and isThinWall; the rest are left as they are (the caller set them
/// to the shell's wall). Returns how many are thin.
size_t thinPieces(Pieces& out, const VoxelField& field, const zome::Structure& frame,
                  const Transform4d& frameToGridMm, const ShellProbe& thin, double shellWallMm,
                  const TenonOptions& options);

}  // namespace zomefab::pieces::detail
