// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/structure.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <tuple>

#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"

namespace zomefab::zome {

namespace {

/// Above this many cells the grid coarsens its cells instead (≈ 50 MB of empty cell headers).
constexpr double kMaxGridCells = 2.0e6;

inline double sq(double x) { return x * x; }
// zome:: has exact (golden) dot and cross; these are the millimetre ones.
using zomefab::dist2;
using zomefab::dot;
using zomefab::sub;

std::string ballName(BallId id) { return "ball " + std::to_string(id); }

}  // namespace

const char* collisionKindName(CollisionKind kind) {
    switch (kind) {
        case CollisionKind::BallBall:
            return "ball-ball";
        case CollisionKind::StrutBall:
            return "strut-ball";
        case CollisionKind::StrutStrut:
            return "strut-strut";
    }
    return "?";
}

namespace {

inline double pointSegmentDistanceSqInline(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    const Vec3d ab = sub(b, a);
    const Vec3d ap = sub(p, a);
    const double len2 = dot(ab, ab);
    double t = len2 > 0.0 ? dot(ap, ab) / len2 : 0.0;
    t = std::clamp(t, 0.0, 1.0);
    const Vec3d c{a[0] + t * ab[0], a[1] + t * ab[1], a[2] + t * ab[2]};
    return dist2(p, c);
}

inline double segmentSegmentDistanceSqInline(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0,
                                             const Vec3d& q1) {
    // Closest points of two segments (Ericson, Real-Time Collision Detection, §5.1.9).
    const Vec3d d1 = sub(p1, p0);
    const Vec3d d2 = sub(q1, q0);
    const Vec3d r = sub(p0, q0);
    const double a = dot(d1, d1);
    const double e = dot(d2, d2);
    const double f = dot(d2, r);
    constexpr double kEps = 1e-18;
    double s = 0.0, t = 0.0;
    if (a <= kEps && e <= kEps) return dot(r, r);
    if (a <= kEps) {
        t = std::clamp(f / e, 0.0, 1.0);
    } else {
        const double c = dot(d1, r);
        if (e <= kEps) {
            s = std::clamp(-c / a, 0.0, 1.0);
        } else {
            const double b = dot(d1, d2);
            const double denom = a * e - b * b;  // ≥ 0; 0 when parallel
            s = denom > kEps * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
            t = (b * s + f) / e;
            if (t < 0.0) {
                t = 0.0;
                s = std::clamp(-c / a, 0.0, 1.0);
            } else if (t > 1.0) {
                t = 1.0;
                s = std::clamp((b - c) / a, 0.0, 1.0);
            }
        }
    }
    const Vec3d c1{p0[0] + d1[0] * s, p0[1] + d1[1] * s, p0[2] + d1[2] * s};
    const Vec3d c2{q0[0] + d2[0] * t, q0[1] + d2[1] * t, q0[2] + d2[2] * t};
    return dist2(c1, c2);
}

/// Cheap rejection: the entry's bounding box is farther than @p limit from [lo, hi] on some axis.
inline bool boxesApart(const detail::GridEntry& e, const Vec3d& lo, const Vec3d& hi, double limit) {
    for (int i = 0; i < 3; ++i) {
        if (std::min(e.p0[i], e.p1[i]) > hi[i] + limit) return true;
        if (std::max(e.p0[i], e.p1[i]) < lo[i] - limit) return true;
    }
    return false;
}

}  // namespace

double pointSegmentDistanceSq(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    return pointSegmentDistanceSqInline(p, a, b);
}

double segmentSegmentDistanceSq(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0, const Vec3d& q1) {
    return segmentSegmentDistanceSqInline(p0, p1, q0, q1);
}

// --- construction ---------------------------------------------------------------------------------

Structure::Structure(const ZomeScale& scale, const CollisionOptions& collision)
    : mScale(scale), mCollision(collision) {
    mScale.validate();
    if (!(std::isfinite(collision.clearanceMm) && collision.clearanceMm >= 0.0))
        throw Error(ErrorCode::Usage, "clearanceMm must be a non-negative number of mm");
    if (!(std::isfinite(collision.gridCellMm) && collision.gridCellMm >= 0.0))
        throw Error(ErrorCode::Usage, "gridCellMm must be a non-negative number of mm (0 = automatic)");
    mUnitMm = mScale.unitMm();
    const double c = mCollision.clearanceMm;
    mBallBallMm = mScale.ballDiameterMm + c;
    double maxRadius = 0.0;
    for (int k = 0; k < kColorCount; ++k) maxRadius = std::max(maxRadius, mScale.strutRadiusMm(Color(k)));
    mBallReachMm = mBallBallMm;
    for (int k = 0; k < kColorCount; ++k) {
        const double r = mScale.strutRadiusMm(Color(k));
        mStrutBallMm[size_t(k)] = mScale.ballRadiusMm() + r + c;
        mBallReachMm = std::max(mBallReachMm, mStrutBallMm[size_t(k)]);
        mStrutReachMm[size_t(k)] = std::max(mStrutBallMm[size_t(k)], r + maxRadius + c);
    }
}

std::vector<BallId> Structure::ballIds() const {
    std::vector<BallId> ids;
    ids.reserve(mBallCount);
    for (BallId i = 0; i < mBalls.size(); ++i)
        if (mBalls[i].isAlive) ids.push_back(i);
    return ids;
}

std::vector<StrutId> Structure::strutIds() const {
    std::vector<StrutId> ids;
    ids.reserve(mStrutCount);
    for (StrutId i = 0; i < mStruts.size(); ++i)
        if (mStruts[i].isAlive) ids.push_back(i);
    return ids;
}

BallId Structure::neighbor(BallId id, int hole) const {
    const StrutId s = mBalls[id].holes[size_t(hole)];
    if (s == kNoId) return kNoId;
    return mStruts[s].a == id ? mStruts[s].b : mStruts[s].a;
}

// --- grid -----------------------------------------------------------------------------------------

detail::GridEntry Structure::ballEntry(BallId id) const {
    detail::GridEntry e;
    e.p0 = e.p1 = mBalls[id].positionMm;
    e.key = e.a = e.b = id;
    return e;
}

detail::GridEntry Structure::strutEntry(StrutId id) const {
    const Strut& s = mStruts[id];
    detail::GridEntry e;
    e.p0 = s.startMm;
    e.p1 = s.endMm;
    e.key = id | kStrutKeyBit;
    e.a = s.a;
    e.b = s.b;
    e.holeA = s.holeA;
    e.holeB = s.holeB;
    e.color = uint8_t(s.color);
    e.isStrut = 1;
    return e;
}

void Structure::ensureGridCovers(const Vec3d& p0, const Vec3d& p1) {
    if (!mGrid.covers(p0, p1)) rebuildGrid(p0, p1);
}

void Structure::rebuildGrid(const Vec3d& p0, const Vec3d& p1) {
    // New bounds: everything alive plus the new element, grown by half the extent on every side,
    // so a structure growing in one direction triggers only O(log n) rebuilds.
    Vec3d bmin = p0, bmax = p0;
    auto expand = [&](const Vec3d& p) {
        for (int i = 0; i < 3; ++i) {
            bmin[i] = std::min(bmin[i], p[i]);
            bmax[i] = std::max(bmax[i], p[i]);
        }
    };
    expand(p1);
    for (const Ball& b : mBalls)
        if (b.isAlive) expand(b.positionMm);
    for (const Strut& s : mStruts)
        if (s.isAlive) {
            expand(s.startMm);
            expand(s.endMm);
        }
    // Automatic cell: b0/√2 (33.4 mm). Results do not depend on it; speed does (docs/benchmarks.md).
    // An irrational multiple of b0 keeps the planes of a B0 lattice off the cell boundaries, where
    // every strut would be listed in two rows of cells.
    double cell = mCollision.gridCellMm > 0.0 ? mCollision.gridCellMm : mScale.b0Mm / std::sqrt(2.0);
    for (int i = 0; i < 3; ++i) {
        const double margin = std::max(0.5 * (bmax[i] - bmin[i]), 4.0 * cell);
        bmin[i] -= margin;
        bmax[i] += margin;
    }
    auto cellCount = [&](double h) {
        double n = 1.0;
        for (int i = 0; i < 3; ++i) n *= std::ceil((bmax[i] - bmin[i]) / h) + 1.0;
        return n;
    };
    while (cellCount(cell) > kMaxGridCells) cell *= 1.25;
    mGrid.reset(bmin, bmax, cell);
    for (BallId i = 0; i < mBalls.size(); ++i)
        if (mBalls[i].isAlive) mGrid.insert(ballEntry(i));
    for (StrutId i = 0; i < mStruts.size(); ++i)
        if (mStruts[i].isAlive) mGrid.insert(strutEntry(i));
}

// --- editing --------------------------------------------------------------------------------------

void Structure::refillFreeBalls() {
    mFreeBalls.clear();
    for (BallId i = BallId(mBalls.size()); i-- > 0;)
        if (!mBalls[i].isAlive) mFreeBalls.push_back(i);  // descending: lowest id pops first
    mFreeBallsStale = false;
}

BallId Structure::placeBall(BallId id, const GoldenVector3& position) {
    Ball& b = mBalls[id];
    b.position = position;
    b.positionMm = mScale.toMm(position);
    b.holes = freeHoles();
    b.valence = 0;
    ensureGridCovers(b.positionMm, b.positionMm);  // before isAlive: a rebuild must not add it
    b.isAlive = true;
    mGrid.insert(ballEntry(id));
    mPositions.insert(position, id);
    ++mBallCount;
    return id;
}

BallId Structure::addBall(const GoldenVector3& position) {
    const BallId existing = findBall(position);
    if (existing != kNoId)
        throw Error(ErrorCode::InvalidInput,
                    "position " + position.toString() + " already holds " + ballName(existing));
    if (mFreeBallsStale) refillFreeBalls();
    BallId id;
    if (mFreeBalls.empty()) {
        id = BallId(mBalls.size());
        if (id >= kStrutKeyBit) throw Error(ErrorCode::ProcessingFailed, "too many balls");
        mBalls.emplace_back();
    } else {
        id = mFreeBalls.back();
        mFreeBalls.pop_back();
    }
    return placeBall(id, position);
}

BallId Structure::addBallWithId(BallId id, const GoldenVector3& position) {
    if (id >= kStrutKeyBit) throw Error(ErrorCode::InvalidInput, ballName(id) + ": id too large");
    if (hasBall(id)) throw Error(ErrorCode::InvalidInput, ballName(id) + ": duplicate id");
    const BallId existing = findBall(position);
    if (existing != kNoId)
        throw Error(ErrorCode::InvalidInput,
                    ballName(id) + ": same position " + position.toString() + " as " + ballName(existing));
    if (id >= mBalls.size()) mBalls.resize(size_t(id) + 1);
    mFreeBallsStale = true;
    return placeBall(id, position);
}

void Structure::removeBall(BallId id) {
    if (!hasBall(id))
        throw Error(ErrorCode::InvalidInput, "cannot remove " + ballName(id) + ": no such ball");
    Ball& b = mBalls[id];
    if (b.valence != 0)
        throw Error(ErrorCode::InvalidInput,
                    "cannot remove " + ballName(id) + ": " + std::to_string(b.valence) + " struts attached");
    mGrid.remove(ballEntry(id));
    mPositions.erase(b.position, id);
    b.isAlive = false;
    if (!mFreeBallsStale) mFreeBalls.push_back(id);
    --mBallCount;
}

std::optional<StrutMatch> Structure::strutBetween(BallId a, BallId b) const {
    if (a == b) return std::nullopt;
    const std::optional<StrutMatch> m = matchStrut(mBalls[b].position - mBalls[a].position);
    if (!m || !isHoleFree(a, m->hole) || !isHoleFree(b, oppositeHole(m->hole))) return std::nullopt;
    return m;
}

StrutId Structure::addStrut(BallId a, BallId b) {
    if (!hasBall(a) || !hasBall(b))
        throw Error(ErrorCode::InvalidInput, "strut from " + ballName(a) + " to " + ballName(b) +
                                                 ": no such ball " + std::to_string(hasBall(a) ? b : a));
    if (a == b) throw Error(ErrorCode::InvalidInput, "strut from " + ballName(a) + " to itself");
    const GoldenVector3 v = mBalls[b].position - mBalls[a].position;
    const std::optional<StrutMatch> m = matchStrut(v);
    if (!m)
        throw Error(ErrorCode::InvalidInput, "strut from " + ballName(a) + " to " + ballName(b) +
                                                 ": vector " + v.toString() + " is not a Zome strut");
    return insertStrut(a, b, *m);
}

StrutId Structure::addStrut(BallId a, int hole, int size) {
    if (!hasBall(a)) throw Error(ErrorCode::InvalidInput, "strut from " + ballName(a) + ": no such ball");
    if (hole < 0 || hole >= kHoleCount || size < 0 || size >= kSizeCount)
        throw Error(ErrorCode::InvalidInput, "strut from " + ballName(a) + ": hole " + std::to_string(hole) +
                                                 " size " + std::to_string(size) + " out of range");
    const GoldenVector3 end = mBalls[a].position + strutVector(hole, size);
    const BallId b = findBall(end);
    if (b == kNoId)
        throw Error(ErrorCode::InvalidInput, "strut from " + ballName(a) + " through hole " +
                                                 std::to_string(hole) + ": no ball at " + end.toString());
    return insertStrut(a, b, StrutMatch{hole, holeColor(hole), size});
}

void Structure::computeStrutProxy(Strut& s) const {
    // The capsule axis runs between the two ball surfaces: the part inside a ball is the ball's.
    const Vec3d& d = holeDirection(s.holeA);
    const double r = mScale.ballRadiusMm();
    const Vec3d& pa = mBalls[s.a].positionMm;
    const Vec3d& pb = mBalls[s.b].positionMm;
    const double length = mScale.strutLengthMm(s.color, s.size);
    if (2.0 * r >= length) {  // absurd options: a ball wider than the strut is long
        s.startMm = s.endMm = {0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1]), 0.5 * (pa[2] + pb[2])};
        return;
    }
    s.startMm = {pa[0] + r * d[0], pa[1] + r * d[1], pa[2] + r * d[2]};
    s.endMm = {pb[0] - r * d[0], pb[1] - r * d[1], pb[2] - r * d[2]};
}

StrutId Structure::insertStrut(BallId a, BallId b, const StrutMatch& m) {
    const int holeB = oppositeHole(m.hole);
    auto busy = [&](BallId ball, int hole) {
        return Error(ErrorCode::InvalidInput, "strut from " + ballName(a) + " to " + ballName(b) + ": hole " +
                                                  std::to_string(hole) + " of " + ballName(ball) +
                                                  " is already used by strut " +
                                                  std::to_string(mBalls[ball].holes[size_t(hole)]));
    };
    if (!isHoleFree(a, m.hole)) throw busy(a, m.hole);
    if (!isHoleFree(b, holeB)) throw busy(b, holeB);
    StrutId id;
    if (mFreeStruts.empty()) {
        id = StrutId(mStruts.size());
        if (id >= kStrutKeyBit) throw Error(ErrorCode::ProcessingFailed, "too many struts");
        mStruts.emplace_back();
    } else {
        id = mFreeStruts.back();
        mFreeStruts.pop_back();
    }
    Strut& s = mStruts[id];
    s.a = a;
    s.b = b;
    s.holeA = uint8_t(m.hole);
    s.holeB = uint8_t(holeB);
    s.color = m.color;
    s.size = uint8_t(m.size);
    computeStrutProxy(s);
    ensureGridCovers(s.startMm, s.endMm);  // before isAlive: a rebuild must not add it
    s.isAlive = true;
    mGrid.insert(strutEntry(id));
    mBalls[a].holes[size_t(m.hole)] = id;
    mBalls[b].holes[size_t(holeB)] = id;
    ++mBalls[a].valence;
    ++mBalls[b].valence;
    ++mStrutCount;
    return id;
}

void Structure::removeStrut(StrutId id) {
    if (!hasStrut(id))
        throw Error(ErrorCode::InvalidInput, "cannot remove strut " + std::to_string(id) + ": no such strut");
    mGrid.remove(strutEntry(id));
    Strut& s = mStruts[id];
    mBalls[s.a].holes[s.holeA] = kNoId;
    mBalls[s.b].holes[s.holeB] = kNoId;
    --mBalls[s.a].valence;
    --mBalls[s.b].valence;
    s.isAlive = false;
    mFreeStruts.push_back(id);
    --mStrutCount;
}

Structure Structure::compacted(std::vector<BallId>* newBallIds) const {
    Structure out(mScale, mCollision);
    std::vector<BallId> map(mBalls.size(), kNoId);
    for (BallId i = 0; i < mBalls.size(); ++i)
        if (mBalls[i].isAlive) map[i] = out.addBall(mBalls[i].position);
    for (const Strut& s : mStruts)
        if (s.isAlive) out.insertStrut(map[s.a], map[s.b], StrutMatch{s.holeA, s.color, s.size});
    if (newBallIds) *newBallIds = std::move(map);
    return out;
}

// --- collision queries ----------------------------------------------------------------------------

bool Structure::ballCollides(const GoldenVector3& position) const {
    if (findBall(position) != kNoId) return true;
    const Vec3d p = mScale.toMm(position);
    const double ballBall2 = sq(mBallBallMm);
    return mGrid.anyNear(p, p, mBallReachMm, [&](const detail::GridEntry& e) {
        if (e.isStrut) {  // no strut ends at an empty position, so none is exempt
            const double limit = mStrutBallMm[e.color];
            return !boxesApart(e, p, p, limit) && pointSegmentDistanceSqInline(p, e.p0, e.p1) < sq(limit);
        }
        return dist2(p, e.p0) < ballBall2;
    });
}

bool Structure::strutCollides(const GoldenVector3& start, int hole, int size) const {
    return strutCollidesImpl(start, findBall(start), mScale.toMm(start), hole, size);
}

bool Structure::strutCollides(BallId start, int hole, int size) const {
    const Ball& b = mBalls[start];
    return strutCollidesImpl(b.position, start, b.positionMm, hole, size);
}

bool Structure::strutCollidesImpl(const GoldenVector3& start, BallId idA, const Vec3d& pa, int hole,
                                  int size) const {
    const GoldenVector3 end = start + strutVector(hole, size);
    const Color color = holeColor(hole);
    const uint32_t holeEnd = uint32_t(oppositeHole(hole));
    const BallId idB = findBall(end);
    const Vec3d& d = holeDirection(hole);
    const double r = mScale.ballRadiusMm();
    const Vec3d pb = mScale.toMm(end);
    const Vec3d p0{pa[0] + r * d[0], pa[1] + r * d[1], pa[2] + r * d[2]};
    const Vec3d p1{pb[0] - r * d[0], pb[1] - r * d[1], pb[2] - r * d[2]};
    Vec3d lo, hi;
    for (int i = 0; i < 3; ++i) {
        lo[i] = std::min(p0[i], p1[i]);
        hi[i] = std::max(p0[i], p1[i]);
    }
    const double strutBall = mStrutBallMm[size_t(color)];
    const double myRadius = mScale.strutRadiusMm(color) + mCollision.clearanceMm;
    return mGrid.anyNear(p0, p1, mStrutReachMm[size_t(color)], [&](const detail::GridEntry& e) {
        if (!e.isStrut) {
            if (e.key == idA || e.key == idB) return false;  // its own end balls
            if (boxesApart(e, lo, hi, strutBall)) return false;
            return pointSegmentDistanceSqInline(e.p0, p0, p1) < sq(strutBall);
        }
        bool sharesBall = false;
        if (idA != kNoId && (e.a == idA || e.b == idA)) {
            if ((e.a == idA ? e.holeA : e.holeB) == uint32_t(hole)) return true;  // same hole: overlap
            sharesBall = true;
        }
        if (idB != kNoId && (e.a == idB || e.b == idB)) {
            if ((e.a == idB ? e.holeA : e.holeB) == holeEnd) return true;
            sharesBall = true;
        }
        if (sharesBall) return false;
        const double limit = myRadius + mScale.strutRadiusMm(Color(e.color));
        if (boxesApart(e, lo, hi, limit)) return false;
        return segmentSegmentDistanceSqInline(p0, p1, e.p0, e.p1) < sq(limit);
    });
}

std::vector<Collision> findCollisions(const Structure& s) {
    std::vector<Collision> out;
    constexpr uint32_t kBit = Structure::kStrutKeyBit;
    for (BallId i = 0; i < s.mBalls.size(); ++i) {
        const Ball& b = s.mBalls[i];
        if (!b.isAlive) continue;
        const Vec3d& p = b.positionMm;
        s.mGrid.anyNear(p, p, s.mBallReachMm, [&](const detail::GridEntry& e) {
            if (e.isStrut) {
                if (e.a == i || e.b == i) return false;
                const double d2 = pointSegmentDistanceSq(p, e.p0, e.p1);
                const double limit = s.mStrutBallMm[e.color];
                if (d2 < sq(limit))
                    out.push_back({CollisionKind::StrutBall, e.key & ~kBit, i, std::sqrt(d2), limit});
            } else if (e.key > i) {
                const double d2 = dist2(p, e.p0);
                if (d2 < sq(s.mBallBallMm))
                    out.push_back({CollisionKind::BallBall, i, e.key, std::sqrt(d2), s.mBallBallMm});
            }
            return false;
        });
    }
    for (StrutId i = 0; i < s.mStruts.size(); ++i) {
        const Strut& st = s.mStruts[i];
        if (!st.isAlive) continue;
        s.mGrid.anyNear(st.startMm, st.endMm, s.mStrutReachMm[size_t(st.color)],
                        [&](const detail::GridEntry& e) {
                            if (!e.isStrut) return false;
                            const StrutId j = e.key & ~kBit;
                            if (j <= i) return false;
                            // Struts sharing a ball use different holes of it (the structure guarantees it).
                            if (e.a == st.a || e.a == st.b || e.b == st.a || e.b == st.b) return false;
                            const double d2 = segmentSegmentDistanceSq(st.startMm, st.endMm, e.p0, e.p1);
                            const double limit = s.strutStrutLimitMm(st.color, Color(e.color));
                            if (d2 < sq(limit))
                                out.push_back({CollisionKind::StrutStrut, i, j, std::sqrt(d2), limit});
                            return false;
                        });
    }
    // An element listed in several grid cells is met once per cell: sort and keep one per pair.
    auto key = [](const Collision& c) { return std::make_tuple(int(c.kind), c.first, c.second); };
    std::sort(out.begin(), out.end(),
              [&](const Collision& x, const Collision& y) { return key(x) < key(y); });
    out.erase(std::unique(out.begin(), out.end(),
                          [&](const Collision& x, const Collision& y) { return key(x) == key(y); }),
              out.end());
    return out;
}

}  // namespace zomefab::zome
