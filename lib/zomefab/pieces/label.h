// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The piece number engraved into the piece's inner surface, so pieces can be told apart:
/// seven-segment digits over an underline (which tells 6 from 9), built from boxes as a small
/// level set and subtracted by CSG. No OpenVDB here. docs/pieces.md, "Engraved number".
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "zomefab/core/tri_mesh.h"
#include "zomefab/pieces/tenons.h"

namespace zomefab::pieces {

/// Size and placement rules of the engraved number.
struct LabelOptions {
    bool isEnabled = true;
    double heightMm = 12.0;  ///< digit height
    /// Line width (and the gap above the underline); at least 2 voxels, else labels are skipped
    /// with a warning: 2.4 mm keeps the digits legible at the default 1 mm voxel.
    double strokeMm = 2.4;
    double depthMm = 1.2;  ///< engraving depth below the inner surface (following the surface)
    /// The surface may leave the label's plane by this much under the label: the digits are drawn
    /// on the plane and cut depthMm into the surface beneath it, so this bounds how far they are
    /// bent (on a thin wall, labelOptionsForWall bounds it to keep the cut off the outer surface).
    double flatnessMm = 2.0;
    double marginMm = 2.0;  ///< clear distance to cut faces, wall edges and tenons
};

/// @throw Error(Usage) naming the option when a value is out of range.
void checkLabelOptions(const LabelOptions& options);

/// @p options for a piece printed with a wall of @p wallMm: the engraving at most a third of the
/// wall deep and the surface within a sixth of it under the number. Then the strokes' solid
/// (depth + flatness below the plane) ends at least the depth above the outer surface, so the
/// engraving never reaches it, and two thirds of the wall stay behind the engraving
/// (a 1.8 mm wall: 0.6 mm deep, within 0.3 mm; the 16 mm shell: 1.2 mm, within 2 mm; docs/pieces.md §3).
LabelOptions labelOptionsForWall(const LabelOptions& options, double wallMm);

/// Where a number is engraved.
struct PieceLabel {
    std::string text;
    Vec3d centerGridMm{0, 0, 0};  ///< on the inner surface, grid mm
    Vec3d normalGrid{0, 0, 1};    ///< out of the wall, into the cavity (towards the reader)
    Vec3d upGrid{0, 1, 0};        ///< the text's up direction, in the surface's plane
    double widthMm = 0.0;         ///< of the text and underline
    double heightMm = 0.0;
};

/// A stroke: an axis-aligned rectangle in label coordinates (mm; origin at the label's centre,
/// x to the right and y up as read from the cavity).
struct Stroke {
    double centerX = 0, centerY = 0, halfWidth = 0, halfHeight = 0;
};

/// The strokes of @p text (decimal digits only) and its underline, centred on the origin.
/// @throw Error(Internal) for a character that is not a digit.
std::vector<Stroke> labelStrokes(const std::string& text, const LabelOptions& options);
/// Width and height of the box around labelStrokes().
Vec3d labelSizeMm(const std::string& text, const LabelOptions& options);

/// Signed distance (negative inside) to the strokes extruded from depthMm + flatnessMm below the
/// label's plane to 2 mm above it (into the cavity), grid mm. The engraving is this solid's
/// part within depthMm of the inner surface (pieces/piece_grid.cpp): the surface moved depthMm
/// into the wall under the strokes, however it curves within flatnessMm of the plane.
double labelSignedDistanceMm(const PieceLabel& label, const std::vector<Stroke>& strokes,
                             const LabelOptions& options, const Vec3d& pGridMm);
/// Axis-aligned box (grid mm) around the engraving solid.
Box3d labelBoundsMm(const PieceLabel& label, const LabelOptions& options);

/// A point of a piece's inner surface seen from the cavity, with the surface normal there.
struct SurfaceSpot {
    Vec3d pointGridMm{0, 0, 0};
    Vec3d normalGrid{0, 0, 1};  ///< out of the wall, into the cavity
};

/// Inner-surface spots of every piece: where rays from the frame's balls along all 62 hole
/// directions first meet the shell, within @p maxDistanceMm of the ball. Indexed by piece.
std::vector<std::vector<SurfaceSpot>> innerSurfaceSpots(const zome::Structure& frame,
                                                        const Transform4d& frameToGridMm,
                                                        const ShellProbe& probe, size_t pieceCount,
                                                        double maxDistanceMm);

/// The best spot of @p spots for @p text on piece @p piece: the flattest where the label and its
/// margin lie on the piece's inner surface, inside its wall and clear of @p tenons. nullopt, with
/// the reason in @p note, when there is none.
std::optional<PieceLabel> placeLabel(const std::string& text, uint32_t piece,
                                     const std::vector<SurfaceSpot>& spots, const std::vector<Tenon>& tenons,
                                     const TenonOptions& tenonOptions, const ShellProbe& probe,
                                     const LabelOptions& options, std::string* note);

}  // namespace zomefab::pieces
