// SPDX-License-Identifier: GPL-3.0-or-later
// Tenons (paper §6.1): candidate rays along the balls' holes, the collision and containment
// tests, the choice along each piece's direction, and the tenon solid's signed distance.
#include "zomefab/pieces/tenons.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/zome/holes.h"
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

/// The prism stops this short of the ball's face (mm): the voxel mesher rounds the concave edge
/// where a prism would meet a peg into a fillet of up to half a voxel, which would sit in the hole's
/// mouth; the exact peg mesh spans the gap instead.
constexpr double kPrismGapMm = 0.3;
/// Wall left between a stem's end and the outer surface, mm: two perimeters of a 0.4 mm nozzle.
constexpr double kOuterSkinMm = 1.0;
/// Least wall left over any point of a cut stem's end face (mm; kOuterSkinMm at the axis on a flat
/// wall, less where the outer surface curves away from the plane).
constexpr double kCutSkinMm = 0.3;
/// How far the peg mesh reaches back into the prism (mm), so the two overlap.
constexpr double kPegRootMm = 1.5;
/// The chamfer around the peg's tip (mm, 45°): it finds the hole before the peg's full section does.
constexpr double kPegChamferMm = 0.4;

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

/// The tenon of @p ball along @p hole before the shell is asked: axes, ball centre, shoulder, tip.
Tenon tenonAlong(const zome::Structure& frame, zome::BallId id, int hole, const Transform4d& frameToGridMm,
                 const TenonOptions& o) {
    Tenon t;
    t.ball = id;
    t.hole = hole;
    t.axisFrame = zome::holeDirection(hole);
    t.axisGrid = normalized(applyLinear(frameToGridMm, t.axisFrame));
    t.longSideGrid = normalized(applyLinear(frameToGridMm, zome::holeSectionAxis(hole)));
    t.ballCenterGridMm = frameToGridMm.apply(frame.ball(id).positionMm);
    t.shoulderMm = frame.scale().ballRadiusMm() * zome::holeFaceRatio(zome::holeColor(hole));
    t.pegTipMm = t.shoulderMm - o.pegDepthMm;
    return t;
}

/// The crossing of the shell's surface on the stem's line at (@p fl, @p fs) between @p outMm
/// (φ ≥ 0) and @p inMm (φ < 0), mm along the axis (bisection to 10⁻⁷ of the interval).
double bisectAlong(const Tenon& t, const ShellProbe& probe, const TenonOptions& o, double fl, double fs,
                   double outMm, double inMm) {
    for (int i = 0; i < 24; ++i) {
        const double mid = 0.5 * (outMm + inMm);
        (probe.signedDistanceMm(stemPointMm(t, o, mid, fl, fs)) < 0 ? inMm : outMm) = mid;
    }
    return 0.5 * (outMm + inMm);
}

/// Where the line at (@p fl, @p fs) first enters the wall, mm along the axis; −1 when it does not
/// before @p untilMm.
double entryAlongMm(const Tenon& t, const ShellProbe& probe, const TenonOptions& o, double fl, double fs,
                    double untilMm) {
    const double step = 0.5 * probe.voxelMm;
    for (double a = t.shoulderMm; a <= untilMm; a += step)
        if (probe.signedDistanceMm(stemPointMm(t, o, a, fl, fs)) < 0)
            return a == t.shoulderMm ? a : bisectAlong(t, probe, o, fl, fs, a - step, a);
    return -1;
}

/// Whether the line at (@p fl, @p fs) of cut stem @p t, which enters the wall at @p entryMm (−1: not
/// within reach), shows through: it leaves the wall before the cut (through the outer surface), or
/// its cut lies within kCutSkinMm of the outer surface. A line cut before the wall ends in the
/// hollow, unseen; one that runs into another piece's wall is containment's "crosses another piece".
bool showsThrough(const Tenon& t, int64_t piece, const ShellProbe& probe, const TenonOptions& o, double fl,
                  double fs, double entryMm) {
    const double step = 0.5 * probe.voxelMm;
    const double cutMm = t.cutAlongAtMm(fl, fs);
    if (entryMm < 0 || entryMm >= cutMm) return false;
    for (double a = entryMm + 0.25 * step; a < cutMm; a += step) {
        const Vec3d q = stemPointMm(t, o, a, fl, fs);
        if (probe.signedDistanceMm(q) >= 0) return true;
        if (probe.pieceAt(q) != piece) return false;
    }
    const Vec3d e = stemPointMm(t, o, cutMm, fl, fs);
    const double phi = probe.signedDistanceMm(e);
    if (!(phi < 0)) return true;
    if (probe.pieceAt(e) != piece) return false;
    // The nearest surface is the outer one where the material's outward normal runs with the axis
    // (the inner one faces the ball): there the cut keeps kCutSkinMm of wall.
    return phi > -kCutSkinMm && dot(probe.normalAt(e), t.axisGrid) > 0;
}

/// For a stem a thin wall cannot bury (tenonCandidate): each of its kCutSide × kCutSide lines runs
/// into the wall and is cut kOuterSkinMm (across the wall) before it leaves it through the outer
/// surface, so the cut follows the outer surface however it curves, and the stem bonds across the
/// wall's whole thickness. False when a line reaches no wall (a piece's edge, an opening), the
/// centre line or a third of the lines reach it too shallowly to bond (half a voxel), a line leaves the wall
/// more than 70° off the outer surface's normal (the cut would be a long sliver), or a line between them
/// would show through (showsThrough, at twice the density).
bool clipThroughWall(Tenon& t, int64_t piece, double hit, const ShellProbe& probe, const TenonOptions& o) {
    const double step = 0.5 * probe.voxelMm;
    const double reach = hit + 4.0 * probe.wallMm + 2.0 * probe.voxelMm + 2.0 * stemHalfWidthMm(o, hit);
    const double minCos = std::cos(70.0 * kPi / 180.0);
    int bonded = 0;
    for (int i = 0; i < kCutSide; ++i)
        for (int j = 0; j < kCutSide; ++j) {
            const double fl = cutLineFraction(i), fs = cutLineFraction(j);
            double& cut = t.cutAlongMm[size_t(i * kCutSide + j)];
            const double entry = entryAlongMm(t, probe, o, fl, fs, reach);
            if (entry < 0) return false;  // past a piece's edge or an opening
            double out = -1;
            for (double a = entry + step; a <= reach && out < 0; a += step)
                if (probe.signedDistanceMm(stemPointMm(t, o, a, fl, fs)) >= 0)
                    out = bisectAlong(t, probe, o, fl, fs, a, a - step);
            if (out < 0) return false;
            const double cosOut = dot(probe.normalAt(stemPointMm(t, o, out, fl, fs)), t.axisGrid);
            if (!(cosOut > minCos)) return false;
            cut = out - kOuterSkinMm / cosOut;
            bonded += cut - entry >= step ? 1 : 0;
        }
    const double centre = t.cutAlongMm[kCutLines / 2];
    if (!(centre - hit >= step) || 3 * bonded < 2 * kCutLines) return false;
    t.isCut = true;
    t.endMm = *std::max_element(t.cutAlongMm.begin(), t.cutAlongMm.end()) + 0.5;
    // Between the lines the cut is bilinear: on a wall curved more than the lines can follow, a
    // point between them could show through.
    for (int i = 0; i <= 2 * (kCutSide - 1); ++i)
        for (int j = 0; j <= 2 * (kCutSide - 1); ++j) {
            const double fl = -1.0 + double(i) / (kCutSide - 1), fs = -1.0 + double(j) / (kCutSide - 1);
            const double entry = entryAlongMm(t, probe, o, fl, fs, t.cutAlongAtMm(fl, fs));
            if (showsThrough(t, piece, probe, o, fl, fs, entry)) {
                t.isCut = false;
                return false;
            }
        }
    return true;
}

/// The prism stays in its piece: wherever it is inside the shell it is this piece's, and its end
/// face (of a stem not cut) lies in this piece's wall with at least half a voxel of wall beyond.
/// The rejection, or empty.
std::string containment(const Tenon& t, int64_t piece, const ShellProbe& probe, const TenonOptions& o) {
    const double step = 0.5 * probe.voxelMm;
    int endInWall = 0, endSamples = 0;
    bool isCentreIn = false;
    for (int i = 0; i < kCutSide; ++i)
        for (int j = 0; j < kCutSide; ++j) {
            const double fl = cutLineFraction(i), fs = cutLineFraction(j);
            auto at = [&](double a) { return stemPointMm(t, o, a, fl, fs); };
            for (double a = t.shoulderMm; a <= t.endMm + 1e-9; a += step) {
                const Vec3d q = at(a);
                if (beyondCutMm(t, o, q) > 0) break;
                if (probe.signedDistanceMm(q) < 0 && probe.pieceAt(q) != piece)
                    return "crosses another piece";
            }
            // A cut stem's lines were followed to the cut by clipThroughWall: none shows
            // through, the centre and two thirds of them bond.
            if (t.isClipped()) continue;
            const Vec3d e = at(t.endMm);
            const bool isIn = probe.signedDistanceMm(e) < -0.5 * probe.voxelMm && probe.pieceAt(e) == piece;
            endInWall += isIn ? 1 : 0;
            ++endSamples;
            if (i == kCutSide / 2 && j == kCutSide / 2) isCentreIn = isIn;
        }
    if (t.isClipped()) return "";
    // The end face bonds to the wall: its centre and most of it (a tilted thin wall may leave a
    // corner in the air, never a corner in another piece).
    return isCentreIn && 3 * endInWall >= 2 * endSamples ? "" : "too close to the piece's edge";
}

}  // namespace

TenonCandidate tenonCandidate(const zome::Structure& frame, zome::BallId id, int hole,
                              const Transform4d& frameToGridMm, const ShellProbe& probe,
                              const TenonOptions& o) {
    TenonCandidate c;
    c.tenon = tenonAlong(frame, id, hole, frameToGridMm, o);
    Tenon& t = c.tenon;
    const double step = 0.5 * probe.voxelMm;
    // March from the ball's face to the first point inside the shell: the inner surface. Rays look
    // twice as far as a tenon may reach, so "too far" is told apart from "no wall".
    if (probe.signedDistanceMm(t.pointAt(t.shoulderMm)) < 0) {
        c.piece = probe.pieceAt(t.pointAt(t.shoulderMm));
        c.rejection = "the ball's face is inside the wall";
        return c;
    }
    double hit = -1;
    for (double s = t.shoulderMm + step; s <= t.shoulderMm + 2.0 * o.maxLengthMm; s += step)
        if (probe.signedDistanceMm(t.pointAt(s)) < 0) {
            hit = bisect(probe, t.ballCenterGridMm, t.axisGrid, s - step, s);
            break;
        }
    if (hit < 0) return c.rejection = "no wall within reach", c;
    t.baseMm = hit;
    c.piece = probe.pieceAt(t.pointAt(hit + 0.5 * probe.voxelMm));
    if (c.piece < 0) c.piece = probe.pieceAt(t.pointAt(hit + probe.voxelMm));
    t.piece = c.piece < 0 ? 0 : uint32_t(c.piece);
    if (c.piece < 0) return c.rejection = "no piece at the wall", c;
    if (!frame.isHoleFree(id, hole)) return c.rejection = "hole holds a strut", c;
    if (t.lengthMm() > o.maxLengthMm) return c.rejection = "too far from the wall", c;
    // The inner surface's normal (out of the wall, into the cavity) by central differences.
    const Vec3d n = probe.normalAt(t.pointAt(hit));
    const double cosTilt = std::clamp(-dot(t.axisGrid, n), -1.0, 1.0);
    t.tiltDeg = std::acos(cosTilt) * 180.0 / kPi;
    if (!(t.tiltDeg <= o.maxTiltDeg)) return c.rejection = "surface too oblique", c;
    // Deep enough that the whole end face is in the wall on a tilted surface, but never through a
    // thin wall: on a locally flat wall the section's nearest corner leaves the outer surface at
    // hit − r·tan(tilt) + wall/cos(tilt); keep kOuterSkinMm of wall beyond it (printed solid).
    const double tanTilt = std::tan(t.tiltDeg * kPi / 180.0);
    const double r = std::sqrt(2.0) * stemHalfWidthMm(o, hit - t.shoulderMm);
    const double deepest =
        hit - r * tanTilt + probe.wallMm / std::cos(t.tiltDeg * kPi / 180.0) - kOuterSkinMm;
    t.endMm = hit + o.embedMm + r * tanTilt;
    // A wall too thin to bury the square end: the stem goes on through it, cut a skin inside the
    // outer surface (clipThroughWall), so it bonds across the wall's whole thickness.
    if (deepest < t.endMm && !clipThroughWall(t, c.piece, hit, probe, o)) {
        t.endMm = deepest;  // buried as deep as the wall allows, the end face partly in it
        if (t.endMm < hit + 0.5 * probe.voxelMm) return c.rejection = "surface too oblique for the wall", c;
    }
    const std::string obstruction = tenonObstruction(frame, t, o);
    if (!obstruction.empty())
        return c.rejection = obstruction.rfind("strut", 0) == 0 ? "strut in the way" : "ball in the way", c;
    c.rejection = containment(t, c.piece, probe, o);
    if (c.rejection.empty()) c.score = cosTilt - 0.5 * t.lengthMm() / o.maxLengthMm;
    return c;
}

const char* tenonHolesName(TenonHoles holes) {
    switch (holes) {
        case TenonHoles::Lattice:
            return "lattice";
        case TenonHoles::Blue:
            return "blue";
        case TenonHoles::All:
            return "all";
    }
    return "all";
}

std::optional<TenonHoles> tenonHolesFromName(std::string_view name) {
    for (TenonHoles h : {TenonHoles::Lattice, TenonHoles::Blue, TenonHoles::All})
        if (name == tenonHolesName(h)) return h;
    return std::nullopt;
}

std::vector<int> tenonHoleSet(TenonHoles holes) {
    if (holes == TenonHoles::Lattice) return {0, 1, 2, 15, 16, 17};  // ±x ±y ±z (zome_system.h numbering)
    std::vector<int> out;
    const int last = holes == TenonHoles::Blue ? zome::holeRange(zome::Color::Blue).second : zome::kHoleCount;
    for (int h = 0; h < last; ++h) out.push_back(h);
    return out;
}

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
    requireRange(o.pegDepthMm, 1.0, 8.0, "the peg depth", "mm");
    requireRange(o.bodyWidthMm, pegLongMm(o), 20.0, "the tenon width", "mm");
    requireRange(o.taperDeg, 0.0, 15.0, "the tenon taper", "degrees");
    requireRange(o.maxLengthMm, 1.0, 200.0, "the longest tenon", "mm");
    requireRange(o.maxTiltDeg, 0.0, 60.0, "the largest tenon tilt", "degrees");
    requireRange(o.embedMm, 0.5, 10.0, "the tenon's depth in the wall", "mm");
    requireRange(o.frameClearanceMm, 0.0, 10.0, "the tenon's clearance to the frame", "mm");
}

double pegLongMm(const TenonOptions& o) {
    const auto section = zome::holeSectionMm(zome::Color::Blue);
    return section[1][0] - section[0][0] - 2 * o.clearanceMm;
}

double pegShortMm(const TenonOptions& o) {
    const auto section = zome::holeSectionMm(zome::Color::Blue);
    return section[2][1] - section[1][1] - 2 * o.clearanceMm;
}

double bodyRadiusMm(const TenonOptions& o) { return o.bodyWidthMm * std::sqrt(0.5); }

double stemHalfWidthMm(const TenonOptions& o, double fromFaceMm) {
    return 0.5 * o.bodyWidthMm + std::max(0.0, fromFaceMm) * std::tan(o.taperDeg * kPi / 180.0);
}

std::vector<std::array<double, 2>> pegSectionMm(int hole, const TenonOptions& o) {
    return zome::insetPolygon(zome::holeSectionMm(zome::holeColor(hole)), o.clearanceMm);
}

double tenonSignedDistanceMm(const Tenon& t, const TenonOptions& o, const Vec3d& p) {
    const Vec3d d = sub(p, t.ballCenterGridMm);
    const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
    const double a = dot(d, t.axisGrid), l = dot(d, t.longSideGrid), s = dot(d, shortSide);
    const double start = t.shoulderMm + kPrismGapMm;
    const double bodyMid = 0.5 * (start + t.endMm), bodyHalf = 0.5 * (t.endMm - start);
    // The frustum by the box of its section at p's depth along the axis: the zero set is exact,
    // distances off it are within 1/cos(taper) of the true ones.
    const double half = stemHalfWidthMm(o, std::clamp(a, start, t.endMm) - t.shoulderMm);
    const double prism = boxDistance({a - bodyMid, l, s}, {bodyHalf, half, half});
    if (!t.isClipped()) return prism;
    // beyondCutMm runs along the axis; across a cut that slants over the section it overstates the
    // distance by the slope's √(1 + |∇h|²) (h: the cut's height over the section, mm per mm).
    const double fl = l / half, fs = s / half, dh = 0.05;
    const double slopeL = (t.cutAlongAtMm(fl + dh, fs) - t.cutAlongAtMm(fl - dh, fs)) / (2 * dh * half);
    const double slopeS = (t.cutAlongAtMm(fl, fs + dh) - t.cutAlongAtMm(fl, fs - dh)) / (2 * dh * half);
    const double beyond = (a - t.cutAlongAtMm(fl, fs)) / std::sqrt(1.0 + slopeL * slopeL + slopeS * slopeS);
    return std::max(prism, beyond);
}

Vec3d stemPointMm(const Tenon& t, const TenonOptions& o, double alongMm, double fl, double fs) {
    const double half = stemHalfWidthMm(o, alongMm - t.shoulderMm);
    const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
    return add(t.pointAt(alongMm), add(scale(t.longSideGrid, fl * half), scale(shortSide, fs * half)));
}

double beyondCutMm(const Tenon& t, const TenonOptions& o, const Vec3d& p) {
    if (!t.isClipped()) return -1e30;
    const Vec3d d = sub(p, t.ballCenterGridMm);
    const double a = dot(d, t.axisGrid);
    const double half = stemHalfWidthMm(o, a - t.shoulderMm);
    const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
    return a - t.cutAlongAtMm(dot(d, t.longSideGrid) / half, dot(d, shortSide) / half);
}

double Tenon::cutAlongAtMm(double fl, double fs) const {
    const double top = kCutSide - 1;
    const double u = std::clamp(0.5 * (fl + 1.0) * top, 0.0, top),
                 v = std::clamp(0.5 * (fs + 1.0) * top, 0.0, top);
    const int i = std::min(int(u), kCutSide - 2), j = std::min(int(v), kCutSide - 2);
    const double du = u - i, dv = v - j;
    auto h = [&](int a, int b) { return cutAlongMm[size_t(a * kCutSide + b)]; };
    return (1 - du) * ((1 - dv) * h(i, j) + dv * h(i, j + 1)) +
           du * ((1 - dv) * h(i + 1, j) + dv * h(i + 1, j + 1));
}

TriMesh pegMesh(const Tenon& t, const TenonOptions& o) {
    const std::vector<std::array<double, 2>> side = pegSectionMm(t.hole, o);
    const std::vector<std::array<double, 2>> tip = zome::insetPolygon(side, kPegChamferMm);
    const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
    TriMesh m;
    auto ring = [&](const std::vector<std::array<double, 2>>& poly, double along) {
        for (const auto& q : poly) {
            const Vec3d x = madd(madd(t.pointAt(along), q[0], t.longSideGrid), q[1], shortSide);
            m.positions.push_back({float(x[0]), float(x[1]), float(x[2])});
        }
    };
    // Rings from the root (in the prism, away from the ball) to the tip (in the hole).
    ring(side, t.shoulderMm + kPegRootMm);
    ring(side, t.pegTipMm + kPegChamferMm);
    ring(tip, t.pegTipMm);
    const uint32_t n = uint32_t(side.size());
    // Counter-clockwise seen from +axis: the root cap faces +axis, the tip cap −axis.
    for (uint32_t k = 1; k + 1 < n; ++k) m.triangles.push_back({0, k, k + 1});
    for (uint32_t k = 1; k + 1 < n; ++k) m.triangles.push_back({2 * n, 2 * n + k + 1, 2 * n + k});
    for (uint32_t r = 0; r < 2; ++r)
        for (uint32_t k = 0; k < n; ++k) {
            const uint32_t k1 = (k + 1) % n;
            const uint32_t top = r * n, bottom = (r + 1) * n;  // top: nearer the root
            m.triangles.push_back({bottom + k, bottom + k1, top + k1});
            m.triangles.push_back({bottom + k, top + k1, top + k});
        }
    return m;
}

std::vector<Vec3d> tenonHullMm(const Tenon& t, const TenonOptions& o) {
    const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
    std::vector<Vec3d> out;
    auto corners = [&](double along, double half) {
        for (double l : {-half, half})
            for (double s : {-half, half})
                out.push_back(madd(madd(t.pointAt(along), l, t.longSideGrid), s, shortSide));
    };
    // The stem's two ends (it tapers toward the ball), then the peg's section at its tip.
    const double start = t.shoulderMm + kPrismGapMm;
    corners(start, stemHalfWidthMm(o, start - t.shoulderMm));
    corners(t.endMm, stemHalfWidthMm(o, t.endMm - t.shoulderMm));
    if (t.isClipped())  // each side edge ends on the cut
        for (size_t k = 4; k < 8; ++k) {
            const double fl = k < 6 ? -1.0 : 1.0, fs = k % 2 == 0 ? -1.0 : 1.0;
            out[k] = stemPointMm(t, o, t.cutAlongAtMm(fl, fs), fl, fs);
        }
    for (const auto& q : pegSectionMm(t.hole, o))
        out.push_back(madd(madd(t.pointAt(t.pegTipMm), q[0], t.longSideGrid), q[1], shortSide));
    return out;
}

Box3d tenonBoundsMm(const Tenon& t, const TenonOptions& o) {
    Box3d box;
    for (const Vec3d& p : tenonHullMm(t, o)) box.expand(p);
    if (t.isClipped())  // a cut that bulges between the corners stays short of the end face
        for (const double fl : {-1.0, 1.0})
            for (const double fs : {-1.0, 1.0}) box.expand(stemPointMm(t, o, t.endMm, fl, fs));
    return box;
}

std::string tenonObstruction(const zome::Structure& frame, const Tenon& t, const TenonOptions& o) {
    // The tapered stem, in the frame's mm (the exact hole direction), as a chain of short capsules,
    // each with the radius of its wider end. Only struts and balls near the whole stem (taken at
    // its widest) can touch one of them: those are found once.
    const zome::Ball& ball = frame.ball(t.ball);
    const double stepMm = 2.0, lengthMm = t.endMm - t.shoulderMm;
    auto stemRadius = [&](double fromFaceMm) {
        return std::sqrt(2.0) * stemHalfWidthMm(o, fromFaceMm) + o.frameClearanceMm;
    };
    const Vec3d start = madd(ball.positionMm, t.shoulderMm, t.axisFrame);
    const Vec3d end = madd(ball.positionMm, t.endMm, t.axisFrame);
    const double widest = stemRadius(lengthMm), ballR = frame.scale().ballRadiusMm();
    std::vector<zome::StrutId> nearStruts;
    for (zome::StrutId id : frame.strutIds()) {
        const zome::Strut& s = frame.strut(id);
        const double limit = widest + frame.scale().strutRadiusMm(s.color);
        if (zome::segmentSegmentDistanceSq(start, end, s.startMm, s.endMm) < limit * limit)
            nearStruts.push_back(id);
    }
    std::vector<zome::BallId> nearBalls;
    for (zome::BallId id : frame.ballIds())
        if (id != t.ball && zome::pointSegmentDistanceSq(frame.ball(id).positionMm, start, end) <
                                (widest + ballR) * (widest + ballR))
            nearBalls.push_back(id);
    for (double from = 0; from < lengthMm; from += stepMm) {
        const double to = std::min(lengthMm, from + stepMm);
        const Vec3d a = madd(ball.positionMm, t.shoulderMm + from, t.axisFrame);
        const Vec3d b = madd(ball.positionMm, t.shoulderMm + to, t.axisFrame);
        const double r = stemRadius(to);
        for (zome::StrutId id : nearStruts) {
            const zome::Strut& s = frame.strut(id);
            const double limit = r + frame.scale().strutRadiusMm(s.color);
            if (zome::segmentSegmentDistanceSq(a, b, s.startMm, s.endMm) < limit * limit)
                return "strut " + std::to_string(id) + " (" + zome::partName(s.color, s.size) +
                       ") in the way";
        }
        for (zome::BallId id : nearBalls)
            if (zome::pointSegmentDistanceSq(frame.ball(id).positionMm, a, b) < (r + ballR) * (r + ballR))
                return "ball " + std::to_string(id) + " in the way";
    }
    return {};
}

std::vector<TenonCandidate> findTenonCandidates(const zome::Structure& frame,
                                                const Transform4d& frameToGridMm, const ShellProbe& probe,
                                                const TenonOptions& o) {
    std::vector<TenonCandidate> out;
    const std::vector<int> holes = tenonHoleSet(o.holes);
    for (zome::BallId id : frame.ballIds())
        for (int hole : holes) out.push_back(tenonCandidate(frame, id, hole, frameToGridMm, probe, o));
    return out;
}

bool stemsMeet(const Tenon& a, const Tenon& b, const TenonOptions& o) {
    std::vector<Vec3d> ha = tenonHullMm(a, o), hb = tenonHullMm(b, o);
    ha.resize(8), hb.resize(8);
    const Vec3d ea[3] = {a.axisGrid, a.longSideGrid, cross(a.axisGrid, a.longSideGrid)};
    const Vec3d eb[3] = {b.axisGrid, b.longSideGrid, cross(b.axisGrid, b.longSideGrid)};
    std::vector<Vec3d> axes(ea, ea + 3);
    axes.insert(axes.end(), eb, eb + 3);
    for (const Vec3d& x : ea)
        for (const Vec3d& y : eb)
            if (const Vec3d n = cross(x, y); norm(n) > 1e-6) axes.push_back(normalized(n));
    for (const Vec3d& n : axes) {
        double a0 = 1e300, a1 = -1e300, b0 = 1e300, b1 = -1e300;
        for (const Vec3d& p : ha) a0 = std::min(a0, dot(p, n)), a1 = std::max(a1, dot(p, n));
        for (const Vec3d& p : hb) b0 = std::min(b0, dot(p, n)), b1 = std::max(b1, dot(p, n));
        if (a1 + o.frameClearanceMm < b0 || b1 + o.frameClearanceMm < a0) return false;
    }
    return true;
}

TenonPlan chooseTenons(const std::vector<TenonCandidate>& candidates, const std::vector<int>& holeOfPiece,
                       const TenonOptions& o) {
    const size_t pieceCount = holeOfPiece.size();
    TenonPlan plan;
    plan.perPiece.assign(pieceCount, {});
    plan.shortfall.assign(pieceCount, {});
    std::vector<std::string> rejection(candidates.size());
    std::vector<std::vector<size_t>> byPiece(pieceCount);
    for (size_t i = 0; i < candidates.size(); ++i) {
        rejection[i] = candidates[i].rejection;
        const int64_t p = candidates[i].piece;
        if (p < 0 || size_t(p) >= pieceCount || candidates[i].tenon.hole != holeOfPiece[size_t(p)]) continue;
        if (rejection[i].empty()) byPiece[size_t(p)].push_back(i);
    }
    std::vector<const TenonCandidate*> chosen;
    auto endRadius = [&](const Tenon& t) {
        return std::sqrt(2.0) * stemHalfWidthMm(o, t.endMm - t.shoulderMm);
    };
    auto conflicts = [&](const TenonCandidate& x) {
        const Tenon& t = x.tenon;
        for (const TenonCandidate* y : chosen) {
            const Tenon& c = y->tenon;
            const double minGap = endRadius(t) + endRadius(c) + o.frameClearanceMm;
            if (zome::segmentSegmentDistanceSq(t.pointAt(t.shoulderMm), t.pointAt(t.endMm),
                                               c.pointAt(c.shoulderMm),
                                               c.pointAt(c.endMm)) < minGap * minGap &&
                // A stave's stem and another out of one ball's holes part from its face: their
                // round bounds overlap where the stems do not (square to each other, 12.5 mm apart
                // at the face), and a stave has few balls behind its wall.
                (!(x.isStave || y->isStave) || c.ball != t.ball || c.hole == t.hole || stemsMeet(t, c, o)))
                return true;
        }
        return false;
    };
    // How much a candidate spreads the piece's tenons: its distance to the balls already chosen,
    // and for a third, to their line (three not on one line hold the piece against turning).
    auto spread = [&](const std::vector<Tenon>& mine, const Tenon& t) {
        if (mine.empty()) return 0.0;
        double nearest = 1e300;
        for (const Tenon& m : mine)
            nearest = std::min(nearest, norm(sub(t.ballCenterGridMm, m.ballCenterGridMm)));
        double offLine = 0.0;
        if (mine.size() >= 2) {
            const Vec3d axis = normalized(sub(mine[1].ballCenterGridMm, mine[0].ballCenterGridMm));
            offLine = norm(cross(axis, sub(t.ballCenterGridMm, mine[0].ballCenterGridMm)));
        }
        return std::min(1.0, nearest / 100.0) + std::min(1.0, offLine / 100.0);
    };
    std::vector<uint8_t> isTaken(candidates.size(), 0);
    // Round-robin: every piece gets its k-th tenon before any gets its (k+1)-th; in each round the
    // pieces with the fewest candidates left choose first, so that a piece with one candidate is not
    // left with none by a neighbour's tenon next to it.
    auto usableCount = [&](size_t p) {
        size_t count = 0;
        for (size_t i : byPiece[p]) count += !isTaken[i] && rejection[i].empty() ? 1 : 0;
        return count;
    };
    for (int round = 0; round < o.maxPerPiece; ++round) {
        std::vector<std::pair<size_t, size_t>> order;  // (candidates left, piece)
        for (size_t p = 0; p < pieceCount; ++p)
            if (plan.perPiece[p].size() == size_t(round)) order.push_back({usableCount(p), p});
        std::sort(order.begin(), order.end());
        for (const auto& [left, p] : order) {
            size_t best = SIZE_MAX;
            double bestKey = -1e300;
            for (size_t i : byPiece[p]) {
                if (isTaken[i] || !rejection[i].empty()) continue;
                if (conflicts(candidates[i])) {
                    rejection[i] = "another tenon in the way";
                    continue;
                }
                const double key = candidates[i].score + spread(plan.perPiece[p], candidates[i].tenon);
                if (key > bestKey + 1e-12) bestKey = key, best = i;
            }
            if (best == SIZE_MAX) continue;
            isTaken[best] = 1;
            plan.perPiece[p].push_back(candidates[best].tenon);
            chosen.push_back(&candidates[best]);
        }
    }
    for (size_t p = 0; p < pieceCount; ++p) {
        if (plan.perPiece[p].size() >= size_t(o.minPerPiece)) continue;
        auto& reasons = plan.shortfall[p];
        for (size_t i = 0; i < candidates.size(); ++i)
            if (candidates[i].piece == int64_t(p) && candidates[i].tenon.hole == holeOfPiece[p] &&
                !rejection[i].empty())
                ++reasons[rejection[i]];
        if (reasons.empty()) reasons["no ball's hole along the piece's direction points at it"] = 1;
    }
    return plan;
}

}  // namespace zomefab::pieces
