// SPDX-License-Identifier: GPL-3.0-or-later
// The graph-cut problems on one or two levels, and the cuts (docs/partition.md §3, "Graph size").
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "zomefab/partition/detail/stage.h"

namespace zomefab::partition::detail {

/// Graph-cut nodes: faces (salient regions contracted), or on very large meshes small clusters
/// of faces; with two levels, also large clusters solved first.
Problems prepareProblems(const Surface& S, const PartitionOptions& opt, PartitionResult& res,
                         const RunContext& run) {
    Problems P;
    auto sizeFor = [&](size_t target) {
        return (target > 0 && S.faceCount > target) ? (S.faceCount + target - 1) / target : size_t(1);
    };
    const size_t nodeSize = sizeFor(opt.refineNodeTarget);
    const size_t clusterSize = std::max(nodeSize, sizeFor(opt.graphNodeTarget));
    P.isTwoLevel = clusterSize > nodeSize;
    P.units = buildUnits(S.graph, res.salientFaces, nodeSize);
    P.prob = makeProblem(S, opt, P.units, P.initial);
    if (P.isTwoLevel) {
        P.clusters = buildUnits(S.graph, res.salientFaces, clusterSize);
        P.clusterProb = makeProblem(S, opt, P.clusters, P.clusterInitial);
    }
    // Band of the refinement: about a large cluster's diameter in rings of faces, at least 3.
    P.bandRings = std::max(3, int(std::ceil(std::sqrt(double(clusterSize)))));
    if (P.isTwoLevel)
        run.debug("graph cut on " + std::to_string(P.clusters.count()) + " clusters of up to " +
                  std::to_string(clusterSize) + " faces, then on the " + std::to_string(P.units.count()) +
                  "-node graph within " + std::to_string(P.bandRings) + " rings of their seams");
    res.graphNodes = P.isTwoLevel ? P.clusters.count() : P.units.count();
    res.candidatePairs = P.isTwoLevel ? P.clusterProb.candidateLabels.size() : P.prob.candidateLabels.size();
    res.refineNodes = P.units.count();
    return P;
}

/// The labelling problem over @p units; @p initial receives each node's cheapest candidate
/// (the nearest ball, summed over a node's faces).
LabelingProblem makeProblem(const Surface& S, const PartitionOptions& opt, const Units& units,
                            std::vector<uint32_t>& initial) {
    const size_t unitCount = units.count();
    const int k = S.k;
    LabelingProblem prob;
    prob.labelCount = S.labelCount;
    initial.resize(unitCount);
    // Singletons take their face's k nearest directly; a cluster or salient region takes the
    // union of its faces' candidates, each cost the sum over its faces with the true distances.
    std::vector<std::vector<std::pair<uint32_t, double>>> multi(unitCount);  // only multi-face units
    std::vector<uint32_t> counts(unitCount);
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, unitCount, 256), [&](const tbb::blocked_range<size_t>& r) {
            std::vector<char> isSeen(S.labelCount, 0);
            std::vector<uint32_t> labels;
            for (size_t u = r.begin(); u < r.end(); ++u) {
                const uint32_t b = units.offsets[u], e = units.offsets[u + 1];
                if (e - b == 1) {
                    counts[u] = uint32_t(k);
                    continue;
                }
                labels.clear();
                for (uint32_t j = b; j < e; ++j)
                    for (int i = 0; i < k; ++i) {
                        const uint32_t l = S.near.labels[units.faces[j] * size_t(k) + size_t(i)];
                        if (!isSeen[l]) isSeen[l] = 1, labels.push_back(l);
                    }
                for (uint32_t l : labels) isSeen[l] = 0;
                std::sort(labels.begin(), labels.end());
                for (uint32_t l : labels) multi[u].push_back({l, unitCost(S, opt, units, u, l)});
                counts[u] = uint32_t(labels.size());
            }
        });
    prob.candidateOffsets.assign(unitCount + 1, 0);
    for (size_t u = 0; u < unitCount; ++u)
        prob.candidateOffsets[u + 1] = prob.candidateOffsets[u] + counts[u];
    prob.candidateLabels.resize(prob.candidateOffsets.back());
    prob.candidateCosts.resize(prob.candidateOffsets.back());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 1024),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t u = r.begin(); u < r.end(); ++u) {
                              uint32_t slot = prob.candidateOffsets[u];
                              double bestCost = 1e300;
                              uint32_t bestLabel = 0;
                              auto put = [&](uint32_t l, double c) {
                                  prob.candidateLabels[slot] = l;
                                  prob.candidateCosts[slot++] = c;
                                  if (c < bestCost || (c == bestCost && l < bestLabel))
                                      bestCost = c, bestLabel = l;
                              };
                              if (units.offsets[u + 1] - units.offsets[u] == 1) {
                                  const size_t f = units.faces[units.offsets[u]];
                                  for (int i = 0; i < k; ++i)
                                      put(S.near.labels[f * size_t(k) + size_t(i)],
                                          dataCost(S, opt, S.near.distancesMm[f * size_t(k) + size_t(i)]));
                              } else {
                                  for (const auto& [l, c] : multi[u]) put(l, c);
                              }
                              initial[u] = bestLabel;
                          }
                      });
    // Smoothness weights between nodes: the sum of Eq. (3) over the face pairs they share.
    // Per node, its (neighbour, weight) entries sorted by (neighbour, weight) and summed in that
    // order, so W_uv and W_vu are the same sum bit for bit (and independent of threads).
    auto gather = [&](size_t u, std::vector<std::pair<uint32_t, double>>& list) {
        list.clear();
        for (uint32_t j = units.offsets[u]; j < units.offsets[u + 1]; ++j) {
            const uint32_t f = units.faces[j];
            for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i) {
                const uint32_t v = units.unitOf[S.graph.neighbors[i]];
                if (v != u) list.push_back({v, S.faceEdgeWeights[i]});
            }
        }
        std::sort(list.begin(), list.end());
    };
    std::vector<uint32_t> neighborCounts(unitCount, 0);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 1024),
                      [&](const tbb::blocked_range<size_t>& r) {
                          std::vector<std::pair<uint32_t, double>> list;
                          for (size_t u = r.begin(); u < r.end(); ++u) {
                              gather(u, list);
                              uint32_t n = 0;
                              for (size_t i = 0; i < list.size(); ++i)
                                  n += (i == 0 || list[i].first != list[i - 1].first) ? 1 : 0;
                              neighborCounts[u] = n;
                          }
                      });
    prob.neighborOffsets.assign(unitCount + 1, 0);
    for (size_t u = 0; u < unitCount; ++u)
        prob.neighborOffsets[u + 1] = prob.neighborOffsets[u] + neighborCounts[u];
    prob.neighbors.resize(prob.neighborOffsets.back());
    prob.neighborWeights.resize(prob.neighborOffsets.back());
    tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 1024),
                      [&](const tbb::blocked_range<size_t>& r) {
                          std::vector<std::pair<uint32_t, double>> list;
                          for (size_t u = r.begin(); u < r.end(); ++u) {
                              gather(u, list);
                              uint32_t slot = prob.neighborOffsets[u];
                              for (size_t i = 0; i < list.size();) {
                                  double w = 0.0;
                                  size_t j = i;
                                  while (j < list.size() && list[j].first == list[i].first)
                                      w += list[j++].second;
                                  prob.neighbors[slot] = list[i].first;
                                  prob.neighborWeights[slot++] = w;
                                  i = j;
                              }
                          }
                      });
    return prob;
}

/// The node-level problem with every node outside @p band held at its label in @p labels (its
/// only candidate) and every node inside also allowed its current label: the same energy as
/// P.prob for labellings that agree outside the band, and expansions only touch the band.
LabelingProblem restrictToBand(const Surface& S, const Problems& P, const PartitionOptions& opt,
                               const std::vector<uint32_t>& labels, const std::vector<char>& band) {
    LabelingProblem r;
    r.labelCount = S.labelCount;
    r.candidateLabels.reserve(P.prob.candidateLabels.size());
    r.candidateCosts.reserve(P.prob.candidateCosts.size());
    auto costOf = [&](size_t u, uint32_t l) {
        const int64_t s = P.prob.slotOf(uint32_t(u), l);
        return s >= 0 ? P.prob.candidateCosts[size_t(s)] : unitCost(S, opt, P.units, u, l);
    };
    for (size_t u = 0; u < P.units.count(); ++u) {
        if (band[u]) {
            for (uint32_t s = P.prob.candidateOffsets[u]; s < P.prob.candidateOffsets[u + 1]; ++s) {
                r.candidateLabels.push_back(P.prob.candidateLabels[s]);
                r.candidateCosts.push_back(P.prob.candidateCosts[s]);
            }
            if (P.prob.slotOf(uint32_t(u), labels[u]) < 0) {
                r.candidateLabels.push_back(labels[u]);
                r.candidateCosts.push_back(costOf(u, labels[u]));
            }
        } else {
            r.candidateLabels.push_back(labels[u]);
            r.candidateCosts.push_back(costOf(u, labels[u]));
        }
        r.candidateOffsets.push_back(uint32_t(r.candidateLabels.size()));
    }
    r.neighborOffsets = P.prob.neighborOffsets;
    r.neighbors = P.prob.neighbors;
    r.neighborWeights = P.prob.neighborWeights;
    return r;
}

/// Nodes within P.bandRings rings of faces of a seam of @p labels.
std::vector<char> seamBand(const Surface& S, const Problems& P, const std::vector<uint32_t>& labels) {
    std::vector<int> ring(S.faceCount, -1);
    std::vector<uint32_t> frontier, next;
    for (uint32_t f = 0; f < S.faceCount; ++f)
        for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i)
            if (labels[P.units.unitOf[S.graph.neighbors[i]]] != labels[P.units.unitOf[f]]) {
                ring[f] = 0;
                frontier.push_back(f);
                break;
            }
    for (int r = 1; r <= P.bandRings && !frontier.empty(); ++r) {
        next.clear();
        for (uint32_t f : frontier)
            for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i) {
                const uint32_t h = S.graph.neighbors[i];
                if (ring[h] < 0) ring[h] = r, next.push_back(h);
            }
        frontier.swap(next);
    }
    std::vector<char> band(P.units.count(), 0);
    for (uint32_t f = 0; f < S.faceCount; ++f)
        if (ring[f] >= 0) band[P.units.unitOf[f]] = 1;
    return band;
}

/// One graph cut at w_smoothness @p ws from the nearest-ball labelling (two levels when set).
AlphaExpansionResult graphCut(const Surface& S, const Problems& P, const PartitionOptions& opt,
                              const RunContext& run, double ws, ScheduleStep& st) {
    AlphaExpansionOptions ao;
    ao.smoothnessWeight = ws;
    ao.maxSweeps = opt.maxSweeps;
    st.energyNearest = labelingEnergy(P.prob, P.initial, ws);
    if (!P.isTwoLevel) return alphaExpansion(P.prob, P.initial, ao, run);
    // Clusters from their nearest balls, then the nodes near the cluster seams from there.
    const AlphaExpansionResult coarse = alphaExpansion(P.clusterProb, P.clusterInitial, ao, run);
    std::vector<uint32_t> projected(P.units.count());
    for (size_t u = 0; u < P.units.count(); ++u)
        projected[u] = coarse.labels[P.clusters.unitOf[P.units.faces[P.units.offsets[u]]]];
    const std::vector<char> band = seamBand(S, P, projected);
    st.clusterSweeps = coarse.sweeps;
    st.clusterExpansions = coarse.expansions;
    st.energyClusters = coarse.sweepEnergies.back();
    st.bandNodes = size_t(std::count(band.begin(), band.end(), char(1)));
    return alphaExpansion(restrictToBand(S, P, opt, projected, band), projected, ao, run);
}

/// A re-cut at w_smoothness @p ws of the faces flagged in @p isFree, every other face held at
/// its label in @p labels (its only candidate). Free nodes start from their nearest ball and may
/// take their k nearest. The problem keeps the face-level energy of the whole surface (held
/// nodes add constants), so the seam weight between a free face and a held neighbour counts:
/// free faces next to a kept partition join its label where that is cheaper than a new seam.
AlphaExpansionResult refineCut(const Surface& S, const Problems& P, const PartitionOptions& opt,
                               const RunContext& run, double ws, const std::vector<uint32_t>& labels,
                               const std::vector<char>& isFree, ScheduleStep& st) {
    AlphaExpansionOptions ao;
    ao.smoothnessWeight = ws;
    ao.maxSweeps = opt.maxSweeps;
    const size_t n = P.units.count();
    std::vector<uint32_t> start(n);
    std::vector<char> isFreeNode(n);
    for (size_t u = 0; u < n; ++u) {
        // A node's faces share one label and are edge-connected, so they lie in one partition:
        // all free or all held.
        const uint32_t f = P.units.faces[P.units.offsets[u]];
        isFreeNode[u] = isFree[f];
        start[u] = isFree[f] ? P.initial[u] : labels[f];
    }
    // restrictToBand adds no candidate here: a free node's start (its nearest ball) is one already.
    const LabelingProblem prob = restrictToBand(S, P, opt, start, isFreeNode);
    st.energyNearest = labelingEnergy(prob, start, ws);
    st.bandNodes = size_t(std::count(isFreeNode.begin(), isFreeNode.end(), char(1)));
    return alphaExpansion(prob, start, ao, run);
}

}  // namespace zomefab::partition::detail
