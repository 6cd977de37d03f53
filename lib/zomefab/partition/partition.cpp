// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/partition.h"

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <numeric>
#include <string>
#include <tuple>

#include "zomefab/core/error.h"
#include "zomefab/partition/alpha_expansion.h"
#include "zomefab/partition/face_graph.h"

namespace zomefab::partition {

namespace {

constexpr uint32_t kNone = 0xFFFFFFFFu;
const double kPi = std::acos(-1.0);

double dist2(const Vec3d& a, const Vec3d& b) {
    const double x = a[0] - b[0], y = a[1] - b[1], z = a[2] - b[2];
    return x * x + y * y + z * z;
}

Vec3d toD(const Vec3f& p) { return {double(p[0]), double(p[1]), double(p[2])}; }

std::string fmt(const char* format, double a, double b = 0, double c = 0, double d = 0) {
    char buf[256];
    std::snprintf(buf, sizeof(buf), format, a, b, c, d);
    return buf;
}

std::string sizeText(const Vec3d& v) { return fmt("%.0f x %.0f x %.0f mm", v[0], v[1], v[2]); }

/// Closest point of triangle abc to p, squared distance (Ericson, Real-Time Collision Detection §5.1.5).
double pointTriangleDist2(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    auto sub = [](const Vec3d& x, const Vec3d& y) { return Vec3d{x[0] - y[0], x[1] - y[1], x[2] - y[2]}; };
    auto dot = [](const Vec3d& x, const Vec3d& y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
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
            for (int i = 0; i < kk; ++i) {
                out.labels[q * size_t(kk) + size_t(i)] = best[size_t(i)].second;
                out.distancesMm[q * size_t(kk) + size_t(i)] = std::sqrt(best[size_t(i)].first);
            }
        }
    });
    return out;
}

// --- graph-cut nodes: faces, clusters of faces, salient regions ------------------------------

struct Units {
    std::vector<uint32_t> unitOf;   ///< per face
    std::vector<uint32_t> offsets;  ///< CSR unit → faces
    std::vector<uint32_t> faces;
    size_t count() const { return offsets.size() - 1; }
};

/// Salient regions become one node each (a seam can never run inside them); the other faces are
/// single nodes, or breadth-first clusters of about @p clusterSize edge-connected faces.
Units buildUnits(const FaceGraph& g, const std::vector<uint8_t>& salient, size_t clusterSize) {
    Units u;
    const size_t n = g.faceCount();
    u.unitOf.assign(n, kNone);
    u.offsets.push_back(0);
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

/// Quick accept: an axis-aligned box or a bounding sphere that fits needs no orientation search.
bool fitsTrivially(const std::vector<Vec3d>& pts, const Vec3d& printer, double margin) {
    Box3d box;
    for (const Vec3d& p : pts) box.expand(p);
    Vec3d e = box.size();
    for (double& x : e) x += 2 * margin;
    std::sort(e.begin(), e.end());
    Vec3d p = printer;
    std::sort(p.begin(), p.end());
    return e[0] <= p[0] && e[1] <= p[1] && e[2] <= p[2];
}

struct Context {
    const TriMesh& mesh;
    const FaceGraph& graph;
    const PartitionOptions& opt;
    const RunContext& run;
    std::vector<uint32_t> stamp;
    uint32_t stampValue = 0;

    PrinterFit fitOf(const std::vector<uint32_t>& faces) {
        const std::vector<Vec3d> pts = faceVertices(mesh, faces, stamp, stampValue);
        return fitInPrinter(pts, opt.printerMm, opt.fitMarginMm);
    }
};

/// The regions (connected components of @p labels) that do not fit the printer, as face lists.
std::vector<std::vector<uint32_t>> oversizedRegions(Context& cx, const std::vector<uint32_t>& labels, size_t* regionCount) {
    std::vector<uint32_t> compOf;
    const uint32_t n = labelComponents(cx.graph, labels, compOf);
    if (regionCount) *regionCount = n;
    std::vector<uint32_t> offsets, faces;
    groupFaces(compOf, n, offsets, faces);
    std::vector<char> isOver(n, 0);
    // Vertex lists per region first (serial, one stamp array), then the fit tests in parallel.
    std::vector<std::vector<Vec3d>> pts(n);
    for (uint32_t c = 0; c < n; ++c)
        pts[c] = faceVertices(cx.mesh, std::vector<uint32_t>(faces.begin() + offsets[c], faces.begin() + offsets[c + 1]),
                              cx.stamp, cx.stampValue);
    tbb::parallel_for(uint32_t(0), n, [&](uint32_t c) {
        if (fitsTrivially(pts[c], cx.opt.printerMm, cx.opt.fitMarginMm)) return;
        isOver[c] = !fitInPrinter(pts[c], cx.opt.printerMm, cx.opt.fitMarginMm).fits;
    });
    std::vector<std::vector<uint32_t>> out;
    for (uint32_t c = 0; c < n; ++c)
        if (isOver[c]) out.emplace_back(faces.begin() + offsets[c], faces.begin() + offsets[c + 1]);
    return out;
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

/// Union-find over pieces.
struct Dsu {
    std::vector<uint32_t> parent;
    explicit Dsu(size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0u); }
    uint32_t find(uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    }
    /// Joins into the smaller root id (keeps numbering deterministic).
    void join(uint32_t a, uint32_t b) {
        a = find(a), b = find(b);
        if (a == b) return;
        if (b < a) std::swap(a, b);
        parent[b] = a;
    }
};

}  // namespace

// --- public helpers ---------------------------------------------------------------------------

void checkPartitionOptions(const PartitionOptions& o, const zome::ZomeScale& scale) {
    auto usage = [](const std::string& m) { throw Error(ErrorCode::Usage, m); };
    for (double p : o.printerMm)
        if (!(p > 0.0) || !std::isfinite(p)) usage("printer size " + sizeText(o.printerMm) + ": every side must be > 0");
    const double minSide = std::min({o.printerMm[0], o.printerMm[1], o.printerMm[2]});
    if (minSide < scale.ballDiameterMm + 2.0 * o.fitMarginMm)
        usage("printer volume " + sizeText(o.printerMm) + " is smaller than a Zome ball (" +
              fmt("%.1f mm across", scale.ballDiameterMm) +
              (o.fitMarginMm > 0 ? fmt(" plus 2 x %.1f mm margin", o.fitMarginMm) : std::string()) + ")");
    if (o.candidateCount < 1) usage("k (candidate labels per triangle) must be >= 1");
    if (!(o.dataWeight > 0.0) || !std::isfinite(o.dataWeight)) usage("w_data must be > 0");
    if (!(o.saliencyWeight >= 0.0) || !std::isfinite(o.saliencyWeight)) usage("w_saliency must be >= 0");
    if (!(o.smoothnessStart >= 0.0) || !std::isfinite(o.smoothnessStart)) usage("w_smoothness must be >= 0");
    if (!(o.smoothnessFactor > 0.0 && o.smoothnessFactor < 1.0)) usage("the w_smoothness factor must be in (0, 1)");
    if (!(o.smoothnessMin >= 0.0)) usage("the smallest w_smoothness must be >= 0");
    if (!(o.fitMarginMm >= 0.0) || !std::isfinite(o.fitMarginMm)) usage("the fit margin must be >= 0 mm");
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

// --- the stage --------------------------------------------------------------------------------

PartitionResult partitionSurface(const TriMesh& meshMm, const zome::Structure& frame,
                                 const std::vector<zome::BallId>& labelBalls, const PartitionOptions& opt,
                                 const RunContext& run) {
    const Stopwatch total;
    checkPartitionOptions(opt, frame.scale());
    if (meshMm.triangles.empty()) throw Error(ErrorCode::InvalidInput, "the mesh has no triangles");
    if (labelBalls.empty())
        throw Error(ErrorCode::InvalidInput, "the frame has no outermost balls to attach pieces to" +
                                                 std::string(frame.ballCount() == 0 ? " (it has no balls at all)" : ""));
    {
        std::vector<zome::BallId> sorted(labelBalls);
        std::sort(sorted.begin(), sorted.end());
        for (size_t i = 0; i < sorted.size(); ++i) {
            if (!frame.hasBall(sorted[i]))
                throw Error(ErrorCode::InvalidInput, "label ball " + std::to_string(sorted[i]) + " is not a ball of the frame");
            if (i > 0 && sorted[i] == sorted[i - 1])
                throw Error(ErrorCode::InvalidInput, "label ball " + std::to_string(sorted[i]) + " is listed twice");
        }
    }
    const double b0 = frame.scale().b0Mm;
    const size_t faceCount = meshMm.triangles.size();
    const uint32_t labelCount = uint32_t(labelBalls.size());

    PartitionResult res;
    res.b0Mm = b0;
    res.printerMm = opt.printerMm;
    res.fitMarginMm = opt.fitMarginMm;
    res.labelBalls = labelBalls;

    // Mesh/frame mismatch: the frame sits inside the shell, so every label ball lies inside the
    // mesh's bounding box (one b0 of slack for rounding and open meshes).
    std::vector<Vec3d> ballMm(labelCount);
    for (uint32_t l = 0; l < labelCount; ++l) ballMm[l] = frame.ball(labelBalls[l]).positionMm;
    {
        const Box3d box = boundingBox(meshMm);
        for (uint32_t l = 0; l < labelCount; ++l) {
            double out = 0.0;
            for (int a = 0; a < 3; ++a)
                out = std::max({out, box.min[size_t(a)] - ballMm[l][size_t(a)], ballMm[l][size_t(a)] - box.max[size_t(a)]});
            if (out > b0)
                throw Error(ErrorCode::InvalidInput,
                            "frame and mesh do not match: ball " + std::to_string(labelBalls[l]) +
                                fmt(" at (%.1f, %.1f, %.1f) mm", ballMm[l][0], ballMm[l][1], ballMm[l][2]) +
                                fmt(" lies %.1f mm outside the mesh's bounding box (check transform_mm)", out));
        }
    }

    run.progress("partition", 0.0);
    const FaceGraph graph = buildFaceGraph(meshMm);
    res.salientFaces = salientFaceFlags(meshMm, opt.salientSpheres, opt.salientFaceIndices);

    // Salient regions: edge-connected salient faces.
    std::vector<uint32_t> salientRegionOf(faceCount, kNone);
    {
        std::vector<uint32_t> tag(faceCount);
        for (size_t f = 0; f < faceCount; ++f) tag[f] = res.salientFaces[f] ? 0u : uint32_t(f + 1);  // non-salient: unique
        std::vector<uint32_t> comp;
        labelComponents(graph, tag, comp);
        std::map<uint32_t, uint32_t> renumber;
        for (size_t f = 0; f < faceCount; ++f)
            if (res.salientFaces[f]) {
                auto it = renumber.emplace(comp[f], uint32_t(renumber.size())).first;
                salientRegionOf[f] = it->second;
            }
        res.salientRegions = renumber.size();
    }

    // Data term, Eq. (2): D(t, n) = log d(t, n), d in units of b0, clamped below.
    const NearestBalls near = nearestBalls(graph.centroidsMm, ballMm, opt.candidateCount, 2.0 * b0);
    const int k = near.k;
    auto dataCost = [&](double dMm) { return opt.dataWeight * std::log(std::max(dMm / b0, opt.minDistanceB0)); };
    res.nearestLabels.resize(faceCount);
    for (size_t f = 0; f < faceCount; ++f) res.nearestLabels[f] = near.labels[f * size_t(k)];
    {
        // A frame made for another mesh (or another scale) leaves the surface far from every ball.
        std::vector<double> d(faceCount);
        for (size_t f = 0; f < faceCount; ++f) d[f] = near.distancesMm[f * size_t(k)];
        std::nth_element(d.begin(), d.begin() + long(faceCount / 2), d.end());
        const double median = d[faceCount / 2];
        if (median > 5.0 * b0)
            throw Error(ErrorCode::InvalidInput,
                        fmt("frame and mesh do not match: the surface lies a median %.0f mm (%.1f b0) from the "
                            "nearest outermost ball (check transform_mm)",
                            median, median / b0));
    }
    run.throwIfCancelled();

    // Graph-cut nodes: faces, or clusters of faces on large meshes.
    const size_t clusterSize = (opt.graphNodeTarget > 0 && faceCount > opt.graphNodeTarget)
                                   ? (faceCount + opt.graphNodeTarget - 1) / opt.graphNodeTarget
                                   : 1;
    const Units units = buildUnits(graph, res.salientFaces, clusterSize);
    if (clusterSize > 1)
        run.debug("graph cut on " + std::to_string(units.count()) + " clusters of up to " + std::to_string(clusterSize) +
                  " faces");
    auto makeProblem = [&](const Units& units, std::vector<uint32_t>& initialUnitLabels) {
        const size_t unitCount = units.count();
        LabelingProblem prob;
        prob.labelCount = labelCount;
        prob.candidateOffsets.assign(1, 0);
        initialUnitLabels.resize(unitCount);
        std::vector<std::vector<std::pair<uint32_t, double>>> perUnit(unitCount);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, unitCount, 256), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t u = r.begin(); u < r.end(); ++u) {
                auto& cand = perUnit[u];
                const uint32_t b = units.offsets[u], e = units.offsets[u + 1];
                if (e - b == 1) {
                    const uint32_t f = units.faces[b];
                    for (int i = 0; i < k; ++i)
                        cand.push_back({near.labels[f * size_t(k) + size_t(i)], dataCost(near.distancesMm[f * size_t(k) + size_t(i)])});
                } else {
                    // A cluster or salient region: the union of its faces' candidates, each cost
                    // the sum over its faces with the true distances.
                    std::vector<uint32_t> labels;
                    for (uint32_t j = b; j < e; ++j)
                        for (int i = 0; i < k; ++i) labels.push_back(near.labels[units.faces[j] * size_t(k) + size_t(i)]);
                    std::sort(labels.begin(), labels.end());
                    labels.erase(std::unique(labels.begin(), labels.end()), labels.end());
                    for (uint32_t l : labels) {
                        double sum = 0.0;
                        for (uint32_t j = b; j < e; ++j)
                            sum += dataCost(std::sqrt(dist2(graph.centroidsMm[units.faces[j]], ballMm[l])));
                        cand.push_back({l, sum});
                    }
                }
            }
        });
        for (size_t u = 0; u < unitCount; ++u) {
            double bestCost = 1e300;
            uint32_t bestLabel = 0;
            for (const auto& [l, c] : perUnit[u]) {
                prob.candidateLabels.push_back(l);
                prob.candidateCosts.push_back(c);
                if (c < bestCost || (c == bestCost && l < bestLabel)) bestCost = c, bestLabel = l;
            }
            prob.candidateOffsets.push_back(uint32_t(prob.candidateLabels.size()));
            initialUnitLabels[u] = bestLabel;  // the nearest ball (summed over a node's faces)
        }
        // Smoothness weights between nodes: the sum of Eq. (3) over the face pairs they share.
        std::vector<std::tuple<uint32_t, uint32_t, double>> pairs;
        pairs.reserve(graph.neighbors.size());
        for (uint32_t f = 0; f < faceCount; ++f)
            for (uint32_t i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
                const uint32_t h = graph.neighbors[i];
                const uint32_t u = units.unitOf[f], v = units.unitOf[h];
                if (u == v) continue;
                pairs.emplace_back(u, v, edgeWeight(graph, res.salientFaces, f, h, opt));
            }
        tbb::parallel_sort(pairs.begin(), pairs.end());  // total order: deterministic sums
        prob.neighborOffsets.assign(unitCount + 1, 0);
        for (size_t i = 0; i < pairs.size();) {
            size_t j = i;
            double w = 0.0;
            while (j < pairs.size() && std::get<0>(pairs[j]) == std::get<0>(pairs[i]) &&
                   std::get<1>(pairs[j]) == std::get<1>(pairs[i]))
                w += std::get<2>(pairs[j++]);
            prob.neighbors.push_back(std::get<1>(pairs[i]));
            prob.neighborWeights.push_back(w);
            ++prob.neighborOffsets[std::get<0>(pairs[i]) + 1];
            i = j;
        }
        for (size_t u = 0; u < unitCount; ++u) prob.neighborOffsets[u + 1] += prob.neighborOffsets[u];
        return prob;
    };
    std::vector<uint32_t> initialLabels;
    const LabelingProblem prob = makeProblem(units, initialLabels);
    res.graphNodes = units.count();
    res.candidatePairs = prob.candidateLabels.size();
    run.throwIfCancelled();

    // --- fit schedule: w_smoothness = 10, ×0.1 while a partition does not fit (§5.1) ---------
    Context cx{meshMm, graph, opt, run, std::vector<uint32_t>(meshMm.positions.size(), 0), 0};
    auto toFaces = [&](const std::vector<uint32_t>& unitLabels) {
        std::vector<uint32_t> f(faceCount);
        for (size_t i = 0; i < faceCount; ++i) f[i] = unitLabels[units.unitOf[i]];
        return f;
    };
    const Stopwatch cutClock;
    double ws = opt.smoothnessStart;
    std::vector<std::vector<uint32_t>> oversized;
    for (int step = 0;; ++step) {
        const Stopwatch stepClock;
        AlphaExpansionOptions ao;
        ao.smoothnessWeight = ws;
        ao.maxSweeps = opt.maxSweeps;
        ScheduleStep st;
        st.smoothnessWeight = ws;
        AlphaExpansionResult ae = alphaExpansion(prob, initialLabels, ao, run);
        st.energyNearest = ae.sweepEnergies.front();
        st.energyGraphCut = ae.sweepEnergies.back();
        st.sweeps = ae.sweeps;
        st.expansions = ae.expansions;
        res.graphCutLabels = toFaces(ae.labels);
        oversized = oversizedRegions(cx, res.graphCutLabels, &st.partitions);
        st.oversized = oversized.size();
        st.seconds = stepClock.seconds();
        res.schedule.push_back(st);
        res.smoothnessWeight = ws;
        res.energyNearest = st.energyNearest;
        res.energyGraphCut = st.energyGraphCut;
        res.sweepEnergies = ae.sweepEnergies;
        res.graphCutPartitions = st.partitions;
        run.info(fmt("w_smoothness %g: E %.6g -> %.6g, %.0f partitions", ws, st.energyNearest, st.energyGraphCut,
                     double(st.partitions)) +
                 (oversized.empty() ? ", all fit the printer" : ", " + std::to_string(oversized.size()) + " too large"));
        if (!ae.isConverged) run.warn(fmt("graph cut at w_smoothness %g stopped after %.0f sweeps before converging", ws, double(ae.sweeps)));
        run.progress("partition", std::min(0.6, 0.1 * (step + 1)));
        if (oversized.empty()) break;
        if (ws * opt.smoothnessFactor < opt.smoothnessMin * (1.0 - 1e-9) || ws == 0.0) {
            res.isScheduleBottomedOut = true;
            break;
        }
        ws *= opt.smoothnessFactor;
    }
    res.secondsGraphCut = cutClock.seconds();
    {
        std::vector<uint32_t> comp;
        res.nearestPartitions = labelComponents(graph, res.nearestLabels, comp);
    }

    // Training classes: the graph-cut labels, plus new classes for split parts.
    std::vector<uint32_t> trainClass = res.graphCutLabels;
    std::vector<zome::BallId> classBall(labelBalls.begin(), labelBalls.end());
    auto newClassFor = [&](const std::vector<uint32_t>& faces) {
        // The ball most of these faces are nearest to (lowest label on ties).
        std::map<uint32_t, size_t> votes;
        for (uint32_t f : faces) ++votes[res.nearestLabels[f]];
        uint32_t best = votes.begin()->first;
        for (const auto& [l, n] : votes)
            if (n > votes[best]) best = l;
        classBall.push_back(labelBalls[best]);
        return uint32_t(classBall.size() - 1);
    };
    auto splitFaces = [&](const std::vector<uint32_t>& faces) {
        std::vector<std::vector<uint32_t>> parts;
        bisectUntilFit(cx, faces, salientRegionOf, parts, 0);
        for (size_t p = 1; p < parts.size(); ++p) {  // the first part keeps its class
            const uint32_t c = newClassFor(parts[p]);
            for (uint32_t f : parts[p]) trainClass[f] = c;
        }
        return parts.size() > 1;
    };
    if (res.isScheduleBottomedOut) {
        size_t count = 0;
        for (const auto& region : oversized) count += splitFaces(region) ? 1 : 0;
        res.splits += count;
        run.warn(fmt("the fit schedule bottomed out at w_smoothness %g with %.0f partitions larger than the printer; "
                     "split them",
                     ws, double(oversized.size())));
    }

    // --- planar cuts (§5.2) and pieces, repaired until every piece fits ------------------------
    const Stopwatch svmClock;
    std::vector<std::vector<uint32_t>> salientFacesOf(res.salientRegions);
    for (uint32_t f = 0; f < faceCount; ++f)
        if (salientRegionOf[f] != kNone) salientFacesOf[salientRegionOf[f]].push_back(f);

    for (int round = 0;; ++round) {
        run.throwIfCancelled();
        // Samples: face centroids. On large meshes, at most half the budget goes to the faces
        // within two rings of a class boundary (where the planes are decided) and the rest to the
        // other faces, each set thinned evenly in face order.
        std::vector<char> keep(faceCount, 1);
        if (faceCount > opt.svmMaxSamples) {
            std::vector<char> band(faceCount, 0);
            for (uint32_t f = 0; f < faceCount; ++f)
                for (uint32_t i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i)
                    if (trainClass[graph.neighbors[i]] != trainClass[f]) band[f] = 1;
            std::vector<char> band2(band);
            for (uint32_t f = 0; f < faceCount; ++f)
                if (band[f])
                    for (uint32_t i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) band2[graph.neighbors[i]] = 1;
            size_t bandCount = 0;
            for (char b : band2) bandCount += b ? 1 : 0;
            const size_t restCount = faceCount - bandCount;
            const size_t bandBudget = std::min(bandCount, opt.svmMaxSamples / 2);
            const size_t restBudget = std::max<size_t>(1, opt.svmMaxSamples - bandBudget);
            auto strideFor = [](size_t count, size_t budget) {
                return budget == 0 ? count + 1 : std::max<size_t>(1, (count + budget - 1) / budget);
            };
            const size_t bandStride = strideFor(bandCount, bandBudget), restStride = strideFor(restCount, restBudget);
            size_t bi = 0, ri = 0;
            for (uint32_t f = 0; f < faceCount; ++f)
                keep[f] = band2[f] ? ((bi++ % bandStride) == 0) : ((ri++ % restStride) == 0);
        }
        std::vector<Vec3d> samples;
        std::vector<uint32_t> sampleClass;
        for (uint32_t f = 0; f < faceCount; ++f)
            if (keep[f]) samples.push_back(graph.centroidsMm[f]), sampleClass.push_back(trainClass[f]);
        const size_t baseSamples = samples.size();

        CellTrainingOptions so = opt.svm;
        so.seed = opt.seed;
        LinearCells cells = trainLinearCells(samples, sampleClass, so);
        auto computeFaceCells = [&](const LinearCells& c) {
            std::vector<uint32_t> fc(faceCount);
            tbb::parallel_for(tbb::blocked_range<size_t>(0, faceCount, 4096), [&](const tbb::blocked_range<size_t>& r) {
                for (size_t f = r.begin(); f < r.end(); ++f) fc[f] = c.cellAt(graph.centroidsMm[f]);
            });
            return fc;
        };
        // A salient region is crossed when its faces' corners do not all lie in one cell.
        auto crossedRegions = [&](const LinearCells& c) {
            std::vector<uint32_t> crossed;
            for (uint32_t r = 0; r < res.salientRegions; ++r) {
                uint32_t first = kNone;
                bool isCrossed = false;
                for (uint32_t f : salientFacesOf[r]) {
                    for (uint32_t v : meshMm.triangles[f]) {
                        const uint32_t cell = c.cellAt(toD(meshMm.positions[v]));
                        if (first == kNone) first = cell;
                        if (cell != first) isCrossed = true;
                    }
                    if (isCrossed) break;
                }
                if (isCrossed) crossed.push_back(r);
            }
            return crossed;
        };
        std::vector<uint32_t> crossed = crossedRegions(cells);
        for (int retry = 0; retry < opt.salientRetries && !crossed.empty(); ++retry) {
            // Weight the crossed regions up: their corners as extra samples, repeated 4^retry times.
            const int repeat = 1 << (2 * retry);
            for (uint32_t r : crossed)
                for (uint32_t f : salientFacesOf[r])
                    for (uint32_t v : meshMm.triangles[f])
                        for (int i = 0; i < repeat; ++i) {
                            samples.push_back(toD(meshMm.positions[v]));
                            sampleClass.push_back(trainClass[f]);
                        }
            run.debug("retraining: " + std::to_string(crossed.size()) + " salient region(s) crossed by a cut");
            cells = trainLinearCells(samples, sampleClass, so);
            crossed = crossedRegions(cells);
        }
        res.svmSamples = samples.size();
        (void)baseSamples;
        std::vector<uint32_t> faceCells = computeFaceCells(cells);

        // Fragments: connected faces of one cell. Each starts as a piece.
        std::vector<uint32_t> fragOf;
        const uint32_t fragCount = labelComponents(graph, faceCells, fragOf);
        std::vector<uint32_t> fragOffsets, fragFaces;
        groupFaces(fragOf, fragCount, fragOffsets, fragFaces);
        std::vector<double> fragArea(fragCount, 0.0);
        for (uint32_t f = 0; f < faceCount; ++f) fragArea[fragOf[f]] += graph.areasMm2[f];

        Dsu dsu(fragCount);
        std::vector<std::vector<uint32_t>> members(fragCount);  // faces of each root
        for (uint32_t c = 0; c < fragCount; ++c)
            members[c].assign(fragFaces.begin() + fragOffsets[c], fragFaces.begin() + fragOffsets[c + 1]);
        std::vector<double> area(fragArea);
        size_t merges = 0;
        auto tryMerge = [&](uint32_t a, uint32_t b) {
            a = dsu.find(a), b = dsu.find(b);
            if (a == b) return true;
            std::vector<uint32_t> joined(members[a]);
            joined.insert(joined.end(), members[b].begin(), members[b].end());
            if (!cx.fitOf(joined).fits) return false;
            dsu.join(a, b);
            const uint32_t root = dsu.find(a), other = root == a ? b : a;
            members[root] = std::move(joined);
            members[other].clear();
            area[root] += area[other];
            ++merges;
            return true;
        };
        // Salient regions a cut still crosses: keep them in one piece by merging the fragments.
        size_t stillSplit = 0;
        for (uint32_t r : crossed) {
            bool isWhole = true;
            const uint32_t first = fragOf[salientFacesOf[r].front()];
            for (uint32_t f : salientFacesOf[r])
                if (!tryMerge(first, fragOf[f])) isWhole = false;
            // Faces in one piece, but the corners of some faces may still lie in another cell.
            if (!isWhole) ++stillSplit;
        }
        // Small fragments into the neighbour they share the longest seam with.
        {
            std::vector<uint32_t> order(fragCount);
            std::iota(order.begin(), order.end(), 0u);
            std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
                return fragArea[a] != fragArea[b] ? fragArea[a] < fragArea[b] : a < b;
            });
            for (uint32_t c : order) {
                const uint32_t root = dsu.find(c);
                if (area[root] >= opt.minPieceAreaMm2) continue;
                std::map<uint32_t, double> seam;  // neighbour root → shared edge length (mm)
                for (uint32_t f : members[root])
                    for (uint32_t i = graph.offsets[f]; i < graph.offsets[f + 1]; ++i) {
                        const uint32_t h = graph.neighbors[i];
                        const uint32_t other = dsu.find(fragOf[h]);
                        if (other == root) continue;
                        const auto& tf = meshMm.triangles[f];
                        const auto& th = meshMm.triangles[h];
                        std::vector<uint32_t> shared;
                        for (uint32_t v : tf)
                            if (v == th[0] || v == th[1] || v == th[2]) shared.push_back(v);
                        if (shared.size() >= 2)
                            seam[other] += std::sqrt(dist2(toD(meshMm.positions[shared[0]]), toD(meshMm.positions[shared[1]])));
                    }
                std::vector<std::pair<double, uint32_t>> byLength;
                for (const auto& [o, len] : seam) byLength.push_back({-len, o});
                std::sort(byLength.begin(), byLength.end());
                for (const auto& [negLen, o] : byLength)
                    if (tryMerge(root, o)) break;
            }
        }

        // Pieces in order of their lowest face.
        std::vector<uint32_t> pieceOfRoot(fragCount, kNone);
        std::vector<uint32_t> facePieces(faceCount);
        uint32_t pieceCount = 0;
        for (uint32_t f = 0; f < faceCount; ++f) {
            const uint32_t root = dsu.find(fragOf[f]);
            if (pieceOfRoot[root] == kNone) pieceOfRoot[root] = pieceCount++;
            facePieces[f] = pieceOfRoot[root];
        }
        std::vector<uint32_t> pieceOffsets, pieceFaces;
        groupFaces(facePieces, pieceCount, pieceOffsets, pieceFaces);
        std::vector<Piece> pieces(pieceCount);
        std::vector<std::vector<Vec3d>> piecePts(pieceCount);
        for (uint32_t p = 0; p < pieceCount; ++p) {
            Piece& piece = pieces[p];
            std::vector<uint32_t> faces(pieceFaces.begin() + pieceOffsets[p], pieceFaces.begin() + pieceOffsets[p + 1]);
            piece.faceCount = uint32_t(faces.size());
            for (uint32_t f : faces) {
                piece.areaMm2 += graph.areasMm2[f];
                piece.cells.push_back(faceCells[f]);
            }
            std::sort(piece.cells.begin(), piece.cells.end());
            piece.cells.erase(std::unique(piece.cells.begin(), piece.cells.end()), piece.cells.end());
            for (uint32_t c : piece.cells) piece.balls.push_back(classBall[cells.classes[c]]);
            std::sort(piece.balls.begin(), piece.balls.end());
            piece.balls.erase(std::unique(piece.balls.begin(), piece.balls.end()), piece.balls.end());
            piecePts[p] = faceVertices(meshMm, faces, cx.stamp, cx.stampValue);
            for (const Vec3d& v : piecePts[p]) piece.boundsMm.expand(v);
        }
        tbb::parallel_for(uint32_t(0), pieceCount, [&](uint32_t p) {
            pieces[p].fit = fitInPrinter(piecePts[p], opt.printerMm, opt.fitMarginMm);
        });

        std::vector<uint32_t> tooLarge;
        for (uint32_t p = 0; p < pieceCount; ++p)
            if (!pieces[p].fit.fits) tooLarge.push_back(p);
        if (tooLarge.empty() || round >= opt.maxRepairRounds) {
            if (!tooLarge.empty()) {
                const Piece& p = pieces[tooLarge.front()];
                throw Error(ErrorCode::ProcessingFailed,
                            std::to_string(tooLarge.size()) + " piece(s) still do not fit the printer " +
                                sizeText(opt.printerMm) + " after " + std::to_string(round) + " repair rounds (piece " +
                                std::to_string(tooLarge.front()) + " needs " + sizeText(p.fit.extentsMm) + ")");
            }
            size_t agree = 0;
            for (uint32_t f = 0; f < faceCount; ++f) agree += cells.classes[faceCells[f]] == trainClass[f] ? 1 : 0;
            res.svmAgreement = double(agree) / double(faceCount);
            res.cells = std::move(cells);
            res.cellBalls.clear();
            for (uint32_t c : res.cells.classes) res.cellBalls.push_back(classBall[c]);
            res.faceCells = std::move(faceCells);
            res.facePieces = std::move(facePieces);
            res.pieces = std::move(pieces);
            res.merges = merges;
            // Regions whose corners still lie in different cells of different pieces.
            res.salientRegionsSplit = 0;
            for (uint32_t r : crossed) {
                bool isSplit = false;
                const uint32_t p0 = res.facePieces[salientFacesOf[r].front()];
                for (uint32_t f : salientFacesOf[r]) {
                    if (res.facePieces[f] != p0) isSplit = true;
                    for (uint32_t v : meshMm.triangles[f]) {
                        const uint32_t c = res.cells.cellAt(toD(meshMm.positions[v]));
                        if (!std::binary_search(res.pieces[p0].cells.begin(), res.pieces[p0].cells.end(), c)) isSplit = true;
                    }
                }
                if (isSplit) ++res.salientRegionsSplit;
            }
            if (res.salientRegionsSplit > 0)
                run.warn(std::to_string(res.salientRegionsSplit) +
                         " salient region(s) are crossed by a planar cut that could not be avoided");
            (void)stillSplit;
            break;
        }
        // Split the pieces that do not fit into new classes and train again.
        for (uint32_t p : tooLarge) {
            std::vector<uint32_t> faces(pieceFaces.begin() + pieceOffsets[p], pieceFaces.begin() + pieceOffsets[p + 1]);
            const uint32_t c = newClassFor(faces);  // the piece's faces get one class of their own first
            for (uint32_t f : faces) trainClass[f] = c;
            if (splitFaces(faces)) ++res.splits;
        }
        run.info(std::to_string(tooLarge.size()) + " piece(s) do not fit the printer after the planar cuts; split and retrain");
    }
    res.secondsSvm = svmClock.seconds();
    res.secondsTotal = total.seconds();
    run.progress("partition", 1.0);
    return res;
}

}  // namespace zomefab::partition
