// SPDX-License-Identifier: GPL-3.0-or-later
// The order the staves go on in (detail/mounting.h; docs/mounting.md, "Three tunnels through one
// point"): rings ordered by their ways out, and staves no hole holds glued in place onto the staves
// on before them.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <tuple>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/zome/holes.h"

namespace zomefab::pieces::detail {

namespace {

/// A stave's ring: the rank's priority, tunnel, mouth and depth (the side and the lift tell the
/// staves of one ring apart).
auto ringKey(const Stave& stave) {
    const auto& r = stave.rank;
    return std::make_tuple(std::get<0>(r), std::get<1>(r), std::get<2>(r), std::get<3>(r), std::get<4>(r));
}

/// Whether pieces @p p and @p q share a cut face large enough to glue across (GlueOnRule).
bool sharesGlueSeam(uint32_t p, uint32_t q, const FaceContacts& faces, double voxelMm) {
    const auto it = faces.find({std::min(p, q), std::max(p, q)});
    size_t voxelFaces = 0;
    if (it != faces.end())
        for (const CutContact& c : it->second) voxelFaces += c.voxelFaces;
    return GlueOnRule{}.isLargeEnough(voxelFaces, voxelMm);
}

/// Which staves of @p ring (order indices) are held or glued in place when @p isOn (held or glued
/// staves already on) are: its held staves, then, in rounds, each that can slide in and shares a seam
/// with one of those (a chain round the ring).
std::vector<uint8_t> ringPlaced(const StaveRings& g, const std::vector<size_t>& ring,
                                const std::vector<uint8_t>& isOn) {
    std::vector<uint8_t> placed(ring.size(), 0);
    for (size_t i = 0; i < ring.size(); ++i) placed[i] = g.isHeld[ring[i]];
    auto isHost = [&](size_t j) {
        if (isOn[j]) return true;
        for (size_t i = 0; i < ring.size(); ++i)
            if (ring[i] == j) return placed[i] != 0;
        return false;
    };
    for (bool isGrown = true; isGrown;) {
        isGrown = false;
        for (size_t i = 0; i < ring.size(); ++i) {
            if (placed[i] || !g.canSlideIn[ring[i]]) continue;
            for (size_t j : g.seamMates[ring[i]])
                if (isHost(j)) {
                    placed[i] = 1, isGrown = true;
                    break;
                }
        }
    }
    return placed;
}

/// Staves of @p order no hole holds (−1) that can slide in along their tunnel leave the fixed bodies at
/// the end of @p list (and @p order) for the movable ones before them: each takes the hole along its
/// slide as its one glue option, with its slide as its sleeve (PlannerInput::isGluingUnheldStaves).
void unfixUnheldStaves(std::vector<MountBody>& list, StaveOrder& order, const PlannerInput& input,
                       const FrameSweeps& sweeps, double voxelMm) {
    const size_t first = list.size() - order.pieces.size();
    std::vector<MountBody> movable, fixedBodies;
    StaveOrder kept;
    for (size_t k = 0; k < order.pieces.size(); ++k) {
        MountBody& body = list[first + k];
        const Stave& stave = *input.staves[order.pieces[k]];
        const int along = holeAlongSlide(stave, sweeps.frameToGridMm());
        if (order.holes[k] >= 0 || along < 0) {
            fixedBodies.push_back(std::move(body));
            kept.pieces.push_back(order.pieces[k]);
            kept.holes.push_back(order.holes[k]);
            kept.hosts.push_back(order.hosts[k]);
            continue;
        }
        body.options.clear();
        body.sleeveGrid = stave.slideGrid;
        addGlueOptions(body, {along}, sweeps, voxelMm);
        movable.push_back(std::move(body));
    }
    list.resize(first);
    for (MountBody& b : movable) list.push_back(std::move(b));
    for (MountBody& b : fixedBodies) list.push_back(std::move(b));
    order = std::move(kept);
}

}  // namespace

int holeAlongSlide(const Stave& stave, const Transform4d& frameToGridMm) {
    for (int h = 0; h < zome::kHoleCount; ++h)
        if (dot(gridDirection(h, frameToGridMm), stave.slideGrid) > std::cos(kPi / 180.0)) return h;
    return -1;
}

std::vector<size_t> orderStaveRings(const StaveRings& g, size_t* cyclesBroken) {
    const size_t n = g.ringOf.size();
    size_t ringCount = 0;
    for (size_t r : g.ringOf) ringCount = std::max(ringCount, r + 1);
    std::vector<std::vector<size_t>> members(ringCount), before(ringCount);
    for (size_t k = 0; k < n; ++k) members[g.ringOf[k]].push_back(k);
    for (size_t r = 0; r < g.later.size(); ++r)
        for (size_t s : g.later[r])
            if (s != r) before[s].push_back(r);
    std::vector<uint8_t> isRingOn(ringCount, 0), isOn(n, 0);
    std::vector<size_t> perm;
    if (cyclesBroken) *cyclesBroken = 0;
    for (size_t done = 0; done < ringCount; ++done) {
        auto isFree = [&](size_t r) {
            return !isRingOn[r] && std::all_of(before[r].begin(), before[r].end(),
                                               [&](size_t q) { return isRingOn[q] != 0; });
        };
        // The first ring (rank order) whose ways allow it and all of whose staves are then held or
        // glued in place; else the first whose ways allow it (its unheld staves stay so); else, in
        // a cycle of ways, the first left.
        size_t pick = ringCount, firstFree = ringCount, firstLeft = ringCount;
        for (size_t r = 0; r < ringCount && pick == ringCount; ++r) {
            if (isRingOn[r]) continue;
            firstLeft = std::min(firstLeft, r);
            if (!isFree(r)) continue;
            firstFree = std::min(firstFree, r);
            const std::vector<uint8_t> placed = ringPlaced(g, members[r], isOn);
            if (std::all_of(placed.begin(), placed.end(), [](uint8_t x) { return x != 0; })) pick = r;
        }
        if (pick == ringCount) pick = firstFree;
        if (pick == ringCount) {
            pick = firstLeft;
            if (cyclesBroken) ++*cyclesBroken;
        }
        const std::vector<uint8_t> placed = ringPlaced(g, members[pick], isOn);
        for (size_t i = 0; i < members[pick].size(); ++i) {
            perm.push_back(members[pick][i]);
            isOn[members[pick][i]] = placed[i];
        }
        isRingOn[pick] = 1;
    }
    return perm;
}

StaveRings staveRings(const StaveOrder& order, const std::vector<MountBody>& bodies,
                      const PlannerInput& input, const FaceContacts& faces, const Transform4d& frameToGridMm,
                      double voxelMm) {
    const size_t n = order.pieces.size();
    StaveRings g;
    g.ringOf.resize(n);
    for (size_t k = 0, ring = 0; k < n; ++k) {
        if (k > 0 && ringKey(*input.staves[order.pieces[k]]) != ringKey(*input.staves[order.pieces[k - 1]]))
            ++ring;
        g.ringOf[k] = ring;
    }
    g.later.resize(n == 0 ? 0 : g.ringOf.back() + 1);
    g.isHeld.resize(n), g.canSlideIn.resize(n), g.seamMates.resize(n);
    // Stave j lies in stave k's way out along its tunnel when their faces say k goes on first, or
    // k's voxels slid out along the tunnel meet j's. Only its slide is swept: its lift (toward the
    // axis, into the hollow) meets only the staves of its own ring, whose order the rank keeps.
    std::vector<std::tuple<size_t, size_t, bool>> toSweep;  // k, j, touching
    for (size_t k = 0; k < n; ++k) {
        const Stave& stave = *input.staves[order.pieces[k]];
        g.isHeld[k] = order.holes[k] >= 0;
        g.canSlideIn[k] = holeAlongSlide(stave, frameToGridMm) >= 0;
        for (size_t j = 0; j < n; ++j) {
            if (j == k) continue;
            if (sharesGlueSeam(order.pieces[k], order.pieces[j], faces, voxelMm)) g.seamMates[k].push_back(j);
            if (g.ringOf[j] == g.ringOf[k]) continue;
            bool isTouching = false;
            if (!facesAllow(bodies[j], bodies[k], stave.slideGrid, faces, &isTouching))
                g.later[g.ringOf[k]].push_back(g.ringOf[j]);
            else if (shadowsMeet(bodies[k].bounds, bodies[j].bounds, stave.slideGrid))
                toSweep.emplace_back(k, j, isTouching);
        }
    }
    std::vector<uint8_t> hits(toSweep.size(), 0);
    tbb::parallel_for(size_t(0), toSweep.size(), [&](size_t i) {
        const auto& [k, j, isTouching] = toSweep[i];
        hits[i] =
            sweepHits(bodies[k], bodies[j], input.staves[order.pieces[k]]->slideGrid, voxelMm, isTouching);
    });
    for (size_t i = 0; i < toSweep.size(); ++i)
        if (hits[i]) g.later[g.ringOf[std::get<0>(toSweep[i])]].push_back(g.ringOf[std::get<1>(toSweep[i])]);
    for (std::vector<size_t>& list : g.later) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
    }
    return g;
}

std::vector<std::string> unheldStaveNotes(const StaveOrder& byRank, const StaveRings& g,
                                          const StaveOrder& order, const std::vector<size_t>& rankOf,
                                          const std::vector<MountBody>& bodies, const FaceContacts& faces,
                                          double voxelMm) {
    std::vector<size_t> placeOf(rankOf.size());  // byRank index → place in the final order
    for (size_t k = 0; k < rankOf.size(); ++k) placeOf[rankOf[k]] = k;
    auto has = [](const std::vector<size_t>& list, size_t x) {
        return std::find(list.begin(), list.end(), x) != list.end();
    };
    std::vector<std::string> notes;
    for (size_t k = 0; k < order.pieces.size(); ++k) {
        if (order.holes[k] >= 0) continue;
        const size_t r = rankOf[k];
        const Box3d& box = bodies[r].bounds;
        std::string note = "stave " + std::to_string(order.pieces[k]) + " placed nowhere, ring " +
                           std::to_string(g.ringOf[r]) + ", place " + std::to_string(k) +
                           formatNumbers(" in (%.0f, %.0f, %.0f)-(%.0f, %.0f, %.0f) mm", box.min[0],
                                         box.min[1], box.min[2], box.max[0], box.max[1], box.max[2]) +
                           (g.canSlideIn[r] ? "" : ", no hole along its slide") + "; its ring:";
        for (size_t j = 0; j < g.ringOf.size(); ++j)
            if (g.ringOf[j] == g.ringOf[r] && j != r)
                note +=
                    " " + std::to_string(byRank.pieces[j]) + (order.holes[placeOf[j]] < 0 ? " (unheld)" : "");
        note += "; seams:";
        for (size_t j : g.seamMates[r]) {
            const size_t place = placeOf[j];
            note += " " + std::to_string(byRank.pieces[j]) + " (ring " + std::to_string(g.ringOf[j]) +
                    (order.holes[place] < 0        ? ", unheld"
                     : !order.hosts[place].empty() ? ", glued"
                                                   : ", held") +
                    (place < k ? ", before" : ", after") +
                    (has(g.later[g.ringOf[r]], g.ringOf[j]) ? ", in its way" : "") +
                    (has(g.later[g.ringOf[j]], g.ringOf[r]) ? ", it in that one's way" : "") + ")";
        }
        note += "; touches:";
        for (const auto& [pair, contacts] : faces) {
            if (pair.first != order.pieces[k] && pair.second != order.pieces[k]) continue;
            size_t voxelFaces = 0;
            for (const CutContact& c : contacts) voxelFaces += c.voxelFaces;
            note += " " + std::to_string(pair.first == order.pieces[k] ? pair.second : pair.first) +
                    formatNumbers(" (%.0f mm²)", double(voxelFaces) * voxelMm * voxelMm);
        }
        notes.push_back(note);
    }
    return notes;
}

StaveOrder placeStaves(std::vector<uint32_t> staves, const PlannerInput& input, const FrameSweeps& sweeps,
                       const FaceContacts& faces, double voxelMm, int maxPerPiece, const RunContext& context,
                       std::vector<MountBody>& list) {
    std::sort(staves.begin(), staves.end(), [&](uint32_t a, uint32_t b) {
        return std::tie(input.staves[a]->rank, a) < std::tie(input.staves[b]->rank, b);
    });
    StaveOrder order{staves, std::vector<int>(staves.size(), -1), {}};
    std::vector<MountBody> staveBodies;
    for (size_t k = 0; k < staves.size(); ++k)
        staveBodies.push_back(
            staveBody(staves[k], input, sweeps.frameToGridMm(), maxPerPiece, &order.holes[k]));
    // Rings in an order their ways out allow, those with staves no hole holds after what they
    // could be glued onto; then, in each, the staves to glue in place after the held ones.
    size_t cycles = 0;
    const StaveRings rings = staveRings(order, staveBodies, input, faces, sweeps.frameToGridMm(), voxelMm);
    const std::vector<size_t> ringOrder = orderStaveRings(rings, &cycles);
    if (cycles > 0)
        context.debug("mounting: " + std::to_string(cycles) + " cycles of staves in each other's way");
    const StaveOrder byRank = order;
    order = permuted(order, ringOrder);
    std::vector<size_t> rankOf;  // per stave in the final order: its index in byRank
    for (size_t k : glueStavesInPlace(order, input, faces, sweeps.frameToGridMm(), voxelMm))
        rankOf.push_back(ringOrder[k]);
    for (const std::string& line :
         unheldStaveNotes(byRank, rings, order, rankOf, staveBodies, faces, voxelMm))
        context.debug("mounting: " + line);
    for (size_t r : rankOf) list.push_back(std::move(staveBodies[r]));
    if (input.isGluingUnheldStaves) unfixUnheldStaves(list, order, input, sweeps, voxelMm);
    return order;
}

std::vector<size_t> glueStavesInPlace(StaveOrder& order, const PlannerInput& input, const FaceContacts& faces,
                                      const Transform4d& frameToGridMm, double voxelMm) {
    const size_t n = order.pieces.size();
    order.hosts.assign(n, {});
    std::vector<size_t> perm;  // the new order, old indices: ring by ring, held staves, then glued ones
    std::vector<uint8_t> isOn(n, 0);  // held or glued in place, on: a host
    for (size_t begin = 0, end = 0; begin < n; begin = end) {
        const auto ring = ringKey(*input.staves[order.pieces[begin]]);
        while (end < n && ringKey(*input.staves[order.pieces[end]]) == ring) ++end;
        for (size_t k = begin; k < end; ++k)
            if (order.holes[k] >= 0) perm.push_back(k), isOn[k] = 1;
        // A stave glued in place may hold the next (a chain round the ring).
        for (bool isGrown = true; isGrown;) {
            isGrown = false;
            for (size_t k = begin; k < end; ++k) {
                const uint32_t p = order.pieces[k];
                const int along = isOn[k] ? -1 : holeAlongSlide(*input.staves[p], frameToGridMm);
                if (along < 0) continue;
                for (size_t j : perm)
                    if (isOn[j] && sharesGlueSeam(p, order.pieces[j], faces, voxelMm))
                        order.hosts[k].push_back(order.pieces[j]);
                if (order.hosts[k].empty()) continue;
                order.holes[k] = along;
                perm.push_back(k), isOn[k] = 1, isGrown = true;
            }
        }
        for (size_t k = begin; k < end; ++k)
            if (!isOn[k]) perm.push_back(k);
    }
    order = permuted(order, perm);
    return perm;
}

FixedStaves fixedStaves(const StaveOrder& order, const PlannerInput& input) {
    FixedStaves out;
    std::map<uint32_t, size_t> indexOf;  // piece → its index in the order
    for (size_t k = 0; k < order.pieces.size(); ++k) {
        const Stave& stave = *input.staves[order.pieces[k]];
        const bool isNewRing = k == 0 || ringKey(stave) != ringKey(*input.staves[order.pieces[k - 1]]);
        out.ringOf.push_back(k == 0 ? 0 : out.ringOf.back() + (isNewRing ? 1 : 0));
        out.slideGrid.push_back(stave.slideGrid);
        indexOf[order.pieces[k]] = k;
    }
    out.hosts.resize(order.pieces.size());
    for (size_t k = 0; k < order.hosts.size() && k < order.pieces.size(); ++k)
        for (uint32_t host : order.hosts[k])
            if (const auto it = indexOf.find(host); it != indexOf.end()) out.hosts[k].push_back(it->second);
    return out;
}

StaveOrder permuted(const StaveOrder& order, const std::vector<size_t>& perm) {
    StaveOrder sorted;
    for (size_t k : perm) {
        sorted.pieces.push_back(order.pieces[k]);
        sorted.holes.push_back(order.holes[k]);
        if (k < order.hosts.size()) sorted.hosts.push_back(order.hosts[k]);
    }
    return sorted;
}

}  // namespace zomefab::pieces::detail
