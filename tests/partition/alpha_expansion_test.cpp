// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "zomefab/core/error.h"
#include "zomefab/partition/alpha_expansion.h"

using namespace zomefab;
using namespace zomefab::partition;

namespace {

/// A problem from per-node cost rows (cost < 1e9 = candidate) and weighted undirected edges.
LabelingProblem makeProblem(uint32_t labels, const std::vector<std::vector<double>>& costs,
                            const std::vector<std::tuple<uint32_t, uint32_t, double>>& edges) {
    LabelingProblem p;
    p.labelCount = labels;
    p.candidateOffsets = {0};
    for (const auto& row : costs) {
        for (uint32_t l = 0; l < labels; ++l)
            if (row[l] < 1e9) p.candidateLabels.push_back(l), p.candidateCosts.push_back(row[l]);
        p.candidateOffsets.push_back(uint32_t(p.candidateLabels.size()));
    }
    std::vector<std::vector<std::pair<uint32_t, double>>> adj(costs.size());
    for (const auto& [a, b, w] : edges) {
        adj[a].push_back({b, w});
        adj[b].push_back({a, w});
    }
    p.neighborOffsets = {0};
    for (const auto& list : adj) {
        for (const auto& [v, w] : list) p.neighbors.push_back(v), p.neighborWeights.push_back(w);
        p.neighborOffsets.push_back(uint32_t(p.neighbors.size()));
    }
    p.validate();
    return p;
}

/// The global minimum by enumeration (small problems only).
double bruteForceMinimum(const LabelingProblem& p, double ws, std::vector<uint32_t>* best = nullptr) {
    const size_t n = p.nodeCount();
    std::vector<uint32_t> f(n, 0);
    double bestE = INFINITY;
    while (true) {
        const double e = labelingEnergy(p, f, ws);
        if (e < bestE) {
            bestE = e;
            if (best) *best = f;
        }
        size_t i = 0;
        while (i < n && ++f[i] == p.labelCount) f[i++] = 0;
        if (i == n) break;
    }
    return bestE;
}

std::vector<uint32_t> argminLabels(const LabelingProblem& p) {
    std::vector<uint32_t> f(p.nodeCount());
    for (size_t u = 0; u < p.nodeCount(); ++u) {
        double best = INFINITY;
        for (uint32_t s = p.candidateOffsets[u]; s < p.candidateOffsets[u + 1]; ++s)
            if (p.candidateCosts[s] < best) best = p.candidateCosts[s], f[u] = p.candidateLabels[s];
    }
    return f;
}

}  // namespace

TEST_CASE("alpha_expansion: two-label chain reaches the known optimum") {
    // Ten nodes in a chain. Data: node i prefers label 0 for i < 4 and label 1 for i >= 4, except
    // node 6 which prefers 0 by a little (0.3). Edges of weight 1: flipping node 6 to 1 saves two
    // cuts (2.0) for 0.3 more data, so the optimum is one cut between nodes 3 and 4, energy =
    // Σ min data + 0.3 + 1 (one cut).
    std::vector<std::vector<double>> costs;
    for (int i = 0; i < 10; ++i) {
        if (i < 4) costs.push_back({0.0, 1.0});
        else if (i == 6) costs.push_back({0.0, 0.3});
        else costs.push_back({1.0, 0.0});
    }
    std::vector<std::tuple<uint32_t, uint32_t, double>> edges;
    for (uint32_t i = 0; i + 1 < 10; ++i) edges.emplace_back(i, i + 1, 1.0);
    const LabelingProblem p = makeProblem(2, costs, edges);
    const std::vector<uint32_t> start = argminLabels(p);
    CHECK(labelingEnergy(p, start, 1.0) == doctest::Approx(3.0));  // two cuts around node 6

    AlphaExpansionOptions o;
    o.smoothnessWeight = 1.0;
    const AlphaExpansionResult r = alphaExpansion(p, start, o, RunContext::silent());
    const std::vector<uint32_t> expected{0, 0, 0, 0, 1, 1, 1, 1, 1, 1};
    CHECK(r.labels == expected);
    CHECK(r.sweepEnergies.back() == doctest::Approx(1.3));
    std::vector<uint32_t> best;
    CHECK(bruteForceMinimum(p, 1.0, &best) == doctest::Approx(1.3));
    CHECK(best == expected);
    CHECK(r.isConverged);

    // With a huge smoothness weight the optimum is one label everywhere: the cheaper one (1).
    o.smoothnessWeight = 100.0;
    const AlphaExpansionResult all = alphaExpansion(p, start, o, RunContext::silent());
    CHECK(all.labels == std::vector<uint32_t>(10, 1));
}

TEST_CASE("alpha_expansion: energy never increases and stays within the Potts bound on random grids") {
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> cost(0.0, 1.0), weight(0.0, 0.6);
    for (int trial = 0; trial < 20; ++trial) {
        // 3 × 3 grid, 3 labels, one random label prohibited at some nodes.
        const uint32_t w = 3, h = 3, labels = 3;
        std::vector<std::vector<double>> costs(w * h);
        for (auto& row : costs) {
            row = {cost(rng), cost(rng), cost(rng)};
            if (cost(rng) < 0.3) row[size_t(rng() % 3)] = 1e10;
            if (row[0] >= 1e9 && row[1] >= 1e9 && row[2] >= 1e9) row[0] = 0.5;
        }
        std::vector<std::tuple<uint32_t, uint32_t, double>> edges;
        for (uint32_t y = 0; y < h; ++y)
            for (uint32_t x = 0; x < w; ++x) {
                if (x + 1 < w) edges.emplace_back(y * w + x, y * w + x + 1, weight(rng));
                if (y + 1 < h) edges.emplace_back(y * w + x, (y + 1) * w + x, weight(rng));
            }
        const LabelingProblem p = makeProblem(labels, costs, edges);
        const std::vector<uint32_t> start = argminLabels(p);
        AlphaExpansionOptions o;
        o.smoothnessWeight = 1.0 + trial % 3;
        const AlphaExpansionResult r = alphaExpansion(p, start, o, RunContext::silent());
        for (size_t i = 1; i < r.sweepEnergies.size(); ++i) CHECK(r.sweepEnergies[i] <= r.sweepEnergies[i - 1]);
        CHECK(r.sweepEnergies.back() == doctest::Approx(labelingEnergy(p, r.labels, o.smoothnessWeight)));
        CHECK(r.sweepEnergies.back() <= labelingEnergy(p, start, o.smoothnessWeight));
        // Expansion-move local minima are within 2× of the optimum for Potts (Boykov et al. 2001);
        // data costs here are >= 0 so the bound applies as stated.
        const double optimum = bruteForceMinimum(p, o.smoothnessWeight);
        CHECK(r.sweepEnergies.back() >= optimum - 1e-12);
        CHECK(r.sweepEnergies.back() <= 2.0 * optimum + 1e-12);
        for (size_t u = 0; u < p.nodeCount(); ++u) CHECK(p.slotOf(uint32_t(u), r.labels[u]) >= 0);
    }
}

TEST_CASE("alpha_expansion: a prohibited starting label is a usage error") {
    const LabelingProblem p = makeProblem(2, {{0.0, 1e10}, {0.0, 1.0}}, {{0, 1, 1.0}});
    CHECK(std::isinf(labelingEnergy(p, {1, 0}, 1.0)));
    CHECK_THROWS_AS(alphaExpansion(p, {1, 0}, {}, RunContext::silent()), Error);
}
