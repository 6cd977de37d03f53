// SPDX-License-Identifier: GPL-3.0-or-later
/// @file From voxels to pieces (internal to lib/zomefab/pieces): the connected components of
/// shell ∩ cell, grouped by the partition's pieces, small ones and shell outside every named cell
/// merged into a neighbour, the owner of every voxel, and each piece's cells. docs/pieces.md §1.
#pragma once

#include <cstdint>
#include <map>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/partition/partition_result.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces::detail {

/// One connected component of shell ∩ cell.
struct Component {
    uint32_t cell = 0;
    size_t voxels = 0;
    uint32_t group = 0;  ///< request index, or requests.size() + component index for an orphan
};

/// The connected components of the inside voxels (6-neighbours, same cell), numbered in slot
/// order; every inside voxel's owner becomes its component. Serial, deterministic.
std::vector<Component> findComponents(VoxelField& field);

/// Voxel faces between inside voxels of different components, per (lower, higher) component.
std::map<std::pair<uint32_t, uint32_t>, size_t> componentContacts(const VoxelField& field);

/// Each component's group: the partition piece (request) that names its cell; when several do,
/// the one whose surface box grown by @p growMm holds most of its voxels; when none does, an
/// orphan group of its own. Returns the volume of the orphans (mm³).
double assignGroups(std::vector<Component>& comps, const VoxelField& field,
                    const std::vector<partition::Piece>& requests, size_t cellCount,
                    const Transform4d& gridToFrame, double growMm, double voxelVolumeMm3);

/// One planar cut face between two pieces: its normal, from the lower piece into the higher, and
/// its size in voxel faces.
struct CutContact {
    Vec3d normal{0, 0, 1};
    size_t voxelFaces = 0;
    /// A stave's border, one of the six ways a voxel step goes: it orders its two pieces however
    /// small (the voxels near it are left out of their sweeps, as near any large face).
    bool isStaveBorder = false;
};
/// The cut faces between pieces: for the pieces (a, b), a < b, one entry per plane they share,
/// the plane between a cell of a and a cell of b, or a plane one was re-cut along; where two pieces
/// share a cell and no plane separates them, the voxels' border with its mean normal
/// (docs/mounting.md, "Order").
using FaceContacts = std::map<std::pair<uint32_t, uint32_t>, std::vector<CutContact>>;

/// The cut faces between the pieces that own the inside voxels of @p field, with their planes
/// from @p cells and @p sets, and every piece's neighbours with the contact areas (mm²).
FaceContacts faceContacts(const VoxelField& field, const GridCells& cells, const std::vector<CellSet>& sets,
                          std::vector<Piece>& pieces);

/// A staved tunnel by its axis and its core's middle across it (grid mm, TunnelPrism): the same
/// in another attempt at the same shell.
struct TunnelKey {
    int axis = 0;
    double centerUMm = 0.0, centerVMm = 0.0;
    int level = 1;  ///< how late (TunnelPrism::priority): the attempt after which it was made so
};

/// What the grouping made: the pieces (ids, cells, requests, neighbours, slivers, shell volume),
/// their cell sets, the cut faces between them, and the merge counts.
struct Grouping {
    std::vector<Piece> pieces;
    std::vector<CellSet> cellSets;
    FaceContacts faces;
    double shellVolumeMm3 = 0.0;
    double outsideCellsVolumeMm3 = 0.0;
    size_t sliversMerged = 0;
    size_t isolatedSlivers = 0;
    /// Staved tunnels whose prisms keep every overlap and whose staves go on last (TunnelPrism::
    /// priority): in a later attempt, those with a ring none of whose staves a peg held before.
    std::vector<TunnelKey> lateTunnels;
    /// After a plan that cannot be carried out: the tunnels of the staves it placed nowhere.
    std::vector<TunnelKey> unheldTunnels;
    /// Staves still placed nowhere once the frame has grown toward them go on with the other
    /// pieces, glued in place (PlannerInput::isGluingUnheldStaves).
    bool isGluingUnheldStaves = false;
};

/// The whole grouping (docs/pieces.md §1, steps 2–4): components, groups, merges of orphans and
/// slivers under @p minPieceVolumeMm3 into the neighbour with the largest cut face, piece order,
/// the owners of band voxels, cell sets and neighbours. Warnings go to @p context.
Grouping groupPieces(VoxelField& field, const GridCells& cells, const std::vector<partition::Piece>& requests,
                     const Transform4d& gridToFrame, double growMm, double minPieceVolumeMm3,
                     const RunContext& context);

}  // namespace zomefab::pieces::detail
