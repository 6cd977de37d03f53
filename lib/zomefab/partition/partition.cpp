// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/partition.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <numeric>
#include <set>
#include <string>

#include "zomefab/core/disjoint_sets.h"
#include "zomefab/core/error.h"
#include "zomefab/core/fabrication.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/alpha_expansion.h"
#include "zomefab/partition/face_graph.h"

namespace zomefab::partition {

namespace {

constexpr uint32_t kNone = 0xFFFFFFFFu;
const double kPi = std::acos(-1.0);

std::string sizeText(const Vec3d& v) { return formatNumbers("%.0f x %.0f x %.0f mm", v[0], v[1], v[2]); }

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

// --- k nearest label balls (uniform grid over the balls) --------------------------------------

/// For every query point its k nearest balls, sorted by (distance, label): labels[q*k + i],
/// distancesMm[q*k + i].
struct NearestBalls {
    int k = 0;
    std::vector<uint32_t> labels;
    std::vector<double> distancesMm;
};

NearestBalls nearestBalls(const std::vector<Vec3d>& queries, const std::vector<Vec3d>& balls, int k, double cellMm) {
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
        tbb::parallel_for(tbb::blocked_range<size_t>(0, queries.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
            std::vector<std::pair<double, uint32_t>> all(balls.size());
            for (size_t q = r.begin(); q < r.end(); ++q) {
                for (uint32_t i = 0; i < balls.size(); ++i) all[i] = {dist2(queries[q], balls[i]), i};
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
    for (int a = 0; a < 3; ++a) dims[size_t(a)] = std::max(1, int(std::floor((box.max[size_t(a)] - box.min[size_t(a)]) / cellMm)) + 1);
    auto cellOf = [&](const Vec3d& p, int a) {
        const int c = int(std::floor((p[size_t(a)] - box.min[size_t(a)]) / cellMm));
        return std::clamp(c, 0, dims[size_t(a)] - 1);
    };
    const size_t cellCount = size_t(dims[0]) * size_t(dims[1]) * size_t(dims[2]);
    std::vector<uint32_t> start(cellCount + 1, 0), items(balls.size());
    auto index = [&](int x, int y, int z) { return (size_t(z) * size_t(dims[1]) + size_t(y)) * size_t(dims[0]) + size_t(x); };
    for (const Vec3d& b : balls) ++start[index(cellOf(b, 0), cellOf(b, 1), cellOf(b, 2)) + 1];
    for (size_t i = 0; i < cellCount; ++i) start[i + 1] += start[i];
    {
        std::vector<uint32_t> fill(start.begin(), start.end() - 1);
        for (uint32_t i = 0; i < balls.size(); ++i) items[fill[index(cellOf(balls[i], 0), cellOf(balls[i], 1), cellOf(balls[i], 2))]++] = i;
    }
    const int maxRing = std::max({dims[0], dims[1], dims[2]});
    tbb::parallel_for(tbb::blocked_range<size_t>(0, queries.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
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
                if (int(best.size()) == kk && best.back().first <= double(ring) * cellMm * double(ring) * cellMm) break;
            }
            store(q, best);
        }
    });
    return out;
}

// --- graph-cut nodes: faces, clusters of faces, salient regions ------------------------------

struct Units {
    std::vector<uint32_t> unitOf;   ///< per face
    std::vector<uint32_t> offsets{0};  ///< CSR unit → faces
    std::vector<uint32_t> faces;
    size_t count() const { return offsets.size() - 1; }
};

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

// --- pieces bookkeeping -----------------------------------------------------------------------

/// The vertices of @p faces (each once, in first-use order).
std::vector<Vec3d> faceVertices(const TriMesh& mesh, const std::vector<uint32_t>& faces, std::vector<uint32_t>& stamp,
                                uint32_t& stampValue) {
    ++stampValue;
    std::vector<Vec3d> pts;
    for (uint32_t f : faces)
        for (uint32_t v : mesh.triangles[f])
            if (stamp[v] != stampValue) {
                stamp[v] = stampValue;
                pts.push_back(toD(mesh.positions[v]));
            }
    return pts;
}

/// Groups faces by a per-face id: CSR id → faces (in increasing face order).
void groupFaces(const std::vector<uint32_t>& idOf, uint32_t idCount, std::vector<uint32_t>& offsets,
                std::vector<uint32_t>& faces) {
    offsets.assign(size_t(idCount) + 1, 0);
    for (uint32_t id : idOf) ++offsets[id + 1];
    for (uint32_t i = 0; i < idCount; ++i) offsets[i + 1] += offsets[i];
    faces.resize(idOf.size());
    std::vector<uint32_t> fill(offsets.begin(), offsets.end() - 1);
    for (uint32_t f = 0; f < idOf.size(); ++f) faces[fill[idOf[f]]++] = f;
}

/// Quick accept: an axis-aligned box that fits needs no orientation search.
bool fitsTrivially(const std::vector<Vec3d>& pts, const Vec3d& printer, double margin) {
    Box3d box;
    for (const Vec3d& p : pts) box.expand(p);
    return boxFitsPrinter(box.size(), printer, margin);
}

/// The schedule's fit test (docs/partition.md §4): the quick accept, else the oriented-box search.
bool fitsPrinter(const std::vector<Vec3d>& pts, const Vec3d& printer, double margin) {
    return fitsTrivially(pts, printer, margin) || fitInPrinter(pts, printer, margin).fits;
}

struct Context {
    const TriMesh& mesh;
    const FaceGraph& graph;
    const Fabrication& fab;
    const RunContext& run;
    std::vector<uint32_t> stamp;
    uint32_t stampValue = 0;

    PrinterFit fitOf(const std::vector<uint32_t>& faces) {
        const std::vector<Vec3d> pts = faceVertices(mesh, faces, stamp, stampValue);
        return fitInPrinter(pts, fab.printerMm, fab.fitMarginMm);
    }
};

/// Does each of @p faceSets fit the printer (its vertices' oriented box, docs/partition.md §4)?
/// Vertex lists are gathered serially (one stamp array), the fit tests run in parallel; the result
/// does not depend on the thread count.
std::vector<char> fitsEach(Context& cx, const std::vector<std::vector<uint32_t>>& faceSets) {
    const size_t n = faceSets.size();
    std::vector<std::vector<Vec3d>> pts(n);
    for (size_t c = 0; c < n; ++c) pts[c] = faceVertices(cx.mesh, faceSets[c], cx.stamp, cx.stampValue);
    std::vector<char> fits(n, 1);
    tbb::parallel_for(size_t(0), n, [&](size_t c) { fits[c] = fitsPrinter(pts[c], cx.fab.printerMm, cx.fab.fitMarginMm); });
    return fits;
}

/// Splits @p faces (one class) into parts that each fit the printer, by recursive bisection
/// across the longest axis of the best oriented box, at its middle. Salient regions stay on one
/// side (the side of their first face). Appends the parts to @p parts.
void bisectUntilFit(Context& cx, const std::vector<uint32_t>& faces, const std::vector<uint32_t>& salientRegionOf,
                    std::vector<std::vector<uint32_t>>& parts, int depth) {
    const PrinterFit fit = cx.fitOf(faces);
    if (fit.fits || depth > 16 || faces.size() < 2) {
        parts.push_back(faces);
        return;
    }
    const Vec3d& axis = fit.axes[2];  // the longest box axis
    const double mid = axis[0] * fit.centerMm[0] + axis[1] * fit.centerMm[1] + axis[2] * fit.centerMm[2];
    auto proj = [&](uint32_t f) {
        const Vec3d& c = cx.graph.centroidsMm[f];
        return axis[0] * c[0] + axis[1] * c[1] + axis[2] * c[2];
    };
    std::map<uint32_t, bool> regionSide;  // salient region → side of its first face
    std::vector<uint32_t> lo, hi;
    for (uint32_t f : faces) {
        bool isHigh = proj(f) >= mid;
        if (salientRegionOf[f] != kNone) {
            auto it = regionSide.find(salientRegionOf[f]);
            if (it == regionSide.end())
                regionSide[salientRegionOf[f]] = isHigh;
            else
                isHigh = it->second;
        }
        (isHigh ? hi : lo).push_back(f);
    }
    if (lo.empty() || hi.empty()) {
        parts.push_back(faces);  // cannot split further (one salient region larger than the printer)
        return;
    }
    bisectUntilFit(cx, lo, salientRegionOf, parts, depth + 1);
    bisectUntilFit(cx, hi, salientRegionOf, parts, depth + 1);
}

/// Length (mm) of the edge faces @p f and @p h share; 0 when they share fewer than two corners.
double sharedEdgeMm(const TriMesh& mesh, uint32_t f, uint32_t h) {
    const auto& tf = mesh.triangles[f];
    const auto& th = mesh.triangles[h];
    uint32_t shared[3];
    int n = 0;
    for (uint32_t v : tf)
        if (v == th[0] || v == th[1] || v == th[2]) shared[n++] = v;
    return n >= 2 ? std::sqrt(dist2(toD(mesh.positions[shared[0]]), toD(mesh.positions[shared[1]]))) : 0.0;
}

}  // namespace

// --- public helpers ---------------------------------------------------------------------------

void checkPartitionOptions(const PartitionOptions& o, const Fabrication& fab, const zome::ZomeScale& scale) {
    auto usage = [](const std::string& m) { throw Error(ErrorCode::Usage, m); };
    checkFabrication(fab);
    const double minSide = std::min({fab.printerMm[0], fab.printerMm[1], fab.printerMm[2]});
    if (minSide < scale.ballDiameterMm + 2.0 * fab.fitMarginMm)
        usage("printer volume " + sizeText(fab.printerMm) + " is smaller than a Zome ball (" +
              formatNumbers("%.1f mm across", scale.ballDiameterMm) +
              (fab.fitMarginMm > 0 ? formatNumbers(" plus 2 x %.1f mm margin", fab.fitMarginMm) : std::string()) + ")");
    if (o.candidateCount < 1) usage("k (candidate labels per triangle) must be >= 1");
    if (!(o.dataWeight > 0.0) || !std::isfinite(o.dataWeight)) usage("w_data must be > 0");
    if (!(o.saliencyWeight >= 0.0) || !std::isfinite(o.saliencyWeight)) usage("w_saliency must be >= 0");
    if (!(o.smoothnessStart >= 0.0) || !std::isfinite(o.smoothnessStart)) usage("w_smoothness must be >= 0");
    if (!(o.smoothnessFactor > 0.0 && o.smoothnessFactor < 1.0)) usage("the w_smoothness factor must be in (0, 1)");
    if (!(o.smoothnessMin >= 0.0)) usage("the smallest w_smoothness must be >= 0");
    if (!(o.minDistanceB0 > 0.0)) usage("the distance clamp must be > 0");
    if (!(o.minDihedralRad > 0.0 && o.minDihedralRad < kPi)) usage("the dihedral clamp must be in (0, pi)");
    if (!(o.svm.cost > 0.0) || !(o.svm.tolerance > 0.0)) usage("SVM cost and tolerance must be > 0");
    if (!(o.minPieceAreaMm2 >= 0.0)) usage("the smallest piece area must be >= 0");
    for (const SalientSphere& s : o.salientSpheres)
        if (!(s.radiusMm > 0.0) || !std::isfinite(s.radiusMm) || !std::isfinite(s.centerMm[0]) ||
            !std::isfinite(s.centerMm[1]) || !std::isfinite(s.centerMm[2]))
            usage("a salient sphere needs a finite centre and a radius > 0");
}

std::vector<uint8_t> salientFaceFlags(const TriMesh& mesh, const std::vector<SalientSphere>& spheres,
                                      const std::vector<uint32_t>& indices) {
    const size_t n = mesh.triangles.size();
    std::vector<uint8_t> flags(n, 0);
    if (!mesh.salientFaces.empty()) {
        if (mesh.salientFaces.size() != n)
            throw Error(ErrorCode::InvalidInput, "the mesh has " + std::to_string(mesh.salientFaces.size()) +
                                                     " salient flags for " + std::to_string(n) + " faces");
        for (size_t f = 0; f < n; ++f) flags[f] = mesh.salientFaces[f] ? 1 : 0;
    }
    for (uint32_t i : indices) {
        if (i >= n)
            throw Error(ErrorCode::Usage, "salient face index " + std::to_string(i) + " is out of range (the mesh has " +
                                              std::to_string(n) + " faces)");
        flags[i] = 1;
    }
    if (!spheres.empty()) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t f = r.begin(); f < r.end(); ++f) {
                const auto& t = mesh.triangles[f];
                const Vec3d a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]), c = toD(mesh.positions[t[2]]);
                for (const SalientSphere& s : spheres)
                    if (pointTriangleDist2(s.centerMm, a, b, c) <= s.radiusMm * s.radiusMm) {
                        flags[f] = 1;
                        break;
                    }
            }
        });
    }
    return flags;
}

RegionMerge mergeRegionsThatFit(const TriMesh& meshMm, const FaceGraph& graph, const std::vector<uint32_t>& regionOf,
                                uint32_t regionCount, const Vec3d& printerMm, double marginMm) {
    const size_t faceCount = graph.faceCount();
    if (regionOf.size() != faceCount)
        throw Error(ErrorCode::Usage, "region merge: " + std::to_string(regionOf.size()) + " region ids for " +
                                          std::to_string(faceCount) + " faces");
    // Per region (indexed by its union-find root): area, vertices (each once per region; a vertex on
    // a seam appears in both, which does not change a box), and the seam length to each neighbour.
    std::vector<double> area(regionCount, 0.0);
    std::vector<std::vector<Vec3d>> pts(regionCount);
    std::vector<std::map<uint32_t, double>> seam(regionCount);
    {
        std::vector<uint32_t> offsets, faces;
        groupFaces(regionOf, regionCount, offsets, faces);
        std::vector<uint32_t> stamp(meshMm.positions.size(), 0);
        uint32_t stampValue = 0;
        for (uint32_t r = 0; r < regionCount; ++r) {
            const std::vector<uint32_t> members(faces.begin() + offsets[r], faces.begin() + offsets[r + 1]);
            pts[r] = faceVertices(meshMm, members, stamp, stampValue);
        }
    }
    for (uint32_t f = 0; f < faceCount; ++f) {
        area[regionOf[f]] += graph.areasMm2[f];
        for (uint32_t i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
            const uint32_t h = graph.neighbors[i];
            if (regionOf[h] != regionOf[f]) seam[regionOf[f]][regionOf[h]] += sharedEdgeMm(meshMm, f, h);
        }
    }
    DisjointSets dsu(regionCount);
    std::vector<char> isRoot(regionCount, 1);
    // Pairs (lower root, higher root) whose union was tested and does not fit. A pair is tested
    // again only after one of its regions grew (its entries are dropped then).
    std::set<std::pair<uint32_t, uint32_t>> isTooLarge;
    RegionMerge out;
    std::vector<uint32_t> order;
    for (;;) {
        order.clear();
        for (uint32_t r = 0; r < regionCount; ++r)
            if (isRoot[r]) order.push_back(r);
        std::sort(order.begin(), order.end(),
                  [&](uint32_t a, uint32_t b) { return area[a] != area[b] ? area[a] < area[b] : a < b; });
        bool isMerged = false;
        for (uint32_t r : order) {
            std::vector<std::pair<double, uint32_t>> byLength;  // (−seam length, neighbour)
            for (const auto& [o, len] : seam[r])
                if (!isTooLarge.count({std::min(r, o), std::max(r, o)})) byLength.push_back({-len, o});
            if (byLength.empty()) continue;
            std::sort(byLength.begin(), byLength.end());
            // The unions with every candidate neighbour are tested in parallel; the first one in
            // seam order that fits wins, so the choice does not depend on the threads.
            std::vector<char> isFit(byLength.size(), 0);
            tbb::parallel_for(size_t(0), byLength.size(), [&](size_t i) {
                std::vector<Vec3d> u(pts[r]);
                const std::vector<Vec3d>& other = pts[byLength[i].second];
                u.insert(u.end(), other.begin(), other.end());
                isFit[i] = fitsPrinter(u, printerMm, marginMm);
            });
            uint32_t into = kNone;
            for (size_t i = 0; i < byLength.size(); ++i) {
                const uint32_t o = byLength[i].second;
                if (isFit[i]) {
                    into = o;
                    break;
                }
                isTooLarge.insert({std::min(r, o), std::max(r, o)});
            }
            if (into == kNone) continue;
            // Merge r and into; the lower id stays the root.
            dsu.unite(r, into);
            const uint32_t root = dsu.find(r), gone = root == r ? into : r;
            isRoot[gone] = 0;
            area[root] += area[gone];
            pts[root].insert(pts[root].end(), pts[gone].begin(), pts[gone].end());
            std::vector<Vec3d>().swap(pts[gone]);
            for (const auto& [o, len] : seam[gone]) {
                if (o == root) continue;
                seam[root][o] += len;
                seam[o].erase(gone);
                seam[o][root] += len;
            }
            seam[root].erase(gone);
            seam[gone].clear();
            for (auto it = isTooLarge.begin(); it != isTooLarge.end();)
                it = (it->first == root || it->second == root || it->first == gone || it->second == gone)
                         ? isTooLarge.erase(it)
                         : std::next(it);
            ++out.merges;
            isMerged = true;
            break;  // areas changed: start again from the smallest region
        }
        if (!isMerged) break;
    }
    out.groupOf.assign(regionCount, kNone);
    std::vector<uint32_t> groupOfRoot(regionCount, kNone);
    for (uint32_t r = 0; r < regionCount; ++r) {
        const uint32_t root = dsu.find(r);
        if (groupOfRoot[root] == kNone) groupOfRoot[root] = out.groupCount++;
        out.groupOf[r] = groupOfRoot[root];
    }
    return out;
}

// --- the stage --------------------------------------------------------------------------------

namespace {

/// One run of the stage: the inputs, the derived geometry and the problems, and one method per
/// phase (docs/partition.md sections 1–6).
class Stage {
public:
    Stage(const TriMesh& meshMm, const zome::Structure& frame, const std::vector<zome::BallId>& labelBalls,
          const Fabrication& fab, const PartitionOptions& opt, const RunContext& run)
        : mMesh(meshMm), mFrame(frame), mLabelBalls(labelBalls), mFab(fab), mOpt(opt), mRun(run),
          mFaceCount(meshMm.triangles.size()), mLabelCount(uint32_t(labelBalls.size())),
          mB0(frame.scale().b0Mm) {}

    PartitionResult run() {
        const Stopwatch total;
        checkInputs();
        mRun.progress("partition", 0.0);
        prepareSurface();
        prepareProblems();
        mRun.throwIfCancelled();
        runSchedule();
        mergeRegions();
        cutAndMakePieces();
        mRes.secondsTotal = total.seconds();
        mRun.progress("partition", 1.0);
        return std::move(mRes);
    }

private:
    // --- inputs ---------------------------------------------------------------------------------

    void checkInputs() {
        checkPartitionOptions(mOpt, mFab, mFrame.scale());
        if (mMesh.triangles.empty()) throw Error(ErrorCode::InvalidInput, "the mesh has no triangles");
        if (mLabelBalls.empty())
            throw Error(ErrorCode::InvalidInput,
                        "the frame has no outermost balls to attach pieces to" +
                            std::string(mFrame.ballCount() == 0 ? " (it has no balls at all)" : ""));
        std::vector<zome::BallId> sorted(mLabelBalls);
        std::sort(sorted.begin(), sorted.end());
        for (size_t i = 0; i < sorted.size(); ++i) {
            if (!mFrame.hasBall(sorted[i]))
                throw Error(ErrorCode::InvalidInput, "label ball " + std::to_string(sorted[i]) + " is not a ball of the frame");
            if (i > 0 && sorted[i] == sorted[i - 1])
                throw Error(ErrorCode::InvalidInput, "label ball " + std::to_string(sorted[i]) + " is listed twice");
        }
        mRes.b0Mm = mB0;
        mRes.printerMm = mFab.printerMm;
        mRes.fitMarginMm = mFab.fitMarginMm;
        mRes.labelBalls = mLabelBalls;

        // Mesh/frame mismatch: the frame sits inside the shell, so every label ball lies inside the
        // mesh's bounding box (one b0 of slack for rounding and open meshes).
        mBallMm.resize(mLabelCount);
        for (uint32_t l = 0; l < mLabelCount; ++l) mBallMm[l] = mFrame.ball(mLabelBalls[l]).positionMm;
        const Box3d box = boundingBox(mMesh);
        for (uint32_t l = 0; l < mLabelCount; ++l) {
            double out = 0.0;
            for (size_t a = 0; a < 3; ++a) out = std::max({out, box.min[a] - mBallMm[l][a], mBallMm[l][a] - box.max[a]});
            if (out > mB0)
                throw Error(ErrorCode::InvalidInput,
                            "frame and mesh do not match: ball " + std::to_string(mLabelBalls[l]) +
                                formatNumbers(" at (%.1f, %.1f, %.1f) mm", mBallMm[l][0], mBallMm[l][1], mBallMm[l][2]) +
                                formatNumbers(" lies %.1f mm outside the mesh's bounding box (check transform_mm)", out));
        }
    }

    /// Face graph, salient regions, the k nearest balls of every face (Eq. 2) and the Eq. (3)
    /// weight of every face pair.
    void prepareSurface() {
        mGraph = buildFaceGraph(mMesh);
        mRes.salientFaces = salientFaceFlags(mMesh, mOpt.salientSpheres, mOpt.salientFaceIndices);

        // Salient regions: edge-connected salient faces.
        mSalientRegionOf.assign(mFaceCount, kNone);
        std::vector<uint32_t> tag(mFaceCount), comp;
        for (size_t f = 0; f < mFaceCount; ++f) tag[f] = mRes.salientFaces[f] ? 0u : uint32_t(f + 1);  // non-salient: unique
        labelComponents(mGraph, tag, comp);
        std::map<uint32_t, uint32_t> renumber;
        for (size_t f = 0; f < mFaceCount; ++f)
            if (mRes.salientFaces[f]) mSalientRegionOf[f] = renumber.emplace(comp[f], uint32_t(renumber.size())).first->second;
        mRes.salientRegions = renumber.size();
        mSalientFacesOf.assign(mRes.salientRegions, {});
        for (uint32_t f = 0; f < mFaceCount; ++f)
            if (mSalientRegionOf[f] != kNone) mSalientFacesOf[mSalientRegionOf[f]].push_back(f);

        mNear = nearestBalls(mGraph.centroidsMm, mBallMm, mOpt.candidateCount, mB0);
        mK = mNear.k;
        mRes.nearestLabels.resize(mFaceCount);
        for (size_t f = 0; f < mFaceCount; ++f) mRes.nearestLabels[f] = mNear.labels[f * size_t(mK)];
        {
            std::vector<uint32_t> comp2;
            mRes.nearestPartitions = labelComponents(mGraph, mRes.nearestLabels, comp2);
        }
        // A frame made for another mesh (or another scale) leaves the surface far from every ball.
        std::vector<double> d(mFaceCount);
        for (size_t f = 0; f < mFaceCount; ++f) d[f] = mNear.distancesMm[f * size_t(mK)];
        std::nth_element(d.begin(), d.begin() + long(mFaceCount / 2), d.end());
        const double median = d[mFaceCount / 2];
        if (median > 5.0 * mB0)
            throw Error(ErrorCode::InvalidInput,
                        formatNumbers("frame and mesh do not match: the surface lies a median %.0f mm (%.1f b0) from the "
                            "nearest outermost ball (check transform_mm)",
                            median, median / mB0));

        mFaceEdgeWeights.resize(mGraph.neighbors.size());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, mFaceCount, 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t f = r.begin(); f < r.end(); ++f)
                for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i)
                    mFaceEdgeWeights[i] = edgeWeight(mGraph, mRes.salientFaces, uint32_t(f), mGraph.neighbors[i], mOpt);
        });
    }

    /// Data term, Eq. (2): D(t, n) = w_data · log d(t, n), d in units of b0, clamped below.
    double dataCost(double dMm) const { return mOpt.dataWeight * std::log(std::max(dMm / mB0, mOpt.minDistanceB0)); }

    /// D summed over the faces of node @p u of @p units, with the true distances.
    double unitCost(const Units& units, size_t u, uint32_t label) const {
        double sum = 0.0;
        for (uint32_t j = units.offsets[u]; j < units.offsets[u + 1]; ++j)
            sum += dataCost(std::sqrt(dist2(mGraph.centroidsMm[units.faces[j]], mBallMm[label])));
        return sum;
    }

    // --- graph-cut problems (docs/partition.md §3, "Graph size") --------------------------------

    /// Graph-cut nodes: faces (salient regions contracted), or on very large meshes small clusters
    /// of faces; with two levels, also large clusters solved first.
    void prepareProblems() {
        auto sizeFor = [&](size_t target) {
            return (target > 0 && mFaceCount > target) ? (mFaceCount + target - 1) / target : size_t(1);
        };
        const size_t nodeSize = sizeFor(mOpt.refineNodeTarget);
        const size_t clusterSize = std::max(nodeSize, sizeFor(mOpt.graphNodeTarget));
        mIsTwoLevel = clusterSize > nodeSize;
        mUnits = buildUnits(mGraph, mRes.salientFaces, nodeSize);
        mProb = makeProblem(mUnits, mInitial);
        if (mIsTwoLevel) {
            mClusters = buildUnits(mGraph, mRes.salientFaces, clusterSize);
            mClusterProb = makeProblem(mClusters, mClusterInitial);
        }
        // Band of the refinement: about a large cluster's diameter in rings of faces, at least 3.
        mBandRings = std::max(3, int(std::ceil(std::sqrt(double(clusterSize)))));
        if (mIsTwoLevel)
            mRun.debug("graph cut on " + std::to_string(mClusters.count()) + " clusters of up to " +
                       std::to_string(clusterSize) + " faces, then on the " + std::to_string(mUnits.count()) +
                       "-node graph within " + std::to_string(mBandRings) + " rings of their seams");
        mRes.graphNodes = mIsTwoLevel ? mClusters.count() : mUnits.count();
        mRes.candidatePairs = mIsTwoLevel ? mClusterProb.candidateLabels.size() : mProb.candidateLabels.size();
        mRes.refineNodes = mUnits.count();
    }

    /// The labelling problem over @p units; @p initial receives each node's cheapest candidate
    /// (the nearest ball, summed over a node's faces).
    LabelingProblem makeProblem(const Units& units, std::vector<uint32_t>& initial) const {
        const size_t unitCount = units.count();
        const int k = mK;
        LabelingProblem prob;
        prob.labelCount = mLabelCount;
        initial.resize(unitCount);
        // Singletons take their face's k nearest directly; a cluster or salient region takes the
        // union of its faces' candidates, each cost the sum over its faces with the true distances.
        std::vector<std::vector<std::pair<uint32_t, double>>> multi(unitCount);  // only multi-face units
        std::vector<uint32_t> counts(unitCount);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 256), [&](const tbb::blocked_range<size_t>& r) {
            std::vector<char> isSeen(mLabelCount, 0);
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
                        const uint32_t l = mNear.labels[units.faces[j] * size_t(k) + size_t(i)];
                        if (!isSeen[l]) isSeen[l] = 1, labels.push_back(l);
                    }
                for (uint32_t l : labels) isSeen[l] = 0;
                std::sort(labels.begin(), labels.end());
                for (uint32_t l : labels) multi[u].push_back({l, unitCost(units, u, l)});
                counts[u] = uint32_t(labels.size());
            }
        });
        prob.candidateOffsets.assign(unitCount + 1, 0);
        for (size_t u = 0; u < unitCount; ++u) prob.candidateOffsets[u + 1] = prob.candidateOffsets[u] + counts[u];
        prob.candidateLabels.resize(prob.candidateOffsets.back());
        prob.candidateCosts.resize(prob.candidateOffsets.back());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 1024), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t u = r.begin(); u < r.end(); ++u) {
                uint32_t slot = prob.candidateOffsets[u];
                double bestCost = 1e300;
                uint32_t bestLabel = 0;
                auto put = [&](uint32_t l, double c) {
                    prob.candidateLabels[slot] = l;
                    prob.candidateCosts[slot++] = c;
                    if (c < bestCost || (c == bestCost && l < bestLabel)) bestCost = c, bestLabel = l;
                };
                if (units.offsets[u + 1] - units.offsets[u] == 1) {
                    const size_t f = units.faces[units.offsets[u]];
                    for (int i = 0; i < k; ++i)
                        put(mNear.labels[f * size_t(k) + size_t(i)], dataCost(mNear.distancesMm[f * size_t(k) + size_t(i)]));
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
                for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i) {
                    const uint32_t v = units.unitOf[mGraph.neighbors[i]];
                    if (v != u) list.push_back({v, mFaceEdgeWeights[i]});
                }
            }
            std::sort(list.begin(), list.end());
        };
        std::vector<uint32_t> neighborCounts(unitCount, 0);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 1024), [&](const tbb::blocked_range<size_t>& r) {
            std::vector<std::pair<uint32_t, double>> list;
            for (size_t u = r.begin(); u < r.end(); ++u) {
                gather(u, list);
                uint32_t n = 0;
                for (size_t i = 0; i < list.size(); ++i) n += (i == 0 || list[i].first != list[i - 1].first) ? 1 : 0;
                neighborCounts[u] = n;
            }
        });
        prob.neighborOffsets.assign(unitCount + 1, 0);
        for (size_t u = 0; u < unitCount; ++u) prob.neighborOffsets[u + 1] = prob.neighborOffsets[u] + neighborCounts[u];
        prob.neighbors.resize(prob.neighborOffsets.back());
        prob.neighborWeights.resize(prob.neighborOffsets.back());
        tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 1024), [&](const tbb::blocked_range<size_t>& r) {
            std::vector<std::pair<uint32_t, double>> list;
            for (size_t u = r.begin(); u < r.end(); ++u) {
                gather(u, list);
                uint32_t slot = prob.neighborOffsets[u];
                for (size_t i = 0; i < list.size();) {
                    double w = 0.0;
                    size_t j = i;
                    while (j < list.size() && list[j].first == list[i].first) w += list[j++].second;
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
    /// mProb for labellings that agree outside the band, and expansions only touch the band.
    LabelingProblem restrictToBand(const std::vector<uint32_t>& labels, const std::vector<char>& band) const {
        LabelingProblem r;
        r.labelCount = mLabelCount;
        r.candidateLabels.reserve(mProb.candidateLabels.size());
        r.candidateCosts.reserve(mProb.candidateCosts.size());
        auto costOf = [&](size_t u, uint32_t l) {
            const int64_t s = mProb.slotOf(uint32_t(u), l);
            return s >= 0 ? mProb.candidateCosts[size_t(s)] : unitCost(mUnits, u, l);
        };
        for (size_t u = 0; u < mUnits.count(); ++u) {
            if (band[u]) {
                for (uint32_t s = mProb.candidateOffsets[u]; s < mProb.candidateOffsets[u + 1]; ++s) {
                    r.candidateLabels.push_back(mProb.candidateLabels[s]);
                    r.candidateCosts.push_back(mProb.candidateCosts[s]);
                }
                if (mProb.slotOf(uint32_t(u), labels[u]) < 0) {
                    r.candidateLabels.push_back(labels[u]);
                    r.candidateCosts.push_back(costOf(u, labels[u]));
                }
            } else {
                r.candidateLabels.push_back(labels[u]);
                r.candidateCosts.push_back(costOf(u, labels[u]));
            }
            r.candidateOffsets.push_back(uint32_t(r.candidateLabels.size()));
        }
        r.neighborOffsets = mProb.neighborOffsets;
        r.neighbors = mProb.neighbors;
        r.neighborWeights = mProb.neighborWeights;
        return r;
    }

    /// Nodes within mBandRings rings of faces of a seam of @p labels.
    std::vector<char> seamBand(const std::vector<uint32_t>& labels) const {
        std::vector<int> ring(mFaceCount, -1);
        std::vector<uint32_t> frontier, next;
        for (uint32_t f = 0; f < mFaceCount; ++f)
            for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i)
                if (labels[mUnits.unitOf[mGraph.neighbors[i]]] != labels[mUnits.unitOf[f]]) {
                    ring[f] = 0;
                    frontier.push_back(f);
                    break;
                }
        for (int r = 1; r <= mBandRings && !frontier.empty(); ++r) {
            next.clear();
            for (uint32_t f : frontier)
                for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i) {
                    const uint32_t h = mGraph.neighbors[i];
                    if (ring[h] < 0) ring[h] = r, next.push_back(h);
                }
            frontier.swap(next);
        }
        std::vector<char> band(mUnits.count(), 0);
        for (uint32_t f = 0; f < mFaceCount; ++f)
            if (ring[f] >= 0) band[mUnits.unitOf[f]] = 1;
        return band;
    }

    /// One graph cut at w_smoothness @p ws from the nearest-ball labelling (two levels when set).
    AlphaExpansionResult graphCut(double ws, ScheduleStep& st) const {
        AlphaExpansionOptions ao;
        ao.smoothnessWeight = ws;
        ao.maxSweeps = mOpt.maxSweeps;
        st.energyNearest = labelingEnergy(mProb, mInitial, ws);
        if (!mIsTwoLevel) return alphaExpansion(mProb, mInitial, ao, mRun);
        // Clusters from their nearest balls, then the nodes near the cluster seams from there.
        const AlphaExpansionResult coarse = alphaExpansion(mClusterProb, mClusterInitial, ao, mRun);
        std::vector<uint32_t> projected(mUnits.count());
        for (size_t u = 0; u < mUnits.count(); ++u)
            projected[u] = coarse.labels[mClusters.unitOf[mUnits.faces[mUnits.offsets[u]]]];
        const std::vector<char> band = seamBand(projected);
        st.clusterSweeps = coarse.sweeps;
        st.clusterExpansions = coarse.expansions;
        st.energyClusters = coarse.sweepEnergies.back();
        st.bandNodes = size_t(std::count(band.begin(), band.end(), char(1)));
        return alphaExpansion(restrictToBand(projected, band), projected, ao, mRun);
    }

    // --- fit schedule (§5.1) ---------------------------------------------------------------------

    /// A re-cut at w_smoothness @p ws of the faces flagged in @p isFree, every other face held at
    /// its label in @p labels (its only candidate). Free nodes start from their nearest ball and may
    /// take their k nearest. The problem keeps the face-level energy of the whole surface (held
    /// nodes add constants), so the seam weight between a free face and a held neighbour counts:
    /// free faces next to a kept partition join its label where that is cheaper than a new seam.
    AlphaExpansionResult refineCut(double ws, const std::vector<uint32_t>& labels, const std::vector<char>& isFree,
                                   ScheduleStep& st) const {
        AlphaExpansionOptions ao;
        ao.smoothnessWeight = ws;
        ao.maxSweeps = mOpt.maxSweeps;
        const size_t n = mUnits.count();
        std::vector<uint32_t> start(n);
        std::vector<char> isFreeNode(n);
        for (size_t u = 0; u < n; ++u) {
            // A node's faces share one label and are edge-connected, so they lie in one partition:
            // all free or all held.
            const uint32_t f = mUnits.faces[mUnits.offsets[u]];
            isFreeNode[u] = isFree[f];
            start[u] = isFree[f] ? mInitial[u] : labels[f];
        }
        // restrictToBand adds no candidate here: a free node's start (its nearest ball) is one already.
        const LabelingProblem prob = restrictToBand(start, isFreeNode);
        st.energyNearest = labelingEnergy(prob, start, ws);
        st.bandNodes = size_t(std::count(isFreeNode.begin(), isFreeNode.end(), char(1)));
        return alphaExpansion(prob, start, ao, mRun);
    }

    /// The fit schedule (docs/partition.md §4). The first step cuts the whole surface at
    /// w_smoothness = smoothnessStart and keeps every partition that fits the printer. Each further
    /// step multiplies w_smoothness by smoothnessFactor and re-cuts only the faces of the partitions
    /// that did not fit, the kept ones held: a single oversized partition no longer sends the whole
    /// surface to a lower smoothness (which gave many small pieces), and what already fits stays
    /// large and smooth. When w_smoothness would fall below smoothnessMin, what still does not fit
    /// is bisected. With refineOversizedOnly = false every step re-cuts the whole surface (the paper).
    void runSchedule() {
        const Stopwatch clock;
        Context& cx = context();
        std::vector<uint32_t>& labels = mRes.graphCutLabels;
        labels.assign(mFaceCount, 0);
        std::vector<char> isFree(mFaceCount, 1);
        // Kept partitions: per face its partition (kNone while free); per partition its label and the
        // step that kept it, which decide its SVM class (below).
        std::vector<uint32_t> regionOf(mFaceCount, kNone), regionLabel;
        std::vector<int> regionStep;
        std::vector<char> isWholeCutStep;               // per step: did it cut the whole surface?
        std::vector<std::vector<uint32_t>> oversized;   // free faces of each partition that does not fit
        std::vector<uint32_t> oversizedLabel;
        double ws = mOpt.smoothnessStart;
        int step = 0;
        for (;; ++step) {
            const Stopwatch stepClock;
            ScheduleStep st;
            st.smoothnessWeight = ws;
            const bool isWholeCut = step == 0 || !mOpt.refineOversizedOnly;
            if (isWholeCut) {
                std::fill(isFree.begin(), isFree.end(), char(1));
                std::fill(regionOf.begin(), regionOf.end(), kNone);
            }
            isWholeCutStep.push_back(isWholeCut ? 1 : 0);
            st.faces = size_t(std::count(isFree.begin(), isFree.end(), char(1)));
            const AlphaExpansionResult ae = isWholeCut ? graphCut(ws, st) : refineCut(ws, labels, isFree, st);
            st.energyGraphCut = ae.sweepEnergies.back();
            st.sweeps = ae.sweeps;
            st.expansions = ae.expansions;
            for (size_t f = 0; f < mFaceCount; ++f)
                if (isFree[f]) labels[f] = ae.labels[mUnits.unitOf[f]];

            // Partitions: connected regions of one label over the whole surface. Only those with free
            // faces are new; the others are kept partitions, unchanged. (Two kept partitions of one
            // label are never edge-adjacent: each was a whole region when it was kept, so a region
            // of its label next to it would have been part of it.)
            std::vector<uint32_t> compOf, compOffsets, compFaces;
            const uint32_t compCount = labelComponents(mGraph, labels, compOf);
            groupFaces(compOf, compCount, compOffsets, compFaces);
            std::vector<std::vector<uint32_t>> candidates;
            for (uint32_t c = 0; c < compCount; ++c) {
                const auto b = compFaces.begin() + compOffsets[c], e = compFaces.begin() + compOffsets[c + 1];
                if (std::any_of(b, e, [&](uint32_t f) { return isFree[f] != 0; })) candidates.emplace_back(b, e);
            }
            const std::vector<char> fits = fitsEach(cx, candidates);
            oversized.clear();
            oversizedLabel.clear();
            for (size_t i = 0; i < candidates.size(); ++i) {
                const uint32_t label = labels[candidates[i].front()];
                if (fits[i]) {
                    // Kept, together with any kept partition its free faces joined (the union fits).
                    const uint32_t r = uint32_t(regionLabel.size());
                    regionLabel.push_back(label);
                    regionStep.push_back(step);
                    for (uint32_t f : candidates[i]) regionOf[f] = r, isFree[f] = 0;
                    ++st.kept;
                } else {
                    // Its kept faces stay kept; its free faces are cut again at the next step.
                    std::vector<uint32_t> freeFaces;
                    for (uint32_t f : candidates[i])
                        if (isFree[f]) freeFaces.push_back(f);
                    oversized.push_back(std::move(freeFaces));
                    oversizedLabel.push_back(label);
                }
            }
            st.partitions = compCount;
            st.oversized = oversized.size();
            st.seconds = stepClock.seconds();
            mRes.schedule.push_back(st);
            mRes.smoothnessWeight = ws;
            mRes.energyNearest = st.energyNearest;
            mRes.energyGraphCut = st.energyGraphCut;
            mRes.sweepEnergies = ae.sweepEnergies;
            mRes.graphCutPartitions = st.partitions;
            mRun.info(formatNumbers("w_smoothness %g: ", ws) +
                      (isWholeCut ? std::string()
                                  : "re-cut " + std::to_string(st.faces) + " faces of the partitions that did not fit, ") +
                      formatNumbers("E %.6g -> %.6g, %.0f partitions", st.energyNearest, st.energyGraphCut, double(st.partitions)) +
                      (oversized.empty() ? ", all fit the printer" : ", " + std::to_string(oversized.size()) + " too large"));
            if (!ae.isConverged)
                mRun.warn(formatNumbers("graph cut at w_smoothness %g stopped after %.0f sweeps before converging", ws, double(ae.sweeps)));
            mRun.progress("partition", std::min(0.6, 0.1 * (step + 1)));
            if (oversized.empty()) break;
            if (ws * mOpt.smoothnessFactor < mOpt.smoothnessMin * (1.0 - 1e-9) || ws == 0.0) {
                mRes.isScheduleBottomedOut = true;
                break;
            }
            ws *= mOpt.smoothnessFactor;
        }
        mRes.secondsGraphCut = clock.seconds();

        // SVM training classes. Class l = label l for the partitions a whole-surface cut kept (as in
        // the paper: one class per ball); a partition kept by a re-cut gets a class per (step, label),
        // so it is never one class with a kept partition of the same ball next to it.
        mClassBall.assign(mLabelBalls.begin(), mLabelBalls.end());
        std::map<std::pair<int, uint32_t>, uint32_t> classOfKey;
        auto classFor = [&](int keptStep, uint32_t label) {
            if (isWholeCutStep[size_t(keptStep)]) return label;
            auto it = classOfKey.find({keptStep, label});
            if (it != classOfKey.end()) return it->second;
            mClassBall.push_back(mLabelBalls[label]);
            const uint32_t c = uint32_t(mClassBall.size() - 1);
            classOfKey.emplace(std::make_pair(keptStep, label), c);
            return c;
        };
        std::vector<uint32_t> regionClass(regionLabel.size());
        for (size_t r = 0; r < regionLabel.size(); ++r) regionClass[r] = classFor(regionStep[r], regionLabel[r]);
        mTrainClass.assign(mFaceCount, 0);
        for (size_t f = 0; f < mFaceCount; ++f)
            if (regionOf[f] != kNone) mTrainClass[f] = regionClass[regionOf[f]];
        // The schedule bottomed out: bisect what still does not fit. Its first part keeps the class
        // of its (step, label), every other part gets a class of its own.
        for (size_t i = 0; i < oversized.size(); ++i) {
            const uint32_t c = classFor(step, oversizedLabel[i]);
            for (uint32_t f : oversized[i]) mTrainClass[f] = c;
            mRes.splits += splitFaces(oversized[i]) ? 1 : 0;
        }
        if (mRes.isScheduleBottomedOut)
            mRun.warn(formatNumbers("the fit schedule bottomed out at w_smoothness %g with %.0f partitions larger than the "
                          "printer; split them",
                          ws, double(oversized.size())));
    }

    /// PartitionOptions::mergeSmallRegions (docs/partition.md §4): the regions are the connected
    /// regions of one training class (after any bisection); merged regions keep their classes, so
    /// the SVM still sees each as it was cut, and form one group, which makePieces turns into one
    /// piece of several cells.
    void mergeRegions() {
        if (!mOpt.mergeSmallRegions) return;
        mRun.throwIfCancelled();
        const Stopwatch clock;
        std::vector<uint32_t> regionOf;
        const uint32_t regionCount = labelComponents(mGraph, mTrainClass, regionOf);
        const RegionMerge m =
            mergeRegionsThatFit(mMesh, mGraph, regionOf, regionCount, mFab.printerMm, mFab.fitMarginMm);
        mFaceGroup.resize(mFaceCount);
        for (uint32_t f = 0; f < mFaceCount; ++f) mFaceGroup[f] = m.groupOf[regionOf[f]];
        mGroupCount = m.groupCount;
        mRes.regionMerges = m.merges;
        mRun.info(std::to_string(regionCount) + " regions, " + std::to_string(m.merges) +
                  " merged into a neighbour they fit the printer with: " + std::to_string(m.groupCount) + " regions");
        mRun.debug(formatNumbers("region merge: %.3f s", clock.seconds()));
    }

    Context& context() {
        if (!mContext)
            mContext = std::make_unique<Context>(
                Context{mMesh, mGraph, mFab, mRun, std::vector<uint32_t>(mMesh.positions.size(), 0), 0});
        return *mContext;
    }

    /// A new training class for @p faces, attached to the ball most of them are nearest to
    /// (lowest label on ties).
    uint32_t newClassFor(const std::vector<uint32_t>& faces) {
        std::map<uint32_t, size_t> votes;
        for (uint32_t f : faces) ++votes[mRes.nearestLabels[f]];
        uint32_t best = votes.begin()->first;
        for (const auto& [l, n] : votes)
            if (n > votes[best]) best = l;
        mClassBall.push_back(mLabelBalls[best]);
        return uint32_t(mClassBall.size() - 1);
    }

    /// Bisects @p faces until the parts fit; every part but the first gets a new class.
    bool splitFaces(const std::vector<uint32_t>& faces) {
        std::vector<std::vector<uint32_t>> parts;
        bisectUntilFit(context(), faces, mSalientRegionOf, parts, 0);
        for (size_t p = 1; p < parts.size(); ++p) {
            const uint32_t c = newClassFor(parts[p]);
            for (uint32_t f : parts[p]) mTrainClass[f] = c;
        }
        return parts.size() > 1;
    }

    // --- planar cuts (§5.2) and pieces ------------------------------------------------------------

    /// Training samples: face centroids. On large meshes, at most half the budget goes to the
    /// faces within two rings of a class boundary (where the planes are decided) and the rest to
    /// the other faces, each set thinned evenly in face order.
    void trainingSamples(std::vector<Vec3d>& samples, std::vector<uint32_t>& classes) const {
        std::vector<char> keep(mFaceCount, 1);
        if (mFaceCount > mOpt.svmMaxSamples) {
            std::vector<char> band(mFaceCount, 0);
            for (uint32_t f = 0; f < mFaceCount; ++f)
                for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i)
                    if (mTrainClass[mGraph.neighbors[i]] != mTrainClass[f]) band[f] = 1;
            std::vector<char> band2(band);
            for (uint32_t f = 0; f < mFaceCount; ++f)
                if (band[f])
                    for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i) band2[mGraph.neighbors[i]] = 1;
            const size_t bandCount = size_t(std::count(band2.begin(), band2.end(), char(1)));
            const size_t restCount = mFaceCount - bandCount;
            const size_t bandBudget = std::min(bandCount, mOpt.svmMaxSamples / 2);
            const size_t restBudget = std::max<size_t>(1, mOpt.svmMaxSamples - bandBudget);
            auto strideFor = [](size_t count, size_t budget) {
                return budget == 0 ? count + 1 : std::max<size_t>(1, (count + budget - 1) / budget);
            };
            const size_t bandStride = strideFor(bandCount, bandBudget), restStride = strideFor(restCount, restBudget);
            size_t bi = 0, ri = 0;
            for (uint32_t f = 0; f < mFaceCount; ++f)
                keep[f] = band2[f] ? ((bi++ % bandStride) == 0) : ((ri++ % restStride) == 0);
        }
        samples.clear();
        classes.clear();
        for (uint32_t f = 0; f < mFaceCount; ++f)
            if (keep[f]) samples.push_back(mGraph.centroidsMm[f]), classes.push_back(mTrainClass[f]);
    }

    /// The salient regions some of whose corners lie in another cell than the others.
    std::vector<uint32_t> crossedRegions(const LinearCells& cells) const {
        std::vector<uint32_t> crossed;
        for (uint32_t r = 0; r < mRes.salientRegions; ++r) {
            uint32_t first = kNone;
            bool isCrossed = false;
            for (uint32_t f : mSalientFacesOf[r]) {
                for (uint32_t v : mMesh.triangles[f]) {
                    const uint32_t cell = cells.cellAt(toD(mMesh.positions[v]));
                    if (first == kNone) first = cell;
                    if (cell != first) isCrossed = true;
                }
                if (isCrossed) break;
            }
            if (isCrossed) crossed.push_back(r);
        }
        return crossed;
    }

    /// Trains the cells; retrains with the corners of crossed salient regions weighted up.
    LinearCells trainCells(std::vector<uint32_t>& crossed) {
        std::vector<Vec3d> samples;
        std::vector<uint32_t> classes;
        trainingSamples(samples, classes);
        CellTrainingOptions so = mOpt.svm;
        so.seed = seedFor(mFab, SeedStream::Partition);
        LinearCells cells = trainLinearCells(samples, classes, so);
        crossed = crossedRegions(cells);
        for (int retry = 0; retry < mOpt.salientRetries && !crossed.empty(); ++retry) {
            // Their corners as extra samples of their class, repeated 4^retry times.
            const int repeat = 1 << (2 * retry);
            for (uint32_t r : crossed)
                for (uint32_t f : mSalientFacesOf[r])
                    for (uint32_t v : mMesh.triangles[f])
                        for (int i = 0; i < repeat; ++i) {
                            samples.push_back(toD(mMesh.positions[v]));
                            classes.push_back(mTrainClass[f]);
                        }
            mRun.debug("retraining: " + std::to_string(crossed.size()) + " salient region(s) crossed by a cut");
            cells = trainLinearCells(samples, classes, so);
            crossed = crossedRegions(cells);
        }
        mRes.svmSamples = samples.size();
        return cells;
    }

    /// Pieces from the cells: fragments (connected faces of one cell), merged for crossed salient
    /// regions and small areas when the result fits, numbered by lowest face, with their fits.
    /// @p pieceFaces receives each piece's faces.
    std::vector<Piece> makePieces(const LinearCells& cells, const std::vector<uint32_t>& faceCells,
                                  const std::vector<uint32_t>& crossed, std::vector<uint32_t>& facePieces,
                                  std::vector<std::vector<uint32_t>>& pieceFaces, size_t& merges) {
        Context& cx = context();
        std::vector<uint32_t> fragOf;
        const uint32_t fragCount = labelComponents(mGraph, faceCells, fragOf);
        std::vector<uint32_t> fragOffsets, fragFaces;
        groupFaces(fragOf, fragCount, fragOffsets, fragFaces);
        std::vector<double> fragArea(fragCount, 0.0);
        for (uint32_t f = 0; f < mFaceCount; ++f) fragArea[fragOf[f]] += mGraph.areasMm2[f];

        DisjointSets dsu(fragCount);
        std::vector<std::vector<uint32_t>> members(fragCount);  // faces of each root
        for (uint32_t c = 0; c < fragCount; ++c)
            members[c].assign(fragFaces.begin() + fragOffsets[c], fragFaces.begin() + fragOffsets[c + 1]);
        std::vector<double> area(fragArea);
        merges = 0;
        // The faces of roots a and b, a's first (the order the fit test samples them in).
        auto facesOf = [&](uint32_t a, uint32_t b) {
            std::vector<uint32_t> joined(members[a]);
            joined.insert(joined.end(), members[b].begin(), members[b].end());
            return joined;
        };
        // Makes roots a and b one piece whose faces are @p joined.
        auto unite = [&](uint32_t a, uint32_t b, std::vector<uint32_t> joined) {
            dsu.unite(a, b);
            const uint32_t root = dsu.find(a), other = root == a ? b : a;
            members[root] = std::move(joined);
            members[other].clear();
            area[root] += area[other];
        };
        auto tryMerge = [&](uint32_t a, uint32_t b, bool isCounted = true) {
            a = dsu.find(a), b = dsu.find(b);
            if (a == b) return true;
            std::vector<uint32_t> joined = facesOf(a, b);
            if (!cx.fitOf(joined).fits) return false;
            unite(a, b, std::move(joined));
            merges += isCounted ? 1 : 0;
            return true;
        };
        // Merged regions (mergeSmallRegions): the fragments of one group that touch each other
        // become one piece. A fragment belongs to the group of most of its area (cells follow the
        // regions only approximately). Normally the whole connected set fits, as the regions' union
        // did: one test; otherwise pairwise, in fragment order, each merge only if it fits.
        if (!mFaceGroup.empty()) {
            std::vector<uint32_t> fragGroup(fragCount, kNone);
            {
                std::vector<std::map<uint32_t, double>> groupArea(fragCount);
                for (uint32_t f = 0; f < mFaceCount; ++f) groupArea[fragOf[f]][mFaceGroup[f]] += mGraph.areasMm2[f];
                for (uint32_t c = 0; c < fragCount; ++c) {
                    double best = -1.0;
                    for (const auto& [gr, a] : groupArea[c])
                        if (a > best) best = a, fragGroup[c] = gr;  // ties: lowest group
                }
            }
            std::set<std::pair<uint32_t, uint32_t>> touching;  // fragment pairs of one group
            for (uint32_t f = 0; f < mFaceCount; ++f)
                for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i) {
                    const uint32_t a = fragOf[f], b = fragOf[mGraph.neighbors[i]];
                    if (a < b && fragGroup[a] == fragGroup[b]) touching.insert({a, b});
                }
            DisjointSets linked(fragCount);
            for (const auto& [a, b] : touching) linked.unite(a, b);
            std::vector<std::vector<uint32_t>> setFaces(fragCount);
            for (uint32_t f = 0; f < mFaceCount; ++f) setFaces[linked.find(fragOf[f])].push_back(f);
            std::vector<uint32_t> setRoots;
            std::vector<std::vector<uint32_t>> sets;
            for (uint32_t c = 0; c < fragCount; ++c)
                if (linked.find(c) == c && setFaces[c].size() > members[c].size())
                    setRoots.push_back(c), sets.push_back(std::move(setFaces[c]));
            const std::vector<char> setFits = fitsEach(cx, sets);  // in parallel, the same test
            std::vector<char> isWhole(fragCount, 0);
            for (size_t i = 0; i < setRoots.size(); ++i) isWhole[setRoots[i]] = setFits[i];
            for (const auto& [a, b] : touching) {
                if (isWhole[linked.find(a)]) {
                    const uint32_t ra = dsu.find(a), rb = dsu.find(b);
                    if (ra != rb) unite(ra, rb, facesOf(std::min(ra, rb), std::max(ra, rb)));  // the lower id is the root
                } else {
                    tryMerge(a, b, false);
                }
            }
        }
        // Salient regions a cut still crosses: keep them in one piece by merging the fragments of
        // their faces and of the faces around them (where corners in another cell lie), if it fits.
        for (uint32_t r : crossed) {
            const uint32_t first = fragOf[mSalientFacesOf[r].front()];
            for (uint32_t f : mSalientFacesOf[r]) {
                tryMerge(first, fragOf[f]);
                for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i) tryMerge(first, fragOf[mGraph.neighbors[i]]);
            }
        }
        // Small fragments, smallest first, into the neighbour they share the longest seam with.
        std::vector<uint32_t> order(fragCount);
        std::iota(order.begin(), order.end(), 0u);
        std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
            return fragArea[a] != fragArea[b] ? fragArea[a] < fragArea[b] : a < b;
        });
        for (uint32_t c : order) {
            const uint32_t root = dsu.find(c);
            if (area[root] >= mOpt.minPieceAreaMm2) continue;
            std::map<uint32_t, double> seam;  // neighbour root → shared edge length (mm)
            for (uint32_t f : members[root])
                for (uint32_t i = mGraph.offsets[f]; i < mGraph.offsets[f + 1]; ++i) {
                    const uint32_t h = mGraph.neighbors[i];
                    const uint32_t other = dsu.find(fragOf[h]);
                    if (other == root) continue;
                    seam[other] += sharedEdgeMm(mMesh, f, h);  // graph neighbours share an edge
                }
            std::vector<std::pair<double, uint32_t>> byLength;
            for (const auto& [o, len] : seam) byLength.push_back({-len, o});
            std::sort(byLength.begin(), byLength.end());
            for (const auto& [negLen, o] : byLength)
                if (tryMerge(root, o)) break;
        }

        // Pieces in order of their lowest face.
        std::vector<uint32_t> pieceOfRoot(fragCount, kNone);
        facePieces.assign(mFaceCount, 0);
        uint32_t pieceCount = 0;
        for (uint32_t f = 0; f < mFaceCount; ++f) {
            const uint32_t root = dsu.find(fragOf[f]);
            if (pieceOfRoot[root] == kNone) pieceOfRoot[root] = pieceCount++;
            facePieces[f] = pieceOfRoot[root];
        }
        pieceFaces.assign(pieceCount, {});
        for (uint32_t f = 0; f < mFaceCount; ++f) pieceFaces[facePieces[f]].push_back(f);
        std::vector<Piece> pieces(pieceCount);
        std::vector<std::vector<Vec3d>> piecePts(pieceCount);
        for (uint32_t p = 0; p < pieceCount; ++p) {
            Piece& piece = pieces[p];
            piece.faceCount = uint32_t(pieceFaces[p].size());
            for (uint32_t f : pieceFaces[p]) {
                piece.areaMm2 += mGraph.areasMm2[f];
                piece.cells.push_back(faceCells[f]);
            }
            std::sort(piece.cells.begin(), piece.cells.end());
            piece.cells.erase(std::unique(piece.cells.begin(), piece.cells.end()), piece.cells.end());
            for (uint32_t c : piece.cells) piece.balls.push_back(mClassBall[cells.classes[c]]);
            std::sort(piece.balls.begin(), piece.balls.end());
            piece.balls.erase(std::unique(piece.balls.begin(), piece.balls.end()), piece.balls.end());
            piecePts[p] = faceVertices(mMesh, pieceFaces[p], cx.stamp, cx.stampValue);
            for (const Vec3d& v : piecePts[p]) piece.boundsMm.expand(v);
        }
        tbb::parallel_for(uint32_t(0), pieceCount, [&](uint32_t p) {
            pieces[p].fit = fitInPrinter(piecePts[p], mFab.printerMm, mFab.fitMarginMm);
        });
        return pieces;
    }

    /// Salient regions whose faces lie in several pieces, or whose corners lie in a cell that is
    /// not one of their piece's cells.
    size_t countCrossedRegions(const std::vector<uint32_t>& crossed) const {
        size_t count = 0;
        for (uint32_t r : crossed) {
            bool isSplit = false;
            const uint32_t p0 = mRes.facePieces[mSalientFacesOf[r].front()];
            const auto& cells = mRes.pieces[p0].cells;
            for (uint32_t f : mSalientFacesOf[r]) {
                if (mRes.facePieces[f] != p0) isSplit = true;
                for (uint32_t v : mMesh.triangles[f])
                    if (!std::binary_search(cells.begin(), cells.end(), mRes.cells.cellAt(toD(mMesh.positions[v]))))
                        isSplit = true;
            }
            count += isSplit ? 1 : 0;
        }
        return count;
    }

    /// Cells, pieces, and split-and-retrain rounds until every piece fits.
    void cutAndMakePieces() {
        const Stopwatch clock;
        for (int round = 0;; ++round) {
            mRun.throwIfCancelled();
            std::vector<uint32_t> crossed;
            LinearCells cells = trainCells(crossed);
            std::vector<uint32_t> faceCells(mFaceCount);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, mFaceCount, 4096), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t f = r.begin(); f < r.end(); ++f) faceCells[f] = cells.cellAt(mGraph.centroidsMm[f]);
            });
            std::vector<uint32_t> facePieces;
            std::vector<std::vector<uint32_t>> pieceFaces;
            size_t merges = 0;
            std::vector<Piece> pieces = makePieces(cells, faceCells, crossed, facePieces, pieceFaces, merges);

            std::vector<uint32_t> tooLarge;
            for (uint32_t p = 0; p < pieces.size(); ++p)
                if (!pieces[p].fit.fits) tooLarge.push_back(p);
            if (!tooLarge.empty() && round >= mOpt.maxRepairRounds)
                throw Error(ErrorCode::ProcessingFailed,
                            std::to_string(tooLarge.size()) + " piece(s) still do not fit the printer " +
                                sizeText(mFab.printerMm) + " after " + std::to_string(round) + " repair rounds (piece " +
                                std::to_string(tooLarge.front()) + " needs " +
                                sizeText(pieces[tooLarge.front()].fit.extentsMm) + ")");
            if (tooLarge.empty()) {
                size_t agree = 0;
                for (uint32_t f = 0; f < mFaceCount; ++f) agree += cells.classes[faceCells[f]] == mTrainClass[f] ? 1 : 0;
                mRes.svmAgreement = double(agree) / double(mFaceCount);
                mRes.cells = std::move(cells);
                mRes.cellBalls.clear();
                for (uint32_t c : mRes.cells.classes) mRes.cellBalls.push_back(mClassBall[c]);
                mRes.faceCells = std::move(faceCells);
                mRes.facePieces = std::move(facePieces);
                mRes.pieces = std::move(pieces);
                mRes.merges = merges;
                mRes.salientRegionsSplit = countCrossedRegions(crossed);
                if (mRes.salientRegionsSplit > 0)
                    mRun.warn(std::to_string(mRes.salientRegionsSplit) +
                              " salient region(s) are crossed by a planar cut that could not be avoided");
                break;
            }
            // Split the pieces that do not fit into new classes and train again.
            for (uint32_t p : tooLarge) {
                const uint32_t c = newClassFor(pieceFaces[p]);  // the piece's faces get one class of their own first
                for (uint32_t f : pieceFaces[p]) mTrainClass[f] = c;
                if (splitFaces(pieceFaces[p])) ++mRes.splits;
                // Its parts leave their merged group (each part a group of its own), so the next
                // round does not join them into the piece that did not fit again.
                if (!mFaceGroup.empty())
                    for (uint32_t f : pieceFaces[p]) mFaceGroup[f] = mGroupCount + mTrainClass[f];
            }
            mRun.info(std::to_string(tooLarge.size()) +
                      " piece(s) do not fit the printer after the planar cuts; split and retrain");
        }
        mRes.secondsSvm = clock.seconds();
    }

    const TriMesh& mMesh;
    const zome::Structure& mFrame;
    const std::vector<zome::BallId>& mLabelBalls;
    const Fabrication& mFab;
    const PartitionOptions& mOpt;
    const RunContext& mRun;
    const size_t mFaceCount;
    const uint32_t mLabelCount;
    const double mB0;

    PartitionResult mRes;
    std::vector<Vec3d> mBallMm;                 ///< label → ball centre, mm
    FaceGraph mGraph;
    std::vector<uint32_t> mSalientRegionOf;     ///< per face, kNone when not salient
    std::vector<std::vector<uint32_t>> mSalientFacesOf;
    NearestBalls mNear;
    int mK = 0;                                 ///< candidates per face (k, at most the label count)
    std::vector<double> mFaceEdgeWeights;       ///< Eq. (3) weights aligned with mGraph.neighbors
    bool mIsTwoLevel = false;
    int mBandRings = 3;
    Units mUnits, mClusters;
    LabelingProblem mProb, mClusterProb;
    std::vector<uint32_t> mInitial, mClusterInitial;
    std::vector<uint32_t> mTrainClass;          ///< per face: SVM class
    std::vector<zome::BallId> mClassBall;       ///< class → ball
    std::vector<uint32_t> mFaceGroup;           ///< per face: its merged region (empty: no merge)
    uint32_t mGroupCount = 0;                   ///< groups of the region merge (ids above: repair parts)
    std::unique_ptr<Context> mContext;
};

}  // namespace

PartitionResult partitionSurface(const TriMesh& meshMm, const zome::Structure& frame,
                                 const std::vector<zome::BallId>& labelBalls, const Fabrication& fabrication,
                                 const PartitionOptions& options, const RunContext& context) {
    return Stage(meshMm, frame, labelBalls, fabrication, options, context).run();
}

}  // namespace zomefab::partition
