// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/frame.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "zomefab/core/error.h"
#include "zomefab/frame/outermost.h"

namespace zomefab::frame {

namespace {

double distance(const Vec3d& a, const Vec3d& b) {
    return std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                     (a[2] - b[2]) * (a[2] - b[2]));
}

/// Smallest depth along the strut axis, sampled every 0.5 mm (reports only).
double strutMinDepthMm(const zome::Strut& s, const zome::Structure& st, const FrameField& field) {
    const Vec3d& p = st.ball(s.a).positionMm;
    const Vec3d& q = st.ball(s.b).positionMm;
    const int n = std::max(2, int(std::ceil(distance(p, q) / 0.5)));
    double best = HUGE_VAL;
    for (int i = 0; i <= n; ++i) {
        const double t = double(i) / n;
        best = std::min(best, field.depthMm({p[0] + t * (q[0] - p[0]), p[1] + t * (q[1] - p[1]),
                                             p[2] + t * (q[2] - p[2])}));
    }
    return best;
}

}  // namespace

FrameMetrics measureFrame(const zome::Structure& s, const FrameField& field, double spacingMm) {
    FrameMetrics m;
    m.parts = zome::partsList(s);
    const double rBall = s.scale().ballRadiusMm();
    m.minBallClearanceMm = m.minStrutClearanceMm = HUGE_VAL;
    m.outermostClearanceMinMm = HUGE_VAL;
    m.outermostClearanceMaxMm = -HUGE_VAL;
    std::vector<Vec3d> centres;
    for (zome::BallId id : s.ballIds()) {
        const zome::Ball& b = s.ball(id);
        centres.push_back(b.positionMm);
        if (m.valenceHistogram.size() <= b.valence) m.valenceHistogram.resize(b.valence + 1u, 0);
        ++m.valenceHistogram[b.valence];
        const double clearance = field.depthMm(b.positionMm) - rBall;
        m.minBallClearanceMm = std::min(m.minBallClearanceMm, clearance);
        if (isOutermostMask(holeMask(b))) {
            ++m.outermostBalls;
            m.outermostClearanceMinMm = std::min(m.outermostClearanceMinMm, clearance);
            m.outermostClearanceMaxMm = std::max(m.outermostClearanceMaxMm, clearance);
        }
    }
    for (zome::StrutId id : s.strutIds()) {
        const zome::Strut& st = s.strut(id);
        m.minStrutClearanceMm = std::min(m.minStrutClearanceMm,
                                         strutMinDepthMm(st, s, field) - s.scale().strutRadiusMm(st.color));
    }
    m.minClearanceMm = std::min(m.minBallClearanceMm, m.minStrutClearanceMm);

    const std::vector<SurfaceSample> samples = sampleSurface(field, spacingMm);
    m.surfaceSamples = samples.size();
    m.coverage = coveredFraction(s, field, samples);
    // Nearest ball of every sample, by brute force in parallel (a few ms); max is order-free.
    std::vector<double> gap(samples.size(), 0.0);
    tbb::parallel_for(size_t(0), samples.size(), [&](size_t i) {
        double best = HUGE_VAL;
        for (const Vec3d& c : centres) best = std::min(best, distance(c, samples[i].positionMm));
        gap[i] = best - rBall;
    });
    for (size_t i = 0; i < samples.size(); ++i) {
        m.largestGapMm = std::max(m.largestGapMm, gap[i]);
        if (samples[i].isReachable) m.largestReachableGapMm = std::max(m.largestReachableGapMm, gap[i]);
    }
    if (m.outermostBalls == 0) m.outermostClearanceMinMm = m.outermostClearanceMaxMm = 0;
    if (s.strutCount() == 0) m.minStrutClearanceMm = 0;
    if (s.ballCount() == 0) m.minBallClearanceMm = m.minClearanceMm = 0;
    return m;
}

nlohmann::json metricsToJson(const FrameMetrics& m) {
    return {{"parts", zome::partsListToJson(m.parts)},
            {"valence_histogram", m.valenceHistogram},
            {"outermost_balls", m.outermostBalls},
            {"min_clearance_mm", m.minClearanceMm},
            {"min_ball_clearance_mm", m.minBallClearanceMm},
            {"min_strut_clearance_mm", m.minStrutClearanceMm},
            {"outermost_clearance_mm", {m.outermostClearanceMinMm, m.outermostClearanceMaxMm}},
            {"largest_gap_mm", m.largestGapMm},
            {"largest_reachable_gap_mm", m.largestReachableGapMm},
            {"coverage", m.coverage},
            {"surface_samples", m.surfaceSamples}};
}

std::vector<std::string> verifyFrame(const zome::Structure& s, const FrameField& field) {
    std::vector<std::string> problems;
    for (zome::StrutId id : s.strutIds()) {
        const zome::Strut& st = s.strut(id);
        const std::string name = "strut " + std::to_string(id);
        const std::optional<zome::StrutMatch> m =
            zome::matchStrut(s.ball(st.b).position - s.ball(st.a).position);
        if (!m || m->hole != st.holeA || m->size != st.size || m->color != st.color)
            problems.push_back(name + " is not the exact catalogue strut it claims");
        if (st.holeB != zome::oppositeHole(st.holeA))
            problems.push_back(name + " uses holes that are not opposite");
        if (s.ball(st.a).holes[st.holeA] != id || s.ball(st.b).holes[st.holeB] != id)
            problems.push_back(name + " is not in the holes of its balls");
        const double limit = field.strutDepthLimitMm(st.color);
        const Vec3d& p = s.ball(st.a).positionMm;
        const Vec3d& q = s.ball(st.b).positionMm;
        if (!field.isSegmentAllowed(p, field.depthMm(p), q, field.depthMm(q), limit))
            problems.push_back(name + " comes closer than dMin to the surface");
    }
    std::vector<zome::BallId> ids = s.ballIds();
    for (zome::BallId id : ids) {
        const zome::Ball& b = s.ball(id);
        int used = 0;
        for (int h = 0; h < zome::kHoleCount; ++h) {
            const zome::StrutId t = b.holes[size_t(h)];
            if (t == zome::kNoId) continue;
            ++used;
            if (!s.hasStrut(t) || !((s.strut(t).a == id && s.strut(t).holeA == h) ||
                                    (s.strut(t).b == id && s.strut(t).holeB == h)))
                problems.push_back("ball " + std::to_string(id) + " hole " + std::to_string(h) +
                                   " holds a strut that does not end there");
        }
        if (used != b.valence) problems.push_back("ball " + std::to_string(id) + " has a wrong valence");
        if (!field.isBallAllowed(field.depthMm(b.positionMm)))
            problems.push_back("ball " + std::to_string(id) + " comes closer than dMin to the surface");
    }
    for (const zome::Collision& c : zome::findCollisions(s))
        problems.push_back(std::string(zome::collisionKindName(c.kind)) + " collision " +
                           std::to_string(c.first) + "/" + std::to_string(c.second));
    if (!ids.empty()) {
        std::vector<uint8_t> seen(s.ballIdBound(), 0);
        std::vector<zome::BallId> queue{ids.front()};
        seen[ids.front()] = 1;
        for (size_t i = 0; i < queue.size(); ++i) {
            const zome::Ball& b = s.ball(queue[i]);
            for (int h = 0; h < zome::kHoleCount; ++h) {
                const zome::StrutId t = b.holes[size_t(h)];
                if (t == zome::kNoId || !s.hasStrut(t)) continue;
                const zome::BallId y = s.strut(t).a == queue[i] ? s.strut(t).b : s.strut(t).a;
                if (!seen[y]) {
                    seen[y] = 1;
                    queue.push_back(y);
                }
            }
        }
        if (queue.size() != ids.size())
            problems.push_back("the frame is not connected (" + std::to_string(queue.size()) + " of " +
                               std::to_string(ids.size()) + " balls reachable)");
    }
    return problems;
}

LatticeOptions latticeOptionsFor(const Fabrication& fabrication, const LatticeOptions& options) {
    LatticeOptions o = options;
    o.scale.b0Mm = fabrication.b0Mm;
    o.zone.dMinMm = fabrication.frameDMinMm();
    o.zone.dMaxMm = fabrication.frameReachMm();
    return o;
}

FrameResult buildFrame(const sdf::InteriorField& field, const Fabrication& fabrication,
                       const FrameOptions& options, RunContext& context) {
    checkFabrication(fabrication);
    const Stopwatch total;
    FrameResult r;
    Stopwatch clock;
    const LatticeOptions lattice = latticeOptionsFor(fabrication, options.lattice);
    r.zone = lattice.zone;
    r.seed = seedFor(fabrication, SeedStream::Frame);
    r.lattice = initialLattice(field, lattice, context);
    r.latticeSeconds = clock.seconds();
    if (r.lattice.cubes == 0)
        context.detail(
            "no whole B0 cube fits (the object is thinner than a cube and its clearance): the frame "
            "starts from " +
            std::to_string(r.lattice.structure.ballCount()) + " balls and " +
            std::to_string(r.lattice.structure.strutCount()) + " B0 struts");
    r.rotationDeg = r.lattice.rotationDeg;
    const FrameField ff(field, r.rotationDeg, r.lattice.structure.scale(), r.zone);

    clock = Stopwatch();
    r.target = estimateTargetCount(r.lattice.structure, ff, options.target, r.seed, context);
    r.targetSeconds = clock.seconds();
    r.energyOptions = options.energy;
    r.energyOptions.targetItemCount = r.target.targetItemCount;
    r.initialEnergy = frameEnergy(r.lattice.structure, ff, r.energyOptions);

    AnnealOptions anneal = options.anneal;
    if (options.checkEveryMove) {
        const EnergyOptions energy = r.energyOptions;
        const std::function<void(const AcceptedMove&)> user = options.anneal.onAccepted;
        anneal.onAccepted = [&ff, energy, user](const AcceptedMove& move) {
            const std::string after = std::string("after ") + moveKindName(move.kind) + " (iteration " +
                                      std::to_string(move.iteration) + "): ";
            const std::vector<std::string> problems = verifyFrame(move.structure, ff);
            if (!problems.empty()) throw Error(ErrorCode::Internal, after + problems.front());
            const double full = frameEnergy(move.structure, ff, energy).total;
            if (std::abs(full - move.energy) > 1e-9 * std::max(1.0, std::abs(full)))
                throw Error(ErrorCode::Internal, after + "incremental energy " + std::to_string(move.energy) +
                                                     " differs from the recomputed " + std::to_string(full));
            if (user) user(move);
        };
    }
    clock = Stopwatch();
    std::vector<ChainResult> chains =
        annealChains(r.lattice.structure, ff, r.energyOptions, anneal, options.chains, r.seed, context);
    r.annealSeconds = clock.seconds();
    r.bestChain = bestChain(chains);
    for (const ChainResult& c : chains) {
        r.chains.push_back(c.stats);
        r.chainEnergies.push_back(c.energy);
    }
    r.annealedEnergy = chains[r.bestChain].energy;
    zome::Structure grown = std::move(chains[r.bestChain].structure);
    r.reach = growForReach(grown, ff, options.reach, context);
    r.finalEnergy = r.reach.strutsAdded > 0 ? frameEnergy(grown, ff, r.energyOptions) : r.annealedEnergy;
    r.structure = grown.compacted();
    r.totalSeconds = total.seconds();
    return r;
}

Transform4d frameTransformMm(const Transform4d& fieldTransformMm, double rotationDeg) {
    if (rotationDeg == 0.0) return fieldTransformMm;
    return rotationAboutZ(-rotationDeg) * fieldTransformMm;
}

nlohmann::json frameReportJson(const FrameResult& r, const FrameOptions& o, const FrameMetrics& before,
                               const FrameMetrics& after) {
    uint64_t iterations = 0, feasible = 0;
    nlohmann::json chains = nlohmann::json::array();
    for (size_t c = 0; c < r.chains.size(); ++c) {
        iterations += r.chains[c].iterations;
        feasible += r.chains[c].feasible;
        nlohmann::json j = chainStatsToJson(r.chains[c]);
        j["energy"] = energyToJson(r.chainEnergies[c]);
        chains.push_back(j);
    }
    const EnergyOptions& e = r.energyOptions;
    const AnnealOptions& a = o.anneal;
    return {{"options",
             {{"weights",
               {{"fidelity", e.fidelityWeight},
                {"regularity", e.regularityWeight},
                {"valence", e.valenceWeight},
                {"simplicity", e.simplicityWeight}}},
              {"target_valence", e.targetValence},
              {"valence_on_internal_only", e.valenceOnInternalOnly},
              {"d_min_mm", r.zone.dMinMm},
              {"d_max_mm", r.zone.dMaxMm},
              {"f_thick", r.zone.fThick},
              {"f_max", r.zone.fMax},
              {"b0_mm", r.structure.scale().b0Mm},
              {"t_init", a.initialTemperature},
              {"cooling_factor", a.coolingFactor},
              {"cooling_interval", a.coolingIntervalIterations},
              {"t_end", a.finalTemperature},
              {"max_iterations", a.maxIterations},
              {"time_limit_s", a.timeLimitSeconds},
              {"chains", o.chains},
              {"seed", r.seed}}},
            {"lattice",
             {{"rotation_deg", r.lattice.rotationDeg},
              {"offset_mm", r.lattice.offsetMm},
              {"placements_tried", r.lattice.placementsTried},
              {"cubes", r.lattice.cubes},
              {"kept_cubes", r.lattice.keptCubes},
              {"first_placement_cubes", r.lattice.firstPlacementCubes},
              {"seconds", r.latticeSeconds}}},
            {"target_count",
             {{"tau", r.target.targetItemCount},
              {"run_items", r.target.runItems},
              {"run_coverage", r.target.runCoverage},
              {"initial_coverage", r.target.initialCoverage},
              {"surface_samples", r.target.surfaceSamples},
              {"reachable_samples", r.target.reachableSamples},
              {"seconds", r.targetSeconds}}},
            {"energy_before", energyToJson(r.initialEnergy)},
            {"energy_annealed", energyToJson(r.annealedEnergy)},
            {"energy_after", energyToJson(r.finalEnergy)},
            {"reach",
             {{"enabled", o.reach.isEnabled},
              {"min_gain_samples", o.reach.minGainSamples},
              {"struts_added", r.reach.strutsAdded},
              {"coverage_before", r.reach.coverageBefore},
              {"coverage_after", r.reach.coverageAfter}}},
            {"best_chain", r.bestChain},
            {"chains", chains},
            {"iterations", iterations},
            {"feasible_proposals", feasible},
            {"anneal_seconds", r.annealSeconds},
            {"iterations_per_second", r.annealSeconds > 0 ? double(iterations) / r.annealSeconds : 0.0},
            {"run_seconds", r.totalSeconds},
            {"initial_frame", metricsToJson(before)},
            {"frame", metricsToJson(after)}};
}

}  // namespace zomefab::frame
