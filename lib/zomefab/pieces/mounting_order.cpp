// SPDX-License-Identifier: GPL-3.0-or-later
// Who goes on first: whether a body can go on after another along a direction, and the disassembly
// that finds the mounting order and each body's direction, rings of staves taken away where nothing
// else can leave (detail/mounting.h, docs/mounting.md, "Order"; mounting_plan.cpp plans with it).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <set>
#include <tuple>

#include "zomefab/core/format.h"
#include "zomefab/mount/sweep.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/zome/holes.h"

namespace zomefab::pieces::detail {

// The raster's pixels are voxels centred on the voxel centres (detail/mounting.h says why).
bool sweepHits(const MountBody& moving, const MountBody& still, const Vec3d& d, double voxelMm,
               bool isTouching) {
    const double stillRadiusMm = 0.499 * voxelMm, h = 0.5 * voxelMm;
    Box3d bounds = moving.bounds;
    bounds.expand(still.bounds.min), bounds.expand(still.bounds.max);
    bounds.expand(sub(bounds.min, {h, h, h})), bounds.expand(add(bounds.max, {h, h, h}));
    const mount::SweepAxes axes(d);
    // Neighbours: a voxel of one near their cut face (kNearCutLayers) meeting a voxel of the other
    // near it is left to facesAllow (seen along a face nearly parallel to d, the voxels on its two
    // sides would seem to lie ahead of each other). Near voxels are swept against the other's
    // voxels away from the face (beyond kWideCutLayers), which may reach round the face's end into
    // the path (a 400 mm cube with a tunnel: a piece ran 11.6 mm into a neighbour that wraps round
    // its end, beside a 94 mm² face whose plane the path slides along); the rest against all.
    auto raster = [&](bool isObstacle) {
        return mount::DepthRaster(axes, bounds, voxelMm, isObstacle, voxelMm);
    };
    mount::DepthRaster stillFar = raster(true), movingFar = raster(false);
    if (!isTouching) {
        for (size_t i = 0; i < still.voxels.size(); ++i)
            stillFar.addPoint(still.voxels[i], stillRadiusMm, uint32_t(i));
        for (size_t i = 0; i < moving.voxels.size(); ++i)
            movingFar.addPoint(moving.voxels[i], 0.0, uint32_t(i));
        return mount::worstHit(stillFar, movingFar, voxelMm).isHit;
    }
    // Each voxel drawn into its parts: near the face, or not (far), and among those not, away from it.
    mount::DepthRaster stillAway = raster(true), stillNear = raster(true);
    mount::DepthRaster movingAway = raster(false), movingNear = raster(false);
    auto draw = [&](const MountBody& body, const MountBody& other, double radiusMm, mount::DepthRaster& near,
                    mount::DepthRaster& far, mount::DepthRaster& away) {
        for (size_t i = 0; i < body.voxels.size(); ++i) {
            const uint8_t layer = body.cutLayerWith(i, other);  // 0: within kWideCutLayers of no face
            if (layer != 0 && layer <= kNearCutLayers) {
                near.addPoint(body.voxels[i], radiusMm, uint32_t(i));
                continue;
            }
            far.addPoint(body.voxels[i], radiusMm, uint32_t(i));
            if (layer == 0) away.addPoint(body.voxels[i], radiusMm, uint32_t(i));
        }
    };
    draw(still, moving, stillRadiusMm, stillNear, stillFar, stillAway);
    draw(moving, still, 0.0, movingNear, movingFar, movingAway);
    return mount::worstHit(stillFar, movingFar, voxelMm).isHit ||
           mount::worstHit(stillAway, movingNear, voxelMm).isHit ||
           mount::worstHit(stillNear, movingAway, voxelMm).isHit;
}

bool facesAllow(const MountBody& still, const MountBody& moving, const Vec3d& d, const FaceContacts& faces,
                bool* isTouching) {
    bool isOk = true;
    *isTouching = false;
    for (uint32_t x : still.pieces)
        for (uint32_t y : moving.pieces) {
            const auto it = faces.find({std::min(x, y), std::max(x, y)});
            if (it == faces.end()) continue;
            *isTouching = true;
            for (const CutContact& c : it->second) {
                if (c.voxelFaces < kMinOrderFaceVoxels && !c.isStaveBorder)
                    continue;  // in the sweeps (plannerInput)
                // The stored normal points from the lower piece into the higher: here, into moving.
                const Vec3d n = x < y ? c.normal : scale(c.normal, -1.0);
                isOk = isOk && mount::faceOrder(n, d, d).isBAfterAOk;
            }
        }
    return isOk;
}

size_t bodyContact(const MountBody& a, const MountBody& b, const FaceContacts& faces) {
    size_t count = 0;
    for (uint32_t x : a.pieces)
        for (uint32_t y : b.pieces) {
            const auto it = faces.find({std::min(x, y), std::max(x, y)});
            if (it == faces.end()) continue;
            for (const CutContact& c : it->second) count += c.voxelFaces;
        }
    return count;
}

namespace {

/// One usable direction of a body: an index into its options (held by tenons) or into its glue
/// options (glued onto a body already in place).
struct Usable {
    size_t option = 0;
    bool isGlue = false;
};

/// One body's usable directions (free, with tenons, in rank order; then its free glue options) and,
/// once asked for, the bodies in the way of each.
struct BodyState {
    std::vector<Usable> usable;
    bool isFixed = false;  ///< in place throughout (a stave): never taken away, in every body's way
    std::vector<std::optional<std::vector<uint32_t>>> blockers;
    bool canGlue() const { return !usable.empty() && usable.back().isGlue; }
};

int holeOf(const std::vector<MountBody>& bodies, const std::vector<BodyState>& state, uint32_t b, size_t k) {
    const Usable& u = state[b].usable[k];
    return (u.isGlue ? bodies[b].glueOptions : bodies[b].options)[u.option].hole;
}

/// The usable directions of @p body: its free options with tenons, then (when it has faces to be
/// glued on across) its free glue options.
std::vector<Usable> usableOf(const MountBody& body, bool hasHosts) {
    std::vector<Usable> list;
    for (size_t i = 0; i < body.options.size(); ++i) {
        const DirectionOption& o = body.options[i];
        if (o.isTested && o.isFree && o.tenons > 0) list.push_back({i, false});
    }
    if (hasHosts)
        for (size_t i = 0; i < body.glueOptions.size(); ++i)
            if (body.glueOptions[i].isTested && body.glueOptions[i].isFree) list.push_back({i, true});
    return list;
}

/// The bodies that keep @p b from going on after them along @p d (grid, unit), remembered in
/// @p cache under @p key (its hole; −1: a stave's slide); the sweeps in parallel.
std::vector<uint32_t> wayBlockers(const std::vector<BodyState>& state, uint32_t b, const Vec3d& d, int key,
                                  const std::vector<MountBody>& bodies, const FaceContacts& faces,
                                  double voxelMm, SweepCache& cache) {
    const int hole = key;
    const size_t n = bodies.size();
    // Faces and cached sweeps first; the sweeps still to make run in parallel.
    std::vector<int8_t> isBlocked(n, 0);
    std::vector<uint32_t> toSweep;
    std::vector<uint8_t> touching(n, 0);
    for (uint32_t a = 0; a < n; ++a) {
        if (a == b || (state[a].usable.empty() && !state[a].isFixed)) continue;
        bool isTouching = false;
        if (!facesAllow(bodies[a], bodies[b], d, faces, &isTouching)) {
            isBlocked[a] = 1;
            continue;
        }
        touching[a] = isTouching;
        // Boxes whose shadows cannot meet never collide: tested before the cache, which is dearer.
        if (!shadowsMeet(bodies[b].bounds, bodies[a].bounds, d)) continue;
        const auto it = cache.find(std::make_tuple(bodies[b].pieces, bodies[a].pieces, hole));
        if (it != cache.end())
            isBlocked[a] = it->second;
        else
            toSweep.push_back(a);
    }
    std::vector<uint8_t> hits(toSweep.size(), 0);
    tbb::parallel_for(size_t(0), toSweep.size(), [&](size_t i) {
        hits[i] = sweepHits(bodies[b], bodies[toSweep[i]], d, voxelMm, touching[toSweep[i]]);
    });
    for (size_t i = 0; i < toSweep.size(); ++i) {
        cache[std::make_tuple(bodies[b].pieces, bodies[toSweep[i]].pieces, hole)] = hits[i];
        isBlocked[toSweep[i]] = int8_t(hits[i]);
    }
    std::vector<uint32_t> list;
    for (uint32_t a = 0; a < n; ++a)
        if (isBlocked[a]) list.push_back(a);
    return list;
}

/// The bodies that keep @p b from going on after them along usable direction @p k (computed once).
const std::vector<uint32_t>& blockersOf(std::vector<BodyState>& state, uint32_t b, size_t k,
                                        const std::vector<MountBody>& bodies, const FaceContacts& faces,
                                        const Transform4d& frameToGridMm, double voxelMm, SweepCache& cache) {
    std::optional<std::vector<uint32_t>>& slot = state[b].blockers[k];
    if (!slot) {
        const int hole = holeOf(bodies, state, b, k);
        slot = wayBlockers(state, b, gridDirection(hole, frameToGridMm), hole, bodies, faces, voxelMm, cache);
    }
    return *slot;
}

/// A cut face a hosted body could be glued on across: host body, host piece, the hosted body's
/// piece, the face's normal into the hosted piece.
struct HostFace {
    uint32_t body, hostPiece, piece;
    Vec3d normal;
};

/// The faces between hosted body @p b and the other bodies large enough to glue on.
std::vector<HostFace> hostFaces(const std::vector<MountBody>& bodies, uint32_t b, const FaceContacts& faces,
                                double voxelMm, const GlueOnRule& rule) {
    std::vector<HostFace> out;
    for (uint32_t a = 0; a < bodies.size(); ++a) {
        if (a == b) continue;
        for (uint32_t x : bodies[a].pieces)
            for (uint32_t y : bodies[b].pieces) {
                const auto it = faces.find({std::min(x, y), std::max(x, y)});
                if (it == faces.end()) continue;
                for (const CutContact& c : it->second)
                    if (rule.isLargeEnough(c.voxelFaces, voxelMm))
                        out.push_back({a, x, y, x < y ? c.normal : scale(c.normal, -1.0)});
            }
    }
    return out;
}

/// The staves' ways out and the ring to take away where no other body can leave (disassemble).
struct RingPicker {
    const std::vector<MountBody>& bodies;
    const std::vector<BodyState>& state;
    const std::vector<uint8_t>& isLeft;
    const std::vector<std::vector<HostFace>>& hosts;
    const FixedStaves& staves;
    const FaceContacts& faces;
    double voxelMm;
    SweepCache& cache;
    std::vector<std::optional<std::vector<uint32_t>>> ways{staves.ringOf.size()};  ///< per stave

    size_t first() const { return bodies.size() - staves.ringOf.size(); }
    /// Body @p a's ring, SIZE_MAX for a body that is no stave.
    size_t ringOf(uint32_t a) const { return a >= first() ? staves.ringOf[a - first()] : SIZE_MAX; }
    /// The bodies in stave @p k's way out along its tunnel (computed once).
    const std::vector<uint32_t>& wayOf(size_t k) {
        if (!ways[k])
            ways[k] = wayBlockers(state, uint32_t(first() + k), staves.slideGrid[k], -1, bodies, faces,
                                  voxelMm, cache);
        return *ways[k];
    }
    /// Whether every stave of ring @p r left can slide out past the bodies left but its ring.
    bool isFree(size_t r) {
        for (size_t k = 0; k < staves.ringOf.size(); ++k) {
            if (staves.ringOf[k] != r || !isLeft[first() + k]) continue;
            for (uint32_t a : wayOf(k))
                if (isLeft[a] && ringOf(a) != r) return false;
        }
        return true;
    }
    /// Rings that must stay: a stave glued in place onto one of theirs is left, or a body left to be
    /// glued on has only their staves left to be glued onto.
    std::vector<uint8_t> mustStay(size_t ringCount) const {
        std::vector<uint8_t> stay(ringCount, 0);
        for (size_t k = 0; k < staves.ringOf.size(); ++k)
            if (isLeft[first() + k])
                for (size_t j : staves.hosts[k])
                    if (staves.ringOf[j] != staves.ringOf[k]) stay[staves.ringOf[j]] = 1;
        for (uint32_t b = 0; b < first(); ++b) {
            if (!isLeft[b] || !state[b].canGlue()) continue;
            size_t ring = SIZE_MAX;
            bool isOther = false;
            for (const HostFace& h : hosts[b]) {
                if (!isLeft[h.body]) continue;
                const size_t r = ringOf(h.body);
                isOther = isOther || r == SIZE_MAX || (ring != SIZE_MAX && r != ring);
                ring = r;
            }
            if (!isOther && ring != SIZE_MAX) stay[ring] = 1;
        }
        return stay;
    }
    /// Rings in the way of a body left (as far as its ways were asked for), of a stave of such a
    /// ring, or glued in place onto one.
    std::vector<uint8_t> wanted(size_t ringCount) {
        std::vector<uint8_t> want(ringCount, 0);
        for (uint32_t b = 0; b < first(); ++b)
            if (isLeft[b])
                for (const auto& slot : state[b].blockers)
                    if (slot)
                        for (uint32_t a : *slot)
                            if (isLeft[a] && ringOf(a) != SIZE_MAX) want[ringOf(a)] = 1;
        for (bool isGrown = true; isGrown;) {
            isGrown = false;
            for (size_t k = 0; k < staves.ringOf.size(); ++k) {
                if (!isLeft[first() + k]) continue;
                const size_t r = staves.ringOf[k];
                for (size_t j : staves.hosts[k])
                    if (want[staves.ringOf[j]] && !want[r]) want[r] = 1, isGrown = true;
                if (!want[r]) continue;
                for (uint32_t a : wayOf(k))
                    if (isLeft[a] && ringOf(a) != SIZE_MAX && !want[ringOf(a)])
                        want[ringOf(a)] = 1, isGrown = true;
            }
        }
        return want;
    }
    /// The last ring in the staves' order that may be taken away now and is wanted, or none.
    std::optional<size_t> pick() {
        if (staves.ringOf.empty()) return std::nullopt;
        const size_t ringCount = staves.ringOf.back() + 1;
        std::vector<uint8_t> isIn(ringCount, 0);
        for (size_t k = 0; k < staves.ringOf.size(); ++k)
            if (isLeft[first() + k]) isIn[staves.ringOf[k]] = 1;
        const std::vector<uint8_t> stay = mustStay(ringCount), want = wanted(ringCount);
        for (size_t r = ringCount; r-- > 0;)
            if (isIn[r] && !stay[r] && want[r] && isFree(r)) return r;
        return std::nullopt;
    }
    /// For the debug output once the bodies left are stuck: why each ring in their way stays.
    std::vector<std::string> notes() {
        std::vector<std::string> out;
        if (staves.ringOf.empty()) return out;
        const size_t ringCount = staves.ringOf.back() + 1;
        const std::vector<uint8_t> stay = mustStay(ringCount), want = wanted(ringCount);
        for (size_t r = 0; r < ringCount; ++r) {
            if (!want[r]) continue;
            std::string note, staveList;
            for (size_t k = 0; k < staves.ringOf.size(); ++k) {
                if (staves.ringOf[k] != r || !isLeft[first() + k]) continue;
                const uint32_t p = bodies[first() + k].pieces[0];
                staveList += " " + std::to_string(p);
                std::string in;
                const MountBody& me = bodies[first() + k];
                for (uint32_t a : wayOf(k)) {
                    if (!isLeft[a] || ringOf(a) == r) continue;
                    in += " " + std::to_string(bodies[a].pieces[0]) + (ringOf(a) == SIZE_MAX ? "" : "s");
                    if (ringOf(a) != SIZE_MAX) continue;
                    bool isTouching = false;
                    const Box3d& b = bodies[a].bounds;
                    in += (facesAllow(bodies[a], me, staves.slideGrid[k], faces, &isTouching) ? " (swept"
                                                                                              : " (face") +
                          formatNumbers(", its box (%.0f, %.0f, %.0f)-(%.0f, %.0f, %.0f))", b.min[0],
                                        b.min[1], b.min[2], b.max[0], b.max[1], b.max[2]);
                }
                const Vec3d& d = staves.slideGrid[k];
                if (!in.empty())
                    note +=
                        "; stave " + std::to_string(p) +
                        formatNumbers(" in (%.0f, %.0f, %.0f)-(%.0f, %.0f, %.0f) along (%.2f, %.2f, %.2f)",
                                      me.bounds.min[0], me.bounds.min[1], me.bounds.min[2], me.bounds.max[0],
                                      me.bounds.max[1], me.bounds.max[2], d[0], d[1], d[2]) +
                        ": its way meets" + in;
                for (size_t j = 0; j < staves.ringOf.size(); ++j)
                    if (isLeft[first() + j] && staves.ringOf[j] != r &&
                        std::count(staves.hosts[j].begin(), staves.hosts[j].end(), k))
                        note += "; stave " + std::to_string(bodies[first() + j].pieces[0]) + " glued onto " +
                                std::to_string(p) + " is on";
            }
            if (staveList.empty()) continue;
            out.push_back("ring of staves" + staveList +
                          (stay[r] ? " stays for a stave or body glued onto it" : "") + note);
        }
        return out;
    }
};

}  // namespace

Disassembly disassemble(const std::vector<MountBody>& bodies, const FaceContacts& faces,
                        const Transform4d& frameToGridMm, double voxelMm, const GlueOnRule& glueOn,
                        SweepCache& cache, const RunContext& context, size_t fixedCount,
                        const FixedStaves* staves) {
    const size_t n = bodies.size();
    std::vector<BodyState> state(n);
    std::vector<std::vector<HostFace>> hosts(n);
    std::vector<uint8_t> isLeft(n, 0);
    size_t left = 0;
    for (uint32_t b = 0; b < n; ++b) {
        BodyState& st = state[b];
        if (b + fixedCount >= n) {
            st.isFixed = true, isLeft[b] = 1;
            continue;
        }
        if (!bodies[b].glueOptions.empty()) hosts[b] = hostFaces(bodies, b, faces, voxelMm, glueOn);
        st.usable = usableOf(bodies[b], !hosts[b].empty());
        st.blockers.resize(st.usable.size());
        if (!st.usable.empty()) isLeft[b] = 1, ++left;
    }
    Disassembly out;
    out.holes.assign(n, -1);
    std::vector<size_t> chosen(n, SIZE_MAX);
    std::vector<uint32_t> removed;
    std::optional<RingPicker> rings;
    if (staves) rings.emplace(RingPicker{bodies, state, isLeft, hosts, *staves, faces, voxelMm, cache});
    auto isClear = [&](const std::vector<uint32_t>& blockers) {
        return std::all_of(blockers.begin(), blockers.end(), [&](uint32_t a) { return !isLeft[a]; });
    };
    // The faces a hosted body can be glued on across along direction k now: hosts in place, pins
    // straight enough (any, for a mouth ring slid into its mouth).
    auto gluable = [&](uint32_t b, size_t k) {
        const Vec3d d = gridDirection(holeOf(bodies, state, b, k), frameToGridMm);
        std::vector<const HostFace*> list;
        const bool isSleeve = dot(d, bodies[b].sleeveGrid) > std::cos(kPi / 180.0);
        for (const HostFace& h : hosts[b])
            if (isLeft[h.body] && (isSleeve || dot(d, h.normal) >= glueOn.minCosine)) list.push_back(&h);
        return list;
    };
    // A body whose removal would leave a body that can only be glued on with nothing to be glued
    // onto goes last.
    auto isLastHost = [&](uint32_t a) {
        for (uint32_t b = 0; b < n; ++b) {
            if (!isLeft[b] || !state[b].canGlue()) continue;
            bool isOther = false, isMine = false;
            for (const HostFace& h : hosts[b]) (h.body == a ? isMine : isOther) |= bool(isLeft[h.body]);
            if (isMine && !isOther) return true;
        }
        return false;
    };
    while (left > 0) {
        context.throwIfCancelled();
        // (kind, rank of the direction it can leave along, −its lowest point, index): the best to
        // take away now. Kinds: a body no peg can hold, glued on (it leaves as soon as it can, its
        // hosts must still be there); a body held by pegs; a body that has pegs but is glued on
        // only when nothing else can leave; each kind those no other needs as its host first.
        // Taking the highest first mounts the lowest first.
        std::optional<std::tuple<int, size_t, double, uint32_t>> best;
        for (uint32_t b = 0; b < n; ++b) {
            if (!isLeft[b] || state[b].isFixed) continue;
            const int lastHost = isLastHost(b) ? 1 : 0;
            const bool hasPegs = !state[b].usable.front().isGlue;
            for (size_t k = 0; k < state[b].usable.size(); ++k) {
                const bool isGlue = state[b].usable[k].isGlue;
                const int kind = (isGlue ? (hasPegs ? 4 : 0) : 2) + lastHost;
                const std::tuple<int, size_t, double, uint32_t> key{kind, k, -bodies[b].bounds.min[2], b};
                if (best && key > *best) continue;
                if (isGlue && gluable(b, k).empty()) continue;
                if (!isClear(blockersOf(state, b, k, bodies, faces, frameToGridMm, voxelMm, cache))) continue;
                best = key;
                break;
            }
        }
        if (!best) {
            // Nothing else can leave: a ring of staves may, its staves the last first (docs above).
            const std::optional<size_t> ring = staves ? rings->pick() : std::nullopt;
            if (!ring) break;
            for (size_t k = fixedCount; k-- > 0;)
                if (staves->ringOf[k] == *ring && isLeft[n - fixedCount + k])
                    removed.push_back(uint32_t(n - fixedCount + k)), isLeft[n - fixedCount + k] = 0;
            ++out.ringsTakenAway;
            continue;
        }
        const auto [kind, k, negLow, b] = *best;
        if (state[b].usable[k].isGlue)
            for (const HostFace* h : gluable(b, k)) {
                out.gluedOn.push_back({h->hostPiece, h->piece});
                out.before.push_back({h->body, b});
            }
        chosen[b] = k;
        out.holes[b] = holeOf(bodies, state, b, k);
        removed.push_back(b);
        isLeft[b] = 0, --left;
    }
    for (uint32_t b = uint32_t(n - fixedCount); b < n; ++b)
        if (isLeft[b]) out.order.push_back(b);  // staves left in place: first, in their order
    out.order.insert(out.order.end(), removed.rbegin(), removed.rend());
    if (rings && left > 0) out.ringNotes = rings->notes();
    for (uint32_t b = 0; b < n; ++b) {
        if (b + fixedCount >= n && !isLeft[b]) {  // a stave taken away: after what its way meets
            for (uint32_t a : *rings->ways[b + fixedCount - n]) out.before.push_back({b, a});
        } else if (chosen[b] != SIZE_MAX) {
            for (uint32_t a : *state[b].blockers[chosen[b]]) out.before.push_back({b, a});
        } else if (isLeft[b] && !state[b].isFixed) {
            out.stuck.push_back(b);
            std::vector<uint32_t> in;
            for (uint32_t a : blockersOf(state, b, 0, bodies, faces, frameToGridMm, voxelMm, cache))
                if (isLeft[a]) in.push_back(a);
            out.stuckBlockers.push_back(std::move(in));
        }
    }
    std::sort(out.before.begin(), out.before.end());
    out.before.erase(std::unique(out.before.begin(), out.before.end()), out.before.end());
    std::sort(out.gluedOn.begin(), out.gluedOn.end());
    out.gluedOn.erase(std::unique(out.gluedOn.begin(), out.gluedOn.end()), out.gluedOn.end());
    return out;
}

}  // namespace zomefab::pieces::detail
