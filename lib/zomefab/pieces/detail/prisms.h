// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The linings of two tunnels that cross, carved out of the partition's pieces (internal to
/// lib/zomefab/pieces). The partition's pieces at a crossing hold parts of both linings and meet the
/// frame along every direction. Each tunnel's lining is carved out along its prism instead (its core
/// grown across its axis by a wall and two voxels): a piece inside a prism slides along the tunnel past no
/// ball and no strut. Where two prisms overlap the earlier axis (x, then y, then z) keeps the shell, so its
/// lining runs through the crossing unbroken and goes on as glued rings, and the other tunnel's
/// segments end against it with faces across their own axis, each glued onto a ring at its far
/// end (docs/mounting.md, "Tunnels that cross"). Where three tunnels cross at one point no lining
/// crosses the crossing's middle and glue alone cannot hold every segment: there the prisms are
/// staved, a later axis keeps every overlap, and the linings are cut into staves (detail/staves.h).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <tuple>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/tunnels.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces::detail {

/// A tunnel's prism: the straight lines within radiusMm of its core's lines (across its axis),
/// between two planes across the axis. With a radius under the frame's clearance, a point of it lies
/// closer to the surface than any ball or strut may (the nearest core line runs outside the
/// object), so it holds only the lining's shell.
struct TunnelPrism {
    int axis = 0;
    int loU = 0, loV = 0;      ///< the raster's first column (voxel indices along axis + 1, axis + 2)
    int sizeU = 0, sizeV = 0;  ///< columns in the raster
    std::vector<float> coreDistanceMm;  ///< per column (u major): to the nearest core column's centre
    double radiusMm = 0.0;
    double loMm = 0.0, hiMm = 0.0;  ///< its ends along the axis (grid mm)
    double voxelMm = 1.0;
    Vec3d originMm{0, 0, 0};  ///< grid mm of voxel index (0, 0, 0)
    /// Its lining is cut into staves (three tunnels cross at one point): a later axis keeps the
    /// shell where prisms overlap.
    bool isStaved = false;
    /// Where staved prisms overlap, the one of the highest priority keeps the shell, and its staves
    /// go on after the others' (Stave::rank): its axis (x 0, y 1, z 2), plus kLatePriority times
    /// its level for a tunnel made late (TunnelKey; its rings' staves glue onto the crossing
    /// tunnels' staves).
    int priority = 0;
    double centerUMm = 0.0, centerVMm = 0.0;  ///< the core's middle across the axis (grid mm)
    double coreRadiusMm = 0.0;                ///< half the core's extent across the axis
    /// Where the staved prisms of other axes cross it (grid mm along its axis, in order), each with
    /// the largest radius of the cores crossing there (markCrossings).
    std::vector<std::pair<double, double>> crossingsMm;

    /// Where its lining is cut in two, each half sliding out of its own mouth (grid mm): of the
    /// crossings (where three tunnels cross the lining is broken anyway) the one nearest its middle,
    /// the lower on a tie; its middle when none is known.
    double splitMm() const;
    /// The point of its core's middle line where the grid's axis coordinate is 0 (grid mm).
    Vec3d axisPointMm() const;

    /// The core distance of column (u, v); a far value off the raster.
    double columnDistanceMm(int u, int v) const;
    /// Whether voxel @p ijk lies in the prism: its column within the radius, its centre between the ends.
    bool contains(const Coord& ijk) const;
    /// Signed distance to the prism at @p x (grid mm, negative inside): the core distance
    /// interpolated between the four nearest columns less the radius, and the distances past the ends.
    double signedDistanceMm(const Vec3d& x) const;
};

/// Added to a late tunnel's priority per level (TunnelPrism::priority): above every axis.
inline constexpr int kLatePriority = 3;

/// Whether @p a and @p b name one tunnel: the same axis, their cores' middles within @p toleranceMm.
bool isSameTunnel(const TunnelKey& a, const TunnelKey& b, double toleranceMm);
/// @p prism's tunnel (at level 1).
TunnelKey tunnelKeyOf(const TunnelPrism& prism);
/// Whether @p prism is @p key's tunnel (isSameTunnel).
bool isTunnelOf(const TunnelKey& key, const TunnelPrism& prism, double toleranceMm);

/// The prism of @p core (the columns of @p field's grid within @p radiusMm of its columns'
/// centres), ends at @p loMm and @p hiMm along its axis.
TunnelPrism tunnelPrism(const TunnelCore& core, const VoxelField& field, double radiusMm, double loMm,
                        double hiMm);

/// Which prism each slot of @p field lies in: of the prisms holding it, the one of the earliest axis
/// (with @p isLaterFirst the highest TunnelPrism::priority); kNone for none. Per slot, band included.
std::vector<uint32_t> prismOwners(const VoxelField& field, const std::vector<TunnelPrism>& prisms,
                                  bool isLaterFirst = false);

/// The prisms of the tunnels of @p field that cross (tunnelCores at least @p minDiameterMm across,
/// coresCross), each @p radiusMm round its core and ending @p endMm inside the object's voxels along
/// its lines (the mouth's own shell stays with the pieces round it). Empty when no two cross.
/// Where three cross at one point @p isTriple is set, and the prisms are staved ones (isStaved,
/// ending at the object's last voxels: the staves slide out through the mouths) with
/// @p isStaving, else none.
std::vector<TunnelPrism> crossingPrisms(const VoxelField& field, double minDiameterMm, double radiusMm,
                                        double endMm, bool* isTriple, bool isStaving = false);

/// Sets every staved prism's crossings (TunnelPrism::crossingsMm): a prism of another axis whose
/// core's middle lies within this one's core radius across both, and between the ends of both.
void markCrossings(std::vector<TunnelPrism>& prisms);

/// The prism a lining's cell set keeps inside, or null.
const TunnelPrism* ownPrism(const CellSet& set);

/// The extent of @p slots' inside voxels along grid axis @p a (mm): lowest and highest centre.
std::pair<double, double> extentAlong(const VoxelField& field, const std::vector<size_t>& slots, int a);

/// The linings of crossing tunnels carved out of the pieces (see the file's comment): every inside
/// voxel of a prism goes to a new piece, one per connected part of the voxels a prism owns (parts
/// under a cubic centimetre stay with their piece); pieces left with no voxels are dropped and the
/// rest renumbered; each remaining piece's cell set keeps out of every prism, each new one keeps to
/// its prism and out of the earlier axes' prisms; the band's owners follow; what is left of a piece
/// under @p minPieceVolumeMm3 joins a neighbour. Then every lining is cut across its axis into equal
/// rings no longer than kTunnelSlabMm and the face contacts are made again. Prisms of radius
/// @p wallMm plus two voxels; nothing is carved unless the wall is under @p frameDMinMm. Returns how
/// many pieces line the tunnels (0: nothing changed). Where three tunnels cross at one point the
/// prisms are staved: a later axis keeps the shell where they overlap, each lining is cut at its
/// tunnel's middle, into rings, and each ring into four staves by planes along the axis at ±√½ of
/// the core's radius across u and at the middle across v (Stave), or turned 45° about the axis
/// where fewer staves then lie under a wall too thin for a ball (@p thinGapMm, cutStaves). With
/// @p isOnlyWhereThreeCross nothing is carved unless three tunnels cross at one point. The staved
/// prisms of @p lateTunnels keep every overlap and their staves go on last (TunnelPrism::priority).
size_t carveCrossingLinings(std::vector<Piece>& pieces, Grouping& grouping, VoxelField& field,
                            const GridCells& cells, double wallMm, double frameDMinMm, double thinGapMm,
                            double minPieceVolumeMm3, const RunContext& context,
                            bool isOnlyWhereThreeCross = false);

}  // namespace zomefab::pieces::detail
