// SPDX-License-Identifier: GPL-3.0-or-later
// Validity and commit: clearance, connectivity and collisions of a Z', applied with exact undo
// (detail/chain.h).
#include <algorithm>

#include "zomefab/core/error.h"
#include "zomefab/frame/detail/chain.h"

namespace zomefab::frame::detail {

bool Chain::staysConnected(const Proposal& p) {
    const BallId a = p.connectA, b = p.connectB;
    if (a == b) return true;
    if (mStampA.size() < mS.ballIdBound()) {
        mStampA.resize(mS.ballIdBound(), 0);
        mStampB.resize(mS.ballIdBound(), 0);
    }
    if (++mStamp == 0) {
        std::fill(mStampA.begin(), mStampA.end(), 0);
        std::fill(mStampB.begin(), mStampB.end(), 0);
        mStamp = 1;
    }
    mQueueA.assign(1, a);
    mQueueB.assign(1, b);
    mStampA[a] = mStamp;
    mStampB[b] = mStamp;
    size_t headA = 0, headB = 0;
    while (headA < mQueueA.size() && headB < mQueueB.size()) {
        const bool fromA = mQueueA.size() <= mQueueB.size();
        std::vector<BallId>& queue = fromA ? mQueueA : mQueueB;
        size_t& head = fromA ? headA : headB;
        std::vector<uint32_t>& own = fromA ? mStampA : mStampB;
        const std::vector<uint32_t>& other = fromA ? mStampB : mStampA;
        const BallId x = queue[head++];
        for (uint64_t m = mBalls[x].mask; m; m &= m - 1) {
            const StrutId t = mS.ball(x).holes[size_t(__builtin_ctzll(m))];
            if (t == p.removed[0] || t == p.removed[1]) continue;
            const BallId y = otherEnd(t, x);
            if (y == p.removedBall) continue;
            if (other[y] == mStamp) return true;
            if (own[y] != mStamp) {
                own[y] = mStamp;
                queue.push_back(y);
            }
        }
    }
    return false;
}

void Chain::revert(std::vector<Edit>& log) {
    for (auto it = log.rbegin(); it != log.rend(); ++it) {
        uint32_t id = kNoId;
        switch (it->kind) {
            case EditKind::AddBall:
                mS.removeBall(it->id);
                continue;
            case EditKind::AddStrut:
                mS.removeStrut(it->id);
                continue;
            case EditKind::RemoveBall:
                id = mS.addBall(it->position);
                break;
            case EditKind::RemoveStrut:
                id = mS.addStrut(it->a, it->hole, it->size);
                break;
        }
        // Ids are reused last-freed-first, so undoing in reverse order restores them.
        if (id != it->id) throw Error(ErrorCode::Internal, "frame: undo changed an element id");
    }
    log.clear();
}

bool Chain::commit(const Proposal& p) {
    for (int i = 0; i < p.addedCount; ++i) {
        const NewStrut& n = p.added[i];
        if (!mField.isSegmentAllowed(n.fromMm, n.fromDepth, n.toMm, n.toDepth,
                                     mField.strutDepthLimitMm(zome::holeColor(n.hole))))
            return false;
    }
    if (p.needsConnectivity && !staysConnected(p)) return false;

    std::vector<Edit>& log = mLog;
    log.clear();
    for (int i = 0; i < p.removedCount; ++i) {
        const zome::Strut& st = mS.strut(p.removed[i]);
        log.push_back({EditKind::RemoveStrut, p.removed[i], {}, st.a, st.holeA, st.size});
        mS.removeStrut(p.removed[i]);
    }
    if (p.removedBall != kNoId) {
        log.push_back({EditKind::RemoveBall, p.removedBall, mS.ball(p.removedBall).position, 0, 0, 0});
        mS.removeBall(p.removedBall);
    }
    BallId newId = kNoId;
    if (p.addsBall) {
        if (mS.ballCollides(p.newPosition)) {
            revert(log);
            return false;
        }
        newId = mS.addBall(p.newPosition);
        log.push_back({EditKind::AddBall, newId, {}, 0, 0, 0});
    }
    StrutId addedIds[2] = {kNoId, kNoId};
    for (int i = 0; i < p.addedCount; ++i) {
        const NewStrut& n = p.added[i];
        if (mS.strutCollides(n.start, n.hole, n.size)) {
            revert(log);
            return false;
        }
        addedIds[i] = mS.addStrut(n.from == kNewBall ? newId : n.from, n.hole, n.size);
        log.push_back({EditKind::AddStrut, addedIds[i], {}, 0, 0, 0});
    }

    // Z' is valid: update the caches and lists.
    for (int i = 0; i < p.removedCount; ++i) removeFromList(mLiveStruts, mStrutListIndex, p.removed[i]);
    if (p.removedBall != kNoId) removeBallFromList(p.removedBall);
    if (p.addsBall) {
        if (mBalls.size() <= newId) mBalls.resize(size_t(newId) + 1);
        BallState& b = mBalls[newId];
        b.mask = p.newMask;
        b.depth = p.newDepth;
        b.summand = p.newSummand;
        b.energy = p.newEnergy;
        b.listIndex = uint32_t(mLiveBalls.size());
        mLiveBalls.push_back(newId);
    }
    for (int i = 0; i < p.touchedCount; ++i) {
        mBalls[p.touched[i]].mask = p.touchedMask[i];
        mBalls[p.touched[i]].energy = p.touchedEnergy[i];
    }
    for (int i = 0; i < p.addedCount; ++i) {
        if (mStrutListIndex.size() <= addedIds[i]) mStrutListIndex.resize(size_t(addedIds[i]) + 1, kNoId);
        mStrutListIndex[addedIds[i]] = uint32_t(mLiveStruts.size());
        mLiveStruts.push_back(addedIds[i]);
    }
    mSums = p.sums;
    mEnergy = p.energy;
    return true;
}

void Chain::removeFromList(std::vector<uint32_t>& list, std::vector<uint32_t>& index, uint32_t id) {
    const uint32_t i = index[id];
    const uint32_t last = list.back();
    list[i] = last;
    index[last] = i;
    list.pop_back();
    index[id] = kNoId;
}

void Chain::removeBallFromList(BallId id) {
    const uint32_t i = mBalls[id].listIndex;
    const BallId last = mLiveBalls.back();
    mLiveBalls[i] = last;
    mBalls[last].listIndex = i;
    mLiveBalls.pop_back();
    mBalls[id] = BallState{};
}

}  // namespace zomefab::frame::detail
