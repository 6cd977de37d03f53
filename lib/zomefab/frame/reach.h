// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Growing the frame toward the surface it does not reach (a deviation from the paper, for
/// mounting): after annealing, exact catalogue struts are added greedily, each to a new ball that
/// keeps the clearance and collides with nothing, the one that covers the most surface samples
/// not yet covered first, until no addition covers minGainSamples more. A piece's tenons run from
/// its inner wall to balls within reach; a frame that is one cube in a 450 mm elephant leaves most
/// pieces with none (docs/frame.md, "Reach").
#pragma once

#include <cstddef>

#include "zomefab/core/run_context.h"
#include "zomefab/frame/frame_field.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame {

struct ReachOptions {
    bool isEnabled = true;  ///< false: the annealed frame as it is (the paper's)
    /// An addition must cover at least this many more surface samples (8 mm apart, about 64 mm² of
    /// surface each) to be made.
    int minGainSamples = 2;
    double sampleSpacingMm = 8.0;  ///< the surface samples (as the τ estimate's)
    /// Stop once this fraction of the reachable samples is covered.
    double coverage = 0.99;
    /// At most this many struts are added (each with its new ball); 0 = no limit.
    int maxStruts = 400;
};

struct ReachResult {
    size_t strutsAdded = 0;
    double coverageBefore = 0, coverageAfter = 0;  ///< covered fraction of the reachable samples
};

/// Whether a strut from ball @p a through @p hole, of @p size, to a new ball at its end may be added
/// to @p structure: the hole free, no ball there yet, the ball and the strut keep the clearance
/// (dMin) and collide with nothing. The test every growth of the frame makes (this one's, and the
/// pieces stage's toward a piece too few pegs hold).
bool canGrowStrut(const zome::Structure& structure, const FrameField& field, zome::BallId a, int hole,
                  int size);

/// Grows @p structure in place (docs above). Deterministic: candidates are ranked by gain, then by
/// (ball id, hole, size). @throw Error(Usage) for bad options; Error(Cancelled).
ReachResult growForReach(zome::Structure& structure, const FrameField& field, const ReachOptions& options,
                         const RunContext& context);

}  // namespace zomefab::frame
