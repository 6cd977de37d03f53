// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Simulated annealing of a frame (paper §4.4, Algorithm 1 with its two slips fixed: the
/// proposal Z' is tested for validity and accepted as Z ← Z'). One chain is sequential and
/// deterministic for its seed; annealChains() runs several with TBB and keeps the best.
/// docs/frame.md, "Moves" and "Annealing".
#pragma once

#include <array>
#include <atomic>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/frame/energy.h"
#include "zomefab/frame/frame_field.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame {

/// The six local operations of paper §4.4 (Fig. 7).
enum class MoveKind : uint8_t { InsNode, DelNode, InsStrut, DelStrut, InsBridge, DelBridge };
inline constexpr int kMoveKindCount = 6;
/// "InsNode", "DelNode", ... (the paper's names).
const char* moveKindName(MoveKind kind);

/// What a test or debug hook sees after every accepted move.
struct AcceptedMove {
    MoveKind kind;
    uint64_t iteration;             ///< 1-based iteration of the chain
    const zome::Structure& structure;
    double energy;                  ///< E after the move, from the incremental sums
};

/// Cooling schedule and budgets (paper §4.4.1: T_init 1, ×0.99 every 100 iterations).
struct AnnealOptions {
    double initialTemperature = 1.0;       ///< T_init
    double coolingFactor = 0.99;           ///< C
    uint64_t coolingIntervalIterations = 100;  ///< T ← C·T every this many iterations
    /// T_end: the chain stops once T < T_end (≤ 0: never; then maxIterations must be set). With
    /// the defaults 1e-3 means 68,800 iterations.
    double finalTemperature = 1e-3;
    uint64_t maxIterations = 0;     ///< per chain; 0 = no iteration budget
    /// Per chain, wall clock; 0 = none. A time budget makes the result depend on machine speed.
    double timeLimitSeconds = 0;
    /// Called after every accepted move (tests, --check-moves); runs on the chain's thread.
    std::function<void(const AcceptedMove&)> onAccepted;
};

/// Counters of one chain.
struct ChainStats {
    int chain = 0;
    uint64_t seed = 0;
    uint64_t iterations = 0;   ///< proposed moves (every iteration proposes one)
    uint64_t feasible = 0;     ///< proposals that form a structure whose ΔE was evaluated
    uint64_t passedMetropolis = 0;
    uint64_t accepted = 0;     ///< also passed clearance, collision and connectivity checks
    std::array<uint64_t, kMoveKindCount> feasibleByKind{};
    std::array<uint64_t, kMoveKindCount> acceptedByKind{};
    double finalTemperature = 0;
    double seconds = 0;     ///< wall clock of the chain
    double cpuSeconds = 0;  ///< CPU time of the chain's thread (robust to other load on the machine)
};

nlohmann::json chainStatsToJson(const ChainStats& stats);

struct ChainResult {
    zome::Structure structure;
    EnergyTerms energy;
    ChainStats stats;
};

/// Anneals a copy of @p initial with seed @p seed. @p field must be the one the structure was
/// built in; @p energy carries τ. @p iterationCounter, when given, is incremented as the chain
/// goes (progress of parallel runs). @throw Error(Usage) for an invalid schedule;
/// Error(Cancelled).
ChainResult annealChain(const zome::Structure& initial, const FrameField& field,
                        const EnergyOptions& energy, const AnnealOptions& anneal, uint64_t seed,
                        int chainIndex, RunContext& context,
                        std::atomic<uint64_t>* iterationCounter = nullptr);

/// The seed of chain @p chainIndex derived from the user's seed.
uint64_t chainSeed(uint64_t seed, int chainIndex);

/// Runs @p chains chains in parallel (TBB) with seeds chainSeed(seed, c). Returns every chain's
/// result; bestChain() picks the lowest final energy, ties by chain index, so the choice does not
/// depend on the thread count. Reports progress (iterations, temperature, best energy) on
/// @p context.
std::vector<ChainResult> annealChains(const zome::Structure& initial, const FrameField& field,
                                      const EnergyOptions& energy, const AnnealOptions& anneal,
                                      int chains, uint64_t seed, RunContext& context);

size_t bestChain(const std::vector<ChainResult>& results);

}  // namespace zomefab::frame
