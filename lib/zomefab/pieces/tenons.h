// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tenons (paper §6.1, made mountable): every piece is pushed onto the built frame along one
/// direction, −d, with d one of the 62 hole directions; every tenon of the piece is a ray from a
/// ball along d, through the ball's hole that points along d. Every ball has the same orientation,
/// so these tenons are parallel by construction. Where the ray meets the piece's inner surface
/// not too obliquely, the hole is free and nothing of the frame is in the way, a tenon is grown: a
/// square prism from the wall to the ball's face, ending in a peg with the hole's own section —
/// the blue golden rectangle, the yellow triangle or the red pentagon, less the clearance on
/// every side. No OpenVDB here: the shell is queried through ShellProbe. docs/pieces.md, "Tenons".
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/core/vec.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces {

/// Which hole directions a piece may be mounted along (and so its tenons use).
enum class TenonHoles : uint8_t {
    Lattice,  ///< the six lattice axes ±x ±y ±z, the paper's "all of 6 slots"
    Blue,     ///< the 30 blue holes
    All,      ///< all 62: blue, yellow and red, so some direction is within about 20° of any normal
};
const char* tenonHolesName(TenonHoles holes);
/// The inverse of tenonHolesName; empty for any other name.
std::optional<TenonHoles> tenonHolesFromName(std::string_view name);

/// Dimensions and limits of the tenons (defaults: docs/pieces.md, "Tenon design").
struct TenonOptions {
    int minPerPiece = 2;  ///< aim: pieces with fewer are reported, with the reasons
    int maxPerPiece = 4;  ///< 0 = no tenons
    /// Gap between the peg and the hole on every side; the peg is the hole's section inset by this.
    /// With a 4 mm peg, 0.15 mm lets the piece go on up to about 2° off its direction.
    double clearanceMm = 0.15;
    double pegDepthMm = 4.0;   ///< how far the peg enters the hole (ZomeFab's LATCH, 4 mm)
    double bodyWidthMm = 7.0;  ///< side of the square stem at the ball's face
    /// Half-angle of the stem's taper (a boss that widens toward the wall): each side moves out by
    /// tan(taperDeg) per mm from the ball's face. A lateral force F at the peg bends a section ℓ
    /// from the peg's tip with stress 6Fℓ/w³ (a square of side w), so a stem as strong as its
    /// root needs w(ℓ) ≥ w₀ (ℓ/ℓ₀)^(1/3); 4° keeps that up to maxLengthMm (docs/pieces.md).
    double taperDeg = 4.0;
    /// Longest stem, from the ball's face to the inner surface: a thin wall stands up to d_min
    /// (16 mm) from the frame, so the stems bridge that gap and the forbidden zone's depth.
    double maxLengthMm = 60.0;
    /// Largest angle between the tenon's axis and the inner surface's normal (§6.1: "perpendicular").
    /// The prism's end is buried deeper on a tilted wall (r·tan(tilt) more), so the bond does not
    /// suffer; through a wall too thin to bury it the stem runs on and is cut a skin inside the
    /// outer surface (Tenon::cutAlongMm), or the ray is refused ("surface too oblique for the wall"). All
    /// pegs of a piece share its direction, so on limbs and round bodies most walls meet it
    /// obliquely: 60° instead of 35° puts 9 more of the 73 pieces of the armadillo, the
    /// elephant and the dino at 400–500 mm on two pegs (docs/pieces.md).
    double maxTiltDeg = 60.0;
    /// Depth of the prism in the wall beyond the axis's surface point, on top of what a tilted
    /// surface needs to bury the whole end face.
    double embedMm = 1.5;
    double frameClearanceMm = 0.5;  ///< extra gap between the prism and struts or other balls
    TenonHoles holes = TenonHoles::All;
};

/// @throw Error(Usage) naming the option when a value is out of range.
void checkTenonOptions(const TenonOptions& options);

/// The holes of @p holes (ascending).
std::vector<int> tenonHoleSet(TenonHoles holes);

/// The blue peg's section: the hole less the clearance on every side (long and short side, mm).
double pegLongMm(const TenonOptions& o);
double pegShortMm(const TenonOptions& o);
/// Coarsest shell voxel that still resolves the tenons' prisms: two voxels across. (The pegs are
/// exact meshes of their own, pegMesh, whatever the voxel.)
inline double maxVoxelForTenonsMm(const TenonOptions& o) { return 0.5 * o.bodyWidthMm; }
/// Radius of the capsule around the prism that the collision tests use (its half-diagonal).
double bodyRadiusMm(const TenonOptions& o);
/// Half the stem's side @p fromFaceMm from the ball's face (the taper), mm.
double stemHalfWidthMm(const TenonOptions& o, double fromFaceMm);

/// A cut stem's lines (Tenon::cutAlongMm): kCutSide × kCutSide across its section, corners
/// included, at fractions −1, −½, 0, ½, 1 of its half-width.
inline constexpr int kCutSide = 5;
inline constexpr int kCutLines = kCutSide * kCutSide;
inline double cutLineFraction(int i) { return -1.0 + 2.0 * i / (kCutSide - 1); }

/// One tenon. Distances are along the axis from the ball's centre, in mm.
struct Tenon {
    zome::BallId ball = zome::kNoId;
    int hole = 0;  ///< 0..61 (zome_system.h numbering): the piece's direction
    uint32_t piece = 0;
    Vec3d axisFrame{0, 0, 1};     ///< zome::holeDirection(hole): exact, frame coordinates
    Vec3d axisGrid{0, 0, 1};      ///< the same in the grid's mm (rotated by frameToGridMm)
    Vec3d longSideGrid{1, 0, 0};  ///< the section's x axis (grid): zome::holeSectionAxis(hole), rotated
    Vec3d ballCenterGridMm{0, 0, 0};
    double shoulderMm = 0.0;  ///< the ball's face around the hole, where the prism ends and the peg starts
    double baseMm = 0.0;      ///< where the axis meets the inner surface
    double endMm = 0.0;       ///< where the prism ends inside the wall
    double pegTipMm = 0.0;    ///< the peg's end in the hole: shoulderMm − pegDepthMm
    double tiltDeg = 0.0;     ///< angle between the axis and the inner surface's normal
    /// A wall too thin to bury the stem's square end (a thin wall met obliquely): the stem runs
    /// on through the wall and is cut a skin inside the outer surface, along a surface that
    /// follows it. cutAlongMm[i·kCutSide + j]: where the stem's line at fractions
    /// (cutLineFraction(i), cutLineFraction(j)) of its half-width (long side, short side) is cut,
    /// mm along the axis from the ball's centre; bilinear between the lines (cutAlongAtMm).
    bool isCut = false;
    std::array<double, kCutLines> cutAlongMm{};

    bool isClipped() const { return isCut; }
    /// Where the cut meets the stem's line at fractions @p fl, @p fs ∈ [−1, 1] of its half-width
    /// (clamped), mm along the axis: bilinear in cutAlongMm.
    double cutAlongAtMm(double fl, double fs) const;
    /// Where the axis meets the cut, mm from the ball's centre (a cut tenon only).
    double clipAlongAxisMm() const { return cutAlongMm[kCutLines / 2]; }

    double lengthMm() const { return baseMm - shoulderMm; }
    Vec3d pointAt(double t) const {
        return {ballCenterGridMm[0] + t * axisGrid[0], ballCenterGridMm[1] + t * axisGrid[1],
                ballCenterGridMm[2] + t * axisGrid[2]};
    }
};

/// The point of stem @p t's line at fractions @p fl, @p fs (−1..1) of its half-width along the long
/// and the short side, @p alongMm along the axis from the ball's centre (the lines spread with the
/// taper), grid mm.
Vec3d stemPointMm(const Tenon& t, const TenonOptions& options, double alongMm, double fl, double fs);

/// How far @p pGridMm lies beyond cut stem @p t's cut, mm along the axis (negative: on the printed
/// side); −1e30 for a stem not cut.
double beyondCutMm(const Tenon& t, const TenonOptions& options, const Vec3d& pGridMm);

/// The peg's section for @p hole: its hole's section (zome::holeSectionMm) inset by the clearance,
/// in the section's frame (x along longSideGrid, y = axis × x), mm.
std::vector<std::array<double, 2>> pegSectionMm(int hole, const TenonOptions& options);

/// Signed distance to the tenon's prism, negative inside, in the grid's mm: the square prism from
/// just short of the ball's face (0.3 mm) to its end in the wall; exact. The peg is not in it: a
/// few voxels across, a voxel mesh would round it by a tenth of its clearance (pegMesh).
double tenonSignedDistanceMm(const Tenon& tenon, const TenonOptions& options, const Vec3d& pGridMm);

/// The peg as an exact closed mesh (grid mm, outward): its section (pegSectionMm) extruded from
/// 1.5 mm inside the prism to the tip, with a 0.4 mm chamfer round the tip. It overlaps the
/// meshed prism, as a second shell of the piece's mesh (slicers print the union).
TriMesh pegMesh(const Tenon& tenon, const TenonOptions& options);
/// Points (grid mm) whose convex hull holds the tenon solid: the corners of the stem's two ends
/// and the peg's section at its tip (the peg is narrower than the stem's start, checkTenonOptions).
std::vector<Vec3d> tenonHullMm(const Tenon& tenon, const TenonOptions& options);
/// Axis-aligned box (grid mm) around the tenon solid (of tenonHullMm).
Box3d tenonBoundsMm(const Tenon& tenon, const TenonOptions& options);

/// What the planner asks about the shell and its pieces, in the grid's mm. Serial use.
struct ShellProbe {
    std::function<double(const Vec3d&)> signedDistanceMm;  ///< φ of the shell, trilinear
    /// The piece owning the voxel nearest to a point in the wall or within its narrow band; −1
    /// farther out. Callers ask φ first: only points with φ < 0 are in the piece's material.
    std::function<int64_t(const Vec3d&)> pieceAt;
    double voxelMm = 1.0;
    double wallMm = 16.0;  ///< the wall's thickness (Fabrication::wallMm): a stem's end stays inside it

    /// Unit normal of the shell's level set at @p p (outward of the material: out of the wall), by
    /// central differences half a voxel apart.
    Vec3d normalAt(const Vec3d& p) const;
};

/// One ray from a ball along a hole: the tenon it would be, and why not (empty = usable).
struct TenonCandidate {
    Tenon tenon;
    int64_t piece = -1;     ///< the piece the ray meets, −1 when it meets none
    std::string rejection;  ///< "hole holds a strut", "too far", "surface too oblique", ...
    double score = 0.0;     ///< larger is better: perpendicular and short
    /// The piece is a stave (detail/staves.h): its stems and another's out of one ball are tested
    /// for a meeting as prisms (stemsMeet), not by their round bounds.
    bool isStave = false;
};

/// Do the stems of @p a and @p b (their tapered prisms, tenonHullMm's first 8 points) come within
/// the frame's clearance of each other? Separating axes: each stem's axis and section sides and
/// their cross products; the slant of the taper makes the test err toward a meeting.
bool stemsMeet(const Tenon& a, const Tenon& b, const TenonOptions& o);

/// The ray of ball @p id along @p hole: where it meets the wall, which piece, and why it cannot be a
/// tenon (empty rejection: it can).
TenonCandidate tenonCandidate(const zome::Structure& frame, zome::BallId id, int hole,
                              const Transform4d& frameToGridMm, const ShellProbe& probe,
                              const TenonOptions& options);

/// The rays of every ball along every hole of options.holes, in (ball id, hole) order.
std::vector<TenonCandidate> findTenonCandidates(const zome::Structure& frame,
                                                const Transform4d& frameToGridMm, const ShellProbe& probe,
                                                const TenonOptions& options);

/// What is in the way of @p tenon's prism (as a capsule of bodyRadiusMm from the shoulder to its end):
/// "strut 12 (B0) in the way", "ball 4 in the way", or empty when the path is clear.
/// Struts and balls are the frame's collision proxies (zome::Structure).
std::string tenonObstruction(const zome::Structure& frame, const Tenon& tenon, const TenonOptions& options);

/// The chosen tenons per piece and, for pieces with fewer than minPerPiece, why.
struct TenonPlan {
    std::vector<std::vector<Tenon>> perPiece;
    std::vector<std::map<std::string, int>> shortfall;
};

/// Picks the tenons of every piece among the candidates along its direction @p holeOfPiece[p]
/// (−1: none), greedily: round-robin over the pieces, best score first, preferring a ball far
/// from the ones already chosen (three not on one line hold best), skipping any that would come
/// within 2 · bodyRadiusMm of one already chosen (the prisms of different pieces must not touch).
/// Deterministic.
TenonPlan chooseTenons(const std::vector<TenonCandidate>& candidates, const std::vector<int>& holeOfPiece,
                       const TenonOptions& options);

}  // namespace zomefab::pieces
