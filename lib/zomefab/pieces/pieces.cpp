// SPDX-License-Identifier: GPL-3.0-or-later
// The pieces stage (paper §6), step by step (docs/pieces.md):
//  1. the shell's voxels (its narrow band and its whole inside) are labelled with their cell,
//     argmax_k w_k·x + b_k (§5.2), and split into connected components per cell (voxels.cpp);
//  2. components become pieces (grouped by the partition's pieces, slivers merged; grouping.cpp);
//  3. tenons and engraved numbers are planned against the shell (plan.cpp);
//  4. each piece's level set is the CSG intersection max(φ_shell, δ_P) of the shell and the level
//     set δ_P of its cells' half-spaces, tenons unioned (min), the number engraved (max with
//     −glyph) (piece_grid.cpp);
//  5. each is meshed through sdf's mesher, checked and oriented for the printer (finish.cpp).
#include "zomefab/pieces/pieces.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/splits.h"
#include "zomefab/pieces/detail/stages.h"
#include "zomefab/pieces/detail/staves.h"
#include "zomefab/pieces/detail/thin_wall.h"
#include "zomefab/sdf/level_set_grid.h"

namespace zomefab::pieces {

using namespace detail;

namespace {

void checkRigid(const Transform4d& t) {
    // Columns orthonormal and a proper rotation: frame and shell were scaled alike and not mirrored.
    double det = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = 0;
            for (int k = 0; k < 3; ++k) d += t.at(k, i) * t.at(k, j);
            if (std::abs(d - (i == j ? 1.0 : 0.0)) > 1e-6)
                throw Error(
                    ErrorCode::InvalidInput,
                    "the frame and the shell are not in the same millimetres (frame→grid transform scales or "
                    "shears: make both from the same scaled mesh)");
        }
    det = t.at(0, 0) * (t.at(1, 1) * t.at(2, 2) - t.at(1, 2) * t.at(2, 1)) -
          t.at(0, 1) * (t.at(1, 0) * t.at(2, 2) - t.at(1, 2) * t.at(2, 0)) +
          t.at(0, 2) * (t.at(1, 0) * t.at(2, 1) - t.at(1, 1) * t.at(2, 0));
    if (det < 0)
        throw Error(ErrorCode::InvalidInput,
                    "the frame→grid transform mirrors: the frame and the shell disagree");
}

/// The inputs checked before any work. @throw as makePieces.
void checkInputs(const sdf::LevelSet& shell, const Transform4d& frameToGridMm,
                 const partition::PartitionResult& partition) {
    const partition::LinearCells& model = partition.cells;
    checkRigid(frameToGridMm);
    if (model.w.empty() || model.w.size() != model.b.size())
        throw Error(ErrorCode::InvalidInput,
                    "the cell model needs as many offsets b as normals w, and at least one cell");
    for (size_t k = 0; k < model.cellCount(); ++k)
        if (!std::isfinite(model.b[k]) || !std::isfinite(model.w[k][0]) || !std::isfinite(model.w[k][1]) ||
            !std::isfinite(model.w[k][2]))
            throw Error(ErrorCode::InvalidInput,
                        "cell " + std::to_string(k) + " has a non-finite coefficient");
    for (size_t r = 0; r < partition.pieces.size(); ++r)
        for (uint32_t c : partition.pieces[r].cells)
            if (c >= model.cellCount())
                throw Error(ErrorCode::InvalidInput, "piece " + std::to_string(r) + " names cell " +
                                                         std::to_string(c) + ", but there are " +
                                                         std::to_string(model.cellCount()) + " cells");
    if (shell.empty()) throw Error(ErrorCode::InvalidInput, "the shell level set is empty");
}

/// The options adapted to the shell's voxel: no tenons finer than it can carry (an error), no
/// engraved numbers it cannot resolve (a warning).
PiecesOptions optionsForVoxel(const PiecesOptions& options, double voxel, const RunContext& context) {
    PiecesOptions opt = options;
    if (opt.tenons.maxPerPiece > 0 && voxel > maxVoxelForTenonsMm(opt.tenons))
        throw Error(ErrorCode::Usage, "tenon prisms " + formatNumber(opt.tenons.bodyWidthMm, 4) +
                                          " mm wide need a voxel of at most " +
                                          formatNumber(maxVoxelForTenonsMm(opt.tenons), 4) +
                                          " mm, but the shell's voxel is " + formatNumber(voxel, 4) +
                                          " mm: rebuild it finer (zf-sdf --voxel-mm) or turn tenons off");
    if (opt.label.isEnabled && opt.label.strokeMm < 2.0 * voxel) {
        context.warn("piece numbers are not engraved: a " + formatNumber(opt.label.strokeMm, 4) +
                     " mm stroke needs a voxel of at most " + formatNumber(opt.label.strokeMm / 2.0, 4) +
                     " mm (the shell's is " + formatNumber(voxel, 4) + " mm)");
        opt.label.isEnabled = false;
    }
    return opt;
}

/// Step 4 for every piece, in parallel: its level set.
std::vector<PieceGrid> pieceGrids(const Pieces& out, const VoxelField& field, const GridCells& cells,
                                  const std::vector<CellSet>& cellSets, const FloatGrid& shell,
                                  const RunContext& context) {
    const size_t pieceCount = out.pieces.size();
    const std::vector<std::vector<uint32_t>> pieceLeaves = leavesOfPieces(field, pieceCount);
    const std::vector<uint8_t> exterior = exteriorBand(field);
    std::vector<PieceGrid> grids(pieceCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pieceCount, 1),
                      [&](const tbb::blocked_range<size_t>& range) {
                          for (size_t p = range.begin(); p < range.end(); ++p) {
                              context.throwIfCancelled();
                              grids[p] = pieceGrid(field, cells, cellSets, out.pieces[p], pieceLeaves[p],
                                                   exterior, shell.transform(), out.options);
                          }
                      });
    context.throwIfCancelled();
    context.progress("pieces", 0.5);
    return grids;
}

/// Step 5 for every piece, in parallel: mesh, checks, orientation.
void meshPieces(Pieces& out, std::vector<PieceGrid>& grids, const GridCells& cells,
                const std::vector<CellSet>& cellSets, const Fabrication& fabrication,
                const RunContext& context) {
    const size_t pieceCount = out.pieces.size();
    const double voxel = out.voxelMm;
    // Not OpenVDB's fracture scheme (VolumeToMesh::setRefGrid): it snaps the seam vertices to the
    // uncut shell's surface, up to a voxel beyond the cut planes, so cut faces would not be flat and
    // neighbours would overlap at their rims (measured, docs/pieces.md).
    sdf::LevelSetToMeshOptions meshing;
    meshing.adaptivity = out.options.adaptivity;
    meshing.minComponentVolumeMm3 = voxel * voxel * voxel;
    std::vector<std::string> notes(pieceCount);  // reported in piece order below
    std::atomic<size_t> meshed{0};
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, pieceCount, 1), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t p = range.begin(); p < range.end(); ++p) {
                context.throwIfCancelled();
                TriMesh mesh;
                tbb::this_task_arena::isolate([&] {
                    mesh = sdf::meshFloatGrid(*grids[p].grid, meshing, grids[p].fullResolution,
                                              grids[p].adaptivityWeight);
                });
                grids[p] = PieceGrid();
                // The pegs as exact meshes, overlapping the meshed prisms (tenons.h, pegMesh).
                for (const Tenon& t : out.pieces[p].tenons) appendMesh(mesh, pegMesh(t, out.options.tenons));
                notes[p] = finishPiece(out.pieces[p], std::move(mesh), cells, cellSets[p], fabrication, voxel,
                                       out.options.seamGapMm, context);
                context.progress("pieces", 0.5 + 0.45 * double(++meshed) / double(pieceCount));
            }
        });
    context.throwIfCancelled();
    size_t offCutFace = 0;
    for (size_t p = 0; p < pieceCount; ++p) {
        if (notes[p].empty()) continue;
        ++offCutFace;
        context.debug("piece " + std::to_string(p) + ": " + notes[p]);
    }
    if (offCutFace > 0)
        context.detail(std::to_string(offCutFace) + " of " + std::to_string(pieceCount) +
                       " pieces have no cut face they can lie on; they rest on their largest base that fits");
}

/// How often the pieces are planned again after cuts for tenons that made a piece too large.
constexpr int kFitRounds = 3;

/// Steps 2–3 (planPieces), then the pieces the tenons made larger than the printer cut
/// (splitOverPrinter) and everything planned again, a few rounds: a piece too large is found
/// here, before the meshing, and not by finishPiece after it.
void planTenonsToFit(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                     const FloatGrid& shell, zome::Structure& frame, const Transform4d& frameToGridMm,
                     const Fabrication& fabrication, const StrutTest& canGrow, const RunContext& context) {
    for (int round = 0;; ++round) {
        planPieces(out, field, cells, grouping, shell, frame, frameToGridMm, fabrication, out.options,
                   canGrow, context);
        // A plan stuck on tunnels that cross is refused whatever the cuts (the cheese at 700 mm
        // planned a second time, 5 minutes, for the same 257 stuck linings); so is one with staves
        // that has no order (the cheese at 700 mm: three rounds of 8 minutes, the same 27 bodies
        // stuck after each).
        const bool isStaved = std::any_of(grouping.cellSets.begin(), grouping.cellSets.end(),
                                          [](const CellSet& set) { return isStaveSet(set); });
        if (round == kFitRounds || out.crossingTunnelPieces > 0 || (isStaved && !out.plan.isBuildable()))
            return;
        const size_t cuts =
            splitOverPrinter(out.pieces, grouping, field, cells, out.options.tenons, fabrication.pieceBoxMm(),
                             fabrication.fitMarginMm, out.options.minPieceVolumeMm3, context);
        if (cuts == 0) return;
        context.info(std::to_string(cuts) +
                     " piece(s) with their tenons larger than the printer cut by planes; planning again");
        for (Piece& piece : out.pieces) piece.pins.clear();  // the rest is planned afresh
    }
}

/// What one attempt at the plan leaves for the meshing: the voxels, the pieces' grouping and the
/// frame as the pieces stage grew it.
struct Attempt {
    VoxelField field;
    Grouping grouping;
    zome::Structure frame;
    size_t unplacedStaves = 0;  ///< staves its plan places nowhere
};

/// How many times the tunnels of staves placed nowhere are made later and the pieces planned again
/// (the cheese at 700 mm: 29 staves placed nowhere, then 16, then 9; a fourth time 9 again).
constexpr int kLateLevels = 2;

/// Adds tunnel @p key to @p late at @p level, or raises it there when it is in already.
void raiseTunnel(std::vector<TunnelKey>& late, const TunnelKey& key, int level) {
    for (TunnelKey& k : late)
        if (isSameTunnel(k, key, 1.0)) {  // one attempt's prisms are the next one's: the same middles
            k.level = level;
            return;
        }
    late.push_back(key);
    late.back().level = level;
}

/// Steps 1–3 (docs/pieces.md): the shell's voxels, the pieces of the partition's cells (@p cells),
/// cut to fit the printer, and their plan, into @p out; the staves of @p lateTunnels go on last.
Attempt planAttempt(Pieces& out, const FloatGrid& shell, const sdf::LevelSet& shellSet,
                    const zome::Structure& frame, const Transform4d& frameToGridMm,
                    const partition::PartitionResult& partition, const GridCells& cells,
                    const Fabrication& fabrication, const PiecesOptions& options,
                    const std::vector<TunnelKey>& lateTunnels, RunContext& context,
                    const StrutTest& canGrow) {
    const double voxel = out.voxelMm;
    Attempt a;
    VoxelField& field = a.field;
    field = buildField(shell);
    out.options.printWallMm =
        resolvePrintWallMm(options.printWallMm, fabrication.wallMm, field.background, voxel);
    if (out.options.printWallMm > 0)
        field.thinPhi = thinWallPhi(field, out.options.printWallMm);
    else if (options.printWallMm == kPrintWallAuto && fabrication.wallMm > 2 * kDefaultPrintWallMm)
        context.info("pieces printed with the shell's " + formatNumber(fabrication.wallMm) +
                     " mm wall: a printed wall of " + formatNumber(kDefaultPrintWallMm) +
                     " mm needs a shell of at least " + formatNumber(2 * field.background + voxel) +
                     " mm and voxels of at least " +
                     formatNumber(kDefaultPrintWallMm / (field.background / voxel - 0.5), 3) + " mm");
    context.throwIfCancelled();
    labelCells(field, cells);
    context.throwIfCancelled();
    // A cell's components shared by several of the partition's pieces go by their surface boxes,
    // grown by the wall's thickness.
    const double growMm = std::max(shellSet.info().shellMm, 4 * voxel) + 2 * voxel;
    Grouping& grouping = a.grouping;
    grouping = groupPieces(field, cells, partition.pieces, affineInverse(frameToGridMm), growMm,
                           out.options.minPieceVolumeMm3, context);
    grouping.lateTunnels = lateTunnels;
    // What the partition's cells could not make small enough (a cell meeting the surface in one
    // large connected patch) is cut by planes here.
    const size_t fitCuts =
        splitTooLarge(grouping.pieces, grouping, field, cells, partition.pieces,
                      partition.printerMm == fabrication.printerMm, fabrication.pieceBoxMm(),
                      fabrication.fitMarginMm, out.options.minPieceVolumeMm3, context);
    if (fitCuts > 0)
        context.info(std::to_string(fitCuts) +
                     " cut(s) by planes made the pieces the partition left larger than the printer fit it");
    out.pieces = std::move(grouping.pieces);
    out.shellVolumeMm3 = grouping.shellVolumeMm3;
    out.outsideCellsVolumeMm3 = grouping.outsideCellsVolumeMm3;
    out.sliversMerged = grouping.sliversMerged;
    out.isolatedSlivers = grouping.isolatedSlivers;
    context.progress("pieces", 0.25);
    context.throwIfCancelled();
    // The frame as the pieces stage may grow it (PiecesOptions::isGrowingFrame).
    a.frame = frame;
    planTenonsToFit(out, field, cells, grouping, shell, a.frame, frameToGridMm, fabrication, canGrow,
                    context);
    a.unplacedStaves = unplacedStaves(out.plan.holeOfPiece, grouping.cellSets);
    return a;
}

}  // namespace

void checkPiecesOptions(const PiecesOptions& o) {
    if (!(o.minPieceVolumeMm3 >= 0 && std::isfinite(o.minPieceVolumeMm3)))
        throw Error(ErrorCode::Usage, "the smallest piece volume must be a finite number ≥ 0 mm³");
    if (!(o.seamGapMm >= 0 && o.seamGapMm <= 2))
        throw Error(ErrorCode::Usage,
                    "the seam gap must be in [0, 2] mm, got " + formatNumber(o.seamGapMm, 4));
    if (!(o.adaptivity >= 0 && o.adaptivity <= 1))
        throw Error(ErrorCode::Usage, "adaptivity must be in [0, 1], got " + formatNumber(o.adaptivity, 4));
    if (!(o.printWallMm == kPrintWallAuto || o.printWallMm == 0 ||
          (o.printWallMm >= 1 && o.printWallMm <= 200)))
        throw Error(ErrorCode::Usage, std::string("--print-wall-mm must be ") + kPrintWallValues + ", got " +
                                          formatNumber(o.printWallMm, 4));
    checkTenonOptions(o.tenons);
    checkLabelOptions(o.label);
}

void requireBuildable(const Pieces& pieces) {
    const std::vector<std::string>& problems = pieces.plan.problems;
    if (problems.empty()) return;
    std::string list;
    for (size_t i = 0; i < problems.size() && i < 3; ++i) list += (i ? "; " : "") + problems[i];
    if (problems.size() > 3) list += "; and " + std::to_string(problems.size() - 3) + " more";
    throw NotBuildable("the pieces cannot be put on the frame: " + list, problems.size(),
                       pieces.crossingTunnelPieces > 0);
}

Pieces makePieces(const sdf::LevelSet& shellSet, const zome::Structure& frame,
                  const Transform4d& frameToGridMm, const partition::PartitionResult& partition,
                  const Fabrication& fabrication, const PiecesOptions& options, RunContext& context,
                  const StrutTest& canGrow) {
    Stopwatch clock;
    checkFabrication(fabrication);
    checkPiecesOptions(options);
    checkInputs(shellSet, frameToGridMm, partition);
    const FloatGrid::ConstPtr shell = sdf::levelSetGrid(shellSet);
    const double voxel = shell->voxelSize()[0];
    Pieces out;
    out.options = optionsForVoxel(options, voxel, context);
    out.printerMm = fabrication.printerMm;
    out.bedMarginMm = fabrication.bedMarginMm;
    out.voxelMm = voxel;
    out.frameToGridMm = frameToGridMm;
    out.gridTransformMm = shellSet.info().transformMm;

    context.progress("pieces", 0.0);
    const GridCells cells = toGridCells(partition.cells, frameToGridMm);
    const Pieces header = out;
    Attempt attempt = planAttempt(out, *shell, shellSet, frame, frameToGridMm, partition, cells, fabrication,
                                  options, {}, context, canGrow);
    // Staves placed nowhere lie in rings of the first tunnels to go on (the cheese at 700 mm: x
    // tunnels under its faces), which no peg reaches and which cannot glue onto the crossing
    // tunnels' staves, on later. Again with those tunnels last: their staves keep the overlaps and
    // may be glued in place onto the crossing staves pegs hold; while fewer are placed nowhere, the
    // tunnels left so then later still.
    std::vector<TunnelKey> late;
    size_t unplaced = attempt.unplacedStaves;
    for (int level = 1; level <= kLateLevels && unplaced > 0 && out.options.tenons.maxPerPiece > 0 &&
                        !attempt.grouping.unheldTunnels.empty();
         ++level) {
        for (const TunnelKey& key : attempt.grouping.unheldTunnels) raiseTunnel(late, key, level);
        context.info(std::to_string(unplaced) + " staves of " +
                     std::to_string(attempt.grouping.unheldTunnels.size()) +
                     " tunnel(s) placed nowhere: planning again with their staves put on later, glued in "
                     "place onto the crossing tunnels' where no peg holds them");
        attempt = Attempt{};  // the last attempt's voxels go before the next one's are made
        out = header;
        attempt = planAttempt(out, *shell, shellSet, frame, frameToGridMm, partition, cells, fabrication,
                              options, late, context, canGrow);
        if (attempt.unplacedStaves >= unplaced) break;  // no better: refused as it is
        unplaced = attempt.unplacedStaves;
    }
    VoxelField& field = attempt.field;
    Grouping& grouping = attempt.grouping;
    if (out.frameStrutsGrown > 0) out.grownFrame = std::move(attempt.frame);
    // An object that cannot be built is said before the meshing, the stage's longest step.
    if (out.options.tenons.maxPerPiece > 0) requireBuildable(out);
    context.progress("pieces", 0.35);
    context.debug("tenons and labels planned: " + formatNumber(clock.seconds(), 3) + " s");
    context.throwIfCancelled();

    std::vector<PieceGrid> grids = pieceGrids(out, field, cells, grouping.cellSets, *shell, context);
    context.debug("level sets: " + formatNumber(clock.seconds(), 3) + " s");
    field = VoxelField();  // the grids hold what meshing needs
    meshPieces(out, grids, cells, grouping.cellSets, fabrication, context);
    out.seconds = clock.seconds();
    context.debug("meshed, checked and oriented: " + formatNumber(out.seconds, 3) + " s");
    return out;
}

}  // namespace zomefab::pieces
