// SPDX-License-Identifier: GPL-3.0-or-later
// The frame grown toward pieces too few pegs hold (detail/replan.h, docs/mounting.md, "Frame grown
// toward a piece"): issue 17's "where no ball is near a piece the frame grows toward it (exact
// struts, collision-free, outside the forbidden zone)". The frame stage grows toward the surface
// it does not reach (frame/reach.h); a piece can still have no ball whose hole along *its*
// direction meets its wall within a tenon's reach. Here a strut to a new ball is added where that
// new ball's hole along the piece's direction is a tenon candidate of the piece, and the plan is
// made again; kept only when fewer pieces are under-held with a plan that can be carried out.
#include <algorithm>
#include <cmath>
#include <tuple>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/replan.h"
#include "zomefab/zome/zome_system.h"

namespace zomefab::pieces::detail {

namespace {

/// Rounds of growth (each a plan): a piece with no peg can gain one ball per round and needs two.
constexpr int kGrowRounds = 3;

/// Rounds of growth toward staves no peg holds (each a plan, quick while any stays unheld): a ball
/// grown for one stave may take the spot or the hole another needed.
constexpr int kStaveGrowRounds = 4;

/// A strut to add: from ball a through hole, of size; the candidate its new ball gives the piece.
struct Growth {
    zome::BallId a = zome::kNoId;
    int hole = 0;
    int size = 0;
    double score = -1e300;
};

/// Adds @p g's strut, with the new ball at its end, to @p frame.
void addGrowth(zome::Structure& frame, const Growth& g) {
    frame.addBall(frame.ball(g.a).position + zome::strutVector(g.hole, g.size));
    frame.addStrut(g.a, g.hole, g.size);
}

/// Does the ray from @p origin along @p dir (unit) meet @p box within @p reach (mm)? Slabs.
bool rayMeetsBox(const Vec3d& origin, const Vec3d& dir, const Box3d& box, double reach) {
    double t0 = 0.0, t1 = reach;
    for (size_t k = 0; k < 3; ++k) {
        if (std::abs(dir[k]) < 1e-12) {
            if (origin[k] < box.min[k] || origin[k] > box.max[k]) return false;
            continue;
        }
        double a = (box.min[k] - origin[k]) / dir[k], b = (box.max[k] - origin[k]) / dir[k];
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a), t1 = std::min(t1, b);
        if (t0 > t1) return false;
    }
    return true;
}

/// Each piece's inside voxels' box (grid mm).
std::vector<Box3d> pieceBoxes(const VoxelField& field, size_t pieceCount) {
    std::vector<Box3d> boxes(pieceCount);
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isInside(s) && field.owner[s] < pieceCount)
            boxes[field.owner[s]].expand(field.world(field.coordOf(s)));
    return boxes;
}

/// The best strut to add to @p frame for piece @p p along @p hole: its new ball's ray along the hole
/// is a tenon candidate of p (the best score; then the shorter strut, the lower ball and hole).
std::optional<Growth> bestGrowth(zome::Structure& frame, uint32_t p, int hole, const Box3d& box,
                                 const Transform4d& frameToGridMm, const ShellProbe& probe,
                                 const TenonOptions& o, const StrutTest& canGrow) {
    const Vec3d axis = gridDirection(hole, frameToGridMm);
    // The wall lies within the ball's radius, a tenon and the wall of the ball's centre.
    const double reach = frame.scale().ballRadiusMm() + o.maxLengthMm + probe.wallMm;
    Box3d grown = box;
    for (size_t k = 0; k < 3; ++k) grown.min[k] -= probe.voxelMm, grown.max[k] += probe.voxelMm;
    std::optional<Growth> best;
    const std::vector<zome::BallId> balls = frame.ballIds();
    for (zome::BallId a : balls)
        for (int h = 0; h < zome::kHoleCount; ++h) {
            if (!frame.isHoleFree(a, h)) continue;
            for (int size = 0; size < zome::kSizeCount; ++size) {
                const zome::GoldenVector3 end = frame.ball(a).position + zome::strutVector(h, size);
                const Vec3d endGrid = frameToGridMm.apply(frame.scale().toMm(end));
                if (!rayMeetsBox(endGrid, axis, grown, reach) || !canGrow(frame, a, h, size)) continue;
                const zome::BallId b = frame.addBall(end);
                const zome::StrutId s = frame.addStrut(a, h, size);
                const TenonCandidate c = tenonCandidate(frame, b, hole, frameToGridMm, probe, o);
                frame.removeStrut(s);
                frame.removeBall(b);
                if (!c.rejection.empty() || c.piece != int64_t(p)) continue;
                // Higher score first; then the shorter strut, the lower (ball, hole): deterministic.
                if (!best || c.score > best->score + 1e-12 ||
                    (std::abs(c.score - best->score) <= 1e-12 &&
                     std::tie(size, a, h) < std::tie(best->size, best->a, best->hole)))
                    best = Growth{a, h, size, c.score};
            }
        }
    return best;
}

/// The struts that give piece @p p up to @p need more tenon candidates along @p hole, found one after
/// another on a copy of @p frame (each new ball in the next one's frame); fewer when no more is found.
std::vector<Growth> growthsAlong(const zome::Structure& frame, uint32_t p, int hole, size_t need,
                                 const Box3d& box, const Replanner& r, const StrutTest& canGrow) {
    zome::Structure trial = frame;
    std::vector<Growth> list;
    for (size_t k = 0; k < need; ++k) {
        const std::optional<Growth> g =
            bestGrowth(trial, p, hole, box, r.frameToGridMm, r.probe, r.opt.tenons, canGrow);
        if (!g) break;
        addGrowth(trial, *g);
        list.push_back(*g);
    }
    return list;
}

/// The struts to add for under-held piece @p p (fewer than minPegs of @p pegs): along its planned
/// direction those it still misses, as many as are found; where none is found there, the one strut
/// that gives it minPegs candidates along another direction its path is free along (the first in
/// hole order; the plan made again may then choose that direction). Empty when nothing helps.
std::vector<Growth> growthsFor(const zome::Structure& frame, uint32_t p, size_t pegs, const Box3d& box,
                               const PlannerInput& input, const Replanner& r, const StrutTest& canGrow) {
    const size_t minPegs = size_t(r.opt.tenons.minPerPiece);
    const int hole = r.out.plan.holeOfPiece[p];
    std::vector<Growth> along = growthsAlong(frame, p, hole, minPegs - pegs, box, r, canGrow);
    if (!along.empty()) return along;
    // Other directions: only those the piece already has a candidate along and lacks one more for
    // (one strut each; trying every free direction for every missing peg tripled the dino's 700 mm run).
    for (const auto& [other, entry] : input.candidatesByHole[p]) {
        if (other == hole || entry.first + 1 != minPegs ||
            !r.sweeps.isFree(input.pieces[p], other, r.field.voxelMm, nullptr))
            continue;
        std::vector<Growth> list = growthsAlong(frame, p, other, 1, box, r, canGrow);
        if (!list.empty()) return list;
    }
    return {};
}

/// Struts added to @p trial toward every stave the plan places nowhere: along the directions it
/// may take (isStaveDirection), the nearest its lift reversed first, up to --min-tenons each.
/// Returns how many.
size_t growTowardStaves(const Replanner& r, const StrutTest& canGrow, zome::Structure& trial) {
    const std::vector<Box3d> boxes = pieceBoxes(r.field, r.out.pieces.size());
    const PlannerInput input = plannerInput(r.out, r.field, r.candidates);
    const size_t minPegs = size_t(std::max(1, r.opt.tenons.minPerPiece));
    size_t added = 0;
    for (uint32_t p = 0; p < r.out.pieces.size(); ++p) {
        if ((r.out.plan.holeOfPiece[p] >= 0 && !isGluedOn(r.out.plan, p)) || boxes[p].isEmpty()) continue;
        const std::optional<Stave> st = staveOf(r.grouping.cellSets[p], input.pieces[p].voxels);
        if (!st) continue;
        std::vector<std::pair<double, int>> holes;
        for (int h = 0; h < zome::kHoleCount; ++h)
            if (const Vec3d d = gridDirection(h, r.frameToGridMm); isStaveDirection(*st, d))
                holes.push_back({dot(d, st->liftGrid), h});
        std::sort(holes.begin(), holes.end());
        for (const auto& [lean, hole] : holes) {
            const std::vector<Growth> list = growthsAlong(trial, p, hole, minPegs, boxes[p], r, canGrow);
            for (const Growth& g : list)
                if (canGrow(trial, g.a, g.hole, g.size)) addGrowth(trial, g), ++added;
            if (!list.empty()) break;
        }
    }
    return added;
}

}  // namespace

size_t growFrameForStaves(Replanner& r, const StrutTest& canGrow) {
    size_t grown = 0;
    for (int round = 0; round < kStaveGrowRounds && canGrow; ++round) {
        r.context.throwIfCancelled();
        const size_t before = peglessStaves(r.out.plan, r.grouping.cellSets);
        if (before == 0) break;
        zome::Structure trial = r.frame;
        const size_t added = growTowardStaves(r, canGrow, trial);
        r.context.debug("mounting: growing the frame: " + std::to_string(added) + " strut(s) found for " +
                        std::to_string(before) + " stave(s) no peg holds");
        if (added == 0 || !r.tryChange([&] { r.frame = std::move(trial); }, before,
                                       "frame grown by " + std::to_string(added) + " struts toward staves",
                                       Replanner::Change::kStaves))
            break;
        grown += added;
    }
    if (grown > 0)
        r.context.detail("the frame grew by " + std::to_string(grown) +
                         " strut(s), each to a new ball, toward staves no peg held");
    return grown;
}

size_t growFrameForPieces(Replanner& r, const StrutTest& canGrow) {
    if (!canGrow) return 0;
    const size_t minPegs = size_t(r.opt.tenons.minPerPiece);
    size_t grown = 0;
    for (int round = 0; round < kGrowRounds && r.out.plan.isBuildable(); ++round) {
        r.context.throwIfCancelled();
        const std::vector<size_t> pegs = r.pegs();
        const size_t before = underHeld(pegs, r.opt.tenons.minPerPiece);
        if (before == 0) break;
        const std::vector<Box3d> boxes = pieceBoxes(r.field, r.out.pieces.size());
        const PlannerInput input = plannerInput(r.out, r.field, r.candidates);
        zome::Structure trial = r.frame;
        size_t added = 0;
        for (uint32_t p = 0; p < r.out.pieces.size(); ++p) {
            if (pegs[p] >= minPegs || r.out.plan.holeOfPiece[p] < 0 || boxes[p].isEmpty()) continue;
            for (const Growth& g : growthsFor(trial, p, pegs[p], boxes[p], input, r, canGrow)) {
                // A strut found for an earlier piece this round may have taken the hole or the spot.
                if (!canGrow(trial, g.a, g.hole, g.size)) continue;
                addGrowth(trial, g);
                ++added;
            }
        }
        r.context.debug("mounting: growing the frame: " + std::to_string(added) + " strut(s) found for " +
                        std::to_string(before) + " piece(s) under " + std::to_string(minPegs) + " pegs");
        if (added == 0) break;
        if (!r.tryChange([&] { r.frame = std::move(trial); }, before,
                         "frame grown by " + std::to_string(added) + " struts", Replanner::Change::kFrame))
            break;
        grown += added;
    }
    if (grown > 0)
        r.context.detail("the frame grew by " + std::to_string(grown) +
                         " strut(s), each to a new ball, toward pieces too few pegs held");
    return grown;
}

}  // namespace zomefab::pieces::detail
