// SPDX-License-Identifier: GPL-3.0-or-later
// The verifier's checks of motion: every body pushed off along its direction meets nothing of the
// frame (real radii; a ball's hole along the direction is open to its floor) and nothing of the
// bodies mounted before it (detail/geometry.h, docs/mounting.md).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <mutex>
#include <optional>

#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/mount/sweep.h"
#include "zomefab/verify/detail/geometry.h"
#include "zomefab/zome/holes.h"

namespace zomefab::verify::detail {

namespace {

constexpr uint32_t kStrutBit = 0x80000000u;

std::string obstacleName(uint32_t id) {
    return (id & kStrutBit) ? "strut " + std::to_string(id & ~kStrutBit) : "ball " + std::to_string(id);
}

Box3d bodyBounds(const std::vector<PieceGeometry>& geometry, const std::vector<uint32_t>& members) {
    Box3d b;
    for (uint32_t p : members) b.expand(geometry[p].bounds.min), b.expand(geometry[p].bounds.max);
    return b;
}

/// The pieces' triangles, moved by @p offsetMm: the pixels whose centre lies within @p growMm of a
/// triangle's shadow.
void drawPieces(mount::DepthRaster& r, const std::vector<PieceGeometry>& geometry,
                const std::vector<uint32_t>& members, double growMm, const Vec3d& offsetMm = {0, 0, 0}) {
    for (uint32_t p : members)
        for (const auto& t : geometry[p].triangles)
            r.addTriangle(add(geometry[p].vertices[t[0]], offsetMm),
                          add(geometry[p].vertices[t[1]], offsetMm),
                          add(geometry[p].vertices[t[2]], offsetMm), growMm, p);
}

/// The frame seen along the raster's direction: every ball with its hole along @p hole open down
/// to the hole's floor (a peg in it moves out along it freely; −1: every ball whole), every strut
/// a capsule of its real radius.
void drawFrame(mount::DepthRaster& r, const Assembly& a, int hole, const VerifyOptions& o) {
    const zome::ZomeScale& scale = a.frame.scale();
    const mount::SweepAxes& axes = r.axes();
    for (zome::BallId id : a.frame.ballIds()) {
        if (hole < 0) {
            r.addSphere(a.frameToGridMm.apply(a.frame.ball(id).positionMm), scale.ballRadiusMm(), 0.0, id);
            continue;
        }
        const HoleFrame h = holeFrame(a, id, hole);
        std::vector<std::array<double, 2>> uv;
        for (const auto& corner : h.section) {
            const Vec3d p = madd(madd(h.centerMm, corner[0], h.x), corner[1], h.y);
            uv.push_back({dot(p, axes.u), dot(p, axes.v)});
        }
        const double floor = dot(h.centerMm, axes.d) + h.faceMm - o.holeDepthMm;
        r.addBallWithHole(h.centerMm, scale.ballRadiusMm(), uv, floor, id);
    }
    for (zome::StrutId id : a.frame.strutIds()) {
        const zome::Strut& s = a.frame.strut(id);
        r.addCapsule(a.frameToGridMm.apply(s.startMm), a.frameToGridMm.apply(s.endMm),
                     scale.strutRadiusMm(s.color), 0.0, kStrutBit | id);
    }
}

/// One leg of a step's way off: its body, moved by @p fromMm, pushed along @p d as far as
/// @p reachMm (0: without end), against the frame (balls open along @p hole, −1: none) and the
/// bodies of the steps before @p s.
struct LegHits {
    mount::SweepHit frame, pieces;
};
LegHits sweepLeg(const Assembly& a, const std::vector<PieceGeometry>& geometry, const VerifyOptions& o,
                 size_t s, const Vec3d& d, const Vec3d& fromMm, double reachMm, int hole, Box3d all) {
    const std::vector<mount::MountStep>& steps = a.pieces.plan.steps;
    const mount::SweepAxes axes(d);
    Box3d bounds = bodyBounds(geometry, steps[s].pieces);
    bounds = {add(bounds.min, fromMm), add(bounds.max, fromMm)};
    all.expand(bounds.min), all.expand(bounds.max);
    // One lattice for the whole object; each test on the window of the moving body.
    const mount::DepthRaster lattice(axes, all, o.pixelMm, true);
    mount::DepthRaster body(lattice, bounds, false, 1.0);
    drawPieces(body, geometry, steps[s].pieces, 0.0, fromMm);
    // A leg of limited reach: the obstacles clipped past the body's far side (a lift, not a push).
    std::optional<mount::DepthRaster> far;
    if (reachMm > 0) {
        far.emplace(lattice, bounds, true, 1.0);
        drawPieces(*far, geometry, steps[s].pieces, 0.0, fromMm);
    }
    mount::DepthRaster frame(lattice, bounds, true, 1.0);
    if (far) frame.limitReach(*far, reachMm);
    drawFrame(frame, a, hole, o);
    LegHits hits;
    hits.frame = mount::worstHit(frame, body, o.materialToleranceMm);
    // Against the pieces before it, both sides' shadows shrunk a little: a cut face the body
    // slides along at a grazing angle is seen edge-on, where the two meshes' few hundredths of
    // a millimetre apart would read as centimetres along the direction.
    mount::DepthRaster before(lattice, bounds, true, 1.0), shrunk(lattice, bounds, false, 1.0);
    if (far) before.limitReach(*far, reachMm);
    for (size_t e = 0; e < s; ++e) drawPieces(before, geometry, steps[e].pieces, -o.orderShrinkMm);
    drawPieces(shrunk, geometry, steps[s].pieces, -o.orderShrinkMm, fromMm);
    hits.pieces = mount::worstHit(before, shrunk, o.orderToleranceMm);
    return hits;
}

std::string stepName(const mount::MountStep& step, size_t s) {
    std::string list;
    for (uint32_t p : step.pieces) list += (list.empty() ? "" : " + ") + std::to_string(p);
    return "step " + std::to_string(s + 1) + " (piece" + (step.pieces.size() > 1 ? "s " : " ") + list + ")";
}

}  // namespace

void checkPaths(const Assembly& a, const std::vector<PieceGeometry>& geometry, const VerifyOptions& o,
                VerifyReport& report, const RunContext& context) {
    CheckResult path{"free path",
                     "every piece or glued group pushed off along its direction meets no ball or strut",
                     0,
                     {}};
    CheckResult order{"order", "and none of the pieces mounted before it", 0, {}};
    const std::vector<mount::MountStep>& steps = a.pieces.plan.steps;
    Box3d all;
    for (const PieceGeometry& g : geometry) all.expand(g.bounds.min), all.expand(g.bounds.max);
    for (zome::BallId id : a.frame.ballIds()) all.expand(a.frameToGridMm.apply(a.frame.ball(id).positionMm));
    std::mutex lock;
    tbb::parallel_for(size_t(0), steps.size(), [&](size_t s) {
        const mount::MountStep& step = steps[s];
        if (step.hole < 0 || all.isEmpty()) return;
        context.throwIfCancelled();
        const Vec3d d = normalized(applyLinear(a.frameToGridMm, zome::holeDirection(step.hole)));
        // Pushed off along its direction; a step of two legs only by its lift, then slid off.
        std::vector<std::pair<std::string, LegHits>> legs;
        if (!step.hasTwoLegs()) {
            legs.push_back({"pushed off along its direction",
                            sweepLeg(a, geometry, o, s, d, {0, 0, 0}, 0.0, step.hole, all)});
        } else {
            const Vec3d slide = normalized(applyLinear(a.frameToGridMm, step.slide));
            legs.push_back({"lifted off its pegs",
                            sweepLeg(a, geometry, o, s, d, {0, 0, 0}, step.liftMm, step.hole, all)});
            legs.push_back({"slid off along its tunnel",
                            sweepLeg(a, geometry, o, s, slide, scale(d, step.liftMm), 0.0, -1, all)});
        }
        const Transform4d gridToFrame = affineInverse(a.frameToGridMm);
        auto at = [&](const mount::SweepHit& hit) {
            const Vec3d x = gridToFrame.apply(hit.atMm);
            return " at frame (" + formatNumber(x[0], 4) + ", " + formatNumber(x[1], 4) + ", " +
                   formatNumber(x[2], 4) + ") mm";
        };
        const std::lock_guard<std::mutex> guard(lock);
        ++path.checked;
        ++order.checked;
        for (const auto& [how, hits] : legs) {
            if (hits.frame.isHit)
                path.failures.push_back(
                    stepName(step, s) + ": " + how + " it meets " + obstacleName(hits.frame.obstacle) + " (" +
                    formatNumber(hits.frame.overlapMm, 3) + " mm of overlap" + at(hits.frame) + ")");
            if (hits.pieces.isHit)
                order.failures.push_back(stepName(step, s) + ": " +
                                         (step.hasTwoLegs() ? how + " it crosses" : "its path crosses") +
                                         " piece " + std::to_string(hits.pieces.obstacle) +
                                         ", mounted before it (" + formatNumber(hits.pieces.overlapMm, 3) +
                                         " mm" + at(hits.pieces) + ")");
        }
    });
    std::sort(path.failures.begin(), path.failures.end());
    std::sort(order.failures.begin(), order.failures.end());
    report.checks.push_back(path);
    report.checks.push_back(order);
}

}  // namespace zomefab::verify::detail
