// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tunnel linings cut into slabs (internal to lib/zomefab/pieces): the pieces that line a
/// tunnel through the object get no peg (every straight path off a ball's hole crosses the tunnel
/// into the frame on its far side) and are glued on instead, sliding in along the tunnel. The
/// partition cuts the lining into pieces with long seams along the tunnel, across which nothing can
/// be glued on along it, and whose ends overlap: no order exists. Cut across the tunnel by planes
/// at the same offsets, the lining becomes rings of slabs: each slides in along the axis and is
/// glued onto the slab put on before it across a plane. docs/mounting.md, "Tunnels".
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces::detail {

/// A tunnel's axis and the pieces lining it (stuck, held by no peg, free along the axis).
struct TunnelGroup {
    Vec3d axis{1, 0, 0};           ///< unit (grid mm); the pieces slide along +axis or −axis
    std::vector<uint32_t> pieces;  ///< sorted
    size_t lining = 0;             ///< how many pieces lined it when found (pieces may be joined since)
};

/// Groups pieces by a common axis: @p freeAlong[k] is piece @p pieces[k]'s free glue directions
/// (unit). An axis is a tunnel's when at least @p minPieces pieces are free along it both ways (a
/// tunnel open at both ends; along a limb the pieces are free outward only), and it takes every
/// piece free along it either way (a piece that reaches round a tunnel's mouth is free outward
/// only); the axis with the most pieces free along it both ways first (then the most pieces), then
/// the next among the rest. Directions within 1°
/// are one. Deterministic (ties: the first direction met).
std::vector<TunnelGroup> tunnelGroups(const std::vector<uint32_t>& pieces,
                                      const std::vector<std::vector<Vec3d>>& freeAlong, size_t minPieces = 2);

/// Tunnel linings are cut into slabs this long along the tunnel (mm): short enough that the seams
/// the partition left along the tunnel seldom zigzag within one slab, long enough not to double the
/// pieces of a lining 200 mm long.
inline constexpr double kTunnelSlabMm = 80.0;

/// Where to cut a piece whose voxel centres lie at @p t along the axis (mm) into slabs: at the
/// multiples of @p slabMm inside its range, skipping a plane that would leave fewer than
/// @p minVoxels on either side of it (counted between the planes kept). Ascending. The same
/// multiples for every piece, so the slabs of all the lining's pieces line up.
std::vector<double> slabOffsets(const std::vector<double>& t, double slabMm, size_t minVoxels);

/// The object's voxels seen along one grid axis: which columns (straight lines along the axis) meet
/// it. A column is indexed by the voxel indices (u, v) of the axes axis + 1 and axis + 2 (mod 3).
/// A shell's field will do for the object: a line that meets the object crosses its wall.
struct AxisShadow {
    int axis = 0;
    int loU = 0, loV = 0;        ///< the first column's indices (the voxel bounds less one)
    int sizeU = 0, sizeV = 0;    ///< columns across; one more than the voxels on every side
    std::vector<uint8_t> isHit;  ///< sizeU · sizeV, u major: the column meets the object

    /// The column (u, v) voxel @p ijk lies in.
    std::array<int, 2> columnOf(const Coord& ijk) const { return {ijk[(axis + 1) % 3], ijk[(axis + 2) % 3]}; }
    /// Where column (u, v) is kept in isHit; SIZE_MAX off the shadow.
    size_t slotOf(int u, int v) const {
        u -= loU, v -= loV;
        return u >= 0 && v >= 0 && u < sizeU && v < sizeV ? size_t(u) * size_t(sizeV) + size_t(v) : SIZE_MAX;
    }
    bool isHitAt(int u, int v) const {
        const size_t k = slotOf(u, v);
        return k != SIZE_MAX && isHit[k];
    }
    /// Marks column (u, v) as meeting the object (nothing off the shadow).
    void mark(int u, int v) {
        if (const size_t k = slotOf(u, v); k != SIZE_MAX) isHit[k] = 1;
    }
};

/// An empty shadow over the voxel bounds [@p lo, @p hi] (inclusive, grid indices) along @p axis.
AxisShadow emptyShadow(int axis, const Coord& lo, const Coord& hi);
/// Marks the column of voxel @p ijk as meeting the object.
void markHit(AxisShadow& shadow, const Coord& ijk);
/// Empty shadows along x, y and z over @p field's leaves' bounds (none for an empty field).
std::array<AxisShadow, 3> emptyShadowsOf(const VoxelField& field);
/// The shadows along x, y and z of @p field's inside voxels (empty for an empty field).
std::array<AxisShadow, 3> shadowsOf(const VoxelField& field);

/// A tunnel's core: the straight lines along a grid axis through the object's bounds that meet
/// none of it and are enclosed by it across the axis (a connected set of free columns that does
/// not reach the shadow's border; the lines round the object do).
struct TunnelCore {
    int axis = 0;
    std::vector<std::array<int, 2>> columns;  ///< (u, v) as in AxisShadow, sorted
    double diameterMm = 0.0;                  ///< of the circle with the columns' area
};

/// The cores along @p shadow's axis at least @p minDiameterMm across (by area; smaller ones are
/// gaps between voxels or pinholes, not tunnels a piece lines). Deterministic order (first column).
std::vector<TunnelCore> tunnelCores(const AxisShadow& shadow, double voxelMm, double minDiameterMm);

/// Do two cores along different axes cross, each line of one meeting lines of the other? Prisms
/// along two axes meet where they share a value of the third axis (the one along neither).
bool coresCross(const TunnelCore& a, const TunnelCore& b);

/// The cores of @p shadows (x, y, then z) at least @p minDiameterMm across (tunnelCores).
std::vector<TunnelCore> coresAlongAxes(const std::array<AxisShadow, 3>& shadows, double voxelMm,
                                       double minDiameterMm);

/// Per core: whether it crosses another (coresCross); @p pairs (optional): how many pairs cross.
std::vector<uint8_t> crossingFlags(const std::vector<TunnelCore>& cores, size_t* pairs);

/// The tunnels of an object that cross each other, and the pieces that line them.
struct CrossingTunnels {
    size_t tunnels = 0;    ///< cores that cross at least one other
    size_t crossings = 0;  ///< pairs of cores that cross
    double meanDiameterMm = 0.0;
    /// per piece: its share of inside voxels within reach of a crossing tunnel's core
    std::vector<double> liningShare;
};

/// The cores along x, y and z of @p field's inside voxels at least @p minDiameterMm across, which of
/// them cross, and each piece's share of voxels within @p reachMm of one that crosses (across its
/// axis): a piece lining such a tunnel, or round its mouth. Pieces are the field's owners
/// (@p pieceCount of them).
CrossingTunnels crossingTunnels(const VoxelField& field, size_t pieceCount, double minDiameterMm,
                                double reachMm);

/// How many of @p pieces line a tunnel that crosses another: half their voxels or more near one.
size_t liningPieces(const CrossingTunnels& tunnels, const std::vector<uint32_t>& pieces);

/// What a failed plan says when most of the pieces it placed nowhere line tunnels that cross
/// (docs/mounting.md, "What is not done"): empty when fewer than half of them (or fewer than
/// @p minPieces) do. @p unplaced: the pieces placed nowhere; @p lining (out): how many line them.
std::string crossingTunnelNote(const CrossingTunnels& tunnels, const std::vector<uint32_t>& unplaced,
                               size_t minPieces, size_t* lining);

/// The fewest pieces placed nowhere that noteCrossingTunnels puts down to crossing tunnels.
inline constexpr size_t kMinCrossingLining = 4;

/// After a plan that places pieces nowhere: how many of them line tunnels that cross (half their
/// voxels or more near the shell's own cores at least two walls across, crossingTunnels), when at
/// least kMinCrossingLining do and, with @p isMostRequired, most of them do; else 0. @p note
/// (optional, with @p isMostRequired) receives what the plan then says.
size_t crossingTunnelLining(const Pieces& out, const VoxelField& field, double wallMm, std::string* note,
                            bool isMostRequired);

/// After a plan that places pieces nowhere: when most of them line tunnels that cross (the shell's
/// own cores at least two walls across, crossingTunnels), says so as the plan's first problem and
/// sets Pieces::crossingTunnelPieces (so zomefab run does not partition again). Returns that count.
size_t noteCrossingTunnels(Pieces& out, const VoxelField& field, double wallMm);

}  // namespace zomefab::pieces::detail
