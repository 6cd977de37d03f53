// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Printing two pieces as one (internal to lib/zomefab/pieces): a piece that fewer than
/// TenonOptions::minPerPiece pegs hold (a limb's tip, a piece beside the frame's reach) is joined
/// with a neighbour when the two fit the printer together and the union, pushed on along one free
/// direction, gets enough pegs. Nothing is glued then, and the maker has one piece less.
/// docs/mounting.md, "Merged pieces".
#pragma once

#include <optional>
#include <utility>
#include <vector>

#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces::detail {

/// Whether pieces @p a and @p b can become one piece: neither was re-cut by a plane, so each is a
/// union of cells and so is the union of the two.
bool isMergeable(const std::vector<CellSet>& sets, uint32_t a, uint32_t b);

/// Whether pieces @p a and @p b are the two halves of one piece cut by a plane (splitPiece): the
/// same cells, the same planes but one, which each has the other way round. Its index in their
/// planes, or empty. Their union is then the piece before the cut: exactly a cell region again.
std::optional<size_t> splitPlaneBetween(const std::vector<CellSet>& sets, uint32_t a, uint32_t b);

/// Makes piece @p gone part of piece @p keep (cells, requests, slivers, shell volume, voxels; the
/// cutters of the union recounted: a cell the two shared alone is no longer cut), removes @p gone
/// and numbers the pieces after it one lower (ids and voxel owners). Returns keep's new id. The
/// caller recomputes the face contacts (faceContacts). @pre isMergeable(sets, keep, gone), or the
/// two are the halves of one split (splitPlaneBetween; keep loses that plane).
uint32_t mergePieces(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field, uint32_t keep,
                     uint32_t gone);

/// What choosing merges needs besides the pieces.
struct MergeSearch {
    Vec3d printerMm{200, 200, 200};
    double fitMarginMm = 2.0;  ///< Fabrication::fitMarginMm
    int minPerPiece = 2;       ///< TenonOptions::minPerPiece: a piece with fewer pegs is under-held
    int maxPerPiece = 4;
};

/// A merge worth trying: an under-held piece, a neighbour, and what their union would have.
struct MergeOption {
    uint32_t piece = 0, neighbor = 0;
    size_t tenons = 0;     ///< candidates along the union's best free direction
    double areaMm2 = 0.0;  ///< their common cut face
};

/// Every merge worth trying: for each piece of @p pegs (per piece: the pegs the plan gives it)
/// under minPerPiece, smallest first, each neighbour mergeable with it whose union fits the
/// printer and has a free direction (against the frame) with at least minPerPiece tenon
/// candidates and more than the piece's own pegs; most tenons first, then the largest cut face.
/// Deterministic.
std::vector<MergeOption> mergeOptions(const std::vector<Piece>& pieces, const std::vector<CellSet>& sets,
                                      const VoxelField& field, const std::vector<size_t>& pegs,
                                      const PlannerInput& input, const FrameSweeps& sweeps,
                                      const MergeSearch& search);

/// The pairs of @p pairs, in order, that share no member with a pair kept before them: one
/// merge (or glue) per piece in a round.
std::vector<std::pair<uint32_t, uint32_t>> disjointPairs(
    const std::vector<std::pair<uint32_t, uint32_t>>& pairs);

/// Merges every pair of @p pairs (ids as before any of them), in order. Returns each piece's id
/// after the merges, by its id before them (a merged piece: the id of the piece it became part of).
std::vector<uint32_t> mergeAll(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field,
                               std::vector<std::pair<uint32_t, uint32_t>> pairs);

}  // namespace zomefab::pieces::detail
