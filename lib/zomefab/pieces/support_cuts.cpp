// SPDX-License-Identifier: GPL-3.0-or-later
// Pieces cut for less support (docs/pieces.md, "Cut for less support"): a piece that, however it
// lies, hangs much of itself over empty space — a cup of shell whose inside overhangs its whole
// height, a head with its ears — is cut in two along a plane that keeps both halves held, where
// the halves need much less support than the piece; kept only when the plan made again holds more
// pieces and no fewer. Estimated on the pieces' cells (restingSupportMm3): the orientation that
// finally prints each half is chosen after meshing (orientation.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <set>
#include <unordered_set>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/replan.h"
#include "zomefab/pieces/detail/support.h"

namespace zomefab::pieces::detail {

namespace {

/// Directions a piece's support is estimated for (Fibonacci sphere), besides its cut planes'.
constexpr int kSupportDirections = 256;
/// Cells the estimate runs on: the coarse cells binned this coarse (mm). A 4 mm wall stays a
/// wall one cell thick; the estimate guides the cut, the orientation decides the print.
constexpr double kSupportCellMm = 4.0;
/// A piece is cut only when its least support (solid columns) is at least this share of its own
/// volume and kMinGainMm3 more than its halves' together, and the halves need at most
/// kMaxHalvesShare of it.
constexpr double kMinSupportShare = 0.5;
constexpr double kMinGainMm3 = 30000.0;
constexpr double kMaxHalvesShare = 0.6;
/// Plans made for these cuts per run (each about 2 s at 400 mm), and planes tried per piece.
constexpr size_t kSupportTrials = 6;
constexpr size_t kPlanesPerPiece = 8;

/// @p cells binned to cubes of @p binMm (their centres, each once).
std::vector<Vec3d> binned(const std::vector<Vec3d>& cells, double binMm) {
    std::unordered_set<int64_t> seen;
    std::vector<Vec3d> out;
    for (const Vec3d& x : cells) {
        const int64_t i = int64_t(std::floor(x[0] / binMm)), j = int64_t(std::floor(x[1] / binMm)),
                      k = int64_t(std::floor(x[2] / binMm));
        if (seen.insert(packCell(i, j, k)).second)
            out.push_back({(double(i) + 0.5) * binMm, (double(j) + 0.5) * binMm, (double(k) + 0.5) * binMm});
    }
    return out;
}

}  // namespace

double leastSupportMm3(const std::vector<Vec3d>& cells, double cellMm, const std::vector<Vec3d>& ups,
                       const Vec3d& boxMm) {
    if (cells.empty()) return 0.0;
    std::vector<Vec3d> directions = fibonacciSphere(kSupportDirections);
    directions.insert(directions.end(), ups.begin(), ups.end());
    double best = std::numeric_limits<double>::infinity();
    for (const Vec3d& up : directions) {
        // The cells' centres: a cell reaches past the solid it samples by up to half its side, so
        // their extent is about the solid's (a thin wall binned to 4 mm cells would seem 4 mm wider).
        if (!fitsOnBed(cells, scale(up, -1.0), boxMm)) continue;
        double lowest = std::numeric_limits<double>::infinity();
        for (const Vec3d& x : cells) lowest = std::min(lowest, dot(up, x));
        best = std::min(best, restingSupportMm3(cells, up, lowest - 0.5 * cellMm, cellMm));
    }
    return best;
}

std::optional<SupportCut> supportCut(const CoarseCells& cells,
                                     const std::vector<const TenonCandidate*>& candidates,
                                     const FrameSweeps& sweeps, SplitSearch search,
                                     const Fabrication& fabrication, size_t minPegs) {
    const double binMm = std::max(kSupportCellMm, cells.cellMm);
    const std::vector<Vec3d> coarse = binned(cells.centresMm, binMm);
    const double volume = double(coarse.size()) * binMm * binMm * binMm;
    SupportCut cut;
    // The printer's box less the fit margin on each side: the piece must fit lying that way.
    const Vec3d margin{2 * fabrication.fitMarginMm, 2 * fabrication.fitMarginMm, 2 * fabrication.fitMarginMm};
    const Vec3d box = sub(fabrication.pieceBoxMm(), margin);
    cut.beforeMm3 = leastSupportMm3(coarse, binMm, {}, box);
    if (!std::isfinite(cut.beforeMm3)) return std::nullopt;  // fits no way here: not this search's to judge
    if (cut.beforeMm3 < kMinSupportShare * volume || cut.beforeMm3 < kMinGainMm3) return std::nullopt;
    search.voxelMm = cells.cellMm;
    const HoldingSplits splits =
        findHoldingSplits(cells, candidates, sweeps, search, fabrication.pieceBoxMm(),
                          fabrication.fitMarginMm, minPegs, kPlanesPerPiece);
    cut.afterMm3 = std::numeric_limits<double>::infinity();
    for (const SplitPlane& plane : splits.bothFit) {
        std::array<std::vector<Vec3d>, 2> halves;
        for (const Vec3d& x : coarse) halves[dot(plane.normal, x) > plane.offsetMm].push_back(x);
        // Each half may lie on its new cut face, or with it up (a cup open side up), exactly.
        const std::vector<Vec3d> ups{plane.normal, scale(plane.normal, -1.0)};
        const double after =
            leastSupportMm3(halves[0], binMm, ups, box) + leastSupportMm3(halves[1], binMm, ups, box);
        if (after < cut.afterMm3) cut.afterMm3 = after, cut.plane = plane;
    }
    if (!(cut.afterMm3 <= kMaxHalvesShare * cut.beforeMm3 && cut.beforeMm3 - cut.afterMm3 >= kMinGainMm3))
        return std::nullopt;
    return cut;
}

void cutForSupport(Replanner& r, const Fabrication& fabrication) {
    const size_t minPegs = size_t(r.opt.tenons.minPerPiece);
    const SplitSearch search = splitSearchFor(r.field, r.opt);
    std::set<uint32_t> given;  // pieces no cut helps, or whose cut the plan did not keep
    size_t trials = 0;
    while (trials < kSupportTrials && r.out.plan.isBuildable()) {
        const std::vector<size_t> pegs = r.pegs();
        const std::vector<std::vector<size_t>> slots = slotsOfPieces(r.field, r.out.pieces.size());
        // The held piece whose cut saves the most support (only a held piece: both halves must be).
        std::optional<SupportCut> best;
        uint32_t bestPiece = 0;
        for (uint32_t p = 0; p < r.out.pieces.size(); ++p) {
            if (pegs[p] < minPegs || given.count(p)) continue;
            r.context.throwIfCancelled();
            const std::optional<SupportCut> cut =
                supportCut(coarseInside(r.field, slots[p]), usableCandidates(r.candidates, {p}), r.sweeps,
                           search, fabrication, minPegs);
            if (!cut) {
                given.insert(p);
                continue;
            }
            if (!best || cut->beforeMm3 - cut->afterMm3 > best->beforeMm3 - best->afterMm3)
                best = cut, bestPiece = p;
        }
        if (!best) return;
        ++trials;
        const uint32_t p = bestPiece;
        const size_t before = r.underHeldNow();
        const std::string what = "piece " + std::to_string(p) + " cut for less support";
        const std::optional<size_t> after =
            r.tryChange([&] { splitPiece(r.out.pieces, r.grouping.cellSets, r.field, p, best->plane); },
                        before, what, Replanner::Change::kMorePieces);
        if (!after) {
            given.insert(p);
            continue;
        }
        ++r.out.supportCuts;
        r.context.detail(what + ": support columns (estimate on " + formatNumber(kSupportCellMm, 2) +
                         " mm cells) " + formatNumber(best->beforeMm3 / 1000.0, 3) + " -> " +
                         formatNumber(best->afterMm3 / 1000.0, 3) + " cm³");
    }
}

}  // namespace zomefab::pieces::detail
