// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Keystones (internal to lib/zomefab/pieces): pieces that line a hole through the object (the
/// inside of a ring, a handle, a tunnel's mouth) form a closed ring, and the cut faces between them
/// meet toward the hole like the joints of an arch: each piece, taken off inward along any
/// direction that holds it, would go into its neighbours, so no order exists. A keystone is cut out
/// of one of them: two new planes parallel to its direction replace the faces that block it, the
/// wedges between them and the old faces become pieces of their own (slivers), and the keystone
/// goes on last, sliding between them. docs/mounting.md, "Keystones".
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <vector>

#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/splits.h"

namespace zomefab::pieces::detail {

/// A keystone cut of one piece: its direction, and per blocking cut face a plane parallel to it.
struct Keystone {
    uint32_t piece = 0;
    int hole = -1;  ///< the direction the keystone goes on along (its tenons' hole)
    /// Per plane: {m, c} with m·d = 0 and m pointing into the keystone; the piece's voxels with
    /// m·x < c (the wedge along the old face) become a sliver.
    std::vector<SplitPlane> planes;
};

/// The keystone of piece @p piece, whose inside voxels' centres are @p voxels and whose voxels
/// touching each neighbour are @p touching (by neighbour), with @p body its direction options
/// (tested against the frame) and @p candidates its usable tenon candidates: along the first free
/// direction d with tenons (rank order) that some cut face with a neighbour forbids (d·n < 0, n into
/// the piece; faces of at least kMinOrderFaceVoxels), one plane per such face, its normal n made
/// perpendicular to d, just past the piece's voxels on that face. Accepted when the face is not
/// square to d (then no plane parallel to d replaces it), every sliver and the keystone hold at least
/// @p search.minVolumeMm3 and the keystone keeps a tenon candidate along d clear of the planes by
/// @p search.edgeMarginMm. Empty when no direction gives one. Deterministic.
std::optional<Keystone> findKeystone(uint32_t piece, const std::vector<Vec3d>& voxels,
                                     const std::map<uint32_t, std::vector<Vec3d>>& touching,
                                     const MountBody& body, const FaceContacts& faces,
                                     const std::vector<const TenonCandidate*>& candidates,
                                     const Transform4d& frameToGridMm, const SplitSearch& search);

}  // namespace zomefab::pieces::detail
