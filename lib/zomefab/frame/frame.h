// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The frame stage (paper §4): initial B0 cube lattice → τ estimate → parallel annealing
/// chains → the best frame, plus the measures and checks the report and the tests use.
/// docs/frame.md.
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/transform.h"
#include "zomefab/frame/anneal.h"
#include "zomefab/frame/energy.h"
#include "zomefab/frame/frame_field.h"
#include "zomefab/frame/lattice.h"
#include "zomefab/frame/reach.h"
#include "zomefab/frame/target_count.h"
#include "zomefab/sdf/interior_field.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame {

struct FrameOptions {
    /// Offset/rotation search and the kit's physical sizes. Its scale.b0Mm and zone.dMinMm /
    /// zone.dMaxMm come from the Fabrication (latticeOptionsFor); what is set here is replaced.
    LatticeOptions lattice;
    EnergyOptions energy;       ///< weights; targetItemCount is replaced by the τ estimate
    TargetCountOptions target;  ///< how τ is estimated (or fixed)
    AnnealOptions anneal;       ///< cooling schedule and budgets
    ReachOptions reach;         ///< growth toward the surface after annealing (reach.h)
    /// Independent annealing chains run in parallel; the best is kept. 8: on the demo bunny at 400 mm
    /// the best of 8 has E = 117.5 against 126.4 for one chain, in 0.08 s on 2 cores (32: 116.2).
    int chains = 8;
    double surfaceSampleSpacingMm = 6.0;  ///< surface samples for the gap measure
    /// Debug: after every accepted move, verifyFrame() and a full energy recomputation; the first
    /// violation or a ΔE mismatch beyond 1e-9 relative throws Error(Internal). Slow.
    bool checkEveryMove = false;
};

/// Quality measures of a frame in its field.
struct FrameMetrics {
    zome::PartsList parts;
    std::vector<size_t> valenceHistogram;  ///< [v] = balls with v struts
    size_t outermostBalls = 0;
    /// Smallest distance of any part's surface to the object's surface: ball centre depth − ball
    /// radius, strut axis depth − strut radius. ≥ dMin for a valid frame.
    double minClearanceMm = 0;
    double minBallClearanceMm = 0;
    double minStrutClearanceMm = 0;
    /// Range of the outermost balls' clearance (centre depth − ball radius).
    double outermostClearanceMinMm = 0;
    double outermostClearanceMaxMm = 0;
    /// Largest distance from a surface sample to the nearest ball's surface: how far the shell
    /// must span where the frame is farthest; over all samples, and over the reachable ones.
    double largestGapMm = 0;
    double largestReachableGapMm = 0;
    double coverage = 0;  ///< covered fraction of the reachable samples (target_count.h)
    size_t surfaceSamples = 0;
};

FrameMetrics measureFrame(const zome::Structure& structure, const FrameField& field, double sampleSpacingMm);
nlohmann::json metricsToJson(const FrameMetrics& metrics);

/// Every violated invariant of a frame, one line each (empty = valid): struts exact catalogue
/// struts whose holes match both balls, each hole used once, no collision, every ball and strut
/// clear of the forbidden zone (dMin), the frame connected.
std::vector<std::string> verifyFrame(const zome::Structure& structure, const FrameField& field);

struct FrameResult {
    zome::Structure structure;       ///< the best chain's frame, ids compacted
    sdf::ForbiddenZoneOptions zone;  ///< the forbidden zone it was built in (from the Fabrication)
    uint64_t seed = 0;               ///< seedFor(fabrication, SeedStream::Frame)
    double rotationDeg = 0;          ///< lattice rotation about z
    LatticeResult lattice;           ///< the initial frame and the search statistics
    TargetCountResult target;        ///< τ and the runs it came from
    EnergyOptions energyOptions;     ///< with τ filled in
    EnergyTerms initialEnergy;
    EnergyTerms annealedEnergy;  ///< the best chain's
    EnergyTerms finalEnergy;     ///< of the structure returned (after the reach growth)
    ReachResult reach;
    std::vector<ChainStats> chains;
    std::vector<EnergyTerms> chainEnergies;
    size_t bestChain = 0;
    double latticeSeconds = 0, targetSeconds = 0, annealSeconds = 0, totalSeconds = 0;
};

/// @p options' lattice with the Fabrication's b0 (the kit's scale) and forbidden zone (d_min =
/// frameClearanceMm, d_max = b0): the one place the frame stage takes them from.
LatticeOptions latticeOptionsFor(const Fabrication& fabrication, const LatticeOptions& options);

/// The frame stage. @p field is the object's "interior" field in mm (z up).
/// @throw Error(ProcessingFailed) when the object is too thin for one cube; Error(Usage) for
///        invalid options; Error(Cancelled).
FrameResult buildFrame(const sdf::InteriorField& field, const Fabrication& fabrication,
                       const FrameOptions& options, RunContext& context);

/// transform_mm of the frame file: the field's transform_mm (input mesh → field mm) followed by
/// the lattice rotation R(−rotationDeg) (field mm → frame mm).
Transform4d frameTransformMm(const Transform4d& fieldTransformMm, double rotationDeg);

/// The JSON report of a run: options, lattice search, τ, energy terms before and after, chains,
/// timings, iterations per second, and the metrics of the initial and final frames.
nlohmann::json frameReportJson(const FrameResult& result, const FrameOptions& options,
                               const FrameMetrics& initialMetrics, const FrameMetrics& finalMetrics);

}  // namespace zomefab::frame
