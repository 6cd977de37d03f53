// SPDX-License-Identifier: GPL-3.0-or-later
// The six moves (paper §4.4, Fig. 7): each proposes a Z' as edits of Z with its energy (detail/chain.h).
#include <algorithm>

#include "zomefab/core/error.h"
#include "zomefab/frame/detail/chain.h"

namespace zomefab::frame::detail {

bool Chain::proposeInsNode(Proposal& p) {
    if (mLiveStruts.empty()) return false;
    const StrutId t = mLiveStruts[mRng.below(uint32_t(mLiveStruts.size()))];
    const zome::Strut& st = mS.strut(t);
    const auto& splits = mTables.splits[size_t(strutKey(st.holeA, st.size))];
    if (splits.empty()) return false;
    const SplitEntry e = splits[mRng.below(uint32_t(splits.size()))];
    const BallId a = st.a, b = st.b;
    uint64_t ma = mBalls[a].mask & ~bit(st.holeA);
    uint64_t mb = mBalls[b].mask & ~bit(st.holeB);
    const int holeAtB = zome::oppositeHole(e.hole2);
    if ((ma & bit(e.hole1)) || (mb & bit(holeAtB))) return false;
    ma |= bit(e.hole1);
    mb |= bit(holeAtB);
    const zome::GoldenVector3 m = mS.ball(a).position + zome::strutVector(e.hole1, e.size1);
    if (mS.findBall(m) != kNoId) return false;
    const Vec3d mMm = mS.scale().toMm(m);
    const double depth = mField.depthMm(mMm);
    if (!mField.isBallAllowed(depth)) return false;
    p.kind = MoveKind::InsNode;
    setTouched(p, a, ma);
    setTouched(p, b, mb);
    p.addsBall = true;
    p.newPosition = m;
    p.newPositionMm = mMm;
    p.newDepth = depth;
    p.newSummand = fidelitySummand(depth, mField);
    p.newMask = bit(zome::oppositeHole(e.hole1)) | bit(e.hole2);
    p.newEnergy = ballEnergy(p.newMask, p.newSummand, mEnergyOptions);
    p.removed[p.removedCount++] = t;
    NewStrut s1 = existingStrut(a, e.hole1, e.size1, a);
    s1.toMm = mMm;
    s1.toDepth = depth;
    NewStrut s2;
    s2.from = kNewBall;
    s2.hole = e.hole2;
    s2.size = e.size2;
    s2.start = m;
    s2.fromMm = mMm;
    s2.fromDepth = depth;
    s2.toMm = mS.ball(b).positionMm;
    s2.toDepth = mBalls[b].depth;
    p.added[p.addedCount++] = s1;
    p.added[p.addedCount++] = s2;
    finish(p, +1, +1);
    return true;
}

bool Chain::proposeDelNode(Proposal& p) {
    if (mLiveBalls.size() < 2) return false;
    const BallId m = mLiveBalls[mRng.below(uint32_t(mLiveBalls.size()))];
    const uint64_t mm = mBalls[m].mask;
    const int valence = __builtin_popcountll(mm);
    if (valence < 1 || valence > 2) return false;
    p.kind = MoveKind::DelNode;
    p.removedBall = m;
    const int h1 = __builtin_ctzll(mm);
    const StrutId t1 = mS.ball(m).holes[size_t(h1)];
    const BallId a = otherEnd(t1, m);
    const uint64_t ma = mBalls[a].mask & ~bit(zome::oppositeHole(h1));
    p.removed[p.removedCount++] = t1;
    if (valence == 1) {
        if (ma == 0) return false;  // a would be left alone
        setTouched(p, a, ma);
        finish(p, -1, -1);
        return true;
    }
    const int h2 = __builtin_ctzll(mm & (mm - 1));
    const StrutId t2 = mS.ball(m).holes[size_t(h2)];
    const BallId b = otherEnd(t2, m);
    const uint64_t mb = mBalls[b].mask & ~bit(zome::oppositeHole(h2));
    p.removed[p.removedCount++] = t2;
    const std::optional<zome::StrutMatch> match = zome::matchStrut(mS.ball(b).position - mS.ball(a).position);
    if (match && (ma & bit(match->hole)) && neighborAt(a, match->hole) == b) {
        // a and b are already joined: delete m and its two struts.
        setTouched(p, a, ma);
        setTouched(p, b, mb);
        finish(p, -1, -2);
        return true;
    }
    const int hb = match ? zome::oppositeHole(match->hole) : 0;
    if (match && !(ma & bit(match->hole)) && !(mb & bit(hb))) {
        setTouched(p, a, ma | bit(match->hole));
        setTouched(p, b, mb | bit(hb));
        p.added[p.addedCount++] = existingStrut(a, match->hole, match->size, b);
        finish(p, -1, -1);
        return true;
    }
    if (ma == 0 || mb == 0) return false;
    setTouched(p, a, ma);
    setTouched(p, b, mb);
    p.needsConnectivity = true;
    p.connectA = a;
    p.connectB = b;
    finish(p, -1, -2);
    return true;
}

int Chain::nthBit(uint64_t mask, uint32_t k) {
    for (; k > 0; --k) mask &= mask - 1;
    return __builtin_ctzll(mask);
}

bool Chain::proposeTriangleStrut(Proposal& p) {
    const BallId a = mLiveBalls[mRng.below(uint32_t(mLiveBalls.size()))];
    const uint64_t maskA = mBalls[a].mask;
    if (maskA == 0) return false;
    const int h1 = nthBit(maskA, mRng.below(uint32_t(__builtin_popcountll(maskA))));
    const zome::Strut& s1 = mS.strut(mS.ball(a).holes[size_t(h1)]);
    const BallId c = s1.a == a ? s1.b : s1.a;
    const uint64_t maskC = mBalls[c].mask & ~bit(zome::oppositeHole(h1));
    if (maskC == 0) return false;
    const int h2 = nthBit(maskC, mRng.below(uint32_t(__builtin_popcountll(maskC))));
    const zome::Strut& s2 = mS.strut(mS.ball(c).holes[size_t(h2)]);
    const BallId b = s2.a == c ? s2.b : s2.a;
    const int key = mTables.closing[size_t(strutKey(h1, s1.size))][size_t(strutKey(h2, s2.size))];
    if (key < 0) return false;
    const int hole = key / zome::kSizeCount, size = key % zome::kSizeCount;
    const int holeB = zome::oppositeHole(hole);
    if ((maskA & bit(hole)) || (mBalls[b].mask & bit(holeB))) return false;
    p.kind = MoveKind::InsStrut;
    setTouched(p, a, maskA | bit(hole));
    setTouched(p, b, mBalls[b].mask | bit(holeB));
    p.added[p.addedCount++] = existingStrut(a, hole, size, b);
    finish(p, 0, +1);
    return true;
}

bool Chain::proposeStrutInsert(Proposal& p) {
    const BallId a = mLiveBalls[mRng.below(uint32_t(mLiveBalls.size()))];
    const int hole = int(mRng.below(zome::kHoleCount));
    const int size = int(mRng.below(zome::kSizeCount));
    if (mBalls[a].mask & bit(hole)) return false;
    const BallId b = mS.findBall(mS.ball(a).position + zome::strutVector(hole, size));
    if (b == kNoId) return false;
    const int holeB = zome::oppositeHole(hole);
    if (mBalls[b].mask & bit(holeB)) return false;
    p.kind = hasCommonNeighbor(a, b) ? MoveKind::InsStrut : MoveKind::InsBridge;
    setTouched(p, a, mBalls[a].mask | bit(hole));
    setTouched(p, b, mBalls[b].mask | bit(holeB));
    p.added[p.addedCount++] = existingStrut(a, hole, size, b);
    finish(p, 0, +1);
    return true;
}

bool Chain::proposeStrutDelete(Proposal& p) {
    const StrutId t = mLiveStruts[mRng.below(uint32_t(mLiveStruts.size()))];
    const zome::Strut& st = mS.strut(t);
    const uint64_t ma = mBalls[st.a].mask & ~bit(st.holeA);
    const uint64_t mb = mBalls[st.b].mask & ~bit(st.holeB);
    if (ma == 0 || mb == 0) return false;  // a ball would be left alone
    const bool isTriangle = hasCommonNeighbor(st.a, st.b);
    p.kind = isTriangle ? MoveKind::DelStrut : MoveKind::DelBridge;
    setTouched(p, st.a, ma);
    setTouched(p, st.b, mb);
    p.removed[p.removedCount++] = t;
    if (!isTriangle) {
        p.needsConnectivity = true;
        p.connectA = st.a;
        p.connectB = st.b;
    }
    finish(p, 0, -1);
    return true;
}

}  // namespace zomefab::frame::detail
