// SPDX-License-Identifier: GPL-3.0-or-later
// Who goes on first: whether a body can go on after another along a direction, the disassembly
// that finds the mounting order and each body's direction, and the glued bodies where none exists
// (detail/mounting.h, docs/mounting.md, "Order" and "Glued groups").
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

namespace {

/// The body names and a list of pieces for messages: "piece 3", "pieces 3 + 4 (glued)".
std::string bodyName(const MountBody& b) {
    if (b.pieces.size() == 1) return "piece " + std::to_string(b.pieces[0]);
    std::string list;
    for (uint32_t p : b.pieces) list += (list.empty() ? "" : " + ") + std::to_string(p);
    return "pieces " + list + " (glued)";
}

/// The pair of pieces, one of each body, with the largest common cut face: where they are glued.
std::pair<uint32_t, uint32_t> gluePair(const MountBody& a, const MountBody& b, const FaceContacts& faces) {
    std::pair<uint32_t, uint32_t> best{a.pieces[0], b.pieces[0]};
    size_t bestCount = 0;
    for (uint32_t x : a.pieces)
        for (uint32_t y : b.pieces) {
            const auto it = faces.find({std::min(x, y), std::max(x, y)});
            if (it == faces.end()) continue;
            size_t count = 0;
            for (const CutContact& c : it->second) count += c.voxelFaces;
            if (count > bestCount) bestCount = count, best = {std::min(x, y), std::max(x, y)};
        }
    return best;
}

/// The planner's state: the bodies and the pieces glued so far.
struct Bodies {
    std::vector<MountBody> list;
    std::vector<std::pair<uint32_t, uint32_t>> glued;

    /// Replaces each pair of bodies (i, j, joined) of @p joins (no body in two) by its joined body,
    /// kept at the lower index; the higher ones are removed.
    void glue(std::vector<std::tuple<uint32_t, uint32_t, MountBody>>&& joins, const FaceContacts& faces) {
        std::vector<uint8_t> isGone(list.size(), 0);
        for (auto& [i, j, joined] : joins) {
            glued.push_back(gluePair(list[i], list[j], faces));
            list[std::min(i, j)] = std::move(joined);
            isGone[std::max(i, j)] = 1;
        }
        size_t kept = 0;
        for (size_t k = 0; k < list.size(); ++k) {
            if (isGone[k]) continue;
            if (kept != k) list[kept] = std::move(list[k]);  // a self-move would empty it
            ++kept;
        }
        list.resize(kept);
    }
};

/// Glues pairs of touching bodies, one of them stuck, whose union has a free direction with
/// tenons: two stuck ones in each other's way first, then two stuck ones, then a stuck one and a
/// neighbour (a piece to be glued on that its only host is in the way of), each by the largest
/// contact. Every pair of the best kind that succeeds is glued in one call, each body at most once
/// (one pair per call took a planning round per pair: the cheese at 700 mm had 135 stuck bodies and
/// a round of 20 s). @p noFreeUnion remembers the unions found with no free direction. Returns how
/// many pairs were glued.
size_t glueStuck(Bodies& bodies, const Disassembly& parts, const PlannerInput& input,
                 const FrameSweeps& sweeps, const FaceContacts& faces, double voxelMm, int maxPerPiece,
                 std::set<std::vector<uint32_t>>& noFreeUnion, size_t fixedCount) {
    auto blocks = [&](size_t k, uint32_t other) {
        const std::vector<uint32_t>& list = parts.stuckBlockers[k];
        return std::find(list.begin(), list.end(), other) != list.end();
    };
    auto hasStave = [&](const MountBody& body) {
        return std::any_of(body.pieces.begin(), body.pieces.end(),
                           [&](uint32_t p) { return input.isStave(p); });
    };
    std::vector<std::tuple<int, size_t, uint32_t, uint32_t>> pairs;  // (−kind, −contact, a, b)
    for (size_t i = 0; i < parts.stuck.size(); ++i)
        for (uint32_t b = 0; b + fixedCount < bodies.list.size(); ++b) {
            const uint32_t a = parts.stuck[i];
            const auto other = std::find(parts.stuck.begin(), parts.stuck.end(), b);
            if (b == a || (other != parts.stuck.end() && b < a)) continue;  // each stuck pair once
            if (hasStave(bodies.list[a]) || hasStave(bodies.list[b])) continue;  // never glued into groups
            const size_t contact = bodyContact(bodies.list[a], bodies.list[b], faces);
            if (contact == 0) continue;
            int kind = 0;
            if (other != parts.stuck.end()) {
                const size_t j = size_t(other - parts.stuck.begin());
                kind = 1 + (blocks(i, b) ? 1 : 0) + (blocks(j, a) ? 1 : 0);
            }
            pairs.push_back({-kind, size_t(0) - contact, a, b});
        }
    std::sort(pairs.begin(), pairs.end());
    std::vector<uint8_t> isUsed(bodies.list.size(), 0);
    std::vector<std::tuple<uint32_t, uint32_t, MountBody>> joins;
    std::optional<int> gluedKind;
    for (const auto& [negKind, contact, a, b] : pairs) {
        if (gluedKind && negKind != *gluedKind) break;
        if (isUsed[a] || isUsed[b]) continue;
        if (bodies.list[a].pieces.size() + bodies.list[b].pieces.size() > kMaxGluedPieces) continue;
        std::vector<uint32_t> members = bodies.list[a].pieces;
        members.insert(members.end(), bodies.list[b].pieces.begin(), bodies.list[b].pieces.end());
        std::sort(members.begin(), members.end());
        if (noFreeUnion.count(members)) continue;
        MountBody u = makeBody(members, input, sweeps, voxelMm, maxPerPiece, 1);
        if (!u.bestFree()) {
            noFreeUnion.insert(members);
            continue;
        }
        testPaths(u, sweeps, voxelMm);
        isUsed[a] = isUsed[b] = 1;
        gluedKind = negKind;
        joins.emplace_back(a, b, std::move(u));
    }
    const size_t count = joins.size();
    bodies.glue(std::move(joins), faces);
    return count;
}

/// The plan of @p parts; the last @p fixedCount bodies are staves, whose problems are the caller's.
mount::InstallationPlan writePlan(const Bodies& bodies, const Disassembly& parts, size_t pieceCount,
                                  size_t fixedCount) {
    mount::InstallationPlan plan;
    plan.holeOfPiece.assign(pieceCount, -1);
    plan.groupOf.assign(pieceCount, 0);
    plan.glued = bodies.glued;
    std::sort(plan.glued.begin(), plan.glued.end());
    for (size_t b = 0; b < bodies.list.size(); ++b)
        for (uint32_t p : bodies.list[b].pieces) {
            plan.holeOfPiece[p] = parts.holes[b];
            plan.groupOf[p] = bodies.list[b].pieces[0];
        }
    for (const auto& [a, b] : parts.before)
        plan.before.push_back({bodies.list[a].pieces[0], bodies.list[b].pieces[0]});
    plan.gluedOn = parts.gluedOn;
    for (size_t b = 0; b + fixedCount < bodies.list.size(); ++b) {
        const MountBody& body = bodies.list[b];
        if (parts.holes[b] >= 0 || std::count(parts.stuck.begin(), parts.stuck.end(), uint32_t(b))) continue;
        std::string why = body.options.empty() ? "no ball's hole points at it within a tenon's reach"
                                               : "every direction with tenons is blocked (" +
                                                     body.options[0].blockedBy + " in the way of the best)";
        const bool isFreeAlong = std::any_of(body.glueOptions.begin(), body.glueOptions.end(),
                                             [](const DirectionOption& o) { return o.isFree; });
        why += isFreeAlong ? ", and it shares no cut face large enough to glue it onto a neighbour"
                           : ", and the frame is in the way of every direction to glue it on along";
        plan.problems.push_back(bodyName(body) + ": no direction to push it on along and hold it: " + why);
    }
    if (!parts.stuck.empty()) {
        std::string list, detail;
        // Named up to kNamed (the cheese at 700 mm has over a hundred: one line must stay readable).
        constexpr size_t kNamed = 6;
        const size_t stuckCount = parts.stuck.size();
        for (size_t k = 0; k < stuckCount; ++k) {
            const uint32_t b = parts.stuck[k];
            if (k < kNamed)
                list += (k == 0 ? "" : k + 1 == stuckCount ? " and " : ", ") + bodyName(bodies.list[b]);
            else if (k == kNamed)
                list += " and " + std::to_string(stuckCount - kNamed) + " more bodies";
            if (k >= 3) continue;
            if (parts.stuckBlockers[k].empty()) {
                detail += (detail.empty() ? "" : "; ") + bodyName(bodies.list[b]) +
                          ": no piece to glue it onto is on when its path is free";
                continue;
            }
            std::string in;
            for (uint32_t o : parts.stuckBlockers[k])
                in += (in.empty() ? "" : ", ") + bodyName(bodies.list[o]);
            detail +=
                (detail.empty() ? "" : "; ") + bodyName(bodies.list[b]) + " along its best direction: " + in;
        }
        plan.problems.push_back(
            list + " cannot be put on in any order: each one's path or cut faces meet another of them (" +
            detail + ")");
    }
    if (parts.stuck.empty())
        for (uint32_t b : parts.order) plan.steps.push_back({bodies.list[b].pieces, parts.holes[b]});
    return plan;
}

}  // namespace

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

/// The bodies that keep @p b from going on after them along usable direction @p k (computed once;
/// the sweeps in parallel).
const std::vector<uint32_t>& blockersOf(std::vector<BodyState>& state, uint32_t b, size_t k,
                                        const std::vector<MountBody>& bodies, const FaceContacts& faces,
                                        const Transform4d& frameToGridMm, double voxelMm, SweepCache& cache) {
    std::optional<std::vector<uint32_t>>& slot = state[b].blockers[k];
    if (slot) return *slot;
    const int hole = holeOf(bodies, state, b, k);
    const Vec3d d = gridDirection(hole, frameToGridMm);
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
    slot.emplace();
    for (uint32_t a = 0; a < n; ++a)
        if (isBlocked[a]) slot->push_back(a);
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

}  // namespace

Disassembly disassemble(const std::vector<MountBody>& bodies, const FaceContacts& faces,
                        const Transform4d& frameToGridMm, double voxelMm, const GlueOnRule& glueOn,
                        SweepCache& cache, const RunContext& context, size_t fixedCount) {
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
        if (!best) break;
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
    out.order.assign(removed.rbegin(), removed.rend());
    for (uint32_t b = 0; b < n; ++b) {
        if (chosen[b] != SIZE_MAX) {
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

mount::InstallationPlan planMounting(const PlannerInput& input, const FrameSweeps& sweeps,
                                     const FaceContacts& faces, double voxelMm, const std::vector<int>& holes,
                                     int maxPerPiece, const RunContext& context) {
    Bodies bodies;
    // Pieces glued before planning start as one body: each pair joins the bodies of its pieces,
    // glued across the largest face between the two sides.
    std::vector<uint32_t> bodyOf(input.pieces.size());
    std::vector<std::vector<uint32_t>> members(input.pieces.size());
    for (uint32_t p = 0; p < input.pieces.size(); ++p) bodyOf[p] = p, members[p] = {p};
    for (const auto& [a, b] : input.preGlued) {
        const uint32_t ba = bodyOf[a], bb = bodyOf[b];
        if (ba == bb || input.isStave(a) || input.isStave(b)) continue;
        MountBody sideA, sideB;
        sideA.pieces = members[ba], sideB.pieces = members[bb];
        bodies.glued.push_back(gluePair(sideA, sideB, faces));
        for (uint32_t p : members[bb]) bodyOf[p] = ba;
        members[ba].insert(members[ba].end(), members[bb].begin(), members[bb].end());
        members[bb].clear();
    }
    std::vector<uint32_t> staves;
    for (uint32_t p = 0; p < input.pieces.size(); ++p) {
        if (members[p].empty()) continue;
        if (input.isStave(p)) {
            staves.push_back(p);
            continue;
        }
        bodies.list.push_back(makeBody(members[p], input, sweeps, voxelMm, maxPerPiece));
        if (bodies.list.back().isHosted()) addGlueOptions(bodies.list.back(), holes, sweeps, voxelMm);
        context.throwIfCancelled();
    }
    // Staves go on first, in their order, and stay in every other body's way: the fixed bodies at
    // the end of the list (those placed nowhere may go on with the rest, isGluingUnheldStaves).
    StaveOrder order = placeStaves(staves, input, sweeps, faces, voxelMm, maxPerPiece, context, bodies.list);
    const size_t fixed = order.pieces.size();
    // A stave no hole holds and none of its ring holds it either leaves no plan to be carried out:
    // the frame must grow toward it first (growFrameForStaves), and an order of the rest is not
    // sought (the cheese at 700 mm: minutes).
    if (std::count(order.holes.begin(), order.holes.end(), -1) > 0)
        return unheldStavesPlan(input, order, sweeps.frameToGridMm());
    SweepCache cache;
    const GlueOnRule glueOn;
    Disassembly parts =
        disassemble(bodies.list, faces, sweeps.frameToGridMm(), voxelMm, glueOn, cache, context, fixed);
    // Bodies held by pegs but stuck may be glued on instead, along a direction no peg uses.
    if (!parts.stuck.empty()) {
        for (uint32_t b : parts.stuck)
            if (bodies.list[b].glueOptions.empty()) addGlueOptions(bodies.list[b], holes, sweeps, voxelMm);
        parts =
            disassemble(bodies.list, faces, sweeps.frameToGridMm(), voxelMm, glueOn, cache, context, fixed);
    }
    // Where no order exists, glue stuck bodies that are in each other's way into one (a few times:
    // what gluing does not resolve is re-cut).
    const size_t maxGlues = std::max<size_t>(4, input.pieces.size() / 4);
    // Gluing that stops lowering the stuck count (no new low in kGlueStall rounds) is given up:
    // the cheese at 700 mm went 137, 119, …, 88, 106, 104, 101, … stuck bodies over 14 rounds of
    // 20 s, its tunnel linings in each other's way across the tunnels whatever was glued.
    constexpr size_t kGlueStall = 3;
    std::set<std::vector<uint32_t>> noFreeUnion;
    size_t fewestStuck = parts.stuck.size(), stall = 0;
    for (size_t glues = 0;
         input.isGluingStuck && !parts.stuck.empty() && glues < maxGlues && stall < kGlueStall;) {
        for (size_t k = 0; k < parts.stuck.size(); ++k) {
            std::string in;
            for (uint32_t o : parts.stuckBlockers[k]) in += " " + bodyName(bodies.list[o]);
            // Where it is and which way it would go (grid mm; none: no peg holds it), to find it.
            const MountBody& body = bodies.list[parts.stuck[k]];
            const Vec3d &lo = body.bounds.min, &hi = body.bounds.max;
            std::string d = " (no peg holds it)";
            if (const DirectionOption* o = body.bestFree()) {
                const Vec3d v = gridDirection(o->hole, sweeps.frameToGridMm());
                d = formatNumbers(" along (%.2f, %.2f, %.2f)", v[0], v[1], v[2]);
            }
            context.debug("mounting: stuck: " + bodyName(body) +
                          formatNumbers(" in (%.0f, %.0f, %.0f)-(%.0f, %.0f, %.0f) mm", lo[0], lo[1], lo[2],
                                        hi[0], hi[1], hi[2]) +
                          d + ", in its way:" + in);
        }
        const size_t glued =
            glueStuck(bodies, parts, input, sweeps, faces, voxelMm, maxPerPiece, noFreeUnion, fixed);
        if (glued == 0) break;
        glues += glued;
        context.debug("mounting: " + std::to_string(parts.stuck.size()) + " bodies stuck, " +
                      std::to_string(glued) + " pairs glued into one");
        parts =
            disassemble(bodies.list, faces, sweeps.frameToGridMm(), voxelMm, glueOn, cache, context, fixed);
        stall = parts.stuck.size() < fewestStuck ? 0 : stall + 1;
        fewestStuck = std::min(fewestStuck, parts.stuck.size());
    }
    const size_t firstStave = bodies.list.size() - fixed;
    for (size_t k = 0; k < fixed; ++k) parts.holes[firstStave + k] = order.holes[k];
    mount::InstallationPlan plan = writePlan(bodies, parts, input.pieces.size(), fixed);
    addStaveSteps(plan, input, order, sweeps.frameToGridMm());
    return plan;
}

}  // namespace zomefab::pieces::detail
