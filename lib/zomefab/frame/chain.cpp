// SPDX-License-Identifier: GPL-3.0-or-later
// One annealing chain: its state, the running sums, one iteration (detail/chain.h).
#include "zomefab/frame/detail/chain.h"

#include <time.h>

#include <cmath>

#include "zomefab/core/error.h"

namespace zomefab::frame::detail {

Chain::Chain(const zome::Structure& initial, const FrameField& field, const EnergyOptions& energy,
             const AnnealOptions& anneal, uint64_t seed, int index)
    : mS(initial), mField(field), mEnergyOptions(energy), mAnneal(anneal), mRng(seed), mTables(moveTables()) {
    mStats.chain = index;
    mStats.seed = seed;
    mBalls.resize(mS.ballIdBound());
    for (BallId id : mS.ballIds()) {
        BallState& b = mBalls[id];
        b.mask = holeMask(mS.ball(id));
        b.depth = mField.depthMm(mS.ball(id).positionMm);
        b.summand = fidelitySummand(b.depth, mField);
        b.energy = ballEnergy(b.mask, b.summand, mEnergyOptions);
        b.listIndex = uint32_t(mLiveBalls.size());
        mLiveBalls.push_back(id);
    }
    mStrutListIndex.resize(mS.strutIdBound(), kNoId);
    for (StrutId id : mS.strutIds()) {
        mStrutListIndex[id] = uint32_t(mLiveStruts.size());
        mLiveStruts.push_back(id);
    }
    resync();
    mBestEnergy = mEnergy;
}

ChainResult Chain::run(RunContext& context, std::atomic<uint64_t>* counter,
                       const std::function<void(double, double)>& tick) {
    const AnnealOptions& a = mAnneal;
    const Stopwatch clock;
    const double cpuStart = threadCpuSeconds();
    double t = a.initialTemperature;
    uint64_t reported = 0;
    uint64_t iter = 0;
    while (true) {
        if (a.maxIterations > 0 && iter >= a.maxIterations) break;
        ++iter;
        step(t, iter);
        if (iter % a.coolingIntervalIterations == 0) {
            t *= a.coolingFactor;
            if (a.finalTemperature > 0 && t < a.finalTemperature) break;
        }
        if ((iter & 0x3FF) == 0) {
            context.throwIfCancelled();
            if (counter) counter->fetch_add(iter - reported, std::memory_order_relaxed);
            reported = iter;
            if (tick) tick(mEnergy, t);
            if (a.timeLimitSeconds > 0 && clock.seconds() >= a.timeLimitSeconds) break;
        }
    }
    if (counter) counter->fetch_add(iter - reported, std::memory_order_relaxed);
    mStats.iterations = iter;
    mStats.finalTemperature = t;
    mStats.seconds = clock.seconds();
    mStats.cpuSeconds = threadCpuSeconds() - cpuStart;
    // The best state visited: the current one unless a saved copy is better.
    const zome::Structure& best = (mIsBestSaved && mBestEnergy < mEnergy) ? mBest : mS;
    ChainResult result{best, frameEnergy(best, mField, mEnergyOptions), mStats};
    return result;
}

void Chain::resync() {
    EnergySums s;
    for (BallId id = 0; id < mS.ballIdBound(); ++id)
        if (mS.hasBall(id)) s.add(mBalls[id].energy);
    s.balls = int64_t(mS.ballCount());
    s.struts = int64_t(mS.strutCount());
    mSums = s;
    mEnergy = totalEnergy(mSums, mEnergyOptions);
}

BallId Chain::otherEnd(StrutId t, BallId x) const {
    const zome::Strut& s = mS.strut(t);
    return s.a == x ? s.b : s.a;
}

BallId Chain::neighborAt(BallId x, int hole) const { return otherEnd(mS.ball(x).holes[size_t(hole)], x); }

bool Chain::hasCommonNeighbor(BallId a, BallId b) const {
    BallId na[zome::kHoleCount];
    int n = 0;
    for (uint64_t m = mBalls[a].mask; m; m &= m - 1) {
        const BallId y = neighborAt(a, __builtin_ctzll(m));
        if (y != b) na[n++] = y;
    }
    for (uint64_t m = mBalls[b].mask; m; m &= m - 1) {
        const BallId y = neighborAt(b, __builtin_ctzll(m));
        if (y == a) continue;
        for (int i = 0; i < n; ++i)
            if (na[i] == y) return true;
    }
    return false;
}

void Chain::setTouched(Proposal& p, BallId id, uint64_t mask) {
    const int i = p.touchedCount++;
    p.touched[i] = id;
    p.touchedMask[i] = mask;
    p.touchedEnergy[i] = ballEnergy(mask, mBalls[id].summand, mEnergyOptions);
}

void Chain::finish(Proposal& p, int dBalls, int dStruts) {
    EnergySums s = mSums;
    for (int i = 0; i < p.touchedCount; ++i) {
        s.subtract(mBalls[p.touched[i]].energy);
        s.add(p.touchedEnergy[i]);
    }
    if (p.removedBall != kNoId) s.subtract(mBalls[p.removedBall].energy);
    if (p.addsBall) s.add(p.newEnergy);
    s.balls += dBalls;
    s.struts += dStruts;
    p.sums = s;
    p.energy = totalEnergy(s, mEnergyOptions);
}

NewStrut Chain::existingStrut(BallId from, int hole, int size, BallId to) const {
    NewStrut n;
    n.from = from;
    n.hole = hole;
    n.size = size;
    n.start = mS.ball(from).position;
    n.fromMm = mS.ball(from).positionMm;
    n.toMm = mS.ball(to).positionMm;
    n.fromDepth = mBalls[from].depth;
    n.toDepth = mBalls[to].depth;
    return n;
}

void Chain::step(double temperature, uint64_t iteration) {
    Proposal p;
    bool isFeasible = false;
    switch (mRng.below(6)) {
        case 0:
            isFeasible = proposeInsNode(p);
            break;
        case 1:
            isFeasible = proposeDelNode(p);
            break;
        case 2:
            isFeasible = proposeTriangleStrut(p);
            break;
        case 3:
            isFeasible = proposeStrutInsert(p);
            break;
        default:
            isFeasible = !mLiveStruts.empty() && proposeStrutDelete(p);
            break;
    }
    if (!isFeasible) return;
    ++mStats.feasible;
    ++mStats.feasibleByKind[size_t(p.kind)];
    // Metropolis (Algorithm 1): accept Z' with probability min(1, exp((E(Z) − E(Z'))/T)).
    const double deltaE = p.energy - mEnergy;
    const double u = mRng.uniform();
    if (!(deltaE <= 0.0 || u < std::exp(-deltaE / temperature))) return;
    ++mStats.passedMetropolis;
    // Leaving the best state seen uphill: keep a copy of it first (returned if the chain ends
    // worse; rare at low temperature, where most accepted moves go downhill).
    if (deltaE > 0.0 && mEnergy <= mBestEnergy && !mIsBestSaved) {
        mBest = mS;
        mIsBestSaved = true;
    }
    // CollisionFree(Z') and the other validity tests, then Z ← Z'.
    if (!commit(p)) return;
    if (mEnergy < mBestEnergy) {
        mBestEnergy = mEnergy;
        mIsBestSaved = false;  // the best is the current state, not the copy
    }
    ++mStats.accepted;
    ++mStats.acceptedByKind[size_t(p.kind)];
    if ((mStats.accepted & 0xFFFF) == 0) resync();
    if (mAnneal.onAccepted) mAnneal.onAccepted(AcceptedMove{p.kind, iteration, mS, mEnergy});
}

}  // namespace zomefab::frame::detail
