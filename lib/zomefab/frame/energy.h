// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The frame energy of paper §4.3, Eq. 1:
///   E = w_fid·E_fid + w_reg·E_reg + w_val·E_val + w_sim·E_sim,
/// written so that every term is a function of per-ball values (the ball's used holes and its
/// cached depth) plus the ball and strut counts. A move then changes E only through the balls it
/// touches, and ΔE is exact arithmetic on a few running sums (docs/frame.md, "Energy").
#pragma once

#include <cstdint>
#include <nlohmann/json.hpp>

#include "zomefab/frame/frame_field.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame {

/// Weights and targets of Eq. 1; defaults are the paper's (§4.3: 1, 100, 1, 1; valence 6).
struct EnergyOptions {
    double fidelityWeight = 1.0;     ///< w_fid
    double regularityWeight = 100.0; ///< w_reg
    double valenceWeight = 1.0;      ///< w_val
    double simplicityWeight = 1.0;   ///< w_sim
    double targetValence = 6.0;      ///< Eq. 5 (the cube lattice's valence)
    /// Which balls E_val sums over (Eq. 5's N_in). false (default): every ball of the frame.
    /// true: only the internal (non-outermost) balls, the literal reading, under which balls of
    /// valence 1 and 2 (always outermost) cost nothing and the annealer tears the lattice into a
    /// tree (docs/frame.md, "Valence").
    bool valenceOnInternalOnly = false;
    /// τ of Eq. 6, the target number of items (balls + struts); > 0. Estimated by
    /// estimateTargetCount() before annealing (paper §4.3.4).
    double targetItemCount = 1.0;
};

/// The four terms (unweighted) and the weighted total.
struct EnergyTerms {
    double fidelity = 0;    ///< E_fid, Eq. 2
    double regularity = 0;  ///< E_reg, Eq. 3 (radians)
    double valence = 0;     ///< E_val, Eq. 5
    double simplicity = 0;  ///< E_sim, Eq. 6
    double total = 0;       ///< Eq. 1
    size_t outermostBalls = 0;
    size_t internalBalls = 0;
    size_t balls = 0;
    size_t struts = 0;
};

nlohmann::json energyToJson(const EnergyTerms& terms);

/// The E_fid summand of one outermost ball whose centre lies @p centreDepthMm inside the surface:
///   ‖p − δ(p)‖² / b0² · (1 + F(clearance)),  ‖p − δ(p)‖ = |centre depth|,
/// with F (sdf::forbiddenZone) evaluated at the ball's clearance = centre depth − ball radius, so
/// that F = 0 exactly where the ball's surface touches dMin (docs/frame.md).
double fidelitySummand(double centreDepthMm, const FrameField& field);

/// What one ball contributes to the running sums.
struct BallEnergy {
    bool isOutermost = false;
    double fidelity = 0;    ///< fidelitySummand when outermost, else 0
    double regularity = 0;  ///< regularityOfMask
    double valence = 0;     ///< (V − 6)²/6 (only when internal if valenceOnInternalOnly)
};

/// The contribution of a ball with used holes @p mask and fidelity summand @p fidelitySummand.
BallEnergy ballEnergy(uint64_t mask, double fidelitySummand, const EnergyOptions& options);

/// Running sums from which E is evaluated (incremental updates add and subtract BallEnergy).
struct EnergySums {
    double fidelity = 0;
    int64_t outermost = 0;
    double regularity = 0;
    double valence = 0;
    int64_t balls = 0;
    int64_t struts = 0;

    void add(const BallEnergy& e) {
        fidelity += e.fidelity;
        outermost += e.isOutermost ? 1 : 0;
        regularity += e.regularity;
        valence += e.valence;
    }
    void subtract(const BallEnergy& e) {
        fidelity -= e.fidelity;
        outermost -= e.isOutermost ? 1 : 0;
        regularity -= e.regularity;
        valence -= e.valence;
    }
};

/// E from the sums:
///   E_fid = Σ_out summand / |N_out|,  E_reg = Σ_balls regularity / (2|S|) (mean over strut ends),
///   E_val = Σ (V − 6)²/6 over all (or the internal) balls,  E_sim = (|N| + |S| − τ)²/τ.
EnergyTerms energyFromSums(const EnergySums& sums, const EnergyOptions& options);

/// Only the weighted total (the annealing hot path).
double totalEnergy(const EnergySums& sums, const EnergyOptions& options);

/// Full recomputation over every ball of @p structure (the reference the incremental ΔE is
/// checked against).
EnergyTerms frameEnergy(const zome::Structure& structure, const FrameField& field,
                        const EnergyOptions& options);

}  // namespace zomefab::frame
