// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/energy.h"

#include "zomefab/frame/move_tables.h"
#include "zomefab/frame/outermost.h"

namespace zomefab::frame {

nlohmann::json energyToJson(const EnergyTerms& t) {
    return {{"total", t.total},          {"fidelity", t.fidelity},
            {"regularity", t.regularity}, {"valence", t.valence},
            {"simplicity", t.simplicity}, {"outermost_balls", t.outermostBalls},
            {"internal_balls", t.internalBalls}, {"balls", t.balls}, {"struts", t.struts}};
}

double fidelitySummand(double centreDepthMm, const FrameField& field) {
    const double b0 = field.scale().b0Mm;  // d_norm = b0 (paper §4.3.1)
    const double clearanceMm = centreDepthMm - field.scale().ballRadiusMm();
    const double d = centreDepthMm / b0;
    return d * d * (1.0 + sdf::forbiddenZone(clearanceMm, field.zone()));
}

BallEnergy ballEnergy(uint64_t mask, double summand, const EnergyOptions& options) {
    BallEnergy e;
    e.isOutermost = isOutermostMask(mask);
    e.regularity = regularityOfMask(mask);
    if (e.isOutermost) e.fidelity = summand;
    if (!e.isOutermost || !options.valenceOnInternalOnly) {
        const double dv = double(__builtin_popcountll(mask)) - options.targetValence;
        e.valence = dv * dv / options.targetValence;
    }
    return e;
}

EnergyTerms energyFromSums(const EnergySums& s, const EnergyOptions& o) {
    EnergyTerms t;
    t.fidelity = s.outermost > 0 ? s.fidelity / double(s.outermost) : 0.0;
    t.regularity = s.struts > 0 ? s.regularity / (2.0 * double(s.struts)) : 0.0;
    t.valence = s.valence;
    const double items = double(s.balls + s.struts) - o.targetItemCount;
    t.simplicity = items * items / o.targetItemCount;
    t.total = o.fidelityWeight * t.fidelity + o.regularityWeight * t.regularity +
              o.valenceWeight * t.valence + o.simplicityWeight * t.simplicity;
    t.outermostBalls = size_t(s.outermost);
    t.internalBalls = size_t(s.balls - s.outermost);
    t.balls = size_t(s.balls);
    t.struts = size_t(s.struts);
    return t;
}

double totalEnergy(const EnergySums& s, const EnergyOptions& o) { return energyFromSums(s, o).total; }

EnergyTerms frameEnergy(const zome::Structure& structure, const FrameField& field,
                        const EnergyOptions& options) {
    EnergySums sums;
    for (zome::BallId id = 0; id < structure.ballIdBound(); ++id) {
        if (!structure.hasBall(id)) continue;
        const zome::Ball& ball = structure.ball(id);
        const double depth = field.depthMm(ball.positionMm);
        sums.add(ballEnergy(holeMask(ball), fidelitySummand(depth, field), options));
    }
    sums.balls = int64_t(structure.ballCount());
    sums.struts = int64_t(structure.strutCount());
    return energyFromSums(sums, options);
}

}  // namespace zomefab::frame
