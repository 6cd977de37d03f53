// SPDX-License-Identifier: GPL-3.0-or-later
// Tenons in later pieces' paths (detail/replan.h, docs/mounting.md, "Tenons lost to other pieces"):
// a stem of a piece already on that a later step's body would sweep, straight or along a stave's
// two legs, is marked lost and the plan made again without it.
#include <optional>
#include <set>

#include "zomefab/mount/sweep.h"
#include "zomefab/pieces/detail/replan.h"

namespace zomefab::pieces::detail {

namespace {

/// The stem of tenon @p t (its tapered prism, ball face to wall) drawn into @p r as its 12 triangles,
/// grown by @p growMm (tenonHullMm's first 8 points: the corners at the ball's end, then at the wall).
void drawStem(mount::DepthRaster& r, const Tenon& t, const TenonOptions& o, double growMm, uint32_t id) {
    const std::vector<Vec3d> c = tenonHullMm(t, o);
    // Corner k = 2·l + s (l, s: the sides); the quads of the two ends and of the four sides.
    static constexpr int kQuads[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                         {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
    for (const auto& q : kQuads) {
        r.addTriangle(c[size_t(q[0])], c[size_t(q[1])], c[size_t(q[2])], growMm, id);
        r.addTriangle(c[size_t(q[0])], c[size_t(q[2])], c[size_t(q[3])], growMm, id);
    }
}

}  // namespace

size_t markTenonsInPaths(const mount::InstallationPlan& plan, const TenonPlan& tenons,
                         const PlannerInput& input, const Transform4d& frameToGridMm, const TenonOptions& o,
                         double voxelMm, std::vector<TenonCandidate>& candidates,
                         std::set<std::pair<zome::BallId, int>>& lost) {
    std::vector<const Tenon*> before;  // the tenons of the steps already on
    std::set<std::pair<zome::BallId, int>> found;
    // Whether the body of @p step, moved by @p fromMm, pushed along @p d (as far as @p reachMm; 0:
    // without end) meets stem @p t.
    auto meets = [&](const mount::MountStep& step, const Tenon& t, const Vec3d& d, const Vec3d& fromMm,
                     double reachMm) {
        Box3d bounds;
        for (uint32_t p : step.pieces)
            bounds.expand(add(input.pieces[p].bounds.min, fromMm)),
                bounds.expand(add(input.pieces[p].bounds.max, fromMm));
        const Box3d stem = tenonBoundsMm(t, o);
        if (!shadowsMeet(bounds, stem, d)) return false;
        Box3d both = bounds;
        both.expand(stem.min), both.expand(stem.max);
        const mount::SweepAxes axes(d);
        mount::DepthRaster obstacle(axes, both, voxelMm, true, voxelMm),
            body(axes, both, voxelMm, false, voxelMm);
        // A leg of limited reach (a lift): the stem clipped past the body's far side.
        std::optional<mount::DepthRaster> far;
        if (reachMm > 0) far.emplace(axes, both, voxelMm, true, voxelMm);
        for (uint32_t p : step.pieces)
            for (const Vec3d& x : input.pieces[p].voxels) {
                body.addPoint(add(x, fromMm), 0.0, p);
                if (far) far->addPoint(add(x, fromMm), 0.0, p);
            }
        if (far) obstacle.limitReach(*far, reachMm);
        drawStem(obstacle, t, o, 0.5 * voxelMm, 0);
        return mount::worstHit(obstacle, body, voxelMm).isHit;
    };
    for (const mount::MountStep& step : plan.steps) {
        if (step.hole >= 0 && !before.empty()) {
            const Vec3d d = gridDirection(step.hole, frameToGridMm);
            // A stave is lifted off its pegs, then slid along its tunnel.
            const Vec3d slide = normalized(applyLinear(frameToGridMm, step.slide));
            for (const Tenon* t : before)
                if (step.hasTwoLegs() ? meets(step, *t, d, {0, 0, 0}, step.liftMm) ||
                                            meets(step, *t, slide, scale(d, step.liftMm), 0.0)
                                      : meets(step, *t, d, {0, 0, 0}, 0.0))
                    found.insert({t->ball, t->hole});
        }
        for (uint32_t p : step.pieces)
            for (const Tenon& t : tenons.perPiece[p]) before.push_back(&t);
    }
    for (TenonCandidate& c : candidates)
        if (c.rejection.empty() && found.count({c.tenon.ball, c.tenon.hole}))
            c.rejection = "in another piece's path";
    lost.insert(found.begin(), found.end());
    return found.size();
}

}  // namespace zomefab::pieces::detail
