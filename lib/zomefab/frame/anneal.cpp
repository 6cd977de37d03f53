// SPDX-License-Identifier: GPL-3.0-or-later
// One annealing chain: proposal generation from tables, local ΔE from running sums, validity
// checks only for proposals that pass the Metropolis test, edits with exact undo.
#include "zomefab/frame/anneal.h"

#include <tbb/parallel_for.h>
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/frame/move_tables.h"
#include "zomefab/frame/outermost.h"
#include "zomefab/frame/random.h"

namespace zomefab::frame {

using zome::BallId;
using zome::kNoId;
using zome::StrutId;

const char* moveKindName(MoveKind kind) {
    switch (kind) {
    case MoveKind::InsNode: return "InsNode";
    case MoveKind::DelNode: return "DelNode";
    case MoveKind::InsStrut: return "InsStrut";
    case MoveKind::DelStrut: return "DelStrut";
    case MoveKind::InsBridge: return "InsBridge";
    case MoveKind::DelBridge: return "DelBridge";
    }
    return "?";
}

nlohmann::json chainStatsToJson(const ChainStats& s) {
    nlohmann::json kinds = nlohmann::json::object();
    for (int k = 0; k < kMoveKindCount; ++k)
        kinds[moveKindName(MoveKind(k))] = {{"feasible", s.feasibleByKind[size_t(k)]},
                                            {"accepted", s.acceptedByKind[size_t(k)]}};
    return {{"chain", s.chain},
            {"seed", s.seed},
            {"iterations", s.iterations},
            {"feasible", s.feasible},
            {"passed_metropolis", s.passedMetropolis},
            {"accepted", s.accepted},
            {"moves", kinds},
            {"final_temperature", s.finalTemperature},
            {"seconds", s.seconds},
            {"cpu_seconds", s.cpuSeconds},
            {"iterations_per_cpu_second", s.cpuSeconds > 0 ? double(s.iterations) / s.cpuSeconds : 0.0}};
}

namespace {

/// CPU time of the calling thread in seconds.
double threadCpuSeconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

constexpr uint64_t kChainSalt = 0x636861696E000000ull;  // "chain"
constexpr uint32_t kNewBall = 0xFFFFFFFEu;

inline uint64_t bit(int h) { return uint64_t(1) << h; }

/// A strut a proposal adds: leaves ball `from` (kNewBall = the proposal's new ball) through `hole`.
struct NewStrut {
    uint32_t from = kNoId;
    int hole = 0;
    int size = 0;
    zome::GoldenVector3 start;  ///< exact position of `from`
    Vec3d fromMm{}, toMm{};
    double fromDepth = 0, toDepth = 0;
};

/// A proposed structure Z', described as edits of Z plus its energy.
struct Proposal {
    MoveKind kind = MoveKind::InsNode;
    int touchedCount = 0;  ///< existing balls whose holes change
    BallId touched[2] = {kNoId, kNoId};
    uint64_t touchedMask[2] = {0, 0};
    BallEnergy touchedEnergy[2];
    bool addsBall = false;
    zome::GoldenVector3 newPosition;
    Vec3d newPositionMm{};
    double newDepth = 0, newSummand = 0;
    uint64_t newMask = 0;
    BallEnergy newEnergy;
    BallId removedBall = kNoId;
    int removedCount = 0;
    StrutId removed[2] = {kNoId, kNoId};
    int addedCount = 0;
    NewStrut added[2];
    bool needsConnectivity = false;  ///< a and b must stay connected without the removed parts
    BallId connectA = kNoId, connectB = kNoId;
    EnergySums sums;
    double energy = 0;
};

class Chain {
public:
    Chain(const zome::Structure& initial, const FrameField& field, const EnergyOptions& energy,
          const AnnealOptions& anneal, uint64_t seed, int index)
        : mS(initial), mField(field), mEnergyOptions(energy), mAnneal(anneal), mRng(seed),
          mTables(moveTables()) {
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

    /// Runs the chain. @p tick, when set, is called every 1024 iterations with the current energy
    /// and temperature (progress reports; it must not touch the chain).
    ChainResult run(RunContext& context, std::atomic<uint64_t>* counter,
                    const std::function<void(double, double)>& tick = {}) {
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

private:
    struct BallState {
        uint64_t mask = 0;
        double depth = 0;
        double summand = 0;
        BallEnergy energy;
        uint32_t listIndex = kNoId;
    };

    enum class EditKind : uint8_t { AddBall, RemoveBall, AddStrut, RemoveStrut };
    struct Edit {
        EditKind kind;
        uint32_t id;
        zome::GoldenVector3 position;  // RemoveBall
        BallId a;                      // RemoveStrut
        int hole, size;                // RemoveStrut
    };

    /// Recomputes the running sums from the per-ball energies in id order (bounds the drift of
    /// the incremental sums; done at fixed accepted-move counts, so it is deterministic).
    void resync() {
        EnergySums s;
        for (BallId id = 0; id < mS.ballIdBound(); ++id)
            if (mS.hasBall(id)) s.add(mBalls[id].energy);
        s.balls = int64_t(mS.ballCount());
        s.struts = int64_t(mS.strutCount());
        mSums = s;
        mEnergy = totalEnergy(mSums, mEnergyOptions);
    }

    BallId otherEnd(StrutId t, BallId x) const {
        const zome::Strut& s = mS.strut(t);
        return s.a == x ? s.b : s.a;
    }
    BallId neighborAt(BallId x, int hole) const { return otherEnd(mS.ball(x).holes[size_t(hole)], x); }

    /// Do a and b share a neighbour other than each other?
    bool hasCommonNeighbor(BallId a, BallId b) const {
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

    void setTouched(Proposal& p, BallId id, uint64_t mask) {
        const int i = p.touchedCount++;
        p.touched[i] = id;
        p.touchedMask[i] = mask;
        p.touchedEnergy[i] = ballEnergy(mask, mBalls[id].summand, mEnergyOptions);
    }

    /// Sums and energy of Z' from the touched balls only.
    void finish(Proposal& p, int dBalls, int dStruts) {
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

    NewStrut existingStrut(BallId from, int hole, int size, BallId to) const {
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

    // --- the six moves (paper §4.4) ------------------------------------------------------------

    /// InsNode: replace strut a→b by a→m→b through a new ball m (a triangle from the split table).
    bool proposeInsNode(Proposal& p) {
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

    /// DelNode: remove a ball of valence 1 or 2 with its struts. For valence 2 with neighbours
    /// a, b: when a–b is a catalogue strut with free holes it is added (the inverse of InsNode);
    /// when a and b are already joined nothing is added; otherwise a and b must stay connected.
    bool proposeDelNode(Proposal& p) {
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
        const std::optional<zome::StrutMatch> match =
            zome::matchStrut(mS.ball(b).position - mS.ball(a).position);
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

    /// The @p k-th set bit of @p mask (0-based).
    static int nthBit(uint64_t mask, uint32_t k) {
        for (; k > 0; --k) mask &= mask - 1;
        return __builtin_ctzll(mask);
    }

    /// InsStrut from the triangle table: a random ball a, a random strut a → c, a random strut
    /// c → b; the proposal is the strut a → b when v(a→c) + v(c→b) is a catalogue strut
    /// (MoveTables::closing) and both holes are free. It closes the triangle a, c, b.
    bool proposeTriangleStrut(Proposal& p) {
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

    /// InsBridge (or InsStrut): a strut from a random ball through a random free hole, of a
    /// random size, to the ball already at its end. InsStrut when the two balls share a neighbour
    /// (the strut closes a triangle), InsBridge when they do not (path length > 2).
    bool proposeStrutInsert(Proposal& p) {
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

    /// DelStrut / DelBridge: remove a random strut. DelStrut when its ends keep a common
    /// neighbour (they stay connected by a path of length 2); DelBridge otherwise, which needs a
    /// connectivity search.
    bool proposeStrutDelete(Proposal& p) {
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

    // --- validity and commit --------------------------------------------------------------------

    /// Bidirectional breadth-first search from a and b in Z minus the proposal's removed struts
    /// and ball: true when they meet. Explores about twice the smaller side.
    bool staysConnected(const Proposal& p) {
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

    void revert(std::vector<Edit>& log) {
        for (auto it = log.rbegin(); it != log.rend(); ++it) {
            uint32_t id = kNoId;
            switch (it->kind) {
            case EditKind::AddBall: mS.removeBall(it->id); continue;
            case EditKind::AddStrut: mS.removeStrut(it->id); continue;
            case EditKind::RemoveBall: id = mS.addBall(it->position); break;
            case EditKind::RemoveStrut: id = mS.addStrut(it->a, it->hole, it->size); break;
            }
            // Ids are reused last-freed-first, so undoing in reverse order restores them.
            if (id != it->id) throw Error(ErrorCode::Internal, "frame: undo changed an element id");
        }
        log.clear();
    }

    /// Checks the clearance of the new struts, connectivity and collisions, then applies the
    /// proposal. Returns false (and leaves Z unchanged) when Z' is invalid.
    bool commit(const Proposal& p) {
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

    static void removeFromList(std::vector<uint32_t>& list, std::vector<uint32_t>& index, uint32_t id) {
        const uint32_t i = index[id];
        const uint32_t last = list.back();
        list[i] = last;
        index[last] = i;
        list.pop_back();
        index[id] = kNoId;
    }
    void removeBallFromList(BallId id) {
        const uint32_t i = mBalls[id].listIndex;
        const BallId last = mLiveBalls.back();
        mLiveBalls[i] = last;
        mBalls[last].listIndex = i;
        mLiveBalls.pop_back();
        mBalls[id] = BallState{};
    }

    void step(double temperature, uint64_t iteration) {
        Proposal p;
        bool isFeasible = false;
        switch (mRng.below(6)) {
        case 0: isFeasible = proposeInsNode(p); break;
        case 1: isFeasible = proposeDelNode(p); break;
        case 2: isFeasible = proposeTriangleStrut(p); break;
        case 3: isFeasible = proposeStrutInsert(p); break;
        default: isFeasible = !mLiveStruts.empty() && proposeStrutDelete(p); break;
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

    zome::Structure mS;
    const FrameField& mField;
    EnergyOptions mEnergyOptions;
    AnnealOptions mAnneal;
    Rng mRng;
    const MoveTables& mTables;
    std::vector<BallState> mBalls;
    std::vector<BallId> mLiveBalls;
    std::vector<uint32_t> mStrutListIndex;
    std::vector<StrutId> mLiveStruts;
    EnergySums mSums;
    double mEnergy = 0;
    std::vector<uint32_t> mStampA, mStampB;
    uint32_t mStamp = 0;
    std::vector<BallId> mQueueA, mQueueB;
    std::vector<Edit> mLog;
    ChainStats mStats;
    double mBestEnergy = 0;     ///< lowest energy visited
    bool mIsBestSaved = false;  ///< mBest holds the state of mBestEnergy (the current one differs)
    zome::Structure mBest;
};

void validate(const AnnealOptions& a, const EnergyOptions& e) {
    if (!(a.initialTemperature > 0) || !std::isfinite(a.initialTemperature))
        throw Error(ErrorCode::Usage, "the initial temperature must be positive");
    if (!(a.coolingFactor > 0 && a.coolingFactor <= 1))
        throw Error(ErrorCode::Usage, "the cooling factor must be in (0, 1]");
    if (a.coolingIntervalIterations < 1)
        throw Error(ErrorCode::Usage, "the cooling interval must be at least one iteration");
    const bool stopsByTemperature = a.finalTemperature > 0 && a.coolingFactor < 1;
    if (!stopsByTemperature && a.maxIterations == 0 && !(a.timeLimitSeconds > 0))
        throw Error(ErrorCode::Usage,
                    "the annealing never stops: give a final temperature below the initial one "
                    "with a cooling factor below 1, an iteration budget or a time limit");
    if (!(e.targetItemCount > 0))
        throw Error(ErrorCode::Usage, "the target item count must be positive");
}

}  // namespace

uint64_t chainSeed(uint64_t seed, int chainIndex) { return deriveSeed(seed, kChainSalt, uint64_t(chainIndex)); }

ChainResult annealChain(const zome::Structure& initial, const FrameField& field,
                        const EnergyOptions& energy, const AnnealOptions& anneal, uint64_t seed,
                        int chainIndex, RunContext& context, std::atomic<uint64_t>* counter) {
    validate(anneal, energy);
    if (initial.ballCount() == 0)
        throw Error(ErrorCode::ProcessingFailed, "cannot anneal an empty frame");
    Chain chain(initial, field, energy, anneal, seed, chainIndex);
    return chain.run(context, counter);
}

size_t bestChain(const std::vector<ChainResult>& results) {
    size_t best = 0;
    for (size_t i = 1; i < results.size(); ++i)
        if (results[i].energy.total < results[best].energy.total) best = i;  // ties: lower index
    return best;
}

std::vector<ChainResult> annealChains(const zome::Structure& initial, const FrameField& field,
                                      const EnergyOptions& energy, const AnnealOptions& anneal,
                                      int chains, uint64_t seed, RunContext& context) {
    if (chains < 1) throw Error(ErrorCode::Usage, "at least one chain is needed");
    validate(anneal, energy);
    std::vector<ChainResult> results;
    results.reserve(size_t(chains));
    for (int c = 0; c < chains; ++c) results.push_back({initial, {}, {}});

    // Expected iterations per chain, for the progress fraction.
    double expected = double(anneal.maxIterations);
    if (anneal.finalTemperature > 0 && anneal.coolingFactor < 1) {
        const double byTemperature =
            std::ceil(std::log(anneal.finalTemperature / anneal.initialTemperature) /
                      std::log(anneal.coolingFactor)) *
            double(anneal.coolingIntervalIterations);
        expected = expected > 0 ? std::min(expected, byTemperature) : byTemperature;
    }
    std::atomic<uint64_t> counter{0};
    std::atomic<int> finished{0};
    std::unique_ptr<std::atomic<double>[]> current(new std::atomic<double>[size_t(chains)]);
    for (int c = 0; c < chains; ++c) current[size_t(c)].store(HUGE_VAL);
    std::mutex reportMutex;
    const Stopwatch clock;
    double lastReport = 0;
    // Progress on the context: at most every 2 s, from whichever chain gets the lock; it reads
    // shared counters only, so it cannot change any chain's result.
    auto report = [&](double temperature) {
        std::unique_lock<std::mutex> lock(reportMutex, std::try_to_lock);
        if (!lock.owns_lock()) return;
        const double now = clock.seconds();
        if (now - lastReport < 2.0) return;
        lastReport = now;
        const uint64_t done = counter.load();
        if (expected > 0) context.progress("anneal", std::min(1.0, double(done) / (expected * chains)));
        double best = HUGE_VAL;
        for (int c = 0; c < chains; ++c) best = std::min(best, current[size_t(c)].load());
        char buf[200];
        std::snprintf(buf, sizeof buf,
                      "anneal: %llu iterations over %d chains (%d finished), T %.3g, best E %.4f",
                      (unsigned long long)done, chains, finished.load(), temperature, best);
        context.info(buf);
    };
    tbb::parallel_for(0, chains, [&](int c) {
        Chain chain(initial, field, energy, anneal, chainSeed(seed, c), c);
        results[size_t(c)] = chain.run(context, &counter, [&, c](double e, double t) {
            current[size_t(c)].store(e, std::memory_order_relaxed);
            report(t);
        });
        current[size_t(c)].store(results[size_t(c)].energy.total);
        ++finished;
    });
    context.progress("anneal", 1.0);
    return results;
}

}  // namespace zomefab::frame
