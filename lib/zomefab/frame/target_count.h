// SPDX-License-Identifier: GPL-3.0-or-later
/// @file τ, the target item count of the simplicity term (paper §4.3.4, Eq. 6): ten random
/// assembling runs, each growing the initial frame with random catalogue struts until the frame
/// reaches a shape-similarity threshold; τ = 90% of the mean item count (balls + struts).
/// docs/frame.md, "Target item count".
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/frame/frame_field.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame {

struct TargetCountOptions {
    int runs = 10;              ///< random assembling runs (paper: ten)
    double fraction = 0.9;      ///< τ = fraction × mean items (paper: 90%)
    /// Shape similarity reached when this fraction of the reachable surface samples has a ball
    /// whose surface is within dMax of it (the forbidden zone's outer edge).
    double coverage = 0.9;
    double sampleSpacingMm = 8.0;  ///< surface sample spacing
    /// A run that has not reached the coverage after this many attempts per initial ball stops
    /// and counts its items as they are (thin parts the frame cannot reach).
    int attemptsPerBall = 1000;
    /// > 0: use this τ and skip the runs.
    double fixedTargetCount = 0;
};

struct TargetCountResult {
    double targetItemCount = 0;        ///< τ
    std::vector<size_t> runItems;      ///< items of each run when it stopped
    std::vector<double> runCoverage;   ///< coverage each run reached
    double initialCoverage = 0;        ///< coverage of the initial frame
    size_t surfaceSamples = 0;
    size_t reachableSamples = 0;
};

/// The samples covered by @p structure: a sample is covered when a ball centre lies within
/// dMax + ball radius of it. Returns the covered fraction of the reachable samples (1 when none
/// is reachable).
double coveredFraction(const zome::Structure& structure, const FrameField& field,
                       const std::vector<SurfaceSample>& samples);

/// Estimates τ from @p initial. Runs in parallel; run r uses deriveSeed(seed, salt, r), so the
/// result does not depend on the thread count. @throw Error(Usage) for runs < 1 or fractions
/// outside (0, 1]; Error(Cancelled).
TargetCountResult estimateTargetCount(const zome::Structure& initial, const FrameField& field,
                                      const TargetCountOptions& options, uint64_t seed,
                                      RunContext& context);

}  // namespace zomefab::frame
