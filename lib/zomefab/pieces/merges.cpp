// SPDX-License-Identifier: GPL-3.0-or-later
// Printing two pieces as one (detail/merges.h, docs/mounting.md "Merged pieces").
#include "zomefab/pieces/detail/merges.h"

#include <algorithm>
#include <iterator>
#include <optional>
#include <set>

#include "zomefab/pieces/detail/splits.h"

namespace zomefab::pieces::detail {

namespace {

/// The sorted union of two sorted lists.
std::vector<uint32_t> sortedUnion(const std::vector<uint32_t>& a, const std::vector<uint32_t>& b) {
    std::vector<uint32_t> out;
    std::set_union(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(out));
    return out;
}

/// The inside slots of each piece of @p wanted (others empty), in slot order.
std::vector<std::vector<size_t>> insideSlots(const VoxelField& field, const std::vector<uint8_t>& wanted) {
    std::vector<std::vector<size_t>> out(wanted.size());
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isInside(s) && field.owner[s] < wanted.size() && wanted[field.owner[s]])
            out[field.owner[s]].push_back(s);
    return out;
}

}  // namespace

bool isMergeable(const std::vector<CellSet>& sets, uint32_t a, uint32_t b) {
    return a != b && sets[a].halfSpaces.empty() && sets[b].halfSpaces.empty() && !sets[a].isLining &&
           !sets[b].isLining;
}

std::optional<size_t> splitPlaneBetween(const std::vector<CellSet>& sets, uint32_t a, uint32_t b) {
    const CellSet &x = sets[a], &y = sets[b];
    if (a == b || x.members != y.members || x.halfSpaces.size() != y.halfSpaces.size()) return std::nullopt;
    std::optional<size_t> differing;
    for (size_t i = 0; i < x.halfSpaces.size(); ++i) {
        const CellSet::HalfSpace &h = x.halfSpaces[i], &k = y.halfSpaces[i];
        if (h.normal == k.normal && h.offsetMm == k.offsetMm) continue;
        const bool isOpposite = h.normal == scale(k.normal, -1.0) && h.offsetMm == -k.offsetMm;
        if (!isOpposite || differing) return std::nullopt;
        differing = i;
    }
    return differing;
}

uint32_t mergePieces(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field, uint32_t keep,
                     uint32_t gone) {
    // The two halves of one split: the union is the piece before it, without that plane.
    if (const std::optional<size_t> plane = splitPlaneBetween(sets, keep, gone))
        sets[keep].halfSpaces.erase(sets[keep].halfSpaces.begin() + std::ptrdiff_t(*plane));
    Piece& k = pieces[keep];
    const Piece& g = pieces[gone];
    k.cells = sortedUnion(k.cells, g.cells);
    k.requests = sortedUnion(k.requests, g.requests);
    k.sliversMerged += g.sliversMerged;
    k.shellVolumeMm3 += g.shellVolumeMm3;
    // The union's cutters: every cell it does not have, and those it shares with a third piece.
    CellSet& set = sets[keep];
    const size_t cellCount = set.isMember.size();
    std::vector<uint32_t> piecesOfCell(cellCount, 0);
    for (uint32_t p = 0; p < pieces.size(); ++p)
        if (p != gone)
            for (uint32_t c : pieces[p].cells) ++piecesOfCell[c];
    set.members = k.cells;
    set.cutters.clear();
    set.isMember.assign(cellCount, 0);
    for (uint32_t c : k.cells) set.isMember[c] = 1;
    for (uint32_t c = 0; c < cellCount; ++c)
        if (!set.isMember[c] || piecesOfCell[c] > 1) set.cutters.push_back(c);

    const uint32_t keepNow = keep > gone ? keep - 1 : keep;
    for (size_t s = 0; s < field.owner.size(); ++s) {
        uint32_t& o = field.owner[s];
        if (o == kNone || o < gone) continue;
        o = o == gone ? keepNow : o - 1;
    }
    pieces.erase(pieces.begin() + gone);
    sets.erase(sets.begin() + gone);
    for (uint32_t p = 0; p < pieces.size(); ++p) pieces[p].id = p;
    return keepNow;
}

std::vector<MergeOption> mergeOptions(const std::vector<Piece>& pieces, const std::vector<CellSet>& sets,
                                      const VoxelField& field, const std::vector<size_t>& pegs,
                                      const PlannerInput& input, const FrameSweeps& sweeps,
                                      const MergeSearch& search) {
    const size_t n = pieces.size();
    std::vector<std::pair<double, uint32_t>> underHeld;  // (volume, piece): smallest first
    std::vector<uint8_t> wanted(n, 0);
    for (uint32_t p = 0; p < n; ++p) {
        if (pegs[p] >= size_t(search.minPerPiece)) continue;
        underHeld.push_back({pieces[p].shellVolumeMm3, p});
        wanted[p] = 1;
        for (const auto& [q, area] : pieces[p].neighbors) wanted[q] |= isMergeable(sets, p, q) ? 1 : 0;
    }
    if (underHeld.empty()) return {};
    std::sort(underHeld.begin(), underHeld.end());
    const std::vector<std::vector<size_t>> slots = insideSlots(field, wanted);
    std::vector<MergeOption> out;
    for (const auto& [volume, p] : underHeld) {
        std::vector<MergeOption> mine;
        for (const auto& [q, area] : pieces[p].neighbors) {
            if (!isMergeable(sets, p, q)) continue;
            if (!coarseFit(coarseUnion(field, slots[p], slots[q]), search.printerMm, search.fitMarginMm).fits)
                continue;
            const MountBody body = makeBody({std::min(p, q), std::max(p, q)}, input, sweeps, field.voxelMm,
                                            search.maxPerPiece, 1);
            const DirectionOption* free = body.bestFree();
            if (!free || free->tenons < size_t(search.minPerPiece) || free->tenons <= pegs[p]) continue;
            mine.push_back({p, q, free->tenons, area});
        }
        // The most tenons along the union's best free direction, then the largest cut face, then
        // the lowest neighbour.
        std::sort(mine.begin(), mine.end(), [](const MergeOption& a, const MergeOption& b) {
            if (a.tenons != b.tenons) return a.tenons > b.tenons;
            if (a.areaMm2 != b.areaMm2) return a.areaMm2 > b.areaMm2;
            return a.neighbor < b.neighbor;
        });
        out.insert(out.end(), mine.begin(), mine.end());
    }
    return out;
}

std::vector<std::pair<uint32_t, uint32_t>> disjointPairs(
    const std::vector<std::pair<uint32_t, uint32_t>>& pairs) {
    std::set<uint32_t> used;
    std::vector<std::pair<uint32_t, uint32_t>> out;
    for (const auto& [a, b] : pairs) {
        if (used.count(a) || used.count(b)) continue;
        out.push_back({a, b});
        used.insert(a), used.insert(b);
    }
    return out;
}

std::vector<uint32_t> mergeAll(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field,
                               std::vector<std::pair<uint32_t, uint32_t>> pairs) {
    std::vector<uint32_t> now(pieces.size());  // original id → current id
    for (uint32_t p = 0; p < now.size(); ++p) now[p] = p;
    for (const auto& [a, b] : pairs) {
        // The lower id stays: the other pieces' numbers move as little as they can.
        const uint32_t keep = std::min(now[a], now[b]), gone = std::max(now[a], now[b]);
        const uint32_t kept = mergePieces(pieces, sets, field, keep, gone);
        for (uint32_t& id : now) id = id == gone ? kept : (id > gone ? id - 1 : id);
    }
    return now;
}

}  // namespace zomefab::pieces::detail
