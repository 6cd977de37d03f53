// SPDX-License-Identifier: GPL-3.0-or-later
// Pieces cut for less support (docs/pieces.md, "Cut for less support"): a piece that, however it
// lies, hangs much of itself over empty space — a cup of shell whose inside overhangs its whole
// height, a head with its ears — is cut in two along a plane that keeps both halves held, where
// the halves need much less support than the piece; kept only when the plan made again holds more
// pieces and no fewer. Estimated on the pieces' cells (restingSupportMm3): the orientation that
// finally prints each half is chosen after meshing (orientation.cpp).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <map>
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
constexpr double kMinSupportShare = 0.25;
constexpr double kMinGainMm3 = 30000.0;
constexpr double kMaxHalvesShare = 0.6;
/// Plans made for these cuts per run (each about 2 s at 400 mm), and planes tried per piece.
constexpr size_t kSupportTrials = 6;
constexpr size_t kPlanesPerPiece = 8;
/// Pieces printed in two parts glued before mounting (splitForPrint): a piece is cut when its
/// least support is at least kMinGainMm3 and its halves save at least that much and need at
/// most kMaxPartsShare of it; at most kPrintSplitTrials plans. The halves' support is searched
/// over kPartDirections directions besides their cut face (39 planes, two halves each).
constexpr size_t kPrintSplitTrials = 10;
constexpr double kMaxPartsShare = 0.6;
constexpr int kPartDirections = 96;

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

/// The printer's box less the fit margin on each side: a piece must fit lying that way.
Vec3d fitBox(const Fabrication& fabrication) {
    const double m = 2 * fabrication.fitMarginMm;
    return sub(fabrication.pieceBoxMm(), Vec3d{m, m, m});
}

}  // namespace

double restingSupportMm3(const std::vector<Vec3d>& cells, const Vec3d& up, double offsetMm, double cellMm) {
    const std::array<Vec3d, 3> rows = rotationDown(scale(up, -1.0));  // rows[2] = up
    std::unordered_map<int64_t, std::vector<double>> columns;
    for (const Vec3d& x : cells) {
        const int64_t i = std::llround(dot(rows[0], x) / cellMm), j = std::llround(dot(rows[1], x) / cellMm);
        columns[packCell(i, j, 0)].push_back(dot(up, x) - offsetMm);
    }
    for (auto& entry : columns) std::sort(entry.second.begin(), entry.second.end());
    // A cell two layers lower within two columns holds it: a slope of up to one cell per layer,
    // the 45° a printer bridges (kOverhangDeg). Without this a thin wall standing at any tilt,
    // which prints without support, would seem to need columns under every cell that steps
    // sideways. Two layers, not one: cells turned off the grid's axes lie up to about half a cell
    // above or below their column's row, so one layer down would hold a level ceiling too.
    auto isHeldBeside = [&](int64_t i, int64_t j, double h) {
        for (int64_t di = -2; di <= 2; ++di)
            for (int64_t dj = -2; dj <= 2; ++dj) {
                const auto it = columns.find(packCell(i + di, j + dj, 0));
                if (it == columns.end()) continue;
                const auto first = std::lower_bound(it->second.begin(), it->second.end(), h - 2.5 * cellMm);
                if (first != it->second.end() && *first <= h - 1.5 * cellMm) return true;
            }
        return false;
    };
    double gaps = 0.0;
    for (const auto& [key, heights] : columns) {
        // The column's indices as packCell wrapped them; packCell wraps their neighbours alike.
        const int64_t i = (key >> 42) & 0x1FFFFF, j = (key >> 21) & 0x1FFFFF;
        double below = 0.0;  // the top of the solid below: the bed first
        for (const double h : heights) {
            const double bottom = h - 0.5 * cellMm;
            // Within a layer of the bed a cell leans on the first layer.
            if (bottom > below + 0.5 * cellMm && bottom > 1.5 * cellMm && !isHeldBeside(i, j, h))
                gaps += bottom - below;
            below = std::max(below, h + 0.5 * cellMm);
        }
    }
    return gaps * cellMm * cellMm;
}

double leastSupportMm3(const std::vector<Vec3d>& cells, double cellMm, const std::vector<Vec3d>& ups,
                       const Vec3d& boxMm, int sphereDirections) {
    if (cells.empty()) return 0.0;
    std::vector<Vec3d> directions = fibonacciSphere(sphereDirections);
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

namespace {

/// The least support of the halves of @p coarse (cells of @p binMm) on either side of @p plane,
/// each also lying exactly on the new cut face or with it up (a cup open side up), summed.
double halvesSupportMm3(const std::vector<Vec3d>& coarse, const SplitPlane& plane, double binMm,
                        const Vec3d& box, int sphereDirections) {
    std::array<std::vector<Vec3d>, 2> halves;
    for (const Vec3d& x : coarse) halves[dot(plane.normal, x) > plane.offsetMm].push_back(x);
    const std::vector<Vec3d> ups{plane.normal, scale(plane.normal, -1.0)};
    return leastSupportMm3(halves[0], binMm, ups, box, sphereDirections) +
           leastSupportMm3(halves[1], binMm, ups, box, sphereDirections);
}

}  // namespace

std::optional<SupportCut> supportCut(const CoarseCells& cells,
                                     const std::vector<const TenonCandidate*>& candidates,
                                     const FrameSweeps& sweeps, SplitSearch search,
                                     const Fabrication& fabrication, size_t minPegs) {
    const double binMm = std::max(kSupportCellMm, cells.cellMm);
    const std::vector<Vec3d> coarse = binned(cells.centresMm, binMm);
    const double volume = double(coarse.size()) * binMm * binMm * binMm;
    SupportCut cut;
    const Vec3d box = fitBox(fabrication);
    cut.beforeMm3 = leastSupportMm3(coarse, binMm, {}, box);
    if (!std::isfinite(cut.beforeMm3)) return std::nullopt;  // fits no way here: not this search's to judge
    if (cut.beforeMm3 < kMinSupportShare * volume || cut.beforeMm3 < kMinGainMm3) return std::nullopt;
    search.voxelMm = cells.cellMm;
    const HoldingSplits splits =
        findHoldingSplits(cells, candidates, sweeps, search, fabrication.pieceBoxMm(),
                          fabrication.fitMarginMm, minPegs, kPlanesPerPiece);
    cut.afterMm3 = std::numeric_limits<double>::infinity();
    for (const SplitPlane& plane : splits.bothFit) {
        const double after = halvesSupportMm3(coarse, plane, binMm, box, kSupportDirections);
        if (after < cut.afterMm3) cut.afterMm3 = after, cut.plane = plane;
    }
    if (!(cut.afterMm3 <= kMaxHalvesShare * cut.beforeMm3 && cut.beforeMm3 - cut.afterMm3 >= kMinGainMm3))
        return std::nullopt;
    return cut;
}

namespace {

/// What cutForSupport and splitForPrint share: up to @p trials plans, each for the piece whose cut
/// (@p cutOf, given the piece and its slots; none: the piece is left alone from then on; a piece
/// @p isPassedOver, given the pegs of every piece along the plan's directions, is only left out of
/// that round) saves the most support, made by
/// @p apply and planned again (Replanner::tryChange with @p kind, judged against @p before()); a
/// cut the plan does not keep leaves its piece alone too. @p counter counts the cuts kept, each
/// told as "piece N " + @p told.
using CutOf = std::function<std::optional<SupportCut>(uint32_t, const std::vector<size_t>& slots)>;
void cutInRounds(Replanner& r, size_t trials, const CutOf& cutOf,
                 const std::function<bool(uint32_t, const std::vector<size_t>& pegs)>& isPassedOver,
                 const std::function<void(uint32_t, const SplitPlane&)>& apply, Replanner::Change kind,
                 const std::function<size_t()>& before, const std::string& told, size_t& counter) {
    std::set<uint32_t> given;  // pieces no cut helps, or whose cut the plan did not keep
    for (size_t trial = 0; trial < trials && r.out.plan.isBuildable(); ++trial) {
        const std::vector<size_t> pegs = r.pegs();
        const std::vector<std::vector<size_t>> slots = slotsOfPieces(r.field, r.out.pieces.size());
        std::optional<SupportCut> best;
        uint32_t bestPiece = 0;
        for (uint32_t p = 0; p < r.out.pieces.size(); ++p) {
            if (given.count(p) || isPassedOver(p, pegs)) continue;
            r.context.throwIfCancelled();
            const std::optional<SupportCut> cut = cutOf(p, slots[p]);
            if (!cut) {
                given.insert(p);
                continue;
            }
            if (!best || cut->beforeMm3 - cut->afterMm3 > best->beforeMm3 - best->afterMm3)
                best = cut, bestPiece = p;
        }
        if (!best) return;
        const std::string what = "piece " + std::to_string(bestPiece) + " " + told;
        if (!r.tryChange([&] { apply(bestPiece, best->plane); }, before(), what, kind)) {
            given.insert(bestPiece);
            continue;
        }
        ++counter;
        r.context.detail(what + ": support columns (estimate on " + formatNumber(kSupportCellMm, 2) +
                         " mm cells) " + formatNumber(best->beforeMm3 / 1000.0, 3) + " -> " +
                         formatNumber(best->afterMm3 / 1000.0, 3) + " cm³");
    }
}

}  // namespace

void cutForSupport(Replanner& r, const Fabrication& fabrication) {
    const size_t minPegs = size_t(r.opt.tenons.minPerPiece);
    const SplitSearch search = splitSearchFor(r.field, r.opt);
    auto cutOf = [&](uint32_t p, const std::vector<size_t>& slots) {
        return supportCut(coarseInside(r.field, slots), usableCandidates(r.candidates, {p}), r.sweeps, search,
                          fabrication, minPegs);
    };
    // Only a held piece: both halves must be.
    auto isUnderHeld = [&](uint32_t p, const std::vector<size_t>& pegs) { return pegs[p] < minPegs; };
    cutInRounds(
        r, kSupportTrials, cutOf, isUnderHeld,
        [&](uint32_t p, const SplitPlane& plane) {
            splitPiece(r.out.pieces, r.grouping.cellSets, r.field, p, plane);
        },
        Replanner::Change::kMorePieces, [&] { return r.underHeldNow(); }, "cut for less support",
        r.out.supportCuts);
}

std::optional<SupportCut> printSplit(const CoarseCells& cells, SplitSearch search,
                                     const Fabrication& fabrication) {
    const double binMm = std::max(kSupportCellMm, cells.cellMm);
    const std::vector<Vec3d> coarse = binned(cells.centresMm, binMm);
    const Vec3d box = fitBox(fabrication);
    SupportCut cut;
    cut.beforeMm3 = leastSupportMm3(coarse, binMm, {}, box);
    if (!std::isfinite(cut.beforeMm3) || cut.beforeMm3 < kMinGainMm3) return std::nullopt;
    // binned() puts the cells' centres at odd multiples of half a bin.
    search.voxelMm = binMm;
    search.originMm = {0.5 * binMm, 0.5 * binMm, 0.5 * binMm};
    const std::vector<SplitPlane> planes = connectedSplitPlanes(coarse, search);
    std::vector<double> after(planes.size());
    tbb::parallel_for(size_t(0), planes.size(), [&](size_t i) {
        after[i] = halvesSupportMm3(coarse, planes[i], binMm, box, kPartDirections);
    });
    cut.afterMm3 = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < planes.size(); ++i)
        if (after[i] < cut.afterMm3) cut.afterMm3 = after[i], cut.plane = planes[i];
    if (!(cut.afterMm3 <= kMaxPartsShare * cut.beforeMm3 && cut.beforeMm3 - cut.afterMm3 >= kMinGainMm3))
        return std::nullopt;
    return cut;
}

void splitForPrint(Replanner& r, const Fabrication& fabrication) {
    const SplitSearch search = splitSearchFor(r.field, r.opt);
    // A piece's cut depends on its voxels alone, which only its own cut changes (and the plan made
    // again leaves alone): each is searched once, again only after its piece was cut.
    std::map<uint32_t, std::optional<SupportCut>> known;
    auto cutOf = [&](uint32_t p, const std::vector<size_t>& slots) {
        const auto it = known.find(p);
        if (it != known.end()) return it->second;
        return known[p] = printSplit(coarseInside(r.field, slots), search, fabrication);
    };
    cutInRounds(
        r, kPrintSplitTrials, cutOf, [](uint32_t, const std::vector<size_t>&) { return false; },
        [&](uint32_t p, const SplitPlane& plane) {
            known.erase(p);
            r.preGlued.push_back({p, splitPiece(r.out.pieces, r.grouping.cellSets, r.field, p, plane)});
        },
        Replanner::Change::kParts, [&] { return r.underHeldStepsNow(); },
        "printed in two parts for less support, glued before mounting", r.out.printSplits);
}

}  // namespace zomefab::pieces::detail
