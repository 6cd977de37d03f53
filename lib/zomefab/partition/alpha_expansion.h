// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Multi-label Potts energy minimisation by alpha-expansion (Boykov, Veksler & Zabih 2001;
/// Boykov & Kolmogorov 2004), each expansion move solved with Debian's libmaxflow. This is the
/// solver of the paper's Eq. (1); partition.h builds the problem from a mesh.
///
/// The energy of a labelling f over nodes ("units": a triangle, or a salient region contracted to
/// one node) is
///   E(f) = Σ_u D_u(f_u) + w_smoothness · Σ_{(u,v)} W_uv · [f_u ≠ f_v],
/// with D_u finite only for the node's candidate labels (any other label is prohibited) and
/// W_uv ≥ 0, so the pairwise term is a metric and every expansion move is an exact s-t min cut.
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/run_context.h"

namespace zomefab::partition {

/// A multi-label problem in CSR form. Node u's candidates are slots
/// candidateOffsets[u] .. candidateOffsets[u+1]) of candidateLabels / candidateCosts; its
/// neighbours are slots neighborOffsets[u] .. neighborOffsets[u+1]) of neighbors / neighborWeights,
/// each undirected pair listed from both ends with the same weight.
struct LabelingProblem {
    uint32_t labelCount = 0;
    std::vector<uint32_t> candidateOffsets{0};
    std::vector<uint32_t> candidateLabels;  ///< label ids < labelCount, distinct per node
    std::vector<double> candidateCosts;     ///< D_u(label), finite, any sign
    std::vector<uint32_t> neighborOffsets{0};
    std::vector<uint32_t> neighbors;
    std::vector<double> neighborWeights;    ///< W_uv ≥ 0, before the w_smoothness factor

    size_t nodeCount() const { return candidateOffsets.size() - 1; }
    /// The candidate slot of @p label at node @p u, or -1 when the label is prohibited there.
    int64_t slotOf(uint32_t u, uint32_t label) const;
    /// @throw Error(Internal) when the arrays are inconsistent (sizes, ranges, asymmetry, W < 0).
    void validate() const;
};

struct AlphaExpansionOptions {
    double smoothnessWeight = 1.0;  ///< w_smoothness of Eq. (1)
    int maxSweeps = 100;            ///< passes over the labels at most (each pass tries only labels
                                    ///< whose neighbourhood changed since their last try)
    /// A move is accepted only when it lowers E by more than this fraction of |E| (+1e-12), so
    /// rounding cannot make the loop cycle.
    double relativeTolerance = 1e-9;
};

struct AlphaExpansionResult {
    std::vector<uint32_t> labels;    ///< per node
    std::vector<double> sweepEnergies;  ///< E before the first sweep, then after each sweep
    int sweeps = 0;                  ///< passes run
    int expansions = 0;              ///< expansion moves tried (max-flow solves)
    int acceptedExpansions = 0;      ///< moves that lowered the energy
    bool isConverged = false;        ///< false when maxSweeps stopped it before no label improved
};

/// E(f) for @p labels; +infinity when some node has a prohibited label.
double labelingEnergy(const LabelingProblem& problem, const std::vector<uint32_t>& labels,
                      double smoothnessWeight);

/// Runs alpha-expansion from @p initialLabels until no expansion move lowers the energy (or
/// maxSweeps). Labels are tried in increasing order; the result is deterministic. The energy never
/// increases: every move is checked against the exact energy before it is kept.
/// @throw Error(Usage) when an initial label is prohibited at its node, Error(Cancelled).
AlphaExpansionResult alphaExpansion(const LabelingProblem& problem, const std::vector<uint32_t>& initialLabels,
                                    const AlphaExpansionOptions& options, const RunContext& context);

}  // namespace zomefab::partition
