// SPDX-License-Identifier: GPL-3.0-or-later
// Tunnel linings cut into slabs (detail/tunnels.h, docs/mounting.md "Tunnels").
#include "zomefab/pieces/detail/tunnels.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <iterator>

#include "zomefab/core/format.h"

namespace zomefab::pieces::detail {

std::vector<TunnelGroup> tunnelGroups(const std::vector<uint32_t>& pieces,
                                      const std::vector<std::vector<Vec3d>>& freeAlong, size_t minPieces) {
    const double sameAxis = std::cos(kPi / 180.0);
    std::vector<uint8_t> isTaken(pieces.size(), 0);
    std::vector<TunnelGroup> out;
    for (;;) {
        // Every axis met, with the pieces free along it either way.
        std::vector<Vec3d> axes;
        for (const auto& list : freeAlong)
            for (const Vec3d& d : list)
                if (std::none_of(axes.begin(), axes.end(),
                                 [&](const Vec3d& a) { return std::abs(dot(a, d)) >= sameAxis; }))
                    axes.push_back(d);
        TunnelGroup best;
        size_t bestThrough = 0;
        for (const Vec3d& a : axes) {
            TunnelGroup g{a, {}};
            auto isFreeAlong = [&](size_t k, double sign) {
                return std::any_of(freeAlong[k].begin(), freeAlong[k].end(),
                                   [&](const Vec3d& d) { return sign * dot(a, d) >= sameAxis; });
            };
            size_t through = 0;  // pieces free along it both ways
            for (size_t k = 0; k < pieces.size(); ++k) {
                if (isTaken[k]) continue;
                const bool isForward = isFreeAlong(k, 1.0), isBack = isFreeAlong(k, -1.0);
                if (isForward || isBack) g.pieces.push_back(pieces[k]);
                through += isForward && isBack ? 1 : 0;
            }
            if (through < std::max<size_t>(1, minPieces)) continue;
            // The most pieces free both ways: a tunnel's lining. Counting the pieces free one way
            // too would let a diagonal win that every piece outside reaches outward along (the
            // cheese at 700 mm: 36 pieces "along" (0.58, 0.58, −0.58), 6 along its tunnels' x).
            if (through > bestThrough || (through == bestThrough && g.pieces.size() > best.pieces.size()))
                best = g, bestThrough = through;
        }
        if (best.pieces.size() < std::max<size_t>(1, minPieces)) break;
        for (size_t k = 0; k < pieces.size(); ++k)
            if (std::count(best.pieces.begin(), best.pieces.end(), pieces[k])) isTaken[k] = 1;
        std::sort(best.pieces.begin(), best.pieces.end());
        best.lining = best.pieces.size();
        out.push_back(best);
    }
    return out;
}

std::vector<double> slabOffsets(const std::vector<double>& t, double slabMm, size_t minVoxels) {
    std::vector<double> out;
    if (t.empty() || !(slabMm > 0.0)) return out;
    std::vector<double> sorted = t;
    std::sort(sorted.begin(), sorted.end());
    const double lo = sorted.front(), hi = sorted.back();
    size_t kept = 0;  // voxels at or below the last plane kept
    for (double k = std::ceil(lo / slabMm); k * slabMm < hi; k += 1.0) {
        const double at = k * slabMm;
        const size_t below = size_t(std::upper_bound(sorted.begin(), sorted.end(), at) - sorted.begin());
        if (below - kept < minVoxels || sorted.size() - below < minVoxels) continue;
        out.push_back(at);
        kept = below;
    }
    return out;
}

AxisShadow emptyShadow(int axis, const Coord& lo, const Coord& hi) {
    AxisShadow s;
    s.axis = axis;
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    s.loU = lo[u] - 1, s.loV = lo[v] - 1;
    s.sizeU = hi[u] - lo[u] + 3, s.sizeV = hi[v] - lo[v] + 3;
    s.isHit.assign(size_t(s.sizeU) * size_t(s.sizeV), 0);
    return s;
}

void markHit(AxisShadow& shadow, const Coord& ijk) {
    const auto [u, v] = shadow.columnOf(ijk);
    shadow.mark(u, v);
}

std::array<AxisShadow, 3> emptyShadowsOf(const VoxelField& field) {
    std::array<AxisShadow, 3> out;
    if (field.leafOrigin.empty()) return out;
    // Over the leaves' bounds (a few voxels more than the inside's: columns no voxel hits).
    Coord lo = field.leafOrigin[0], hi = field.leafOrigin[0];
    for (const Coord& o : field.leafOrigin) lo.minComponent(o), hi.maxComponent(o);
    hi.offset(7);
    for (int a = 0; a < 3; ++a) out[size_t(a)] = emptyShadow(a, lo, hi);
    return out;
}

std::array<AxisShadow, 3> shadowsOf(const VoxelField& field) {
    std::array<AxisShadow, 3> out = emptyShadowsOf(field);
    for (size_t s = 0; s < field.isActive.size(); ++s)
        if (field.isInside(s))
            for (AxisShadow& shadow : out) markHit(shadow, field.coordOf(s));
    return out;
}

std::vector<TunnelCore> tunnelCores(const AxisShadow& shadow, double voxelMm, double minDiameterMm) {
    std::vector<TunnelCore> out;
    const int nu = shadow.sizeU, nv = shadow.sizeV;
    // Indexed as isHit (AxisShadow::slotOf without the offsets): hit columns count as seen.
    std::vector<uint8_t> isSeen(shadow.isHit);
    auto seen = [&](int u, int v) -> uint8_t& { return isSeen[size_t(u) * size_t(nv) + size_t(v)]; };
    for (int u0 = 0; u0 < nu; ++u0)
        for (int v0 = 0; v0 < nv; ++v0) {
            if (seen(u0, v0)) continue;
            // One connected set of free columns (4-neighbours), flood-filled.
            TunnelCore core;
            core.axis = shadow.axis;
            bool isOpen = false;  // reaches the border: the lines round the object
            std::deque<std::array<int, 2>> queue{{u0, v0}};
            seen(u0, v0) = 1;
            while (!queue.empty()) {
                const auto [u, v] = queue.front();
                queue.pop_front();
                core.columns.push_back({u + shadow.loU, v + shadow.loV});
                isOpen |= u == 0 || v == 0 || u == nu - 1 || v == nv - 1;
                const int du[4] = {1, -1, 0, 0}, dv[4] = {0, 0, 1, -1};
                for (int k = 0; k < 4; ++k) {
                    const int a = u + du[k], b = v + dv[k];
                    if (a < 0 || b < 0 || a >= nu || b >= nv || seen(a, b)) continue;
                    seen(a, b) = 1;
                    queue.push_back({a, b});
                }
            }
            core.diameterMm = 2.0 * std::sqrt(double(core.columns.size()) / kPi) * voxelMm;
            if (isOpen || core.diameterMm < minDiameterMm) continue;
            std::sort(core.columns.begin(), core.columns.end());
            out.push_back(std::move(core));
        }
    return out;
}

namespace {

/// The values of grid axis @p c that @p core's columns take (sorted, unique).
std::vector<int> valuesAlong(const TunnelCore& core, int c) {
    const size_t k = (core.axis + 1) % 3 == c ? 0 : 1;
    std::vector<int> out;
    for (const auto& column : core.columns) out.push_back(column[k]);
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

}  // namespace

bool coresCross(const TunnelCore& a, const TunnelCore& b) {
    if (a.axis == b.axis) return false;
    const int c = 3 - a.axis - b.axis;
    const std::vector<int> x = valuesAlong(a, c), y = valuesAlong(b, c);
    std::vector<int> both;
    std::set_intersection(x.begin(), x.end(), y.begin(), y.end(), std::back_inserter(both));
    return !both.empty();
}

std::vector<TunnelCore> coresAlongAxes(const std::array<AxisShadow, 3>& shadows, double voxelMm,
                                       double minDiameterMm) {
    std::vector<TunnelCore> cores;
    for (const AxisShadow& s : shadows)
        for (TunnelCore& core : tunnelCores(s, voxelMm, minDiameterMm)) cores.push_back(std::move(core));
    return cores;
}

std::vector<uint8_t> crossingFlags(const std::vector<TunnelCore>& cores, size_t* pairs) {
    std::vector<uint8_t> crosses(cores.size(), 0);
    size_t count = 0;
    for (size_t i = 0; i < cores.size(); ++i)
        for (size_t j = i + 1; j < cores.size(); ++j)
            if (coresCross(cores[i], cores[j])) crosses[i] = crosses[j] = 1, ++count;
    if (pairs) *pairs = count;
    return crosses;
}

CrossingTunnels crossingTunnels(const VoxelField& field, size_t pieceCount, double minDiameterMm,
                                double reachMm) {
    CrossingTunnels out;
    out.liningShare.assign(pieceCount, 0.0);
    std::array<AxisShadow, 3> shadows = shadowsOf(field);
    if (shadows[0].isHit.empty()) return out;
    const std::vector<TunnelCore> cores = coresAlongAxes(shadows, field.voxelMm, minDiameterMm);
    const std::vector<uint8_t> crosses = crossingFlags(cores, &out.crossings);
    // Near a crossing core: within reach of one of its columns across its axis (a disc stamped
    // round each column at the core's edge, next to a column the object hits).
    std::array<AxisShadow, 3> near = shadows;
    for (AxisShadow& s : near) std::fill(s.isHit.begin(), s.isHit.end(), 0);
    const int r = int(std::ceil(reachMm / field.voxelMm));
    for (size_t i = 0; i < cores.size(); ++i) {
        if (!crosses[i]) continue;
        ++out.tunnels;
        out.meanDiameterMm += cores[i].diameterMm;
        const AxisShadow& hit = shadows[size_t(cores[i].axis)];
        AxisShadow& mark = near[size_t(cores[i].axis)];
        for (const auto& [cu, cv] : cores[i].columns) {
            if (!hit.isHitAt(cu + 1, cv) && !hit.isHitAt(cu - 1, cv) && !hit.isHitAt(cu, cv + 1) &&
                !hit.isHitAt(cu, cv - 1))
                continue;
            for (int du = -r; du <= r; ++du)
                for (int dv = -r; dv <= r; ++dv)
                    if (du * du + dv * dv <= r * r) mark.mark(cu + du, cv + dv);
        }
    }
    if (out.tunnels == 0) return out;
    out.meanDiameterMm /= double(out.tunnels);
    std::vector<size_t> total(pieceCount, 0), lining(pieceCount, 0);
    for (size_t s = 0; s < field.isActive.size(); ++s) {
        if (!field.isInside(s) || field.owner[s] >= pieceCount) continue;
        const Coord c = field.coordOf(s);
        ++total[field.owner[s]];
        const bool isNear = std::any_of(near.begin(), near.end(), [&](const AxisShadow& n) {
            const auto [u, v] = n.columnOf(c);
            return n.isHitAt(u, v);
        });
        lining[field.owner[s]] += isNear ? 1 : 0;
    }
    for (size_t p = 0; p < pieceCount; ++p)
        out.liningShare[p] = total[p] > 0 ? double(lining[p]) / double(total[p]) : 0.0;
    return out;
}

size_t liningPieces(const CrossingTunnels& tunnels, const std::vector<uint32_t>& pieces) {
    return size_t(std::count_if(pieces.begin(), pieces.end(), [&](uint32_t p) {
        return p < tunnels.liningShare.size() && tunnels.liningShare[p] >= 0.5;
    }));
}

std::string crossingTunnelNote(const CrossingTunnels& tunnels, const std::vector<uint32_t>& unplaced,
                               size_t minPieces, size_t* lining) {
    const size_t count = liningPieces(tunnels, unplaced);
    if (lining) *lining = 0;
    if (count < std::max<size_t>(1, minPieces) || 2 * count < unplaced.size()) return "";
    if (lining) *lining = count;
    return std::to_string(count) + " of the " + std::to_string(unplaced.size()) +
           " pieces placed nowhere line tunnels through the object that cross each other (" +
           std::to_string(tunnels.tunnels) + " straight tunnels about " +
           formatNumbers("%.0f", tunnels.meanDiameterMm) + " mm across, " +
           std::to_string(tunnels.crossings) + (tunnels.crossings == 1 ? " pair" : " pairs") +
           " of them crossing): such a piece can reach its place only through the tunnels, and "
           "zomefab lines a tunnel with rings that slide in along it where no other tunnel crosses it "
           "or where tunnels cross two at a time, and with staves where three meet at one point, and "
           "these were not placed (docs/mounting.md, \"Tunnels that cross\"), so partitioning again "
           "does not help";
}

size_t crossingTunnelLining(const Pieces& out, const VoxelField& field, double wallMm, std::string* note,
                            bool isMostRequired) {
    std::vector<uint32_t> unplaced;
    for (size_t p = 0; p < out.plan.holeOfPiece.size(); ++p)
        if (out.plan.holeOfPiece[p] < 0) unplaced.push_back(uint32_t(p));
    if (unplaced.size() < kMinCrossingLining) return 0;
    // A gap narrower than two walls is a crack between parts, not a tunnel a piece lines; a voxel
    // within a wall and two voxels of a core's edge is in the lining (or round a mouth).
    const CrossingTunnels tunnels =
        crossingTunnels(field, out.pieces.size(), 2.0 * wallMm, wallMm + 2.0 * field.voxelMm);
    if (!isMostRequired) {
        const size_t lining = liningPieces(tunnels, unplaced);
        return lining >= kMinCrossingLining ? lining : 0;
    }
    size_t lining = 0;
    const std::string text = crossingTunnelNote(tunnels, unplaced, kMinCrossingLining, &lining);
    if (note) *note = text;
    return text.empty() ? 0 : lining;
}

size_t noteCrossingTunnels(Pieces& out, const VoxelField& field, double wallMm) {
    std::string note;
    const size_t lining = crossingTunnelLining(out, field, wallMm, &note, true);
    if (lining == 0) return 0;
    out.plan.problems.insert(out.plan.problems.begin(), note);
    out.crossingTunnelPieces = lining;
    return lining;
}

}  // namespace zomefab::pieces::detail
