// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Staves (internal to lib/zomefab/pieces): where three tunnels cross at one point, each
/// tunnel's lining, carved along its prism (detail/prisms.h) with a later axis keeping the shell
/// where prisms overlap, is cut into rings and each ring into four staves. A stave reaches its place
/// only along its tunnel: it slides in held off its wall toward the axis, then is pushed onto pegs
/// of balls behind the wall (mount::MountStep's two legs). docs/mounting.md, "Three tunnels through
/// one point".
#pragma once

#include <array>
#include <cstddef>
#include <optional>
#include <tuple>
#include <vector>

#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/prisms.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces::detail {

/// A stave: a piece of the lining of a tunnel that crosses two others at one point. Its place is
/// reached only along its tunnel, out of the nearer mouth, held off its wall toward the axis, and it
/// is then pushed onto pegs of balls behind the wall (docs/mounting.md, "Three tunnels through one
/// point"). Staves go on before every other piece: x tunnels' first, then y's, then z's, then the
/// late tunnels' (TunnelPrism::priority: each later one keeps the shell where prisms overlap, so a
/// stave's way meets only staves of its own tunnel), along a tunnel the deepest first, in a ring the
/// side staves (across u) first.
struct Stave {
    Vec3d slideGrid{0, 0, 0};  ///< unit, along the axis: the way it slides off, out of its mouth
    Vec3d liftGrid{0, 0, 0};   ///< unit, across the axis and out of it: the way it is pushed on
    Vec3d seamGrid{0, 0,
                   0};    ///< unit, across the axis: the normal of the seams between side staves and the rest
    bool isSide = false;  ///< a side stave (beyond the seams across seamGrid), else top or bottom
    /// The mounting order, lowest first: priority (TunnelPrism::priority), tunnel (its core's middle), mouth,
    /// −depth from the mouth, side (0) or top and bottom (1), then the lift's sign.
    std::tuple<int, double, double, double, double, int, double> rank;
};

/// Rings of staves are no longer than this (mm): long enough that a ring round a crossing, whose
/// ridges alone are narrow, takes wall behind which balls lie; short enough for a printer's bed.
inline constexpr double kStaveRingMm = 160.0;

/// How far a stave's direction may lean along its axis off its lift (degrees): the red and yellow
/// holes beside a lift square to the grid (31.7°, 20.9°), and the yellow holes (±1, ±1, ±1) beside a
/// lift along a diagonal of a turned ring (35.26°).
inline constexpr double kStaveLeanDeg = 36.0;

/// Whether a stave may take the direction @p d (grid, unit; the hole's, toward the tunnel's axis):
/// within kStaveLeanDeg of its lift reversed, leaning only along the axis and not back toward the deeper
/// rings, which are on. Leaning round the axis, its lift (up to a stem's length) would carry a top
/// stave across its seams into the side staves, which are on, and a side stave's edges out of the
/// prism past the corners, into the frame.
bool isStaveDirection(const Stave& stave, const Vec3d& d);

/// After a plan that cannot be carried out: when staves (@p sets) are placed nowhere, the plan's
/// first problem says how many and why, how many of them lie under a wall too thin for a ball
/// (staveUnderThinWall, with @p thinGapMm), and Pieces::crossingTunnelPieces is set (another
/// partition leaves the same tunnels and the same frame behind them). Returns how many.
size_t noteUnheldStaves(Pieces& out, const std::vector<CellSet>& sets, const VoxelField& field,
                        double thinGapMm);

/// The hollow a ball needs between two walls (mm): its diameter and, on each side, the air the
/// frame keeps beyond the wall (@p frameDMinMm − @p wallMm).
inline double ballGapMm(double ballRadiusMm, double frameDMinMm, double wallMm) {
    return 2.0 * (ballRadiusMm + frameDMinMm - wallMm);
}

/// Whether the stave (@p voxelsMm, grid mm; its own piece @p p) lies under a wall too thin for a
/// ball behind it: from most of the voxels at its wall's back along its lift (hollow beyond them),
/// another piece's wall begins within @p thinGapMm of hollow (the cheese at 700 mm: a face 13.5 mm
/// away). Such a stave no peg can hold, however the frame grows.
bool staveUnderThinWall(const Stave& stave, uint32_t p, const std::vector<Vec3d>& voxelsMm,
                        const VoxelField& field, double thinGapMm);

/// How many staves (@p sets) a plan places nowhere (@p holeOfPiece −1).
size_t unplacedStaves(const std::vector<int>& holeOfPiece, const std::vector<CellSet>& sets);

/// The tunnels (each once) of the staves a plan places nowhere (@p holeOfPiece −1): made late in
/// another attempt (Grouping::lateTunnels), their staves may glue onto the crossing tunnels'.
std::vector<TunnelKey> unheldTunnels(const std::vector<int>& holeOfPiece, const std::vector<CellSet>& sets);

/// Whether @p plan glues piece @p p on (a stave glued in place: no peg holds it).
bool isGluedOn(const mount::InstallationPlan& plan, uint32_t p);

/// How many staves (@p sets) no peg holds in @p plan: placed nowhere or glued in place.
size_t peglessStaves(const mount::InstallationPlan& plan, const std::vector<CellSet>& sets);

/// Whether @p set's piece lines a staved prism: a stave or a mouth ring (CellSet::isMouthRing).
bool isStavedLining(const CellSet& set);

/// Whether @p set's piece is a stave (a staved prism's lining but not a mouth ring), which no
/// re-cut may cut across its seams.
bool isStaveSet(const CellSet& set);

/// The four ways the staves of a ring of a lining along grid axis @p axis are lifted (grid, unit):
/// +u, −u (the side staves), +v, −v (top and bottom), u and v the next grid axes, or their
/// diagonals (u + v)/√2 and (v − u)/√2 when @p isTurned.
std::array<Vec3d, 4> staveLifts(int axis, bool isTurned);

/// The stave @p set's piece is (its voxels' centres @p voxelsMm, grid mm), or none for a piece that
/// lines no staved prism.
std::optional<Stave> staveOf(const CellSet& set, const std::vector<Vec3d>& voxelsMm);

/// A mouth ring's way out of its mouth along its tunnel (grid, unit): toward the mouth on the side of
/// its tunnel's split its voxels' centres (@p voxelsMm, grid mm) lie on, as a stave's slide; none
/// for a piece that is not a mouth ring (CellSet::isMouthRing).
std::optional<Vec3d> mouthRingSlide(const CellSet& set, const std::vector<Vec3d>& voxelsMm);

/// A staved lining at a mouth no longer than this many walls stays one ring (cutStaves).
inline constexpr double kMouthRingWalls = 3.0;

/// Whether a lining of @p prism whose voxels' centres lie between @p loMm and @p hiMm along its axis
/// stays one mouth ring: it reaches a mouth and is no longer than kMouthRingWalls walls (@p wallMm),
/// or ends before the first crossing from that mouth while the hollow between the face's wall and
/// that crossing tunnel's wall is too thin for a ball (@p thinGapMm): the cheese at 700 mm, 87.5 mm
/// from a face to the axis of a crossing 88 mm across, 11.5 mm of hollow.
bool isMouthRingExtent(const TunnelPrism& prism, double loMm, double hiMm, double voxelMm, double wallMm,
                       double thinGapMm);

/// Every lining of a staved prism cut where its tunnel is split (TunnelPrism::splitMm: each half
/// slides out of its own mouth) and where tunnels cross it (TunnelPrism::crossingsMm), each segment
/// into equal rings no longer than kStaveRingMm, each ring
/// into four staves: across u at ±√½ of the core's radius (the side staves, whose seams are across
/// their lift), then across v at the middle (top and bottom, sliding along the side staves' seams as
/// they are lifted). A lining that isMouthRingExtent (@p wallMm, @p thinGapMm) stays one ring, a
/// mouth ring (CellSet::isMouthRing): behind it lies only the face's wall, no ball. A lining whose
/// staves, cut square to the grid, would lie under a wall too thin for a ball (staveUnderThinWall
/// with @p thinGapMm) more often than turned 45° about the axis is cut turned
/// (CellSet::isStaveTurned): under a face, a tunnel's stave facing the face has no room for a ball
/// behind it, one facing the diagonal between the face and the inside has. Sets each ring's depth
/// (CellSet::ringDepthMm). A cut at a crossing or a seam that would leave less than @p minVolumeMm3
/// on one side is not made: that side stays with the rest. Returns how many cuts; pieces the cuts
/// left empty are the caller's to drop.
size_t cutStaves(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field, double wallMm,
                 double thinGapMm, double minVolumeMm3);

/// How far a stave is held off its place while it slides (mm) before its tenons are known: its
/// pegs' depth (4 mm) and as much again (setStaveLifts makes it longer).
inline constexpr double kStaveLiftMm = 8.0;

/// Each stave's lift (the plan's steps of two legs) once its tenons are known: held that far off
/// its place along its direction, every peg's tip lies at least 2 mm shallower under its wall than
/// the frame may come (@p frameDMinMm), so its stems slide along the tunnel past no ball and no
/// strut. Depth is taken across the wall (of the ways its ring's staves are lifted, staveLifts,
/// the nearest the direction reversed), from the stave's voxel nearest the tunnel's axis (a voxel's
/// half under the surface).
void setStaveLifts(Pieces& out, const std::vector<CellSet>& sets, const VoxelField& field,
                   const Transform4d& frameToGridMm, double frameDMinMm);

}  // namespace zomefab::pieces::detail
