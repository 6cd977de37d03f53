// SPDX-License-Identifier: GPL-3.0-or-later
// The installation plan: the pieces as bodies (glued before planning, staves in their order), the
// disassembly, stuck bodies glued into one where no order exists, and the plan written
// (detail/mounting.h, docs/mounting.md, "Order" and "Glued groups").
#include <algorithm>
#include <optional>
#include <set>
#include <string>
#include <tuple>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/zome/holes.h"

namespace zomefab::pieces::detail {

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
    // Staves, and mouth rings, which go on after every stave of their tunnel (each lies in their
    // way out): glued to a face piece that has to go on before some of those staves, a mouth ring
    // leaves the group no order (the cheese at 700 mm).
    auto isNeverGlued = [&](const MountBody& body) {
        return std::any_of(body.pieces.begin(), body.pieces.end(),
                           [&](uint32_t p) { return input.isStave(p) || input.isMouthRing(p); });
    };
    std::vector<std::tuple<int, size_t, uint32_t, uint32_t>> pairs;  // (−kind, −contact, a, b)
    for (size_t i = 0; i < parts.stuck.size(); ++i)
        for (uint32_t b = 0; b + fixedCount < bodies.list.size(); ++b) {
            const uint32_t a = parts.stuck[i];
            const auto other = std::find(parts.stuck.begin(), parts.stuck.end(), b);
            if (b == a || (other != parts.stuck.end() && b < a)) continue;       // each stuck pair once
            if (isNeverGlued(bodies.list[a]) || isNeverGlued(bodies.list[b])) continue;
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

/// The plan of @p parts; the last @p fixedCount bodies are staves, whose problems and steps are the
/// caller's: per stave in its mounting order, (its index among them, how many steps go on before
/// it) in @p staveSlots.
mount::InstallationPlan writePlan(const Bodies& bodies, const Disassembly& parts, size_t pieceCount,
                                  size_t fixedCount, std::vector<std::pair<size_t, size_t>>* staveSlots) {
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
        for (uint32_t b : parts.order) {
            if (b + fixedCount >= bodies.list.size())  // a stave: its step is addStaveSteps'
                staveSlots->push_back({b + fixedCount - bodies.list.size(), plan.steps.size()});
            else
                plan.steps.push_back({bodies.list[b].pieces, parts.holes[b]});
        }
    return plan;
}

}  // namespace

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
    // Where nothing else can be taken away, the disassembly takes a ring of them (FixedStaves): the
    // bodies left go on before it.
    StaveOrder order = placeStaves(staves, input, sweeps, faces, voxelMm, maxPerPiece, context, bodies.list);
    const size_t fixed = order.pieces.size();
    // A stave no hole holds and none of its ring holds it either leaves no plan to be carried out:
    // the frame must grow toward it first (growFrameForStaves), and an order of the rest is not
    // sought (the cheese at 700 mm: minutes).
    if (std::count(order.holes.begin(), order.holes.end(), -1) > 0)
        return unheldStavesPlan(input, order, sweeps.frameToGridMm());
    SweepCache cache;
    const GlueOnRule glueOn;
    const FixedStaves fixedInfo = fixedStaves(order, input);
    auto takeApart = [&] {
        return disassemble(bodies.list, faces, sweeps.frameToGridMm(), voxelMm, glueOn, cache, context, fixed,
                           &fixedInfo);
    };
    Disassembly parts = takeApart();
    // Bodies held by pegs but stuck may be glued on instead, along a direction no peg uses.
    if (!parts.stuck.empty()) {
        for (uint32_t b : parts.stuck)
            if (bodies.list[b].glueOptions.empty()) addGlueOptions(bodies.list[b], holes, sweeps, voxelMm);
        parts = takeApart();
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
        parts = takeApart();
        stall = parts.stuck.size() < fewestStuck ? 0 : stall + 1;
        fewestStuck = std::min(fewestStuck, parts.stuck.size());
    }
    const size_t firstStave = bodies.list.size() - fixed;
    for (size_t k = 0; k < fixed; ++k) parts.holes[firstStave + k] = order.holes[k];
    for (const std::string& line : parts.ringNotes) context.debug("mounting: " + line);
    if (parts.ringsTakenAway > 0)
        context.debug("mounting: " + std::to_string(parts.ringsTakenAway) +
                      " rings of staves go on among the other pieces");
    std::vector<std::pair<size_t, size_t>> staveSlots;
    mount::InstallationPlan plan = writePlan(bodies, parts, input.pieces.size(), fixed, &staveSlots);
    addStaveSteps(plan, input, order, sweeps.frameToGridMm(), staveSlots);
    return plan;
}

}  // namespace zomefab::pieces::detail
