// SPDX-License-Identifier: GPL-3.0-or-later
// Who goes on first: the blocking relation between bodies for given directions, the choice of
// directions that lets an order exist, and the glued bodies where none does (detail/mounting.h,
// docs/mounting.md, "Order" and "Glued groups").
#include <algorithm>
#include <optional>
#include <set>
#include <tuple>

#include "zomefab/mount/sweep.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/zome/holes.h"

namespace zomefab::pieces::detail {

namespace {

Vec3d gridDirection(int hole, const Transform4d& frameToGridMm) {
    return normalized(applyLinear(frameToGridMm, zome::holeDirection(hole)));
}

/// Could the boxes meet when @p moving is pushed off along @p d past @p still? Their shadows on
/// the plane normal to d overlap, and something of @p still lies ahead of @p moving's rear.
bool shadowsMeet(const Box3d& moving, const Box3d& still, const Vec3d& d) {
    const mount::SweepAxes axes(d);
    auto range = [](const Box3d& b, const Vec3d& e) {
        double lo = 1e300, hi = -1e300;
        for (int k = 0; k < 8; ++k) {
            const Vec3d p{(k & 1) ? b.max[0] : b.min[0], (k & 2) ? b.max[1] : b.min[1],
                          (k & 4) ? b.max[2] : b.min[2]};
            lo = std::min(lo, dot(p, e)), hi = std::max(hi, dot(p, e));
        }
        return std::make_pair(lo, hi);
    };
    for (const Vec3d& e : {axes.u, axes.v}) {
        const auto [a0, a1] = range(moving, e);
        const auto [b0, b1] = range(still, e);
        if (a1 < b0 || b1 < a0) return false;
    }
    return range(still, d).second > range(moving, d).first;
}

/// Does @p moving, pushed off along @p d, run into @p still's voxels? A voxel of tolerance: two
/// neighbours' voxels across their cut face are a voxel apart (the face itself is tested exactly
/// by facesOrder).
bool sweepHits(const MountBody& moving, const MountBody& still, const Vec3d& d, double voxelMm,
               bool isTouching) {
    if (!shadowsMeet(moving.bounds, still.bounds, d)) return false;
    Box3d bounds = moving.bounds;
    bounds.expand(still.bounds.min), bounds.expand(still.bounds.max);
    const mount::SweepAxes axes(d);
    mount::DepthRaster obstacle(axes, bounds, voxelMm, true, voxelMm),
        body(axes, bounds, voxelMm, false, voxelMm);
    // Neighbours: the voxels along their cut faces are left to facesOrder (seen along a face nearly
    // parallel to d, the voxels on its two sides would seem to lie ahead of each other).
    for (size_t i = 0; i < still.voxels.size(); ++i)
        if (!isTouching || !still.isNearCut[i])
            obstacle.addPoint(still.voxels[i], 0.5 * voxelMm, uint32_t(i));
    for (size_t i = 0; i < moving.voxels.size(); ++i)
        if (!isTouching || !moving.isNearCut[i]) body.addPoint(moving.voxels[i], 0.0, uint32_t(i));
    return mount::worstHit(obstacle, body, voxelMm).isHit;
}

/// The order the cut faces between bodies @p a and @p b allow for their directions; isBAfterAOk
/// and isAAfterBOk both true when they share no face.
mount::FaceOrder facesOrder(const MountBody& a, const MountBody& b, const FaceContacts& faces,
                            const Vec3d& da, const Vec3d& db, bool* isTouching) {
    mount::FaceOrder all;
    *isTouching = false;
    for (uint32_t x : a.pieces)
        for (uint32_t y : b.pieces) {
            const auto it = faces.find({std::min(x, y), std::max(x, y)});
            if (it == faces.end()) continue;
            *isTouching = true;
            for (const CutContact& c : it->second) {
                // From the lower piece into the higher; flipped when a's piece is the higher.
                const Vec3d n = x < y ? c.normal : scale(c.normal, -1.0);
                const mount::FaceOrder f = mount::faceOrder(n, da, db);
                all.isBAfterAOk = all.isBAfterAOk && f.isBAfterAOk;
                all.isAAfterBOk = all.isAAfterBOk && f.isAAfterBOk;
            }
        }
    return all;
}

/// The body names and a list of pieces for messages: "piece 3", "pieces 3 + 4 (glued)".
std::string bodyName(const MountBody& b) {
    if (b.pieces.size() == 1) return "piece " + std::to_string(b.pieces[0]);
    std::string list;
    for (uint32_t p : b.pieces) list += (list.empty() ? "" : " + ") + std::to_string(p);
    return "pieces " + list + " (glued)";
}

std::vector<int> chosenHoles(const std::vector<MountBody>& bodies) {
    std::vector<int> holes(bodies.size(), -1);
    for (size_t b = 0; b < bodies.size(); ++b)
        if (const DirectionOption* o = bodies[b].bestFree()) holes[b] = o->hole;
    return holes;
}

/// Bottom first: the lowest point of each body.
std::vector<double> priorities(const std::vector<MountBody>& bodies) {
    std::vector<double> p;
    for (const MountBody& b : bodies) p.push_back(b.bounds.min[2]);
    return p;
}

/// Changes one body's direction at a time until the relation has an order: among the bodies in
/// trouble and their free directions with tenons, the change that leaves the least trouble (ties:
/// more tenons, then the lower body and rank); changes that leave as much trouble as before are
/// taken too (a plateau), but never back to a direction the body had in the last rounds.
/// Returns the least trouble seen; @p holes holds its directions.
Trouble improveDirections(const std::vector<MountBody>& bodies, std::vector<int>& holes,
                          const FaceContacts& faces, const Transform4d& frameToGridMm, double voxelMm,
                          SweepCache& cache, const RunContext& context) {
    Trouble trouble = blockingTrouble(bodies, holes, faces, frameToGridMm, voxelMm, cache);
    Trouble best = trouble;
    std::vector<int> bestHoles = holes;
    std::vector<std::pair<uint32_t, int>> recent;  // (body, hole) it left: tabu for a while
    const size_t tabu = 2 * bodies.size() + 2;
    for (size_t round = 0; best.count() > 0 && round < 8 * bodies.size() + 16; ++round) {
        context.throwIfCancelled();
        std::set<uint32_t> involved(trouble.cycle.begin(), trouble.cycle.end());
        for (const auto& [a, b] : trouble.deadlocks) involved.insert(a), involved.insert(b);
        std::optional<std::tuple<size_t, size_t, uint32_t, size_t>> choice;  // (trouble, −tenons, body, rank)
        Trouble chosen;
        for (uint32_t b : involved)
            for (size_t rank = 0; rank < bodies[b].options.size(); ++rank) {
                const DirectionOption& o = bodies[b].options[rank];
                if (!o.isFree || o.tenons == 0 || o.hole == holes[b]) continue;
                if (std::find(recent.begin(), recent.end(), std::make_pair(b, o.hole)) != recent.end())
                    continue;
                std::vector<int> trial = holes;
                trial[b] = o.hole;
                Trouble t = blockingTrouble(bodies, trial, faces, frameToGridMm, voxelMm, cache);
                const auto key = std::make_tuple(t.count(), size_t(1000000) - o.tenons, b, rank);
                if (!choice || key < *choice) choice = key, chosen = std::move(t);
            }
        if (!choice || std::get<0>(*choice) > trouble.count()) break;  // only worse moves left
        const uint32_t b = std::get<2>(*choice);
        recent.push_back({b, holes[b]});
        if (recent.size() > tabu) recent.erase(recent.begin());
        holes[b] = bodies[b].options[std::get<3>(*choice)].hole;
        trouble = std::move(chosen);
        if (trouble.count() < best.count()) best = trouble, bestHoles = holes;
    }
    holes = bestHoles;
    return best;
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

    /// Replaces bodies @p i and @p j by @p joined (kept at the lower index).
    void glue(size_t i, size_t j, MountBody joined, const FaceContacts& faces) {
        glued.push_back(gluePair(list[i], list[j], faces));
        if (i > j) std::swap(i, j);
        list[i] = std::move(joined);
        list.erase(list.begin() + std::ptrdiff_t(j));
    }
};

/// Tenons of a body along its best free direction (0 when it has none).
size_t heldBy(const MountBody& b) {
    const DirectionOption* o = b.bestFree();
    return o ? o->tenons : 0;
}

/// The best union of body @p i with a neighbour: the one with the most tenons along a free
/// direction, then the largest contact, then the lowest index; at least @p minTenons of them.
/// SIZE_MAX when there is none.
size_t bestPartner(const Bodies& bodies, size_t i, size_t minTenons, const PlannerInput& input,
                   const FrameSweeps& sweeps, const FaceContacts& faces, double voxelMm, int maxPerPiece,
                   MountBody* joined) {
    size_t best = SIZE_MAX;
    std::tuple<size_t, double, size_t> bestKey{0, 0.0, 0};
    for (size_t j = 0; j < bodies.list.size(); ++j) {
        if (j == i) continue;
        const size_t contact = bodyContact(bodies.list[i], bodies.list[j], faces);
        if (contact == 0) continue;
        std::vector<uint32_t> members = bodies.list[i].pieces;
        members.insert(members.end(), bodies.list[j].pieces.begin(), bodies.list[j].pieces.end());
        MountBody u = makeBody(members, input, sweeps, voxelMm, maxPerPiece, true);
        const DirectionOption* o = u.bestFree();
        if (!o || o->tenons < minTenons) continue;
        const std::tuple<size_t, double, size_t> key{o->tenons, o->score, contact};
        if (best == SIZE_MAX || key > bestKey) best = j, bestKey = key, *joined = std::move(u);
    }
    return best;
}

/// Glues every body held by fewer than @p minTenons tenons to the partner that gives their union
/// the most (at least @p minTenons and more than the body had), as long as one does.
void glueWeak(Bodies& bodies, size_t minTenons, const PlannerInput& input, const FrameSweeps& sweeps,
              const FaceContacts& faces, double voxelMm, int maxPerPiece, const RunContext& context) {
    std::set<uint32_t> hopeless;  // by first piece: no partner helps them
    for (bool isChanged = true; isChanged;) {
        isChanged = false;
        for (size_t i = 0; i < bodies.list.size(); ++i) {
            const size_t own = heldBy(bodies.list[i]);
            if (own >= minTenons || hopeless.count(bodies.list[i].pieces[0])) continue;
            context.throwIfCancelled();
            MountBody joined;
            const size_t j = bestPartner(bodies, i, std::max(minTenons, own + 1), input, sweeps, faces,
                                         voxelMm, maxPerPiece, &joined);
            if (j == SIZE_MAX) {
                hopeless.insert(bodies.list[i].pieces[0]);
                continue;
            }
            context.debug("mounting: " + bodyName(bodies.list[i]) + " (" + std::to_string(own) +
                          " tenons) glued to " + bodyName(bodies.list[j]) + ": " +
                          std::to_string(heldBy(joined)) + " tenons");
            testPaths(joined, sweeps, voxelMm);
            bodies.glue(i, j, std::move(joined), faces);
            hopeless.clear();  // the bodies changed: a partner may exist now
            isChanged = true;
            break;
        }
    }
    for (const MountBody& b : bodies.list) {
        if (heldBy(b) >= minTenons) continue;
        std::string options;
        for (const DirectionOption& o : b.options)
            options += " " + std::to_string(o.hole) + ":" + std::to_string(o.tenons) +
                       (o.isFree ? "" : "(" + o.blockedBy + ")");
        context.debug("mounting: " + bodyName(b) + " held by " + std::to_string(heldBy(b)) +
                      " tenons; options" + options);
    }
}

/// Glues one pair of bodies that keeps the relation from an order (a deadlocked pair, else two
/// neighbours of the cycle) when their union is held. False when no such pair can be glued.
bool glueTrouble(Bodies& bodies, const Trouble& trouble, const PlannerInput& input, const FrameSweeps& sweeps,
                 const FaceContacts& faces, double voxelMm, int maxPerPiece) {
    std::vector<std::pair<uint32_t, uint32_t>> pairs = trouble.deadlocks;
    for (size_t k = 0; k < trouble.cycle.size(); ++k)
        pairs.push_back({trouble.cycle[k], trouble.cycle[(k + 1) % trouble.cycle.size()]});
    for (const auto& [a, b] : pairs) {
        if (a == b || bodyContact(bodies.list[a], bodies.list[b], faces) == 0) continue;
        std::vector<uint32_t> members = bodies.list[a].pieces;
        members.insert(members.end(), bodies.list[b].pieces.begin(), bodies.list[b].pieces.end());
        MountBody u = makeBody(members, input, sweeps, voxelMm, maxPerPiece, true);
        if (!u.bestFree()) continue;
        testPaths(u, sweeps, voxelMm);
        bodies.glue(a, b, std::move(u), faces);
        return true;
    }
    return false;
}

mount::InstallationPlan writePlan(const Bodies& bodies, const std::vector<int>& holes, const Trouble& trouble,
                                  size_t pieceCount) {
    mount::InstallationPlan plan;
    plan.holeOfPiece.assign(pieceCount, -1);
    plan.groupOf.assign(pieceCount, 0);
    plan.glued = bodies.glued;
    std::sort(plan.glued.begin(), plan.glued.end());
    for (size_t b = 0; b < bodies.list.size(); ++b)
        for (uint32_t p : bodies.list[b].pieces) {
            plan.holeOfPiece[p] = holes[b];
            plan.groupOf[p] = bodies.list[b].pieces[0];
        }
    for (const auto& [a, b] : trouble.before)
        plan.before.push_back({bodies.list[a].pieces[0], bodies.list[b].pieces[0]});
    for (size_t b = 0; b < bodies.list.size(); ++b) {
        if (holes[b] >= 0) continue;
        const MountBody& body = bodies.list[b];
        std::string why = body.options.empty() ? "no ball's hole points at it within a tenon's reach"
                                               : "every direction with tenons is blocked (" +
                                                     body.options[0].blockedBy + " in the way of the best)";
        plan.problems.push_back(bodyName(body) + ": no direction to push it on along and hold it: " + why);
    }
    for (const auto& [a, b] : trouble.deadlocks)
        plan.problems.push_back(bodyName(bodies.list[a]) + " and " + bodyName(bodies.list[b]) +
                                " block each other: each would have to go on before the other");
    if (trouble.deadlocks.empty() && !trouble.cycle.empty()) {
        std::string list;
        for (uint32_t b : trouble.cycle) list += (list.empty() ? "" : ", ") + bodyName(bodies.list[b]);
        plan.problems.push_back(list + " block each other in a cycle");
    }
    for (uint32_t b : trouble.order) plan.steps.push_back({bodies.list[b].pieces, holes[b]});
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

Trouble blockingTrouble(const std::vector<MountBody>& bodies, const std::vector<int>& holes,
                        const FaceContacts& faces, const Transform4d& frameToGridMm, double voxelMm,
                        SweepCache& cache) {
    Trouble t;
    const size_t n = bodies.size();
    for (uint32_t a = 0; a < n; ++a)
        for (uint32_t b = a + 1; b < n; ++b) {
            if (holes[a] < 0 || holes[b] < 0) continue;
            const Vec3d da = gridDirection(holes[a], frameToGridMm),
                        db = gridDirection(holes[b], frameToGridMm);
            // Neighbours by their cut faces (a shallow crossing of a face), and every pair by a sweep
            // (a neighbour may also lie across the path farther on: a piece that wraps around).
            bool isTouching = false;
            mount::FaceOrder order = facesOrder(bodies[a], bodies[b], faces, da, db, &isTouching);
            auto hits = [&](uint32_t moving, uint32_t still, int hole, const Vec3d& d) {
                const auto key = std::make_tuple(bodies[moving].pieces, bodies[still].pieces, hole);
                const auto it = cache.find(key);
                if (it != cache.end()) return it->second;
                return cache[key] = sweepHits(bodies[moving], bodies[still], d, voxelMm, isTouching);
            };
            order.isBAfterAOk = order.isBAfterAOk && !hits(b, a, holes[b], db);
            order.isAAfterBOk = order.isAAfterBOk && !hits(a, b, holes[a], da);
            if (order.isBAfterAOk && order.isAAfterBOk) continue;
            if (order.isBAfterAOk)
                t.before.push_back({a, b});
            else if (order.isAAfterBOk)
                t.before.push_back({b, a});
            else
                t.deadlocks.push_back({a, b});
        }
    if (t.deadlocks.empty()) t.order = mount::mountingOrder(n, t.before, priorities(bodies), &t.cycle);
    return t;
}

mount::InstallationPlan planMounting(const PlannerInput& input, const FrameSweeps& sweeps,
                                     const FaceContacts& faces, double voxelMm, int minPerPiece,
                                     int maxPerPiece, const RunContext& context) {
    Bodies bodies;
    for (const MountBody& piece : input.pieces)
        bodies.list.push_back(makeBody(piece.pieces, input, sweeps, voxelMm, maxPerPiece));
    context.throwIfCancelled();
    // First every body held at all (a thin ear glued to the head), then by minPerPiece tenons.
    glueWeak(bodies, 1, input, sweeps, faces, voxelMm, maxPerPiece, context);
    glueWeak(bodies, size_t(minPerPiece), input, sweeps, faces, voxelMm, maxPerPiece, context);
    SweepCache cache;
    std::vector<int> holes = chosenHoles(bodies.list);
    Trouble trouble =
        improveDirections(bodies.list, holes, faces, sweeps.frameToGridMm(), voxelMm, cache, context);
    // Where no choice of directions lets an order exist, glue bodies that block each other.
    while (trouble.count() > 0 && glueTrouble(bodies, trouble, input, sweeps, faces, voxelMm, maxPerPiece)) {
        holes = chosenHoles(bodies.list);
        trouble =
            improveDirections(bodies.list, holes, faces, sweeps.frameToGridMm(), voxelMm, cache, context);
    }
    if (trouble.count() > 0) trouble.order.clear();
    return writePlan(bodies, holes, trouble, input.pieces.size());
}

}  // namespace zomefab::pieces::detail
