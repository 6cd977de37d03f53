// SPDX-License-Identifier: GPL-3.0-or-later
// Tenons (paper §6.1): candidate rays along the balls' blue holes, the collision and containment
// tests, the greedy choice, and the tenon solid's signed distance.
#include "zomefab/pieces/tenons.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/zome/zome_system.h"

namespace zomefab::pieces {

using namespace detail;

Vec3d ShellProbe::normalAt(const Vec3d& p) const {
    const double h = 0.5 * voxelMm;
    Vec3d g;
    for (int k = 0; k < 3; ++k) {
        Vec3d e{0, 0, 0};
        e[size_t(k)] = h;
        g[size_t(k)] = signedDistanceMm(add(p, e)) - signedDistanceMm(sub(p, e));
    }
    return normalized(g);
}

namespace {

constexpr double kPi = 3.14159265358979323846;
/// The lattice axes' blue holes: +x +y +z, then −x −y −z (zome_system.h numbering).
constexpr int kLatticeHoles[6] = {0, 1, 2, 15, 16, 17};

/// The holes a tenon may plug into: the six lattice ones first (the paper's), then the other 24 blue.
std::vector<int> tenonHoles(const TenonOptions& o) {
    std::vector<int> holes(std::begin(kLatticeHoles), std::end(kLatticeHoles));
    if (o.latticeHolesOnly) return holes;
    const auto [first, last] = zome::holeRange(zome::Color::Blue);
    for (int hole = first; hole < last; ++hole)
        if (std::find(holes.begin(), holes.end(), hole) == holes.end()) holes.push_back(hole);
    return holes;
}
/// How far the peg reaches into the prism so that the union has no seam at the shoulder.
constexpr double kPegOverlapMm = 0.5;

void requireRange(double value, double lo, double hi, const char* name, const char* unit) {
    if (!(value >= lo && value <= hi))
        throw Error(ErrorCode::Usage, std::string(name) + " must be in [" + formatNumber(lo) + ", " +
                                          formatNumber(hi) + "] " + unit + ", got " + formatNumber(value));
}

/// Refines the first crossing φ < 0 on the ray between t0 (outside) and t1 (inside).
double bisect(const ShellProbe& probe, const Vec3d& origin, const Vec3d& dir, double t0, double t1) {
    for (int i = 0; i < 24; ++i) {
        const double tm = 0.5 * (t0 + t1);
        if (probe.signedDistanceMm(madd(origin, tm, dir)) < 0)
            t1 = tm;
        else
            t0 = tm;
    }
    return 0.5 * (t0 + t1);
}

}  // namespace

void checkTenonOptions(const TenonOptions& o) {
    if (o.minPerPiece < 0 || o.minPerPiece > 62)
        throw Error(ErrorCode::Usage,
                    "the tenons wanted per piece must be in [0, 62], got " + std::to_string(o.minPerPiece));
    if (o.maxPerPiece < 0 || o.maxPerPiece > 62)
        throw Error(ErrorCode::Usage,
                    "the most tenons per piece must be in [0, 62], got " + std::to_string(o.maxPerPiece));
    if (o.maxPerPiece > 0 && o.maxPerPiece < o.minPerPiece)
        throw Error(ErrorCode::Usage, "the most tenons per piece (" + std::to_string(o.maxPerPiece) +
                                          ") is below the number wanted (" + std::to_string(o.minPerPiece) +
                                          ")");
    requireRange(o.clearanceMm, 0.0, 0.5, "the tenon clearance", "mm");
    requireRange(o.holeLongMm, 1.0, 20.0, "the hole's long side", "mm");
    requireRange(o.holeShortMm, 1.0, o.holeLongMm, "the hole's short side", "mm");
    if (pegShortMm(o) < 1.0)
        throw Error(ErrorCode::Usage,
                    "the peg (hole less twice the clearance) must be at least 1 mm thick, got " +
                        formatNumber(pegShortMm(o)) + " mm");
    requireRange(o.pegDepthMm, 1.0, 8.0, "the peg depth", "mm");
    requireRange(o.bodyWidthMm, pegLongMm(o), 20.0, "the tenon width", "mm");
    requireRange(o.maxLengthMm, 1.0, 200.0, "the longest tenon", "mm");
    requireRange(o.maxTiltDeg, 0.0, 60.0, "the largest tenon tilt", "degrees");
    requireRange(o.embedMm, 0.5, 10.0, "the tenon's depth in the wall", "mm");
    requireRange(o.frameClearanceMm, 0.0, 10.0, "the tenon's clearance to the frame", "mm");
}

double bodyRadiusMm(const TenonOptions& o) { return o.bodyWidthMm * std::sqrt(0.5); }

double tenonSignedDistanceMm(const Tenon& t, const TenonOptions& o, const Vec3d& p) {
    const Vec3d d = sub(p, t.ballCenterGridMm);
    const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
    const double a = dot(d, t.axisGrid), l = dot(d, t.longSideGrid), s = dot(d, shortSide);
    const double bodyMid = 0.5 * (t.shoulderMm + t.endMm), bodyHalf = 0.5 * (t.endMm - t.shoulderMm);
    const double body =
        boxDistance({a - bodyMid, l, s}, {bodyHalf, 0.5 * o.bodyWidthMm, 0.5 * o.bodyWidthMm});
    const double pegEnd = t.shoulderMm + kPegOverlapMm;
    const double pegMid = 0.5 * (t.pegTipMm + pegEnd), pegHalf = 0.5 * (pegEnd - t.pegTipMm);
    const double peg = boxDistance({a - pegMid, l, s}, {pegHalf, 0.5 * pegLongMm(o), 0.5 * pegShortMm(o)});
    return std::min(body, peg);
}

Box3d tenonBoundsMm(const Tenon& t, const TenonOptions& o) {
    Box3d box;
    const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
    const double half = 0.5 * o.bodyWidthMm;  // ≥ the peg's half sections (checkTenonOptions)
    for (double a : {t.pegTipMm, t.endMm})
        for (double l : {-half, half})
            for (double s : {-half, half})
                box.expand(madd(madd(t.pointAt(a), l, t.longSideGrid), s, shortSide));
    return box;
}

std::string tenonObstruction(const zome::Structure& frame, const Tenon& t, const TenonOptions& o) {
    // The prism as a capsule around its axis, in the frame's mm (the exact hole direction).
    const zome::Ball& ball = frame.ball(t.ball);
    const Vec3d a = madd(ball.positionMm, t.shoulderMm, t.axisFrame);
    const Vec3d b = madd(ball.positionMm, t.endMm, t.axisFrame);
    const double r = bodyRadiusMm(o) + o.frameClearanceMm;
    for (zome::StrutId id : frame.strutIds()) {
        const zome::Strut& s = frame.strut(id);
        const double limit = r + frame.scale().strutRadiusMm(s.color);
        if (zome::segmentSegmentDistanceSq(a, b, s.startMm, s.endMm) < limit * limit)
            return "strut " + std::to_string(id) + " (" + zome::partName(s.color, s.size) + ") in the way";
    }
    const double ballLimit = r + frame.scale().ballRadiusMm();
    for (zome::BallId id : frame.ballIds()) {
        if (id == t.ball) continue;
        if (zome::pointSegmentDistanceSq(frame.ball(id).positionMm, a, b) < ballLimit * ballLimit)
            return "ball " + std::to_string(id) + " in the way";
    }
    return {};
}

std::vector<TenonCandidate> findTenonCandidates(const zome::Structure& frame,
                                                const Transform4d& frameToGridMm, const ShellProbe& probe,
                                                const TenonOptions& o) {
    std::vector<TenonCandidate> out;
    const double voxel = probe.voxelMm;
    const double step = 0.5 * voxel;
    const double shoulder = frame.scale().ballRadiusMm();
    // Rays look twice as far as a tenon may reach, so "too far" is told apart from "no wall".
    const double reach = shoulder + 2.0 * o.maxLengthMm;
    const double halfWidth = 0.5 * o.bodyWidthMm;
    const std::vector<int> holes = tenonHoles(o);
    for (zome::BallId id : frame.ballIds()) {
        const zome::Ball& ball = frame.ball(id);
        const Vec3d center = frameToGridMm.apply(ball.positionMm);
        for (int hole : holes) {
            TenonCandidate c;
            Tenon& t = c.tenon;
            t.ball = id;
            t.hole = hole;
            t.axisFrame = zome::holeDirection(hole);
            t.axisGrid = normalized(applyLinear(frameToGridMm, t.axisFrame));
            t.longSideGrid = normalized(applyLinear(frameToGridMm, zome::holeSectionAxis(hole)));
            t.ballCenterGridMm = center;
            t.shoulderMm = shoulder;
            t.pegTipMm = shoulder - o.pegDepthMm;
            const Vec3d& u = t.axisGrid;
            auto reject = [&](const char* why) {
                c.rejection = why;
                out.push_back(c);
            };

            // March from the ball's face to the first point inside the shell: the inner surface.
            if (probe.signedDistanceMm(t.pointAt(shoulder)) < 0) {
                c.piece = probe.pieceAt(t.pointAt(shoulder));
                reject("the ball's face is inside the wall");
                continue;
            }
            double hit = -1;
            for (double s = shoulder + step; s <= reach; s += step) {
                if (probe.signedDistanceMm(t.pointAt(s)) < 0) {
                    hit = bisect(probe, center, u, s - step, s);
                    break;
                }
            }
            if (hit < 0) {
                reject("no wall within reach");
                continue;
            }
            t.baseMm = hit;
            c.piece = probe.pieceAt(t.pointAt(hit + 0.5 * voxel));
            if (c.piece < 0) c.piece = probe.pieceAt(t.pointAt(hit + voxel));
            t.piece = c.piece < 0 ? 0 : uint32_t(c.piece);
            if (c.piece < 0) {
                reject("no piece at the wall");
                continue;
            }
            if (!frame.isHoleFree(id, hole)) {
                reject("hole holds a strut");
                continue;
            }
            if (t.lengthMm() > o.maxLengthMm) {
                reject("too far from the wall");
                continue;
            }
            // The inner surface's normal (out of the wall, into the cavity) by central differences.
            const Vec3d p = t.pointAt(hit);
            const Vec3d n = probe.normalAt(p);
            const double cosTilt = std::clamp(-dot(u, n), -1.0, 1.0);
            t.tiltDeg = std::acos(cosTilt) * 180.0 / kPi;
            if (!(t.tiltDeg <= o.maxTiltDeg)) {
                reject("surface too oblique");
                continue;
            }
            // Deep enough that the whole end face is in the wall on a tilted surface.
            t.endMm = hit + o.embedMm + bodyRadiusMm(o) * std::tan(t.tiltDeg * kPi / 180.0);

            const std::string obstruction = tenonObstruction(frame, t, o);
            if (!obstruction.empty()) {
                reject(obstruction.rfind("strut", 0) == 0 ? "strut in the way" : "ball in the way");
                continue;
            }
            // Containment: wherever the prism is inside the shell it is inside this piece, and its
            // end face lies in this piece's wall with at least half a voxel of wall beyond.
            const Vec3d shortSide = cross(u, t.longSideGrid);
            bool crossesOther = false, isEndOutside = false;
            const int lateral = 4;  // 5 × 5 samples across the section
            for (int i = 0; i <= lateral && !crossesOther; ++i) {
                for (int j = 0; j <= lateral && !crossesOther; ++j) {
                    const double l = -halfWidth + 2 * halfWidth * i / lateral;
                    const double s = -halfWidth + 2 * halfWidth * j / lateral;
                    const Vec3d offset = add(scale(t.longSideGrid, l), scale(shortSide, s));
                    for (double a = shoulder; a <= t.endMm + 1e-9; a += step) {
                        const Vec3d q = add(t.pointAt(a), offset);
                        if (probe.signedDistanceMm(q) < 0 && probe.pieceAt(q) != c.piece) {
                            crossesOther = true;
                            break;
                        }
                    }
                    const Vec3d e = add(t.pointAt(t.endMm), offset);
                    if (!(probe.signedDistanceMm(e) < -0.5 * voxel) || probe.pieceAt(e) != c.piece)
                        isEndOutside = true;
                }
            }
            if (crossesOther) {
                reject("crosses another piece");
                continue;
            }
            if (isEndOutside) {
                reject("too close to the piece's edge");
                continue;
            }
            c.score = cosTilt - 0.5 * t.lengthMm() / o.maxLengthMm;
            out.push_back(c);
        }
    }
    return out;
}

TenonPlan chooseTenons(const std::vector<TenonCandidate>& candidates, size_t pieceCount,
                       const TenonOptions& o) {
    TenonPlan plan;
    plan.perPiece.assign(pieceCount, {});
    plan.shortfall.assign(pieceCount, {});
    std::vector<std::string> rejection(candidates.size());
    std::vector<std::vector<size_t>> byPiece(pieceCount);
    for (size_t i = 0; i < candidates.size(); ++i) {
        rejection[i] = candidates[i].rejection;
        const int64_t p = candidates[i].piece;
        if (p >= 0 && size_t(p) < pieceCount && rejection[i].empty()) byPiece[size_t(p)].push_back(i);
    }
    // Best first; ties by (ball, hole) through the candidates' order.
    for (auto& list : byPiece)
        std::stable_sort(list.begin(), list.end(),
                         [&](size_t x, size_t y) { return candidates[x].score > candidates[y].score; });

    std::vector<const Tenon*> chosen;
    const double minGap = 2 * bodyRadiusMm(o) + o.frameClearanceMm;
    auto conflicts = [&](const Tenon& t) {
        for (const Tenon* c : chosen) {
            const double d2 = zome::segmentSegmentDistanceSq(t.pointAt(t.shoulderMm), t.pointAt(t.endMm),
                                                             c->pointAt(c->shoulderMm), c->pointAt(c->endMm));
            if (d2 < minGap * minGap) return true;
        }
        return false;
    };
    std::vector<uint8_t> isTaken(candidates.size(), 0);
    // Round-robin: every piece gets its k-th tenon before any gets its (k+1)-th. After the first,
    // a piece prefers tenons parallel to it (one insertion direction, docs/pieces.md).
    for (int round = 0; round < o.maxPerPiece; ++round) {
        for (size_t p = 0; p < pieceCount; ++p) {
            if (plan.perPiece[p].size() != size_t(round)) continue;
            const int firstHole = round == 0 ? -1 : plan.perPiece[p].front().hole;
            for (int pass = 0; pass < 2; ++pass) {
                bool isDone = false;
                for (size_t i : byPiece[p]) {
                    if (isTaken[i] || !rejection[i].empty()) continue;
                    const bool isParallel = candidates[i].tenon.hole == firstHole;
                    if (firstHole >= 0 && pass == 0 && !isParallel) continue;
                    if (conflicts(candidates[i].tenon)) {
                        rejection[i] = "another tenon in the way";
                        continue;
                    }
                    isTaken[i] = 1;
                    plan.perPiece[p].push_back(candidates[i].tenon);
                    chosen.push_back(&candidates[i].tenon);
                    isDone = true;
                    break;
                }
                if (isDone || firstHole < 0) break;
            }
        }
    }
    for (size_t p = 0; p < pieceCount; ++p) {
        if (plan.perPiece[p].size() >= size_t(o.minPerPiece)) continue;
        auto& reasons = plan.shortfall[p];
        for (size_t i = 0; i < candidates.size(); ++i)
            if (candidates[i].piece == int64_t(p) && !rejection[i].empty()) ++reasons[rejection[i]];
        if (reasons.empty()) reasons["no blue hole of a ball points at this piece"] = 1;
    }
    return plan;
}

}  // namespace zomefab::pieces
