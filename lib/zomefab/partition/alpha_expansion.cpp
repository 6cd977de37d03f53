// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/alpha_expansion.h"

#include <maxflow.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>

#include "zomefab/core/error.h"

namespace zomefab::partition {

int64_t LabelingProblem::slotOf(uint32_t u, uint32_t label) const {
    for (uint32_t s = candidateOffsets[u]; s < candidateOffsets[u + 1]; ++s)
        if (candidateLabels[s] == label) return s;
    return -1;
}

void LabelingProblem::validate() const {
    auto fail = [](const std::string& what) {
        throw Error(ErrorCode::Internal, "labeling problem: " + what);
    };
    if (candidateOffsets.empty() || neighborOffsets.size() != candidateOffsets.size())
        fail("offset sizes differ");
    if (candidateOffsets.back() != candidateLabels.size() || candidateCosts.size() != candidateLabels.size())
        fail("candidate arrays");
    if (neighborOffsets.back() != neighbors.size() || neighborWeights.size() != neighbors.size())
        fail("neighbour arrays");
    const size_t n = nodeCount();
    for (size_t u = 0; u < n; ++u) {
        if (candidateOffsets[u + 1] <= candidateOffsets[u])
            fail("node " + std::to_string(u) + " has no candidate");
        for (uint32_t s = candidateOffsets[u]; s < candidateOffsets[u + 1]; ++s) {
            if (candidateLabels[s] >= labelCount) fail("label out of range");
            if (!std::isfinite(candidateCosts[s])) fail("non-finite data cost");
            for (uint32_t t = candidateOffsets[u]; t < s; ++t)
                if (candidateLabels[t] == candidateLabels[s]) fail("duplicate candidate");
        }
        for (uint32_t i = neighborOffsets[u]; i < neighborOffsets[u + 1]; ++i) {
            const uint32_t v = neighbors[i];
            if (v >= n || v == u) fail("bad neighbour");
            if (!(neighborWeights[i] >= 0.0) || !std::isfinite(neighborWeights[i])) fail("negative weight");
            bool isFound = false;
            for (uint32_t j = neighborOffsets[v]; j < neighborOffsets[v + 1]; ++j)
                if (neighbors[j] == u && neighborWeights[j] == neighborWeights[i]) isFound = true;
            if (!isFound) fail("asymmetric neighbour lists");
        }
    }
}

double labelingEnergy(const LabelingProblem& p, const std::vector<uint32_t>& labels,
                      double smoothnessWeight) {
    const size_t n = p.nodeCount();
    double data = 0.0, smooth = 0.0;
    for (size_t u = 0; u < n; ++u) {
        const int64_t s = p.slotOf(uint32_t(u), labels[u]);
        if (s < 0) return std::numeric_limits<double>::infinity();
        data += p.candidateCosts[size_t(s)];
        for (uint32_t i = p.neighborOffsets[u]; i < p.neighborOffsets[u + 1]; ++i) {
            const uint32_t v = p.neighbors[i];
            if (v > u && labels[v] != labels[u]) smooth += p.neighborWeights[i];
        }
    }
    return data + smoothnessWeight * smooth;
}

namespace {

using FlowGraph = maxflow::Graph<double, double, double>;

/// The state of one alpha-expansion run: current labels, their slots, per-label node lists.
class Expander {
public:
    Expander(const LabelingProblem& p, std::vector<uint32_t> labels, double ws)
        : mP(p), mWs(ws), mLabels(std::move(labels)) {
        const size_t n = p.nodeCount();
        mSlot.resize(n);
        for (size_t u = 0; u < n; ++u) {
            const int64_t s = p.slotOf(uint32_t(u), mLabels[u]);
            if (s < 0)
                throw Error(ErrorCode::Usage, "initial label " + std::to_string(mLabels[u]) + " of node " +
                                                  std::to_string(u) + " is not one of its candidates");
            mSlot[u] = uint32_t(s);
        }
        // label → (node, slot) lists
        mLabelOffsets.assign(p.labelCount + 1, 0);
        for (uint32_t l : p.candidateLabels) ++mLabelOffsets[l + 1];
        for (uint32_t l = 0; l < p.labelCount; ++l) mLabelOffsets[l + 1] += mLabelOffsets[l];
        mLabelNodes.resize(p.candidateLabels.size());
        mLabelSlots.resize(p.candidateLabels.size());
        std::vector<uint32_t> fill(mLabelOffsets.begin(), mLabelOffsets.end() - 1);
        for (size_t u = 0; u < n; ++u)
            for (uint32_t s = p.candidateOffsets[u]; s < p.candidateOffsets[u + 1]; ++s) {
                const uint32_t k = fill[p.candidateLabels[s]]++;
                mLabelNodes[k] = uint32_t(u);
                mLabelSlots[k] = s;
            }
        size_t maxActive = 0, maxEdges = 0;
        for (uint32_t l = 0; l < p.labelCount; ++l) {
            const size_t a = mLabelOffsets[l + 1] - mLabelOffsets[l];
            maxActive = std::max(maxActive, a);
        }
        maxEdges = 2 * maxActive;  // a first guess: the graph grows when needed
        mGraph = std::make_unique<FlowGraph>(int(std::max<size_t>(maxActive, 16)),
                                             int(std::max<size_t>(maxEdges, 16)));
        mNodeOf.assign(n, -1);
        mEnergy = labelingEnergy(p, mLabels, ws);
    }

    double energy() const { return mEnergy; }
    std::vector<uint32_t>& labels() { return mLabels; }

    /// One expansion move for @p alpha; returns true when it was accepted. @p dirty receives the
    /// labels whose expansion may now find a better move.
    bool expand(uint32_t alpha, std::vector<char>& dirty, double relTol) {
        mActive.clear();
        mAlphaSlot.clear();
        for (uint32_t k = mLabelOffsets[alpha]; k < mLabelOffsets[alpha + 1]; ++k) {
            const uint32_t u = mLabelNodes[k];
            if (mLabels[u] == alpha) continue;  // already alpha: fixed
            mNodeOf[u] = int(mActive.size());
            mActive.push_back(u);
            mAlphaSlot.push_back(mLabelSlots[k]);
        }
        if (mActive.empty()) return false;

        FlowGraph& g = *mGraph;
        g.reset();
        g.add_node(int(mActive.size()));
        for (size_t i = 0; i < mActive.size(); ++i) {
            const uint32_t u = mActive[i];
            const uint32_t fu = mLabels[u];
            // x_u = 0 keeps f_u (source side), x_u = 1 takes alpha (sink side).
            double e0 = mP.candidateCosts[mSlot[u]];
            double e1 = mP.candidateCosts[mAlphaSlot[i]];
            for (uint32_t j = mP.neighborOffsets[u]; j < mP.neighborOffsets[u + 1]; ++j) {
                const uint32_t v = mP.neighbors[j];
                const double w = mWs * mP.neighborWeights[j];
                if (w == 0.0) continue;
                const uint32_t fv = mLabels[v];
                const int nv = mNodeOf[v];
                if (nv >= 0) {
                    if (v < u) continue;  // each active pair once
                    // E(0,0) = w[f_u≠f_v], E(0,1) = E(1,0) = w, E(1,1) = 0: regular since
                    // E00 + E11 ≤ E01 + E10 (Kolmogorov & Zabih 2004).
                    const double a = fu != fv ? w : 0.0;
                    e0 += a;
                    g.add_edge(int(i), nv, float(w - a), float(w));
                } else {
                    // v keeps its label fv (it cannot take alpha, or already has it).
                    if (fu != fv) e0 += w;
                    if (alpha != fv) e1 += w;
                }
            }
            // cap_source is paid when x = 1, cap_sink when x = 0; only the difference matters, and
            // taking it in double keeps the float capacities exact enough.
            const double d = e1 - e0;
            g.add_tweights(int(i), float(d > 0.0 ? d : 0.0), float(d < 0.0 ? -d : 0.0));
        }
        g.maxflow();

        // The exact energy change of the move, so that it is kept only when it lowers E.
        mIsSink.assign(mActive.size(), 0);
        bool isAny = false;
        for (size_t i = 0; i < mActive.size(); ++i)
            if (g.what_segment(int(i)) == FlowGraph::SINK) mIsSink[i] = 1, isAny = true;
        bool isAccepted = false;
        if (isAny) {
            double delta = 0.0;
            for (size_t i = 0; i < mActive.size(); ++i) {
                if (!mIsSink[i]) continue;
                const uint32_t u = mActive[i];
                delta += mP.candidateCosts[mAlphaSlot[i]] - mP.candidateCosts[mSlot[u]];
                for (uint32_t j = mP.neighborOffsets[u]; j < mP.neighborOffsets[u + 1]; ++j) {
                    const uint32_t v = mP.neighbors[j];
                    const int nv = mNodeOf[v];
                    const bool isVChanged = nv >= 0 && mIsSink[size_t(nv)];
                    if (isVChanged && v < u) continue;  // counted from v
                    const uint32_t fvNew = isVChanged ? alpha : mLabels[v];
                    const double before = mLabels[u] != mLabels[v] ? 1.0 : 0.0;
                    const double after = alpha != fvNew ? 1.0 : 0.0;
                    delta += mWs * mP.neighborWeights[j] * (after - before);
                }
            }
            if (delta < -(relTol * std::abs(mEnergy) + 1e-12)) {
                isAccepted = true;
                mEnergy += delta;
                for (size_t i = 0; i < mActive.size(); ++i) {
                    if (!mIsSink[i]) continue;
                    const uint32_t u = mActive[i];
                    mLabels[u] = alpha;
                    mSlot[u] = mAlphaSlot[i];
                }
                for (size_t i = 0; i < mActive.size(); ++i) {
                    if (!mIsSink[i]) continue;
                    const uint32_t u = mActive[i];
                    markCandidates(u, alpha, dirty);
                    for (uint32_t j = mP.neighborOffsets[u]; j < mP.neighborOffsets[u + 1]; ++j)
                        markCandidates(mP.neighbors[j], alpha, dirty);
                }
            }
        }
        for (uint32_t u : mActive) mNodeOf[u] = -1;
        return isAccepted;
    }

    void recomputeEnergy() { mEnergy = labelingEnergy(mP, mLabels, mWs); }

private:
    void markCandidates(uint32_t u, uint32_t alpha, std::vector<char>& dirty) const {
        for (uint32_t s = mP.candidateOffsets[u]; s < mP.candidateOffsets[u + 1]; ++s)
            if (mP.candidateLabels[s] != alpha) dirty[mP.candidateLabels[s]] = 1;
    }

    const LabelingProblem& mP;
    double mWs;
    std::vector<uint32_t> mLabels;
    std::vector<uint32_t> mSlot;
    std::vector<uint32_t> mLabelOffsets, mLabelNodes, mLabelSlots;
    std::unique_ptr<FlowGraph> mGraph;
    std::vector<int> mNodeOf;
    std::vector<uint32_t> mActive, mAlphaSlot;
    std::vector<char> mIsSink;
    double mEnergy = 0.0;
};

}  // namespace

AlphaExpansionResult alphaExpansion(const LabelingProblem& problem,
                                    const std::vector<uint32_t>& initialLabels,
                                    const AlphaExpansionOptions& options, const RunContext& context) {
    if (initialLabels.size() != problem.nodeCount())
        throw Error(ErrorCode::Usage, "alpha-expansion: " + std::to_string(initialLabels.size()) +
                                          " initial labels for " + std::to_string(problem.nodeCount()) +
                                          " nodes");
    if (!(options.smoothnessWeight >= 0.0) || !std::isfinite(options.smoothnessWeight))
        throw Error(ErrorCode::Usage, "alpha-expansion: w_smoothness must be finite and >= 0");
    AlphaExpansionResult result;
    Expander ex(problem, initialLabels, options.smoothnessWeight);
    result.sweepEnergies.push_back(ex.energy());
    // Every label starts dirty; a label is tried again only after a move touched a node that has
    // it as a candidate, or a neighbour of such a node: otherwise its move cannot have changed.
    std::vector<char> dirty(problem.labelCount, 1);
    for (int sweep = 0; sweep < options.maxSweeps; ++sweep) {
        bool isAnyTried = false;
        for (uint32_t alpha = 0; alpha < problem.labelCount; ++alpha) {
            if (!dirty[alpha]) continue;
            dirty[alpha] = 0;
            isAnyTried = true;
            if ((result.expansions & 63) == 0) context.throwIfCancelled();
            ++result.expansions;
            if (ex.expand(alpha, dirty, options.relativeTolerance)) ++result.acceptedExpansions;
        }
        if (!isAnyTried) {
            result.isConverged = true;
            break;
        }
        ++result.sweeps;
        ex.recomputeEnergy();  // drop the rounding of the incremental updates
        result.sweepEnergies.push_back(ex.energy());
    }
    if (!result.isConverged) {
        result.isConverged = true;
        for (char d : dirty)
            if (d) result.isConverged = false;
    }
    result.labels = std::move(ex.labels());
    return result;
}

}  // namespace zomefab::partition
