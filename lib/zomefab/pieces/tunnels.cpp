// SPDX-License-Identifier: GPL-3.0-or-later
// Tunnel linings cut into slabs (detail/tunnels.h, docs/mounting.md "Tunnels").
#include "zomefab/pieces/detail/tunnels.h"

#include <algorithm>
#include <cmath>

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

}  // namespace zomefab::pieces::detail
