// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/target_count.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <optional>

#include "zomefab/core/error.h"
#include "zomefab/frame/detail/coverage.h"
#include "zomefab/frame/random.h"

namespace zomefab::frame {

namespace {

constexpr uint64_t kTargetSalt = 0x7461750000000000ull;  // "tau"

using detail::CoverageGrid;

double reachOf(const FrameField& field) { return detail::coverageReachMm(field); }

struct RunOutcome {
    size_t items = 0;
    double coverage = 0;
};

/// One random assembling run: random ball, random free hole, random size; the strut is added
/// when it and its end ball (new, or an existing ball with the opposite hole free) keep the
/// clearance and collide with nothing.
RunOutcome assembleRandomly(const zome::Structure& initial, const FrameField& field,
                            const std::vector<SurfaceSample>& samples, const TargetCountOptions& o,
                            uint64_t seed, RunContext& context) {
    zome::Structure s = initial;
    CoverageGrid grid(samples, reachOf(field));
    std::vector<zome::BallId> live = s.ballIds();
    for (zome::BallId id : live) grid.cover(s.ball(id).positionMm);
    Rng rng(seed);
    const uint64_t budget = uint64_t(o.attemptsPerBall) * uint64_t(std::max<size_t>(1, live.size()));
    for (uint64_t attempt = 0; attempt < budget && grid.fraction() < o.coverage; ++attempt) {
        if ((attempt & 0xFFF) == 0) context.throwIfCancelled();
        const zome::BallId a = live[rng.below(uint32_t(live.size()))];
        const int hole = int(rng.below(zome::kHoleCount));
        const int size = int(rng.below(zome::kSizeCount));
        const std::optional<detail::StrutAddition> add = detail::strutAddition(s, field, a, hole, size);
        if (!add) continue;
        if (add->existing == zome::kNoId) {
            live.push_back(s.addBall(add->end));
            grid.cover(add->endMm);
        }
        s.addStrut(a, hole, size);
    }
    return {s.ballCount() + s.strutCount(), grid.fraction()};
}

}  // namespace

double coveredFraction(const zome::Structure& structure, const FrameField& field,
                       const std::vector<SurfaceSample>& samples) {
    CoverageGrid grid(samples, reachOf(field));
    for (zome::BallId id : structure.ballIds()) grid.cover(structure.ball(id).positionMm);
    return grid.fraction();
}

TargetCountResult estimateTargetCount(const zome::Structure& initial, const FrameField& field,
                                      const TargetCountOptions& o, uint64_t seed, RunContext& context) {
    if (o.runs < 1) throw Error(ErrorCode::Usage, "the target count needs at least one run");
    if (!(o.fraction > 0 && o.fraction <= 1) || !(o.coverage > 0 && o.coverage <= 1))
        throw Error(ErrorCode::Usage, "target-count fraction and coverage must be in (0, 1]");
    TargetCountResult result;
    const std::vector<SurfaceSample> samples = sampleSurface(field, o.sampleSpacingMm);
    result.surfaceSamples = samples.size();
    for (const SurfaceSample& s : samples) result.reachableSamples += s.isReachable ? 1 : 0;
    result.initialCoverage = coveredFraction(initial, field, samples);
    if (o.fixedTargetCount > 0) {
        result.targetItemCount = o.fixedTargetCount;
        return result;
    }
    context.progress("target count", 0.0);
    std::vector<RunOutcome> runs(size_t(o.runs));
    tbb::parallel_for(0, o.runs, [&](int r) {
        runs[size_t(r)] =
            assembleRandomly(initial, field, samples, o, deriveSeed(seed, kTargetSalt, uint64_t(r)), context);
    });
    context.throwIfCancelled();
    double sum = 0;
    for (const RunOutcome& r : runs) {
        result.runItems.push_back(r.items);
        result.runCoverage.push_back(r.coverage);
        sum += double(r.items);
    }
    result.targetItemCount = o.fraction * sum / double(o.runs);
    context.progress("target count", 1.0);
    return result;
}

}  // namespace zomefab::frame
