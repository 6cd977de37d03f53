// SPDX-License-Identifier: GPL-3.0-or-later
// Re-cutting a piece no direction can mount (detail/splits.h, docs/mounting.md).
#include "zomefab/pieces/detail/splits.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <tuple>
#include <unordered_map>

#include "zomefab/core/format.h"
#include "zomefab/mount/plan.h"
#include "zomefab/partition/printer_fit.h"
#include "zomefab/pieces/detail/support.h"
#include "zomefab/zome/holes.h"

namespace zomefab::pieces::detail {

namespace {

/// Directions of the extremes the fits of findHoldingSplits search on (about 13° apart).
constexpr int kSearchDirections = 250;
/// Planes findHoldingSplits fits and compares by their halves' support, best held first.
constexpr size_t kFittingPlanes = 8;

/// Free directions tested per half, in rank order: the pair that lets the halves be ordered
/// across their plane is chosen among them.
constexpr size_t kFreeOptionsPerHalf = 4;

/// Where split planes cut a piece along each direction: the median first, then the thirds.
constexpr double kSplitQuantiles[] = {0.5, 1.0 / 3.0, 2.0 / 3.0};

/// The 13 directions of the split planes: axes, face diagonals, body diagonals (unit).
std::vector<Vec3d> splitDirections() {
    std::vector<Vec3d> out;
    for (int x = -1; x <= 1; ++x)
        for (int y = -1; y <= 1; ++y)
            for (int z = -1; z <= 1; ++z) {
                const Vec3d d{double(x), double(y), double(z)};
                // One of ±d: the first non-zero component positive.
                const bool isFirst = x > 0 || (x == 0 && (y > 0 || (y == 0 && z > 0)));
                if (isFirst) out.push_back(normalized(d));
            }
    return out;
}

/// The piece's voxels with their 6-neighbours (indices, kNone where the neighbour is not in it).
struct VoxelGraph {
    const std::vector<Vec3d>* voxels = nullptr;
    std::vector<std::array<uint32_t, 6>> neighbours;
};

VoxelGraph voxelGraph(const std::vector<Vec3d>& voxels, const SplitSearch& s) {
    auto key = [&](const Vec3d& x, int dx, int dy, int dz) {
        const int64_t i = std::llround((x[0] - s.originMm[0]) / s.voxelMm) + dx;
        const int64_t j = std::llround((x[1] - s.originMm[1]) / s.voxelMm) + dy;
        const int64_t k = std::llround((x[2] - s.originMm[2]) / s.voxelMm) + dz;
        return packCell(i, j, k);
    };
    std::unordered_map<int64_t, uint32_t> index;
    index.reserve(voxels.size() * 2);
    for (uint32_t v = 0; v < voxels.size(); ++v) index.emplace(key(voxels[v], 0, 0, 0), v);
    VoxelGraph g;
    g.voxels = &voxels;
    g.neighbours.resize(voxels.size());
    static const int offsets[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (uint32_t v = 0; v < voxels.size(); ++v)
        for (int k = 0; k < 6; ++k) {
            const auto it = index.find(key(voxels[v], offsets[k][0], offsets[k][1], offsets[k][2]));
            g.neighbours[v][size_t(k)] = it == index.end() ? kNone : it->second;
        }
    return g;
}

/// Whether the voxels with @p side[v] == @p which are 6-connected (and there are some).
bool isConnected(const VoxelGraph& g, const std::vector<uint8_t>& side, uint8_t which) {
    uint32_t start = kNone;
    size_t count = 0;
    for (uint32_t v = 0; v < side.size(); ++v)
        if (side[v] == which) {
            if (start == kNone) start = v;
            ++count;
        }
    if (count == 0) return false;
    std::vector<uint8_t> seen(side.size(), 0);
    std::vector<uint32_t> queue{start};
    seen[start] = 1;
    for (size_t q = 0; q < queue.size(); ++q)
        for (uint32_t w : g.neighbours[queue[q]])
            if (w != kNone && side[w] == which && !seen[w]) {
                seen[w] = 1;
                queue.push_back(w);
            }
    return queue.size() == count;
}

/// Per hole, the candidates (count, summed score) that half @p which of @p plane keeps (0: normal·x
/// ≤ offset, 1: beyond): those whose wall point lies at least edgeMarginMm inside it.
std::map<int, std::pair<size_t, double>> halfCandidates(const std::vector<const TenonCandidate*>& candidates,
                                                        const SplitPlane& plane, uint8_t which,
                                                        const SplitSearch& s) {
    const double sign = which ? 1.0 : -1.0;
    std::map<int, std::pair<size_t, double>> byHole;
    for (const TenonCandidate* c : candidates) {
        const double along = sign * (dot(plane.normal, c->tenon.pointAt(c->tenon.baseMm)) - plane.offsetMm);
        if (along < s.edgeMarginMm) continue;
        byHole[c->tenon.hole].first += 1;
        byHole[c->tenon.hole].second += c->score;
    }
    return byHole;
}

/// One half as a body: its surface voxels (a neighbour missing or across the cut), the candidates
/// on its side away from the cut, its options tested along the ranking until the first free one.
MountBody halfBody(const VoxelGraph& g, const std::vector<uint8_t>& side, uint8_t which,
                   const std::vector<const TenonCandidate*>& candidates, const SplitPlane& plane,
                   const FrameSweeps& sweeps, const SplitSearch& s) {
    MountBody half;
    for (uint32_t v = 0; v < side.size(); ++v) {
        if (side[v] != which) continue;
        bool isSurface = false;
        for (uint32_t w : g.neighbours[v]) isSurface = isSurface || w == kNone || side[w] != which;
        if (!isSurface) continue;
        half.voxels.push_back((*g.voxels)[v]);
        half.nearCutOf.push_back({kNone, kNone});
        half.cutLayer.push_back({0, 0});
        half.bounds.expand((*g.voxels)[v]);
    }
    half.options = rankedOptions(halfCandidates(candidates, plane, which, s), size_t(s.maxPerPiece));
    testPaths(half, sweeps, s.voxelMm, kFreeOptionsPerHalf);
    return half;
}

/// The best pair of free directions with tenons for the halves (0: normal·x ≤ offset, 1: beyond) that
/// lets one go on after the other across the plane (mount::faceOrder; a half moving away from the
/// plane cannot meet the other, so the plane decides): (tenons of the weaker, of both), or (0, 0).
std::pair<size_t, size_t> bestOrderedPair(const MountBody& a, const MountBody& b, const SplitPlane& plane,
                                          const FrameSweeps& sweeps, size_t cap) {
    std::pair<size_t, size_t> best{0, 0};
    for (const DirectionOption& oa : a.options) {
        if (!oa.isTested || !oa.isFree || oa.tenons == 0) continue;
        const Vec3d da = gridDirection(oa.hole, sweeps.frameToGridMm());
        for (const DirectionOption& ob : b.options) {
            if (!ob.isTested || !ob.isFree || ob.tenons == 0) continue;
            const mount::FaceOrder order =
                mount::faceOrder(plane.normal, da, gridDirection(ob.hole, sweeps.frameToGridMm()));
            if (!order.isBAfterAOk && !order.isAAfterBOk) continue;
            const size_t ta = std::min(oa.tenons, cap), tb = std::min(ob.tenons, cap);
            best = std::max(best, std::make_pair(std::min(ta, tb), ta + tb));
        }
    }
    return best;
}

/// How good a split is, compared as a tuple: the halves that can be held (both, and ordered across
/// the plane, is best; one is a step: the other is cut again or glued on), then the tenons of the
/// weaker held half and of both.
using SplitValue = std::tuple<size_t, size_t, size_t>;

/// The side of @p plane each voxel of @p g lies on (1: beyond it), when both halves are connected
/// and hold at least s.minVolumeMm3; empty otherwise.
std::optional<std::vector<uint8_t>> connectedSides(const VoxelGraph& g, const SplitPlane& plane,
                                                   const SplitSearch& s) {
    const std::vector<Vec3d>& voxels = *g.voxels;
    std::vector<uint8_t> side(voxels.size());
    size_t above = 0;
    for (size_t v = 0; v < voxels.size(); ++v)
        above += side[v] = dot(plane.normal, voxels[v]) > plane.offsetMm;
    const double voxelVolume = s.voxelMm * s.voxelMm * s.voxelMm;
    if (double(std::min(above, voxels.size() - above)) * voxelVolume < s.minVolumeMm3) return std::nullopt;
    if (!isConnected(g, side, 0) || !isConnected(g, side, 1)) return std::nullopt;
    return side;
}

/// The value of cutting along @p plane: (0, 0, 0) unless both halves are connected and large
/// enough and one at least can be held.
SplitValue splitValue(const VoxelGraph& g, const std::vector<const TenonCandidate*>& candidates,
                      const SplitPlane& plane, const FrameSweeps& sweeps, const SplitSearch& s) {
    const std::optional<std::vector<uint8_t>> sides = connectedSides(g, plane, s);
    if (!sides) return {0, 0, 0};
    const std::vector<uint8_t>& side = *sides;
    const MountBody a = halfBody(g, side, 0, candidates, plane, sweeps, s);
    const MountBody b = halfBody(g, side, 1, candidates, plane, sweeps, s);
    const DirectionOption *oa = a.bestFree(), *ob = b.bestFree();
    if (oa && ob) {
        const auto [weaker, both] = bestOrderedPair(a, b, plane, sweeps, size_t(s.maxPerPiece));
        if (weaker > 0) return {2, weaker, both};
    }
    if (!oa && !ob) return {0, 0, 0};
    const size_t held = std::min((oa ? oa : ob)->tenons, size_t(s.maxPerPiece));
    return {1, held, held};
}

/// The plane of normal @p n through the @p quantile of @p voxels along it, halfway between voxel
/// centres (of side @p voxelMm), so no voxel lies on it.
SplitPlane planeAt(const std::vector<Vec3d>& voxels, const Vec3d& n, double quantile, double voxelMm) {
    std::vector<double> along;
    along.reserve(voxels.size());
    for (const Vec3d& x : voxels) along.push_back(dot(n, x));
    const size_t k = size_t(quantile * double(along.size() - 1));
    std::nth_element(along.begin(), along.begin() + std::ptrdiff_t(k), along.end());
    return {n, (std::floor(along[k] / voxelMm) + 0.5) * voxelMm};
}

/// findFitSplit on a piece's coarse cells (coarseInside) against their fit @p whole (coarseFit
/// with @p marginMm).
std::optional<SplitPlane> coarseFitSplit(const VoxelField& field, const CoarseCells& cells,
                                         const partition::PrinterFit& whole, const Vec3d& printerMm,
                                         double marginMm, double minVolumeMm3) {
    SplitSearch search;
    search.voxelMm = cells.cellMm;
    search.originMm = field.world(Coord(0, 0, 0));
    search.minVolumeMm3 = minVolumeMm3;
    return findFitSplit(cells.centresMm, whole, printerMm, coarseMarginMm(cells, marginMm), search);
}

}  // namespace

std::vector<SplitPlane> connectedSplitPlanes(const std::vector<Vec3d>& cells, const SplitSearch& search) {
    std::vector<SplitPlane> out;
    if (cells.size() < 2) return out;
    const VoxelGraph graph = voxelGraph(cells, search);
    for (const double quantile : kSplitQuantiles)
        for (const Vec3d& n : splitDirections()) {
            const SplitPlane plane = planeAt(cells, n, quantile, search.voxelMm);
            if (connectedSides(graph, plane, search)) out.push_back(plane);
        }
    return out;
}

std::optional<SplitPlane> findSplit(const std::vector<Vec3d>& voxels,
                                    const std::vector<const TenonCandidate*>& candidates,
                                    const FrameSweeps& sweeps, const SplitSearch& search) {
    if (voxels.size() < 2) return std::nullopt;
    const VoxelGraph graph = voxelGraph(voxels, search);
    std::optional<SplitPlane> best;
    SplitValue bestValue{0, 0, 0};
    for (const double quantile : kSplitQuantiles) {
        for (const Vec3d& n : splitDirections()) {
            const SplitPlane plane = planeAt(voxels, n, quantile, search.voxelMm);
            const SplitValue value = splitValue(graph, candidates, plane, sweeps, search);
            if (std::get<0>(value) > 0 && value > bestValue) best = plane, bestValue = value;
        }
        if (best && std::get<0>(bestValue) == 2)
            return best;  // the median planes first: halves of similar size
    }
    return best;
}

HoldingSplits findHoldingSplits(const CoarseCells& cells,
                                const std::vector<const TenonCandidate*>& candidates,
                                const FrameSweeps& sweeps, const SplitSearch& search, const Vec3d& printerMm,
                                double marginMm, size_t minTenons, size_t maxPlanes) {
    const std::vector<Vec3d>& voxels = cells.centresMm;
    // Each half needs minTenons candidates of its own.
    if (voxels.size() < 2 || minTenons == 0 || candidates.size() < 2 * minTenons) return {};
    const VoxelGraph graph = voxelGraph(voxels, search);
    // The grid's 13 directions and the frame's 31 Zome axes (a cut across a limb is often square to
    // one of them), through percentiles from the 20th to the 80th: the search is cheap next to a
    // plan (most planes leave one side too few candidates and cost no path test).
    std::vector<Vec3d> normals = splitDirections();
    for (int hole = 0; hole < zome::kHoleCount; ++hole) {
        const Vec3d n = gridDirection(hole, sweeps.frameToGridMm());
        const bool isNew = std::none_of(normals.begin(), normals.end(),
                                        [&](const Vec3d& m) { return std::abs(dot(m, n)) > 0.9999; });
        if (isNew) normals.push_back(n);
    }
    std::vector<SplitPlane> planes;
    for (const double quantile : {0.5, 0.4, 0.6, 1.0 / 3.0, 2.0 / 3.0, 0.45, 0.55, 0.25, 0.75, 0.2, 0.8})
        for (const Vec3d& n : normals) planes.push_back(planeAt(voxels, n, quantile, search.voxelMm));
    // The tenons first (in parallel: the sweeps are thread-safe), the fit only for planes whose
    // halves are both held well enough, best first; ties in plane order (deterministic).
    std::vector<SplitValue> values(planes.size(), {0, 0, 0});
    tbb::parallel_for(size_t(0), planes.size(), [&](size_t i) {
        // The candidates each side keeps, per hole, first: most planes leave one side too few
        // along every hole, and cost no connectivity or path test then.
        for (const uint8_t which : {0, 1}) {
            size_t most = 0;
            for (const auto& [hole, kept] : halfCandidates(candidates, planes[i], which, search))
                most = std::max(most, kept.first);
            if (most < minTenons) return;
        }
        values[i] = splitValue(graph, candidates, planes[i], sweeps, search);
    });
    // Among the planes that hold both halves well enough, the one with the most tenons first (a
    // half with only minTenons candidates often loses one to a neighbour's tenon when the plan is
    // made again); ties in plane order, the median planes first.
    std::vector<size_t> order;
    for (size_t i = 0; i < planes.size(); ++i)
        if (std::get<0>(values[i]) == 2 && std::get<1>(values[i]) >= minTenons) order.push_back(i);
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return values[a] > values[b]; });
    const double margin = coarseMarginMm(cells, marginMm);
    // (support of the halves, plane), by the halves that fit: [1] one, [2] both.
    std::array<std::vector<std::pair<double, size_t>>, 3> fitting;
    for (size_t i : order) {
        if (fitting[2].size() == kFittingPlanes) break;
        std::array<std::vector<Vec3d>, 2> halves;
        for (const Vec3d& x : voxels) halves[dot(planes[i].normal, x) > planes[i].offsetMm].push_back(x);
        // Searched on fewer extremes (a box up to a few tenths of a mm from the best can be
        // missed, never one too small: the box is measured on every cell), as the search
        // tries many planes; the pieces are fitted again with their tenons (splitOverPrinter).
        size_t fits = 0;
        for (const std::vector<Vec3d>& half : halves)
            fits += fitOfSolid(half, printerMm, margin, kSearchDirections).fits ? 1 : 0;
        if (fits == 0 || fitting[fits].size() == kFittingPlanes) continue;
        const double support =
            restingSupportMm3(halves[0], scale(planes[i].normal, -1.0), -planes[i].offsetMm, cells.cellMm) +
            restingSupportMm3(halves[1], planes[i].normal, planes[i].offsetMm, cells.cellMm);
        fitting[fits].push_back({support, i});
    }
    // The halves that print with the least support first: a plane can leave a half that lies on
    // no face (on the demo one such cut cost 9 h of print time more than the pair before it).
    auto best = [&](std::vector<std::pair<double, size_t>>& list) {
        std::stable_sort(list.begin(), list.end(),
                         [](const auto& a, const auto& b) { return a.first < b.first; });
        std::vector<SplitPlane> out;
        for (size_t k = 0; k < list.size() && k < maxPlanes; ++k) out.push_back(planes[list[k].second]);
        return out;
    };
    HoldingSplits out{best(fitting[2]), {}};
    if (out.bothFit.empty()) out.oneFits = best(fitting[1]);
    return out;
}

std::optional<SplitPlane> findFitSplit(const std::vector<Vec3d>& voxels, const partition::PrinterFit& whole,
                                       const Vec3d& printerMm, double marginMm, const SplitSearch& search) {
    if (voxels.size() < 2) return std::nullopt;
    const VoxelGraph graph = voxelGraph(voxels, search);
    std::vector<Vec3d> normals = splitDirections();
    normals.push_back(whole.axes[2]);  // the longest side of the best box, then the middle one
    normals.push_back(whole.axes[1]);
    const double cellVolume = search.voxelMm * search.voxelMm * search.voxelMm;
    std::vector<SplitPlane> planes;
    for (const double quantile : {0.5, 1.0 / 3.0, 2.0 / 3.0})
        for (const Vec3d& n : normals) {
            std::vector<double> along;
            along.reserve(voxels.size());
            for (const Vec3d& x : voxels) along.push_back(dot(n, x));
            const size_t k = size_t(quantile * double(along.size() - 1));
            std::nth_element(along.begin(), along.begin() + std::ptrdiff_t(k), along.end());
            planes.push_back({n, along[k] + 1e-6});
        }
    // (halves that fit, −the larger fit ratio) per plane; (−1, 0) for planes that leave a half
    // too small or not connected. Evaluated in parallel, chosen in plane order (deterministic).
    std::vector<std::pair<int, double>> values(planes.size(), {-1, 0.0});
    tbb::parallel_for(size_t(0), planes.size(), [&](size_t i) {
        const SplitPlane& plane = planes[i];
        std::vector<uint8_t> side(voxels.size());
        std::array<std::vector<Vec3d>, 2> halves;
        for (size_t v = 0; v < voxels.size(); ++v) {
            side[v] = dot(plane.normal, voxels[v]) > plane.offsetMm;
            halves[side[v]].push_back(voxels[v]);
        }
        if (double(std::min(halves[0].size(), halves[1].size())) * cellVolume < search.minVolumeMm3) return;
        if (!isConnected(graph, side, 0) || !isConnected(graph, side, 1)) return;
        int fitting = 0;
        double worst = 0.0;
        for (const std::vector<Vec3d>& half : halves) {
            const partition::PrinterFit fit = partition::fitInPrinter(half, printerMm, marginMm);
            fitting += fit.fits ? 1 : 0;
            worst = std::max(worst, fit.ratio);
        }
        values[i] = {fitting, -worst};
    });
    std::optional<SplitPlane> best;
    std::pair<int, double> bestValue{-1, 0.0};
    for (size_t i = 0; i < planes.size(); ++i)
        if (values[i].first >= 0 && values[i] > bestValue) best = planes[i], bestValue = values[i];
    return best;
}

CoarseCells coarseInside(const VoxelField& field, const std::vector<size_t>& slots) {
    constexpr double kMaxCells = 500000.0;
    size_t inside = 0;
    for (size_t s : slots) inside += field.isInside(s) ? 1 : 0;
    const int factor = std::max({1, int(std::ceil(2.0 / field.voxelMm - 1e-9)),
                                 int(std::ceil(std::cbrt(double(inside) / kMaxCells)))});
    CoarseCells out;
    out.cellMm = factor * field.voxelMm;
    std::unordered_map<int64_t, char> seen;
    for (size_t s : slots) {
        if (!field.isInside(s)) continue;
        const Coord c = field.coordOf(s);
        const int64_t i = int64_t(std::floor(double(c.x()) / factor)),
                      j = int64_t(std::floor(double(c.y()) / factor)),
                      k = int64_t(std::floor(double(c.z()) / factor));
        if (!seen.emplace(packCell(i, j, k), 1).second) continue;
        const double half = 0.5 * double(factor - 1);
        const Vec3d corner = field.world(Coord(int(i * factor), int(j * factor), int(k * factor)));
        out.centresMm.push_back(add(corner, scale(Vec3d{1, 1, 1}, half * field.voxelMm)));
    }
    return out;
}

double coarseMarginMm(const CoarseCells& cells, double marginMm) {
    // A cell's centre lies up to half its diagonal inside the piece's true extent.
    return marginMm + 0.5 * std::sqrt(3.0) * cells.cellMm;
}

partition::PrinterFit coarseFit(const CoarseCells& cells, const Vec3d& printerMm, double marginMm) {
    return fitOfSolid(cells.centresMm, printerMm, coarseMarginMm(cells, marginMm));
}

std::vector<std::vector<size_t>> slotsOfPieces(const VoxelField& field, size_t pieceCount) {
    std::vector<std::vector<size_t>> slotsOf(pieceCount);
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isActive[s] && field.owner[s] != kNone && field.owner[s] < pieceCount)
            slotsOf[field.owner[s]].push_back(s);
    return slotsOf;
}

std::vector<Vec3d> extremePoints(const std::vector<Vec3d>& points, int directions) {
    // Directions on a Fibonacci sphere; 1,000 (the default) are about 6.5° apart: a point of the
    // hull between two of their extremes lies within r (1 − cos 3.3°), 0.17 mm at r = 100 mm, of
    // their box sides.
    std::vector<uint32_t> chosen;
    for (const Vec3d& d : fibonacciSphere(directions)) {
        uint32_t best = 0;
        double furthest = -1e300;
        for (uint32_t k = 0; k < points.size(); ++k)
            if (const double along = dot(d, points[k]); along > furthest) best = k, furthest = along;
        chosen.push_back(best);
    }
    std::sort(chosen.begin(), chosen.end());
    chosen.erase(std::unique(chosen.begin(), chosen.end()), chosen.end());
    std::vector<Vec3d> out;
    for (uint32_t k : chosen) out.push_back(points[k]);
    return out;
}

partition::PrinterFit fitOfSolid(const std::vector<Vec3d>& points, const Vec3d& printerMm, double marginMm,
                                 int directions) {
    if (points.empty()) return partition::fitInPrinter(points, printerMm, marginMm);
    // The search on the hull's extremes (fitInPrinter searches on at most 4,096 points, which
    // a strided sample of a wall's voxels leaves a few mm short at the hull), the box on all points.
    const partition::PrinterFit onHull =
        partition::fitInPrinter(extremePoints(points, directions), printerMm, marginMm);
    return partition::evaluateFit(points, onHull.axes, printerMm, marginMm);
}

std::vector<std::vector<Vec3d>> wallSurfaceMm(const VoxelField& field, size_t pieceCount) {
    std::vector<std::vector<Vec3d>> out(pieceCount);
    auto keep = [&](size_t s, const Vec3d& x) {
        if (field.owner[s] < pieceCount) out[field.owner[s]].push_back(x);
    };
    // Inside voxel s, its 6-neighbour t: where the wall's surface crosses the edge between them
    // (φ linear along it, as the mesher's edge points), or t's centre when t is another piece's
    // (their cut plane lies between the two centres).
    auto visit = [&](size_t s, size_t t) {
        if (!field.isInside(s)) return;
        const Vec3d xs = field.world(field.coordOf(s)), xt = field.world(field.coordOf(t));
        if (!field.isInside(t)) {
            const double a = double(field.phi[s]), b = std::max(0.0, double(field.phi[t]));
            keep(s, madd(xs, a / (a - b), sub(xt, xs)));
        } else if (field.owner[t] != field.owner[s]) {
            keep(s, xt);
        }
    };
    forEachForwardPair(field, [&](size_t s, size_t t) {
        visit(s, t);
        visit(t, s);
    });
    return out;
}

size_t splitOverPrinter(std::vector<Piece>& pieces, Grouping& grouping, VoxelField& field,
                        const GridCells& cells, const TenonOptions& tenons, const Vec3d& printerMm,
                        double marginMm, double minVolumeMm3, const RunContext& context) {
    std::vector<std::vector<Vec3d>> points = wallSurfaceMm(field, pieces.size());
    std::vector<std::vector<size_t>> slotsOf;  // gathered at the first cut
    const size_t pieceCount = pieces.size();
    Vec3d printer = printerMm;
    std::sort(printer.begin(), printer.end());  // as a fit's extentsMm, shortest side first
    // Halves still to test, with the margin their cut was planned with: on their coarse cells
    // (their tenons are planned again), cut again until they fit, as splitTooLarge.
    std::vector<std::pair<uint32_t, double>> halves;
    auto cut = [&](uint32_t p, double margin, const CoarseCells& cellsOfP,
                   const partition::PrinterFit& whole) {
        const std::optional<SplitPlane> plane =
            coarseFitSplit(field, cellsOfP, whole, printerMm, margin, minVolumeMm3);
        if (!plane) return false;
        std::vector<size_t> otherSlots;
        const uint32_t other =
            splitPiece(pieces, grouping.cellSets, field, p, *plane, &slotsOf[p], &otherSlots);
        slotsOf.push_back(std::move(otherSlots));
        halves.push_back({p, margin});
        halves.push_back({other, margin});
        context.detail(
            formatNumbers("piece %.0f: cut in two (%.0f and %.0f)", double(p), double(p), double(other)));
        return true;
    };
    size_t cuts = 0;
    for (uint32_t p = 0; p < pieceCount; ++p) {
        context.throwIfCancelled();
        for (const Tenon& t : pieces[p].tenons)
            for (const Vec3d& x : tenonHullMm(t, tenons)) points[p].push_back(x);
        // The mesher's vertices lie among the wall's edge points (wallSurfaceMm).
        const partition::PrinterFit fit = fitOfSolid(points[p], printerMm, 0.0);
        if (fit.fits) continue;
        if (slotsOf.empty()) slotsOf = slotsOfPieces(field, pieceCount);
        double overshootMm = 0.0;
        for (int a = 0; a < 3; ++a)
            overshootMm = std::max(overshootMm, fit.extentsMm[size_t(a)] - printer[size_t(a)]);
        context.detail(
            formatNumbers("piece %.0f with its tenons is %.1f mm larger than the printer's %g x %g x %g "
                          "mm in every orientation",
                          double(p), overshootMm, printerMm[0], printerMm[1], printerMm[2]));
        // The halves are fitted without their tenons: the margin takes what the tenons added.
        const double margin = marginMm + 0.5 * overshootMm;
        const CoarseCells cellsOfP = coarseInside(field, slotsOf[p]);
        cuts += cut(p, margin, cellsOfP, coarseFit(cellsOfP, printerMm, margin)) ? 1 : 0;
    }
    for (size_t k = 0; k < halves.size() && cuts < 4 * pieceCount + 64; ++k) {
        context.throwIfCancelled();
        const auto [p, margin] = halves[k];
        const CoarseCells cellsOfP = coarseInside(field, slotsOf[p]);
        const partition::PrinterFit whole = coarseFit(cellsOfP, printerMm, margin);
        if (!whole.fits) cuts += cut(p, margin, cellsOfP, whole) ? 1 : 0;
    }
    if (cuts > 0) grouping.faces = faceContacts(field, cells, grouping.cellSets, pieces);
    return cuts;
}

size_t splitTooLarge(std::vector<Piece>& pieces, Grouping& grouping, VoxelField& field,
                     const GridCells& cells, const std::vector<partition::Piece>& requests,
                     bool isRequestFitTrusted, const Vec3d& printerMm, double marginMm, double minVolumeMm3,
                     const RunContext& context) {
    // Each piece's band and inside slots, gathered once (a scan of the whole field per cut is slow
    // at 700 mm).
    std::vector<std::vector<size_t>> slotsOf = slotsOfPieces(field, pieces.size());
    size_t cuts = 0;
    std::vector<uint32_t> queue(pieces.size());
    for (uint32_t p = 0; p < pieces.size(); ++p) queue[p] = p;
    // What the partition fitted to this printer stays as it is (its surface test is the one the
    // cuts were made for); a piece with a request it could not fit is tested here.
    auto isFitted = [&](uint32_t p) {
        if (!isRequestFitTrusted) return false;
        for (uint32_t r : pieces[p].requests)
            if (r >= requests.size() || !requests[r].fit.fits) return false;
        return !pieces[p].requests.empty();
    };
    for (size_t q = 0; q < queue.size() && cuts < 4 * pieces.size() + 64; ++q) {
        context.throwIfCancelled();
        const uint32_t p = queue[q];
        if (isFitted(p)) continue;
        const CoarseCells points = coarseInside(field, slotsOf[p]);
        const partition::PrinterFit whole = coarseFit(points, printerMm, marginMm);
        if (whole.fits) continue;
        const std::optional<SplitPlane> plane =
            coarseFitSplit(field, points, whole, printerMm, marginMm, minVolumeMm3);
        if (!plane) continue;
        std::vector<size_t> otherSlots;
        const uint32_t other =
            splitPiece(pieces, grouping.cellSets, field, p, *plane, &slotsOf[p], &otherSlots);
        slotsOf.push_back(std::move(otherSlots));
        context.detail("piece " + std::to_string(p) +
                       " is larger than the printer in every orientation: cut in two (" + std::to_string(p) +
                       " and " + std::to_string(other) + ")");
        ++cuts;
        queue.push_back(p);
        queue.push_back(other);
    }
    if (cuts > 0) grouping.faces = faceContacts(field, cells, grouping.cellSets, pieces);
    return cuts;
}

uint32_t splitPiece(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field, uint32_t p,
                    const SplitPlane& plane, std::vector<size_t>* slots, std::vector<size_t>* newSlots) {
    const uint32_t q = uint32_t(pieces.size());
    Piece half;
    half.id = q;
    half.cells = pieces[p].cells;
    half.requests = pieces[p].requests;
    pieces.push_back(half);
    CellSet other = sets[p];
    sets[p].halfSpaces.push_back({plane.normal, plane.offsetMm});
    other.halfSpaces.push_back({scale(plane.normal, -1.0), -plane.offsetMm});
    sets.push_back(other);
    const double voxelVolume = field.voxelMm * field.voxelMm * field.voxelMm;
    pieces[p].shellVolumeMm3 = 0.0;
    auto visit = [&](size_t s) {
        if (dot(plane.normal, field.world(field.coordOf(s))) > plane.offsetMm) field.owner[s] = q;
        if (field.isInside(s)) (field.owner[s] == q ? pieces[q] : pieces[p]).shellVolumeMm3 += voxelVolume;
    };
    if (slots) {
        for (size_t s : *slots) visit(s);
        std::vector<size_t> kept;
        for (size_t s : *slots) (field.owner[s] == q ? *newSlots : kept).push_back(s);
        *slots = std::move(kept);
    } else {
        for (size_t s = 0; s < field.phi.size(); ++s)
            if (field.isActive[s] && field.owner[s] == p) visit(s);
    }
    return q;
}

}  // namespace zomefab::pieces::detail
