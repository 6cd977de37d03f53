// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tenons (paper §6.1): from the frame's balls, rays along the blue holes (all 30 by default;
/// the paper's 6 lattice axes with latticeHolesOnly) find the pieces' inner surface; where it is met
/// nearly perpendicularly, the hole
/// is free and nothing of the frame is in the way, a tenon is grown: a square prism from the wall
/// to the ball's blue face, ending in a peg with the golden-rectangle section of the blue hole.
/// No OpenVDB here: the shell is queried through ShellProbe. docs/pieces.md, "Tenons".
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces {

/// Dimensions and limits of the tenons (defaults: docs/pieces.md, "Tenon design").
struct TenonOptions {
    int minPerPiece = 2;          ///< aim: pieces with fewer are reported, with the reasons
    int maxPerPiece = 4;          ///< 0 = no tenons
    /// Gap between the peg and the hole on every side; the peg is the hole less twice this.
    double clearanceMm = 0.15;
    /// The blue hole's golden rectangle: the blue strut's section in vZome's lifelike model,
    /// 1/φ × 1/φ² vZome units at 8.8365 mm (../shared/docs/zome-geometry.md §3).
    double holeLongMm = 5.46;
    double holeShortMm = 3.38;
    double pegDepthMm = 4.0;      ///< how far the peg enters the hole (ZomeFab's LATCH, 4 mm)
    double bodyWidthMm = 7.0;     ///< side of the square prism from the wall to the ball's face
    double maxLengthMm = 40.0;    ///< longest prism, from the ball's blue face to the inner surface
    /// Largest angle between the hole axis and the inner surface's normal (§6.1: "perpendicular";
    /// the paper's voxel surfaces were axis-aligned). 35° gives 10 of the bunny's 33 pieces fewer
    /// than 2 tenons where 30° gives 13 (docs/pieces.md); the prism's end is buried deeper on a
    /// tilted wall, so the bond does not suffer.
    double maxTiltDeg = 35.0;
    /// Depth of the prism in the wall beyond the axis's surface point, on top of what a tilted
    /// surface needs to bury the whole end face.
    double embedMm = 1.5;
    double frameClearanceMm = 0.5; ///< extra gap between the prism and struts or other balls
    /// true: only the six lattice-axis holes (±x ±y ±z), as the paper (§6.1); false: all 30 blue
    /// holes, which reach walls the lattice axes meet too obliquely (docs/pieces.md, "Tenons").
    bool latticeHolesOnly = false;
};

/// @throw Error(Usage) naming the option when a value is out of range.
void checkTenonOptions(const TenonOptions& options);

/// The peg's section: the hole less the clearance on every side.
inline double pegLongMm(const TenonOptions& o) { return o.holeLongMm - 2 * o.clearanceMm; }
inline double pegShortMm(const TenonOptions& o) { return o.holeShortMm - 2 * o.clearanceMm; }
/// Coarsest shell voxel that still resolves the pegs: two voxels across their short side.
inline double maxVoxelForPegsMm(const TenonOptions& o) { return 0.5 * pegShortMm(o); }
/// Radius of the capsule around the prism that the collision tests use (its half-diagonal).
double bodyRadiusMm(const TenonOptions& o);

/// One tenon. Distances are along the axis from the ball's centre, in mm.
struct Tenon {
    zome::BallId ball = zome::kNoId;
    int hole = 0;                  ///< a blue hole, 0..29 (zome_system.h numbering)
    uint32_t piece = 0;
    Vec3d axisFrame{0, 0, 1};      ///< zome::holeDirection(hole): exact, frame coordinates
    Vec3d axisGrid{0, 0, 1};       ///< the same in the grid's mm (rotated by frameToGridMm)
    Vec3d longSideGrid{1, 0, 0};   ///< the peg's long side (grid): zome::holeSectionAxis(hole), rotated
    Vec3d ballCenterGridMm{0, 0, 0};
    double shoulderMm = 0.0;       ///< the ball's blue face, where the prism ends and the peg starts
    double baseMm = 0.0;           ///< where the axis meets the inner surface
    double endMm = 0.0;            ///< where the prism ends inside the wall
    double pegTipMm = 0.0;         ///< the peg's end in the hole: shoulderMm − pegDepthMm
    double tiltDeg = 0.0;          ///< angle between the axis and the inner surface's normal

    double lengthMm() const { return baseMm - shoulderMm; }
    Vec3d pointAt(double t) const {
        return {ballCenterGridMm[0] + t * axisGrid[0], ballCenterGridMm[1] + t * axisGrid[1],
                ballCenterGridMm[2] + t * axisGrid[2]};
    }
};

/// Signed distance to the tenon solid (prism ∪ peg), negative inside, in the grid's mm. Exact
/// outside each box, and where one box is nearest inside.
double tenonSignedDistanceMm(const Tenon& tenon, const TenonOptions& options, const Vec3d& pGridMm);
/// Axis-aligned box (grid mm) around the tenon solid.
Box3d tenonBoundsMm(const Tenon& tenon, const TenonOptions& options);

/// What the planner asks about the shell and its pieces, in the grid's mm. Serial use.
struct ShellProbe {
    std::function<double(const Vec3d&)> signedDistanceMm;  ///< φ of the shell, trilinear
    /// The piece owning the voxel nearest to a point in the wall or within its narrow band; −1
    /// farther out. Callers ask φ first: only points with φ < 0 are in the piece's material.
    std::function<int64_t(const Vec3d&)> pieceAt;
    double voxelMm = 1.0;

    /// Unit normal of the shell's level set at @p p (outward of the material: out of the wall), by
    /// central differences half a voxel apart.
    Vec3d normalAt(const Vec3d& p) const;
};

/// One ray from a ball along a lattice hole: the tenon it would be, and why not (empty = usable).
struct TenonCandidate {
    Tenon tenon;
    int64_t piece = -1;     ///< the piece the ray meets, −1 when it meets none
    std::string rejection;  ///< "hole holds a strut", "too far", "surface too oblique", ...
    double score = 0.0;     ///< larger is better: perpendicular and short
};

/// All 6 lattice rays of every ball, in (ball id, hole) order.
std::vector<TenonCandidate> findTenonCandidates(const zome::Structure& frame, const Transform4d& frameToGridMm,
                                                const ShellProbe& probe, const TenonOptions& options);

/// What is in the way of @p tenon's prism (as a capsule of bodyRadiusMm from the shoulder to its end):
/// "strut 12 (B0) in the way", "ball 4 in the way", or empty when the path is clear.
/// Struts and balls are the frame's collision proxies (zome::Structure).
std::string tenonObstruction(const zome::Structure& frame, const Tenon& tenon, const TenonOptions& options);

/// The chosen tenons per piece and, for pieces with fewer than minPerPiece, why.
struct TenonPlan {
    std::vector<std::vector<Tenon>> perPiece;
    std::vector<std::map<std::string, int>> shortfall;
};

/// Picks tenons greedily: first up to minPerPiece for every piece, then up to maxPerPiece, best
/// score first, skipping any that would come within 2 · bodyRadiusMm of one already chosen (the
/// prisms of different pieces must not touch). Deterministic.
TenonPlan chooseTenons(const std::vector<TenonCandidate>& candidates, size_t pieceCount, const TenonOptions& options);

}  // namespace zomefab::pieces
