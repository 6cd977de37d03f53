// SPDX-License-Identifier: GPL-3.0-or-later
// The surface, its saliency and its nearest balls, and the energy terms (Eq. 2, 3): docs/partition.md §1–2.
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <map>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/detail/stage.h"

namespace zomefab::partition::detail {

/// Closest point of triangle abc to p, squared distance (Ericson, Real-Time Collision Detection §5.1.5).
double pointTriangleDist2(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    auto at = [&](const Vec3d& o, const Vec3d& u, double s, const Vec3d& v, double t) {
        return Vec3d{o[0] + s * u[0] + t * v[0], o[1] + s * u[1] + t * v[1], o[2] + s * u[2] + t * v[2]};
    };
    const Vec3d ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return dist2(p, a);
    const Vec3d bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return dist2(p, b);
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return dist2(p, at(a, ab, d1 / (d1 - d3), ac, 0));
    const Vec3d cp = sub(p, c);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return dist2(p, c);
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return dist2(p, at(a, ab, 0, ac, d2 / (d2 - d6)));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) {
        const double w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return dist2(p, {b[0] + w * (c[0] - b[0]), b[1] + w * (c[1] - b[1]), b[2] + w * (c[2] - b[2])});
    }
    const double denom = 1.0 / (va + vb + vc);
    return dist2(p, at(a, ab, vb * denom, ac, vc * denom));
}

NearestBalls nearestBalls(const std::vector<Vec3d>& queries, const std::vector<Vec3d>& balls, int k,
                          double cellMm) {
    NearestBalls out;
    out.k = std::min<int>(k, int(balls.size()));
    const int kk = out.k;
    out.labels.resize(queries.size() * size_t(kk));
    out.distancesMm.resize(queries.size() * size_t(kk));
    auto store = [&](size_t q, const std::vector<std::pair<double, uint32_t>>& best) {
        for (int i = 0; i < kk; ++i) {
            out.labels[q * size_t(kk) + size_t(i)] = best[size_t(i)].second;
            out.distancesMm[q * size_t(kk) + size_t(i)] = std::sqrt(best[size_t(i)].first);
        }
    };
    if (balls.size() <= 512) {
        // Few balls (a frame has a few hundred outermost balls): a linear scan beats the grid.
        tbb::parallel_for(tbb::blocked_range<size_t>(0, queries.size(), 1024),
                          [&](const tbb::blocked_range<size_t>& r) {
                              std::vector<std::pair<double, uint32_t>> all(balls.size());
                              for (size_t q = r.begin(); q < r.end(); ++q) {
                                  for (uint32_t i = 0; i < balls.size(); ++i)
                                      all[i] = {dist2(queries[q], balls[i]), i};
                                  std::nth_element(all.begin(), all.begin() + (kk - 1), all.end());
                                  std::sort(all.begin(), all.begin() + kk);
                                  store(q, all);
                              }
                          });
        return out;
    }
    Box3d box;
    for (const Vec3d& b : balls) box.expand(b);
    std::array<int, 3> dims;
    for (int a = 0; a < 3; ++a)
        dims[size_t(a)] =
            std::max(1, int(std::floor((box.max[size_t(a)] - box.min[size_t(a)]) / cellMm)) + 1);
    auto cellOf = [&](const Vec3d& p, int a) {
        const int c = int(std::floor((p[size_t(a)] - box.min[size_t(a)]) / cellMm));
        return std::clamp(c, 0, dims[size_t(a)] - 1);
    };
    const size_t cellCount = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
    std::vector<uint32_t> start(cellCount + 1, 0), items(balls.size());
    auto index = [&](int x, int y, int z) {
        return (size_t(z) * size_t(dims[1]) + size_t(y)) * size_t(dims[0]) + size_t(x);
    };
    for (const Vec3d& b : balls) ++start[index(cellOf(b, 0), cellOf(b, 1), cellOf(b, 2)) + 1];
    for (size_t i = 0; i < cellCount; ++i) start[i + 1] += start[i];
    {
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (uint32_t i = 0; i < balls.size(); ++i)
            items[fill[index(cellOf(balls[i], 0), cellOf(balls[i], 1), cellOf(balls[i], 2))]++] = i;
    }
    const int maxRing = std::max({dims[0], dims[1], dims[2]});
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, queries.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
            std::vector<std::pair<double, uint32_t>> best;  // (d², label), sorted
            for (size_t q = r.begin(); q < r.end(); ++q) {
                const Vec3d& p = queries[q];
                best.clear();
                const int cx = cellOf(p, 0), cy = cellOf(p, 1), cz = cellOf(p, 2);
                for (int ring = 0; ring <= maxRing; ++ring) {
                    for (int z = cz - ring; z <= cz + ring; ++z) {
                        if (z < 0 || z >= dims[2]) continue;
                        for (int y = cy - ring; y <= cy + ring; ++y) {
                            if (y < 0 || y >= dims[1]) continue;
                            const bool isYZShell = std::abs(z - cz) == ring || std::abs(y - cy) == ring;
                            for (int x = cx - ring; x <= cx + ring; ++x) {
                                if (x < 0 || x >= dims[0]) continue;
                                if (!isYZShell && std::abs(x - cx) != ring) continue;  // inner cells: done
                                const size_t c = index(x, y, z);
                                for (uint32_t i = start[c]; i < start[c + 1]; ++i) {
                                    const uint32_t label = items[i];
                                    const std::pair<double, uint32_t> e{dist2(p, balls[label]), label};
                                    if (int(best.size()) == kk && !(e < best.back())) continue;
                                    if (int(best.size()) == kk) best.pop_back();
                                    best.insert(std::upper_bound(best.begin(), best.end(), e), e);
                                }
                            }
                        }
                    }
                    // Balls in rings beyond this one are at least ring·cell away.
                    if (int(best.size()) == kk &&
                        best.back().first <= double(ring) * cellMm * double(ring) * cellMm)
                        break;
                }
                store(q, best);
            }
        });
    return out;
}

/// Salient regions become one node each (a seam can never run inside them); the other faces are
/// single nodes, or breadth-first clusters of about @p clusterSize edge-connected faces.
Units buildUnits(const FaceGraph& g, const std::vector<uint8_t>& salient, size_t clusterSize) {
    Units u;
    const size_t n = g.faceCount();
    u.unitOf.assign(n, kNone);
    std::vector<uint32_t> queue;
    for (size_t seed = 0; seed < n; ++seed) {
        if (u.unitOf[seed] != kNone) continue;
        const uint32_t id = uint32_t(u.count());
        const bool isSalient = salient[seed] != 0;
        const size_t limit = isSalient ? n : clusterSize;
        queue.clear();
        queue.push_back(uint32_t(seed));
        u.unitOf[seed] = id;
        for (size_t head = 0; head < queue.size() && queue.size() < limit; ++head) {
            const uint32_t f = queue[head];
            for (uint32_t i = g.offsets[f]; i < g.offsets[f + 1] && queue.size() < limit; ++i) {
                const uint32_t h = g.neighbors[i];
                if (u.unitOf[h] != kNone || (salient[h] != 0) != isSalient) continue;
                u.unitOf[h] = id;
                queue.push_back(h);
            }
        }
        u.faces.insert(u.faces.end(), queue.begin(), queue.end());
        u.offsets.push_back(uint32_t(u.faces.size()));
    }
    return u;
}

/// Smoothness weight of Eq. (3) for the edge-adjacent faces a, b, before w_smoothness:
/// −log(θ/π)·φ + w_saliency·E_saliency, with θ the angle between the normals (clamped below),
/// φ the centroid distance in mm and E_saliency = 1 when either face is salient.
double edgeWeight(const FaceGraph& g, const std::vector<uint8_t>& salient, uint32_t a, uint32_t b,
                  const PartitionOptions& o) {
    const double theta = std::clamp(dihedralAngleRad(g, a, b), o.minDihedralRad, kPi);
    const double phi = std::sqrt(dist2(g.centroidsMm[a], g.centroidsMm[b]));
    const double sal = (salient[a] || salient[b]) ? 1.0 : 0.0;
    return -std::log(theta / kPi) * phi + o.saliencyWeight * sal;
}

void checkInputs(const zome::Structure& frame, const Fabrication& fab, const PartitionOptions& opt,
                 Surface& S, PartitionResult& res) {
    checkPartitionOptions(opt, fab, frame.scale());
    if (S.mesh.triangles.empty()) throw Error(ErrorCode::InvalidInput, "the mesh has no triangles");
    if (S.labelBalls.empty())
        throw Error(ErrorCode::InvalidInput,
                    "the frame has no outermost balls to attach pieces to" +
                        std::string(frame.ballCount() == 0 ? " (it has no balls at all)" : ""));
    std::vector<zome::BallId> sorted(S.labelBalls);
    std::sort(sorted.begin(), sorted.end());
    for (size_t i = 0; i < sorted.size(); ++i) {
        if (!frame.hasBall(sorted[i]))
            throw Error(ErrorCode::InvalidInput,
                        "label ball " + std::to_string(sorted[i]) + " is not a ball of the frame");
        if (i > 0 && sorted[i] == sorted[i - 1])
            throw Error(ErrorCode::InvalidInput,
                        "label ball " + std::to_string(sorted[i]) + " is listed twice");
    }
    res.b0Mm = S.b0;
    res.printerMm = fab.printerMm;
    res.fitMarginMm = fab.fitMarginMm;
    res.labelBalls = S.labelBalls;

    // Mesh/frame mismatch: the frame sits inside the shell, so every label ball lies inside the
    // mesh's bounding box (one b0 of slack for rounding and open meshes).
    S.ballMm.resize(S.labelCount);
    for (uint32_t l = 0; l < S.labelCount; ++l) S.ballMm[l] = frame.ball(S.labelBalls[l]).positionMm;
    const Box3d box = boundingBox(S.mesh);
    for (uint32_t l = 0; l < S.labelCount; ++l) {
        double out = 0.0;
        for (size_t a = 0; a < 3; ++a)
            out = std::max({out, box.min[a] - S.ballMm[l][a], S.ballMm[l][a] - box.max[a]});
        if (out > S.b0)
            throw Error(
                ErrorCode::InvalidInput,
                "frame and mesh do not match: ball " + std::to_string(S.labelBalls[l]) +
                    formatNumbers(" at (%.1f, %.1f, %.1f) mm", S.ballMm[l][0], S.ballMm[l][1],
                                  S.ballMm[l][2]) +
                    formatNumbers(" lies %.1f mm outside the mesh's bounding box (check transform_mm)", out));
    }
}

/// Face graph, salient regions, the k nearest balls of every face (Eq. 2) and the Eq. (3)
/// weight of every face pair.
void prepareSurface(Surface& S, const PartitionOptions& opt, PartitionResult& res) {
    S.graph = buildFaceGraph(S.mesh);
    res.salientFaces = salientFaceFlags(S.mesh, opt.salientSpheres, opt.salientFaceIndices);

    // Salient regions: edge-connected salient faces.
    S.salientRegionOf.assign(S.faceCount, kNone);
    std::vector<uint32_t> tag(S.faceCount), comp;
    for (size_t f = 0; f < S.faceCount; ++f)
        tag[f] = res.salientFaces[f] ? 0u : uint32_t(f + 1);  // non-salient: unique
    labelComponents(S.graph, tag, comp);
    std::map<uint32_t, uint32_t> renumber;
    for (size_t f = 0; f < S.faceCount; ++f)
        if (res.salientFaces[f])
            S.salientRegionOf[f] = renumber.emplace(comp[f], uint32_t(renumber.size())).first->second;
    res.salientRegions = renumber.size();
    S.salientFacesOf.assign(res.salientRegions, {});
    for (uint32_t f = 0; f < S.faceCount; ++f)
        if (S.salientRegionOf[f] != kNone) S.salientFacesOf[S.salientRegionOf[f]].push_back(f);

    S.near = nearestBalls(S.graph.centroidsMm, S.ballMm, opt.candidateCount, S.b0);
    S.k = S.near.k;
    res.nearestLabels.resize(S.faceCount);
    for (size_t f = 0; f < S.faceCount; ++f) res.nearestLabels[f] = S.near.labels[f * size_t(S.k)];
    {
        std::vector<uint32_t> comp2;
        res.nearestPartitions = labelComponents(S.graph, res.nearestLabels, comp2);
    }
    // A frame made for another mesh (or another scale) leaves the surface far from every ball; a
    // small frame in a thin object (a few balls joined by struts) may lie half the object away.
    std::vector<double> d(S.faceCount);
    for (size_t f = 0; f < S.faceCount; ++f) d[f] = S.near.distancesMm[f * size_t(S.k)];
    std::nth_element(d.begin(), d.begin() + long(S.faceCount / 2), d.end());
    const double median = d[S.faceCount / 2];
    if (median > std::max(5.0 * S.b0, 0.5 * norm(boundingBox(S.mesh).size())))
        throw Error(
            ErrorCode::InvalidInput,
            formatNumbers("frame and mesh do not match: the surface lies a median %.0f mm (%.1f b0) from the "
                          "nearest outermost ball (check transform_mm)",
                          median, median / S.b0));

    S.faceEdgeWeights.resize(S.graph.neighbors.size());
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, S.faceCount, 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t f = r.begin(); f < r.end(); ++f)
                for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i)
                    S.faceEdgeWeights[i] =
                        edgeWeight(S.graph, res.salientFaces, uint32_t(f), S.graph.neighbors[i], opt);
        });
}

/// Data term, Eq. (2): D(t, n) = w_data · log d(t, n), d in units of b0, clamped below.
double dataCost(const Surface& S, const PartitionOptions& opt, double dMm) {
    return opt.dataWeight * std::log(std::max(dMm / S.b0, opt.minDistanceB0));
}

/// D summed over the faces of node @p u of @p units, with the true distances.
double unitCost(const Surface& S, const PartitionOptions& opt, const Units& units, size_t u, uint32_t label) {
    double sum = 0.0;
    for (uint32_t j = units.offsets[u]; j < units.offsets[u + 1]; ++j)
        sum += dataCost(S, opt, std::sqrt(dist2(S.graph.centroidsMm[units.faces[j]], S.ballMm[label])));
    return sum;
}

}  // namespace zomefab::partition::detail
