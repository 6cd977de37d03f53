// SPDX-License-Identifier: GPL-3.0-or-later
/// @file One annealing chain (internal to lib/zomefab/frame): its state and running energy sums
/// (chain.cpp), the six moves that propose a Z' (chain_moves.cpp), and the edits that check a Z'
/// and apply it with exact undo (chain_edits.cpp). Paper §4.4, Algorithm 1; docs/frame.md.
#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/frame/anneal.h"
#include "zomefab/frame/energy.h"
#include "zomefab/frame/frame_field.h"
#include "zomefab/frame/move_tables.h"
#include "zomefab/frame/outermost.h"
#include "zomefab/frame/random.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame::detail {

using zome::BallId;
using zome::kNoId;
using zome::StrutId;

/// CPU time of the calling thread in seconds.
double threadCpuSeconds();

inline constexpr uint64_t kChainSalt = 0x636861696E000000ull;  // "chain"
inline constexpr uint32_t kNewBall = 0xFFFFFFFEu;

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
          const AnnealOptions& anneal, uint64_t seed, int index);

    /// Runs the chain. @p tick, when set, is called every 1024 iterations with the current energy
    /// and temperature (progress reports; it must not touch the chain).
    ChainResult run(RunContext& context, std::atomic<uint64_t>* counter,
                    const std::function<void(double, double)>& tick = {});

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
    void resync();

    BallId otherEnd(StrutId t, BallId x) const;
    BallId neighborAt(BallId x, int hole) const;

    /// Do a and b share a neighbour other than each other?
    bool hasCommonNeighbor(BallId a, BallId b) const;

    void setTouched(Proposal& p, BallId id, uint64_t mask);

    /// Sums and energy of Z' from the touched balls only.
    void finish(Proposal& p, int dBalls, int dStruts);

    NewStrut existingStrut(BallId from, int hole, int size, BallId to) const;

    // --- the six moves (paper §4.4) ------------------------------------------------------------

    /// InsNode: replace strut a→b by a→m→b through a new ball m (a triangle from the split table).
    bool proposeInsNode(Proposal& p);

    /// DelNode: remove a ball of valence 1 or 2 with its struts. For valence 2 with neighbours
    /// a, b: when a–b is a catalogue strut with free holes it is added (the inverse of InsNode);
    /// when a and b are already joined nothing is added; otherwise a and b must stay connected.
    bool proposeDelNode(Proposal& p);

    /// The @p k-th set bit of @p mask (0-based).
    static int nthBit(uint64_t mask, uint32_t k);

    /// InsStrut from the triangle table: a random ball a, a random strut a → c, a random strut
    /// c → b; the proposal is the strut a → b when v(a→c) + v(c→b) is a catalogue strut
    /// (MoveTables::closing) and both holes are free. It closes the triangle a, c, b.
    bool proposeTriangleStrut(Proposal& p);

    /// InsBridge (or InsStrut): a strut from a random ball through a random free hole, of a
    /// random size, to the ball already at its end. InsStrut when the two balls share a neighbour
    /// (the strut closes a triangle), InsBridge when they do not (path length > 2).
    bool proposeStrutInsert(Proposal& p);

    /// DelStrut / DelBridge: remove a random strut. DelStrut when its ends keep a common
    /// neighbour (they stay connected by a path of length 2); DelBridge otherwise, which needs a
    /// connectivity search.
    bool proposeStrutDelete(Proposal& p);

    // --- validity and commit --------------------------------------------------------------------

    /// Bidirectional breadth-first search from a and b in Z minus the proposal's removed struts
    /// and ball: true when they meet. Explores about twice the smaller side.
    bool staysConnected(const Proposal& p);

    void revert(std::vector<Edit>& log);

    /// Checks the clearance of the new struts, connectivity and collisions, then applies the
    /// proposal. Returns false (and leaves Z unchanged) when Z' is invalid.
    bool commit(const Proposal& p);

    static void removeFromList(std::vector<uint32_t>& list, std::vector<uint32_t>& index, uint32_t id);
    void removeBallFromList(BallId id);

    void step(double temperature, uint64_t iteration);

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

}  // namespace zomefab::frame::detail
