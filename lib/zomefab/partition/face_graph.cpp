// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/face_graph.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"

namespace zomefab::partition {

FaceGraph buildFaceGraph(const TriMesh& meshMm) {
    const size_t faceCount = meshMm.triangles.size();
    const size_t vertexCount = meshMm.positions.size();
    for (size_t f = 0; f < faceCount; ++f)
        for (uint32_t v : meshMm.triangles[f])
            if (v >= vertexCount)
                throw Error(ErrorCode::InvalidInput, "triangle " + std::to_string(f) + " references vertex " +
                                                         std::to_string(v) + " of " +
                                                         std::to_string(vertexCount));

    FaceGraph g;
    g.centroidsMm.resize(faceCount);
    g.normals.resize(faceCount);
    g.areasMm2.resize(faceCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, faceCount, 4096), [&](const tbb::blocked_range<size_t>&
                                                                              r) {
        for (size_t f = r.begin(); f < r.end(); ++f) {
            const auto& t = meshMm.triangles[f];
            const Vec3d a = toD(meshMm.positions[t[0]]), b = toD(meshMm.positions[t[1]]),
                        c = toD(meshMm.positions[t[2]]);
            g.centroidsMm[f] = {(a[0] + b[0] + c[0]) / 3.0, (a[1] + b[1] + c[1]) / 3.0,
                                (a[2] + b[2] + c[2]) / 3.0};
            const Vec3d u{b[0] - a[0], b[1] - a[1], b[2] - a[2]}, v{c[0] - a[0], c[1] - a[1], c[2] - a[2]};
            const Vec3d n{u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
            const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
            g.areasMm2[f] = 0.5 * len;
            g.normals[f] = len > 0.0 ? Vec3d{n[0] / len, n[1] / len, n[2] / len} : Vec3d{0.0, 0.0, 0.0};
        }
    });

    // Every undirected edge as (min vertex, max vertex) → faces; (key, face) pairs are unique, so
    // the parallel sort gives the same order whatever the thread count.
    std::vector<std::pair<uint64_t, uint32_t>> edges(3 * faceCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, faceCount, 4096),
                      [&](const tbb::blocked_range<size_t>& r) {
                          for (size_t f = r.begin(); f < r.end(); ++f) {
                              const auto& t = meshMm.triangles[f];
                              for (int e = 0; e < 3; ++e) {
                                  uint64_t a = t[e], b = t[(e + 1) % 3];
                                  if (a > b) std::swap(a, b);
                                  edges[3 * f + e] = {(a << 32) | b, uint32_t(f)};
                              }
                          }
                      });
    tbb::parallel_sort(edges.begin(), edges.end());

    std::vector<std::pair<uint32_t, uint32_t>> pairs;  // both directions
    pairs.reserve(3 * faceCount);
    for (size_t i = 0; i < edges.size();) {
        size_t j = i + 1;
        while (j < edges.size() && edges[j].first == edges[i].first) ++j;
        for (size_t p = i; p < j; ++p)
            for (size_t q = p + 1; q < j; ++q) {
                const uint32_t fa = edges[p].second, fb = edges[q].second;
                if (fa == fb) continue;  // a degenerate triangle repeating a vertex
                pairs.push_back({fa, fb});
                pairs.push_back({fb, fa});
            }
        i = j;
    }
    tbb::parallel_sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());  // faces sharing two edges

    g.offsets.assign(faceCount + 1, 0);
    for (const auto& p : pairs) ++g.offsets[p.first + 1];
    for (size_t f = 0; f < faceCount; ++f) g.offsets[f + 1] += g.offsets[f];
    g.neighbors.resize(pairs.size());
    for (size_t i = 0; i < pairs.size(); ++i) g.neighbors[i] = pairs[i].second;  // pairs sorted by first
    return g;
}

double dihedralAngleRad(const FaceGraph& graph, uint32_t a, uint32_t b) {
    const Vec3d& n = graph.normals[a];
    const Vec3d& m = graph.normals[b];
    const double dot = n[0] * m[0] + n[1] * m[1] + n[2] * m[2];
    const Vec3d c{n[1] * m[2] - n[2] * m[1], n[2] * m[0] - n[0] * m[2], n[0] * m[1] - n[1] * m[0]};
    // atan2 is accurate for small angles, where acos(dot) loses half the digits.
    return std::atan2(std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2]), dot);
}

uint32_t labelComponents(const FaceGraph& graph, const std::vector<uint32_t>& labels,
                         std::vector<uint32_t>& componentOf) {
    const size_t n = graph.faceCount();
    constexpr uint32_t kUnset = 0xFFFFFFFFu;
    componentOf.assign(n, kUnset);
    std::vector<uint32_t> stack;
    uint32_t count = 0;
    for (size_t seed = 0; seed < n; ++seed) {
        if (componentOf[seed] != kUnset) continue;
        componentOf[seed] = count;
        stack.push_back(uint32_t(seed));
        while (!stack.empty()) {
            const uint32_t f = stack.back();
            stack.pop_back();
            for (uint32_t i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
                const uint32_t g = graph.neighbors[i];
                if (componentOf[g] == kUnset && labels[g] == labels[f]) {
                    componentOf[g] = count;
                    stack.push_back(g);
                }
            }
        }
        ++count;
    }
    return count;
}

}  // namespace zomefab::partition
