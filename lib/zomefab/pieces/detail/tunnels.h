// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tunnel linings cut into slabs (internal to lib/zomefab/pieces): the pieces that line a
/// tunnel through the object get no peg (every straight path off a ball's hole crosses the tunnel
/// into the frame on its far side) and are glued on instead, sliding in along the tunnel. The
/// partition cuts the lining into pieces with long seams along the tunnel, across which nothing can
/// be glued on along it, and whose ends overlap: no order exists. Cut across the tunnel by planes
/// at the same offsets, the lining becomes rings of slabs: each slides in along the axis and is
/// glued onto the slab put on before it across a plane. docs/mounting.md, "Tunnels".
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/vec.h"

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

/// Where to cut a piece whose voxel centres lie at @p t along the axis (mm) into slabs: at the
/// multiples of @p slabMm inside its range, skipping a plane that would leave fewer than
/// @p minVoxels on either side of it (counted between the planes kept). Ascending. The same
/// multiples for every piece, so the slabs of all the lining's pieces line up.
std::vector<double> slabOffsets(const std::vector<double>& t, double slabMm, size_t minVoxels);

}  // namespace zomefab::pieces::detail
