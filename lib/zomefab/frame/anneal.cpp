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
#include "zomefab/core/format.h"
#include "zomefab/frame/detail/chain.h"
#include "zomefab/frame/move_tables.h"
#include "zomefab/frame/outermost.h"
#include "zomefab/frame/random.h"

namespace zomefab::frame {

using zome::BallId;
using zome::kNoId;
using zome::StrutId;

const char* moveKindName(MoveKind kind) {
    switch (kind) {
        case MoveKind::InsNode:
            return "InsNode";
        case MoveKind::DelNode:
            return "DelNode";
        case MoveKind::InsStrut:
            return "InsStrut";
        case MoveKind::DelStrut:
            return "DelStrut";
        case MoveKind::InsBridge:
            return "InsBridge";
        case MoveKind::DelBridge:
            return "DelBridge";
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

namespace detail {

/// CPU time of the calling thread in seconds.
double threadCpuSeconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace detail

using detail::Chain;
using detail::kChainSalt;

namespace {

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
    if (!(e.targetItemCount > 0)) throw Error(ErrorCode::Usage, "the target item count must be positive");
}

}  // namespace

uint64_t chainSeed(uint64_t seed, int chainIndex) {
    return deriveSeed(seed, kChainSalt, uint64_t(chainIndex));
}

ChainResult annealChain(const zome::Structure& initial, const FrameField& field, const EnergyOptions& energy,
                        const AnnealOptions& anneal, uint64_t seed, int chainIndex, RunContext& context,
                        std::atomic<uint64_t>* counter) {
    validate(anneal, energy);
    if (initial.ballCount() == 0) throw Error(ErrorCode::ProcessingFailed, "cannot anneal an empty frame");
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
                                      const EnergyOptions& energy, const AnnealOptions& anneal, int chains,
                                      uint64_t seed, RunContext& context) {
    if (chains < 1) throw Error(ErrorCode::Usage, "at least one chain is needed");
    validate(anneal, energy);
    std::vector<ChainResult> results;
    results.reserve(size_t(chains));
    for (int c = 0; c < chains; ++c) results.push_back({initial, {}, {}});

    // Expected iterations per chain, for the progress fraction.
    double expected = double(anneal.maxIterations);
    if (anneal.finalTemperature > 0 && anneal.coolingFactor < 1) {
        const double byTemperature = std::ceil(std::log(anneal.finalTemperature / anneal.initialTemperature) /
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
        context.detail("anneal: " + std::to_string(done) + " iterations over " + std::to_string(chains) +
                       " chains (" + std::to_string(finished.load()) + " finished), " +
                       formatNumbers("T %.3g, best E %.4f", temperature, best));
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
