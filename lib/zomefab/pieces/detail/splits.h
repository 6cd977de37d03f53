// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Re-cutting a piece no direction can mount (internal to lib/zomefab/pieces): a piece whose
/// wall wraps around part of the frame (a ring around a limb, a cap over a ball) meets a ball or a
/// strut along every direction. Cut in two by a plane, each half can often be pushed on from its
/// own side. The halves are new pieces: the cells' region of the old one, each intersected with
/// one side of the plane (CellSet::halfSpaces), so the new cut face is exactly planar and both
/// halves see the same plane. docs/mounting.md, "Re-cut pieces".
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "zomefab/partition/printer_fit.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/voxels.h"

namespace zomefab::pieces::detail {

/// A cell index (i, j, k) packed into one key (21 bits each, wrapping: the grids here span far
/// fewer than 2^21 cells).
inline int64_t packCell(int64_t i, int64_t j, int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
}

/// A cut plane: the part with normal·x > offsetMm becomes the new piece (grid mm).
struct SplitPlane {
    Vec3d normal{0, 0, 1};
    double offsetMm = 0.0;
};

/// What a split search needs beyond the piece itself.
struct SplitSearch {
    double voxelMm = 1.0;
    Vec3d originMm{0, 0, 0};       ///< the voxel grid's origin (to find voxel neighbours)
    double minVolumeMm3 = 2000.0;  ///< each half at least this (PiecesOptions::minPieceVolumeMm3)
    /// Tenon candidates whose wall point lies closer than this to the plane are lost with the cut.
    double edgeMarginMm = 6.0;
    int maxPerPiece = 4;
};

/// The best plane that cuts the piece of @p voxels (all its inside voxels' centres) into two
/// connected halves: both with a free direction along which at least one of its tenon candidates
/// (@p candidates: the piece's usable ones) holds it, in directions that let one go on after the
/// other across the plane, the one whose weaker half has the most tenons; else one half held
/// (the other is cut again, or glued on). Planes tried: 13 directions (the axes, the face and the
/// body diagonals of the grid) through the median of the piece's voxels along each, then through
/// its thirds. Empty when none works.
std::optional<SplitPlane> findSplit(const std::vector<Vec3d>& voxels,
                                    const std::vector<const TenonCandidate*>& candidates,
                                    const FrameSweeps& sweeps, const SplitSearch& search);

/// The plane that cuts a piece too large for the printer (@p voxels: its inside voxels' centres,
/// or the centres of coarser cells of side @p search.voxelMm) into two connected halves: planes
/// with both halves fitting @p printerMm (each box side grown by @p marginMm) first, then the one
/// whose worse half has the lowest fit ratio. The same 13 directions as findSplit and the
/// printer-fit box's two longest axes, through the median and the thirds. Empty when no plane
/// leaves two connected halves of at least search.minVolumeMm3. @p whole: the voxels' own fit
/// (fitInPrinter with the same printer and margin), which the caller has already tested.
std::optional<SplitPlane> findFitSplit(const std::vector<Vec3d>& voxels, const partition::PrinterFit& whole,
                                       const Vec3d& printerMm, double marginMm, const SplitSearch& search);

/// Cuts every piece that holds a partition piece (of @p requests) the partition could not fit and
/// whose inside voxels fit @p printerMm in no orientation (each box side grown by @p marginMm)
/// along findFitSplit's planes until all fit: the partition could not separate them with its
/// cells (a cell that meets the surface in one large connected patch, seen on a cube with
/// cavities). Pieces of fitted requests only are left alone when @p isRequestFitTrusted (the
/// partition was cut for this printer); otherwise every piece is tested. The search runs on cells
/// of about 2 mm or coarser (at most ~500,000 per piece). Recomputes @p grouping's faces when it
/// cut. Returns how many cuts; pieces no plane helps stay as they are (finishPiece then says so).
size_t splitTooLarge(std::vector<Piece>& pieces, Grouping& grouping, VoxelField& field,
                     const GridCells& cells, const std::vector<partition::Piece>& requests,
                     bool isRequestFitTrusted, const Vec3d& printerMm, double marginMm, double minVolumeMm3,
                     const RunContext& context);

/// Each piece's active slots (band and inside), in slot order.
std::vector<std::vector<size_t>> slotsOfPieces(const VoxelField& field, size_t pieceCount);

/// The points of @p points that lie furthest along one of @p directions directions spread over
/// the sphere: nearly the vertices of their convex hull, which alone decide a box around them.
std::vector<Vec3d> extremePoints(const std::vector<Vec3d>& points, int directions = 1000);
/// The printer fit of a solid given by @p points (fitInPrinter), searched on extremePoints and
/// measured on all of them: a strided sample of a wall's voxels misses the hull by a few mm.
partition::PrinterFit fitOfSolid(const std::vector<Vec3d>& points, const Vec3d& printerMm, double marginMm,
                                 int directions = 1000);

/// Points (grid mm) around each piece's wall: for each inside voxel of the piece and each 6-neighbour
/// not inside, the point where φ crosses zero on the edge between them (linear, as the mesher's
/// edge points, among which its vertices lie); for a neighbour inside another piece, that
/// neighbour's centre (the cut plane lies between the two).
std::vector<std::vector<Vec3d>> wallSurfaceMm(const VoxelField& field, size_t pieceCount);

/// Cuts every piece whose printed solid, its wall (wallSurfaceMm) with its tenons and pegs
/// (tenonHullMm), fits @p printerMm in no orientation: the partition and splitTooLarge fit the
/// surface and the wall, but a tenon reaching in to the frame can add several mm (seen at 700 mm:
/// 3.8 mm). The plane is findFitSplit's for the piece's coarse cells with @p marginMm grown by half
/// the overshoot, and the halves are cut again on their coarse cells until they fit (as
/// splitTooLarge); the caller plans the tenons again. Recomputes @p grouping's faces when it cut.
/// Returns how many cuts.
size_t splitOverPrinter(std::vector<Piece>& pieces, Grouping& grouping, VoxelField& field,
                        const GridCells& cells, const TenonOptions& tenons, const Vec3d& printerMm,
                        double marginMm, double minVolumeMm3, const RunContext& context);

/// A piece's inside voxels (of @p slots) as the centres of cells of about 2 mm or coarser (at most
/// ~500,000 cells): what the printer-fit tests and the fit cuts run on.
struct CoarseCells {
    std::vector<Vec3d> centresMm;  ///< grid mm, in slot order
    double cellMm = 0.0;           ///< the cells' side
};
CoarseCells coarseInside(const VoxelField& field, const std::vector<size_t>& slots);
/// coarseInside of two pieces' slots together (@p a, then @p b): their union printed as one piece.
inline CoarseCells coarseUnion(const VoxelField& field, const std::vector<size_t>& a,
                               const std::vector<size_t>& b) {
    std::vector<size_t> both = a;
    both.insert(both.end(), b.begin(), b.end());
    return coarseInside(field, both);
}
/// @p marginMm grown by the half diagonal of a cell: the fit margin for the cells' centres.
double coarseMarginMm(const CoarseCells& cells, double marginMm);
/// The printer fit of @p cells (fitOfSolid), each box side grown by coarseMarginMm.
partition::PrinterFit coarseFit(const CoarseCells& cells, const Vec3d& printerMm, double marginMm);

/// The planes that cut two neighbours' union (@p cells: its coarse cells, coarseInside) anew so
/// that each half has a free direction with at least @p minTenons of @p candidates (the two pieces'
/// usable ones), ordered across the plane, and fits @p printerMm (each box side grown by
/// @p marginMm): where the partition's seam left both pieces, or one, under-held, another plane
/// through their union may hold both. Planes: findSplit's 13 directions and the frame's 31 Zome
/// axes through the 20th to the 80th percentiles (11). Of the best held (the most tenons in the weaker half,
/// then both) that fit, up to 8, at most @p maxPlanes are returned, those whose halves need the least support
/// lying on their new cut face first (restingSupportMm3); the plan made again decides which helps.
/// @p search.voxelMm is the cells' side. bothFit is empty when no plane does; then oneFits holds,
/// chosen the same way, the planes whose halves are both held and of which exactly one fits (the
/// other is cut again by this search on it: a union three pieces are needed for). One evaluation of
/// the planes serves both. docs/mounting.md, "Pairs cut anew".
struct HoldingSplits {
    std::vector<SplitPlane> bothFit;
    std::vector<SplitPlane> oneFits;  ///< only when bothFit is empty
};
HoldingSplits findHoldingSplits(const CoarseCells& cells,
                                const std::vector<const TenonCandidate*>& candidates,
                                const FrameSweeps& sweeps, const SplitSearch& search, const Vec3d& printerMm,
                                double marginMm, size_t minTenons, size_t maxPlanes);

/// The support a half needs printed lying on its cut face, estimated on its cells (of side
/// @p cellMm): the plane {x : up·x = @p offsetMm} is the bed and @p up (unit) points into the half;
/// in each column of cells along @p up, the empty space under every solid run down to the solid
/// below or the bed (the orientation's support columns, on cells), where no cell two layers lower
/// within two columns holds the run's lowest cell (a slope of up to 45°, which prints without
/// support) and it is more than a layer above the bed, mm³ (support_cuts.cpp).
double restingSupportMm3(const std::vector<Vec3d>& cells, const Vec3d& up, double offsetMm, double cellMm);

/// The planes of findSplit (its 13 directions through the median of @p cells along each, then
/// through the thirds; coarse cells of side @p search.voxelMm) that leave two 6-connected halves
/// of at least search.minVolumeMm3, in that order.
std::vector<SplitPlane> connectedSplitPlanes(const std::vector<Vec3d>& cells, const SplitSearch& search);

/// Cuts piece @p p along @p plane: its voxels beyond the plane (inside and band) go to a new piece
/// with the next id, its cell set with the other half-space; shell volumes recounted. Returns the
/// new piece's id. The caller recomputes the face contacts (faceContacts). With @p slots (the
/// piece's active slots, band and inside) only those are visited, and they are divided: @p slots
/// keeps the piece's, @p newSlots receives the new piece's.
uint32_t splitPiece(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field, uint32_t p,
                    const SplitPlane& plane, std::vector<size_t>* slots = nullptr,
                    std::vector<size_t>* newSlots = nullptr);

}  // namespace zomefab::pieces::detail
