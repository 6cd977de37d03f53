// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The steps of makePieces after the grouping (internal to lib/zomefab/pieces): the tenons
/// and numbers planned against the shell, each piece's level set by CSG, and each piece's mesh
/// checked and turned for the printer. docs/pieces.md §2–5.
#pragma once

#include <openvdb/openvdb.h>

#include <string>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces::detail {

/// The installation plan (every piece's direction and the order, docs/mounting.md; pieces the
/// frame is in the way of re-cut, which changes @p field's owners and @p grouping's cell sets and
/// faces; pieces too few pegs hold merged with a neighbour, which renumbers them), then the tenons
/// (paper §6.1) along each piece's direction and the engraved numbers, against the shell @p shell.
/// @p fabrication: the wall (a stem's end stays in it) and the printer (what a merged piece must
/// fit). With @p canGrow, @p frame may grow toward pieces too few pegs hold (growFrameForPieces).
/// Warnings for pieces short of tenons or numbers.
void planPieces(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                const FloatGrid& shell, zome::Structure& frame, const Transform4d& frameToGridMm,
                const Fabrication& fabrication, const PiecesOptions& options, const StrutTest& canGrow,
                const RunContext& context);

/// For every piece, the leaves that hold its inside voxels and their 26 neighbours (the band is
/// three voxels wide).
std::vector<std::vector<uint32_t>> leavesOfPieces(const VoxelField& field, size_t pieceCount);

/// Per slot of @p field: 1 for the band voxels outside the wall 6-connected to the topmost one (the
/// object's outside), 0 for the rest (inside the wall, the hollow's band, and the band of any other
/// component of the object, which the outer surface's meshing then treats as inner).
std::vector<uint8_t> exteriorBand(const VoxelField& field);

/// One piece's level set ψ_P = max(φ_shell, δ_P) ∪ tenons − number, where the mesher keeps full
/// resolution (cut faces, around tenons and numbers; null when there are none) and where it merges
/// little (the outer surface next to @p exterior, exteriorBand; null at adaptivity 0).
struct PieceGrid {
    FloatGrid::Ptr grid;
    openvdb::BoolTree::Ptr fullResolution;
    /// The mesher's adaptivity scaled down on the outer surface (kOuterAdaptivityWeight), 1 elsewhere.
    FloatGrid::Ptr adaptivityWeight;
};
PieceGrid pieceGrid(const VoxelField& field, const GridCells& cells, const std::vector<CellSet>& sets,
                    const Piece& piece, const std::vector<uint32_t>& leaves,
                    const std::vector<uint8_t>& exterior, const openvdb::math::Transform& transform,
                    const PiecesOptions& options);

/// Checks @p mesh (closed, outward; sealed pockets filled), measures its cut faces, turns it onto
/// @p fabrication's printer bed and stores it in @p piece: within the bed less its margin on each
/// side (Fabrication::pieceBoxMm), centred on the bed, with the least support for the printer's
/// overhang. Returns the orientation's note (empty when a cut face lies on the bed).
/// @throw Error(ProcessingFailed) naming the piece when its mesh is not closed; PieceTooLarge when
/// it fits that box in no orientation.
std::string finishPiece(Piece& piece, TriMesh mesh, const GridCells& cells, const CellSet& set,
                        const Fabrication& fabrication, double voxelMm, double seamGapMm,
                        const RunContext& context);

}  // namespace zomefab::pieces::detail
