// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Alignment pins between glued pieces (internal to lib/zomefab/pieces): where on their
/// common cut face they go, and their solids (a pin unioned into one piece, a socket cut from the
/// other). docs/mounting.md, "Glued groups".
#pragma once

#include <vector>

#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces::detail {

/// For every glued pair (a, b) of @p out.plan, up to PinOptions::perPair pins on the largest plane
/// they share, as far apart as it allows, each where the wall is thick enough round it and the pin
/// and its socket stay inside the two pieces; the pin on the lower piece, along the plane's normal,
/// the socket in the other. For every pair glued on (host, piece), the pins on the host along the
/// piece's direction, on the largest plane that direction meets at most acos(@p minCosine) off its
/// normal. Fills Piece::pins and returns how many pairs got fewer than asked (a note, not an
/// error: glue holds them).
size_t placePins(Pieces& out, const VoxelField& field, const GridCells& cells,
                 const std::vector<CellSet>& sets, const PiecesOptions& options, double minCosine);

/// Signed distance to the solid of @p pin as seen from its piece: the pin (negative inside) for
/// the piece that has it, the socket (the pin grown by the clearance, 0.3 mm deeper) for the other.
double pinSignedDistanceMm(const AlignmentPin& pin, double clearanceMm, const Vec3d& pGridMm);
/// Axis-aligned box around that solid.
Box3d pinBoundsMm(const AlignmentPin& pin, double clearanceMm);

}  // namespace zomefab::pieces::detail
