// SPDX-License-Identifier: GPL-3.0-or-later
// The verifier's static checks: tenons against the plan and the frame, the pegs' axes, their fit
// in the holes, and no printed material inside balls or struts (detail/geometry.h).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <unordered_map>

#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/verify/detail/geometry.h"
#include "zomefab/zome/holes.h"

namespace zomefab::verify::detail {

namespace {

/// Ids of objects bucketed by the cells of a uniform grid their boxes touch.
class BoxGrid {
public:
    explicit BoxGrid(double cellMm) : mInv(1.0 / cellMm) {}
    void insert(const Box3d& box, uint32_t id) {
        for (int64_t i = cell(box.min[0]); i <= cell(box.max[0]); ++i)
            for (int64_t j = cell(box.min[1]); j <= cell(box.max[1]); ++j)
                for (int64_t k = cell(box.min[2]); k <= cell(box.max[2]); ++k)
                    mCells[pack(i, j, k)].push_back(id);
    }
    const std::vector<uint32_t>* at(const Vec3d& p) const {
        const auto it = mCells.find(pack(cell(p[0]), cell(p[1]), cell(p[2])));
        return it == mCells.end() ? nullptr : &it->second;
    }

private:
    int64_t cell(double x) const { return int64_t(std::floor(x * mInv)); }
    static int64_t pack(int64_t i, int64_t j, int64_t k) {
        return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
    }
    double mInv;
    std::unordered_map<int64_t, std::vector<uint32_t>> mCells;
};

std::string pieceLabel(uint32_t p) { return "piece " + std::to_string(p); }

/// The tip face of a peg: the piece's triangles inside the hole (a millimetre or more past the
/// ball's face, within the ball) whose normal faces the ball's centre within 15°; their
/// area-weighted normal, reversed, is the peg's measured axis. Zero when none.
Vec3d measuredAxis(const PieceGeometry& g, const HoleFrame& h) {
    Vec3d sum{0, 0, 0};
    const double reach2 = h.faceMm * h.faceMm, cosLimit = std::cos(15.0 * kPi / 180.0);
    auto isInHole = [&](const Vec3d& p) {
        return dist2(p, h.centerMm) <= reach2 && dot(sub(p, h.centerMm), h.d) <= h.faceMm - 1.0;
    };
    for (const auto& t : g.triangles) {
        const Vec3d& a = g.vertices[t[0]];
        const Vec3d& b = g.vertices[t[1]];
        const Vec3d& c = g.vertices[t[2]];
        if (!isInHole(a) || !isInHole(b) || !isInHole(c)) continue;
        const Vec3d area = cross(sub(b, a), sub(c, a));  // twice the area, outward
        const double len = norm(area);
        if (len == 0 || dot(area, h.d) > -cosLimit * len) continue;  // facing the centre: along −d
        sum = add(sum, area);
    }
    return norm(sum) > 0 ? scale(normalized(sum), -1.0) : Vec3d{0, 0, 0};
}

/// What one piece's samples inside balls show: the gap to the hole walls and the depth per tenon,
/// and the samples in a ball it has no peg in.
struct BallFindings {
    std::map<zome::BallId, double> gapMm;    ///< per tenon's ball: smallest gap to the hole's walls
    std::map<zome::BallId, double> depthMm;  ///< per tenon's ball: deepest point past the face
    std::map<zome::BallId, double> stray;    ///< balls it enters without a peg: how deep (mm)
    std::map<zome::BallId, double> tooDeep;  ///< pegs past the hole's floor: by how much
};

BallFindings inspectBalls(const Assembly& a, const PieceGeometry& g, const BoxGrid& balls,
                          const std::map<zome::BallId, HoleFrame>& pegHoles, const VerifyOptions& o) {
    BallFindings f;
    const double R = a.frame.scale().ballRadiusMm(), inner = R - o.materialToleranceMm;
    for (const Vec3d& p : g.samples()) {
        const std::vector<uint32_t>* near = balls.at(p);
        if (!near) continue;
        for (uint32_t id : *near) {
            const Vec3d c = a.frameToGridMm.apply(a.frame.ball(id).positionMm);
            if (dist2(p, c) >= inner * inner) continue;
            const auto hole = pegHoles.find(id);
            const double depthInBall = R - std::sqrt(dist2(p, c));
            if (hole == pegHoles.end()) {
                f.stray[id] = std::max(f.stray[id], depthInBall);
                continue;
            }
            const HoleFrame& h = hole->second;
            const Vec3d q = sub(p, c);
            const double gap = insideDistance(h.section, dot(q, h.x), dot(q, h.y));
            const double past = h.faceMm - dot(q, h.d);  // how far past the face, into the hole
            auto gapIt = f.gapMm.emplace(id, gap).first;
            gapIt->second = std::min(gapIt->second, gap);
            auto depthIt = f.depthMm.emplace(id, past).first;
            depthIt->second = std::max(depthIt->second, past);
            if (past > o.holeDepthMm + o.materialToleranceMm)
                f.tooDeep[id] = std::max(f.tooDeep[id], past - o.holeDepthMm);
        }
    }
    return f;
}

}  // namespace

std::vector<Vec3d> PieceGeometry::samples() const {
    std::vector<Vec3d> out = vertices;
    for (const auto& t : triangles)
        out.push_back(scale(add(add(vertices[t[0]], vertices[t[1]]), vertices[t[2]]), 1.0 / 3.0));
    return out;
}

std::vector<PieceGeometry> pieceGeometries(const pieces::Pieces& all) {
    std::vector<PieceGeometry> out(all.pieces.size());
    tbb::parallel_for(size_t(0), all.pieces.size(), [&](size_t p) {
        const pieces::Piece& piece = all.pieces[p];
        const Transform4d toGrid = affineInverse(piece.gridToPrintMm);
        PieceGeometry& g = out[p];
        for (const Vec3f& v : piece.mesh.positions) {
            g.vertices.push_back(toGrid.apply(toD(v)));
            g.bounds.expand(g.vertices.back());
        }
        for (const auto& t : piece.mesh.triangles) g.triangles.push_back({t[0], t[1], t[2]});
    });
    return out;
}

HoleFrame holeFrame(const Assembly& a, zome::BallId ball, int hole) {
    HoleFrame h;
    h.centerMm = a.frameToGridMm.apply(a.frame.ball(ball).positionMm);
    h.d = normalized(applyLinear(a.frameToGridMm, zome::holeDirection(hole)));
    h.x = normalized(applyLinear(a.frameToGridMm, zome::holeSectionAxis(hole)));
    h.y = cross(h.d, h.x);
    h.section = zome::holeSectionMm(zome::holeColor(hole));
    h.faceMm = a.frame.scale().ballRadiusMm() * zome::holeFaceRatio(zome::holeColor(hole));
    return h;
}

double insideDistance(const std::vector<std::array<double, 2>>& poly, double qx, double qy) {
    double inside = 1e300;
    const size_t n = poly.size();
    for (size_t k = 0; k < n; ++k) {
        const auto& a = poly[k];
        const auto& b = poly[(k + 1) % n];
        const double ex = b[0] - a[0], ey = b[1] - a[1];
        // Left of a counter-clockwise edge is inside.
        inside = std::min(inside, (ex * (qy - a[1]) - ey * (qx - a[0])) / std::hypot(ex, ey));
    }
    return inside;
}

void checkTenons(const Assembly& a, VerifyReport& report) {
    CheckResult c{"tenons", "every tenon in a free hole of a frame ball along its piece's direction", 0, {}};
    for (const pieces::Piece& piece : a.pieces.pieces)
        for (const pieces::Tenon& t : piece.tenons) {
            ++c.checked;
            const std::string who = pieceLabel(piece.id) + ", tenon into ball " + std::to_string(t.ball);
            if (!a.frame.hasBall(t.ball)) {
                c.failures.push_back(who + ": the frame has no such ball");
                continue;
            }
            if (t.hole != piece.hole)
                c.failures.push_back(who + ": hole " + std::to_string(t.hole) +
                                     " is not the piece's direction " + std::to_string(piece.hole));
            if (!a.frame.isHoleFree(t.ball, t.hole))
                c.failures.push_back(who + ": hole " + std::to_string(t.hole) + " holds a strut");
        }
    report.checks.push_back(c);
}

void checkPegs(const Assembly& a, const std::vector<PieceGeometry>& geometry, const VerifyOptions& o,
               VerifyReport& report, const RunContext& context) {
    CheckResult axes{"peg axes",
                     "every peg's measured axis within " + formatNumber(o.axisToleranceDeg, 3) +
                         "° of its piece's direction",
                     0,
                     {}};
    CheckResult fit{
        "peg fit", "pegs inside their holes with the clearance; no other material inside a ball", 0, {}};
    const double R = a.frame.scale().ballRadiusMm();
    BoxGrid balls(2 * R);
    for (zome::BallId id : a.frame.ballIds()) {
        const Vec3d c = a.frameToGridMm.apply(a.frame.ball(id).positionMm);
        balls.insert({{c[0] - R, c[1] - R, c[2] - R}, {c[0] + R, c[1] + R, c[2] + R}}, id);
    }
    const double clearance = a.pieces.options.tenons.clearanceMm;
    std::mutex lock;
    tbb::parallel_for(size_t(0), a.pieces.pieces.size(), [&](size_t p) {
        context.throwIfCancelled();
        const pieces::Piece& piece = a.pieces.pieces[p];
        std::map<zome::BallId, HoleFrame> holes;
        std::vector<std::string> axisFailures, fitFailures;
        PieceResult result = report.pieces[p];
        result.worstClearanceMm = 1e300;
        for (const pieces::Tenon& t : piece.tenons)
            if (a.frame.hasBall(t.ball)) holes.emplace(t.ball, holeFrame(a, t.ball, t.hole));
        for (const auto& [ball, h] : holes) {
            const Vec3d axis = measuredAxis(geometry[p], h);
            const std::string who = pieceLabel(uint32_t(p)) + ", peg in ball " + std::to_string(ball);
            if (norm(axis) == 0) {
                axisFailures.push_back(who + ": no peg tip found at the hole");
                continue;
            }
            const double deg = std::acos(std::clamp(dot(axis, h.d), -1.0, 1.0)) * 180.0 / kPi;
            result.worstAxisDeg = std::max(result.worstAxisDeg, deg);
            if (deg > o.axisToleranceDeg)
                axisFailures.push_back(who + ": axis " + formatNumber(deg, 3) + "° off the direction");
        }
        const BallFindings f = inspectBalls(a, geometry[p], balls, holes, o);
        for (const auto& [ball, depth] : f.stray)
            fitFailures.push_back(pieceLabel(uint32_t(p)) + ": material " + formatNumber(depth, 3) +
                                  " mm inside ball " + std::to_string(ball) + ", where it has no peg");
        for (const auto& [ball, over] : f.tooDeep)
            fitFailures.push_back(pieceLabel(uint32_t(p)) + ": the peg in ball " + std::to_string(ball) +
                                  " goes " + formatNumber(over, 3) + " mm past the hole's floor");
        for (const auto& [ball, h] : holes) {
            const auto gap = f.gapMm.find(ball);
            const auto depth = f.depthMm.find(ball);
            if (gap == f.gapMm.end()) continue;  // no peg material in the ball: not seated
            result.worstClearanceMm = std::min(result.worstClearanceMm, gap->second);
            if (gap->second < clearance - o.materialToleranceMm)
                fitFailures.push_back(
                    pieceLabel(uint32_t(p)) + ": the peg in ball " + std::to_string(ball) +
                    (gap->second < 0
                         ? " reaches " + formatNumber(-gap->second, 3) + " mm beyond the hole's walls"
                         : " leaves only " + formatNumber(gap->second, 3) + " mm of clearance"));
            if (depth->second >= o.minSeatedDepthMm) ++result.pegsSeated;
        }
        if (result.worstClearanceMm > 1e299) result.worstClearanceMm = 0;
        const std::lock_guard<std::mutex> guard(lock);
        report.pieces[p] = result;
        axes.checked += holes.size();
        fit.checked += holes.size();
        axes.failures.insert(axes.failures.end(), axisFailures.begin(), axisFailures.end());
        fit.failures.insert(fit.failures.end(), fitFailures.begin(), fitFailures.end());
    });
    std::sort(axes.failures.begin(), axes.failures.end());
    std::sort(fit.failures.begin(), fit.failures.end());
    report.checks.push_back(axes);
    report.checks.push_back(fit);
}

void checkStruts(const Assembly& a, const std::vector<PieceGeometry>& geometry, const VerifyOptions& o,
                 VerifyReport& report, const RunContext& context) {
    CheckResult c{"struts", "no printed material inside a strut", 0, {}};
    BoxGrid struts(10.0);
    std::vector<std::array<Vec3d, 2>> axis;
    std::vector<double> radius;
    for (zome::StrutId id : a.frame.strutIds()) {
        const zome::Strut& s = a.frame.strut(id);
        const Vec3d p = a.frameToGridMm.apply(s.startMm), q = a.frameToGridMm.apply(s.endMm);
        const double r = a.frame.scale().strutRadiusMm(s.color);
        Box3d box;
        box.expand(p), box.expand(q);
        box.min = sub(box.min, {r, r, r}), box.max = add(box.max, {r, r, r});
        if (axis.size() <= id) axis.resize(id + 1), radius.resize(id + 1);
        axis[id] = {p, q};
        radius[id] = r;
        struts.insert(box, id);
    }
    std::mutex lock;
    tbb::parallel_for(size_t(0), geometry.size(), [&](size_t p) {
        context.throwIfCancelled();
        std::map<zome::StrutId, double> inside;
        for (const Vec3d& x : geometry[p].samples()) {
            const std::vector<uint32_t>* near = struts.at(x);
            if (!near) continue;
            for (uint32_t id : *near) {
                const Vec3d& s = axis[id][0];
                const Vec3d e = sub(axis[id][1], s);
                const double t = std::clamp(dot(sub(x, s), e) / std::max(1e-12, dot(e, e)), 0.0, 1.0);
                const double dist = std::sqrt(dist2(x, madd(s, t, e)));
                if (dist < radius[id] - o.materialToleranceMm)
                    inside[id] = std::max(inside[id], radius[id] - dist);
            }
        }
        const std::lock_guard<std::mutex> guard(lock);
        ++c.checked;
        for (const auto& [id, depth] : inside)
            c.failures.push_back(pieceLabel(uint32_t(p)) + ": material " + formatNumber(depth, 3) +
                                 " mm inside strut " + std::to_string(id));
    });
    std::sort(c.failures.begin(), c.failures.end());
    report.checks.push_back(c);
}

}  // namespace zomefab::verify::detail
