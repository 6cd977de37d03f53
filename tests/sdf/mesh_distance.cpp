// SPDX-License-Identifier: GPL-3.0-or-later
#include "mesh_distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <random>
#include <utility>

namespace zomefab::test {

namespace {

using V = Vec3d;
V sub(const V& a, const V& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V add(const V& a, const V& b) { return {a[0] + b[0], a[1] + b[1], a[2] + b[2]}; }
V mul(const V& a, double s) { return {a[0] * s, a[1] * s, a[2] * s}; }
double dot(const V& a, const V& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
V cross(const V& a, const V& b) {
    return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
V toD(const Vec3f& p) { return {p[0], p[1], p[2]}; }

/// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
V closestOnTriangle(const V& p, const V& a, const V& b, const V& c) {
    const V ab = sub(b, a), ac = sub(c, a), ap = sub(p, a);
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const V bp = sub(p, b);
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return add(a, mul(ab, d1 / (d1 - d3)));
    const V cp = sub(p, c);
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return add(a, mul(ac, d2 / (d2 - d6)));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
        return add(b, mul(sub(c, b), (d4 - d3) / ((d4 - d3) + (d5 - d6))));
    const double denom = 1.0 / (va + vb + vc);
    return add(a, add(mul(ab, vb * denom), mul(ac, vc * denom)));
}

}  // namespace

MeshDistance::MeshDistance(const TriMesh& mesh, double cellMm) : mMesh(mesh) {
    const Box3d box = boundingBox(mesh);
    if (cellMm <= 0) {
        double sum = 0;
        for (const Triangle& t : mesh.triangles) {
            const V a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]),
                    c = toD(mesh.positions[t[2]]);
            sum += std::sqrt(dot(sub(b, a), sub(b, a))) + std::sqrt(dot(sub(c, a), sub(c, a)));
        }
        cellMm = std::max(4.0 * sum / (2.0 * double(std::max<size_t>(1, mesh.triangles.size()))), 1e-6);
        // Keep the grid within a few million cells.
        const V size = box.size();
        while (size[0] / cellMm * size[1] / cellMm * size[2] / cellMm > 4e6) cellMm *= 1.25;
    }
    mCell = cellMm;
    mOrigin = box.min;
    for (int a = 0; a < 3; ++a) mDims[a] = std::max(1, int(std::ceil((box.max[a] - box.min[a]) / mCell)) + 1);
    const size_t cells = size_t(mDims[0]) * mDims[1] * mDims[2];
    auto cellRange = [&](const Triangle& t, int lo[3], int hi[3]) {
        for (int a = 0; a < 3; ++a) {
            double mn = 1e300, mx = -1e300;
            for (int k = 0; k < 3; ++k) {
                mn = std::min(mn, double(mesh.positions[t[k]][a]));
                mx = std::max(mx, double(mesh.positions[t[k]][a]));
            }
            lo[a] = std::clamp(int((mn - mOrigin[a]) / mCell), 0, mDims[a] - 1);
            hi[a] = std::clamp(int((mx - mOrigin[a]) / mCell), 0, mDims[a] - 1);
        }
    };
    std::vector<uint32_t> counts(cells + 1, 0);
    for (const Triangle& t : mesh.triangles) {
        int lo[3], hi[3];
        cellRange(t, lo, hi);
        for (int i = lo[0]; i <= hi[0]; ++i)
            for (int j = lo[1]; j <= hi[1]; ++j)
                for (int k = lo[2]; k <= hi[2]; ++k) ++counts[(size_t(i) * mDims[1] + j) * mDims[2] + k + 1];
    }
    std::partial_sum(counts.begin(), counts.end(), counts.begin());
    mStart = counts;
    mItems.resize(mStart.back());
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
        int lo[3], hi[3];
        cellRange(mesh.triangles[f], lo, hi);
        for (int i = lo[0]; i <= hi[0]; ++i)
            for (int j = lo[1]; j <= hi[1]; ++j)
                for (int k = lo[2]; k <= hi[2]; ++k)
                    mItems[counts[(size_t(i) * mDims[1] + j) * mDims[2] + k]++] = f;
    }
}

double MeshDistance::distance(const Vec3d& p, Vec3d* closest) const {
    int c[3];
    for (int a = 0; a < 3; ++a)
        c[a] = std::clamp(int(std::floor((p[a] - mOrigin[a]) / mCell)), 0, mDims[a] - 1);
    double best2 = std::numeric_limits<double>::infinity();
    V bestPoint = p;
    const int maxRing = std::max({mDims[0], mDims[1], mDims[2]});
    for (int r = 0; r <= maxRing; ++r) {
        for (int i = c[0] - r; i <= c[0] + r; ++i) {
            if (i < 0 || i >= mDims[0]) continue;
            for (int j = c[1] - r; j <= c[1] + r; ++j) {
                if (j < 0 || j >= mDims[1]) continue;
                for (int k = c[2] - r; k <= c[2] + r; ++k) {
                    if (k < 0 || k >= mDims[2]) continue;
                    // Only the shell of ring r: inner cells were done before.
                    if (std::max({std::abs(i - c[0]), std::abs(j - c[1]), std::abs(k - c[2])}) != r) continue;
                    const size_t cell = (size_t(i) * mDims[1] + j) * mDims[2] + k;
                    for (uint32_t n = mStart[cell]; n < mStart[cell + 1]; ++n) {
                        const Triangle& t = mMesh.triangles[mItems[n]];
                        const V q = closestOnTriangle(p, toD(mMesh.positions[t[0]]),
                                                      toD(mMesh.positions[t[1]]), toD(mMesh.positions[t[2]]));
                        const double d2 = dot(sub(q, p), sub(q, p));
                        if (d2 < best2) {
                            best2 = d2;
                            bestPoint = q;
                        }
                    }
                }
            }
        }
        // Every unvisited cell lies outside the box of rings 0..r; stop once the best distance is
        // shorter than the way from p out of that box.
        double margin = 1e300;
        for (int a = 0; a < 3; ++a) {
            const double lo = mOrigin[a] + (c[a] - r) * mCell, hi = mOrigin[a] + (c[a] + r + 1) * mCell;
            margin = std::min({margin, p[a] - lo, hi - p[a]});
        }
        if (margin > 0 && best2 <= margin * margin) break;
    }
    if (closest) *closest = bestPoint;
    return std::sqrt(best2);
}

std::vector<Vec3d> sampleSurface(const TriMesh& mesh, size_t count, uint32_t seed,
                                 std::vector<uint32_t>* facets) {
    std::vector<double> cumulative(mesh.triangles.size());
    double total = 0;
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
        const Triangle& t = mesh.triangles[f];
        const V a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]), c = toD(mesh.positions[t[2]]);
        const V n = cross(sub(b, a), sub(c, a));
        total += 0.5 * std::sqrt(dot(n, n));
        cumulative[f] = total;
    }
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::vector<Vec3d> points;
    points.reserve(count);
    for (size_t s = 0; s < count; ++s) {
        const double x = uniform(rng) * total;
        const size_t f =
            std::min(size_t(std::lower_bound(cumulative.begin(), cumulative.end(), x) - cumulative.begin()),
                     mesh.triangles.size() - 1);
        const Triangle& t = mesh.triangles[f];
        if (facets != nullptr) facets->push_back(uint32_t(f));
        double u = uniform(rng), v = uniform(rng);
        if (u + v > 1) {
            u = 1 - u;
            v = 1 - v;
        }
        const V a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]), c = toD(mesh.positions[t[2]]);
        points.push_back(add(a, add(mul(sub(b, a), u), mul(sub(c, a), v))));
    }
    return points;
}

double quantile(std::vector<double> values, double q) {
    if (values.empty()) return 0;
    const size_t k = std::min(values.size() - 1, size_t(q * double(values.size() - 1) + 0.5));
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(k), values.end());
    return values[k];
}

std::vector<double> distancesTo(const MeshDistance& mesh, const std::vector<Vec3d>& points) {
    std::vector<double> d(points.size());
    for (size_t i = 0; i < points.size(); ++i) d[i] = mesh.distance(points[i]);
    return d;
}

EdgeReport edgeReport(const TriMesh& mesh) {
    EdgeReport report;
    // Every directed edge as (undirected key, forward?, triangle), sorted so equal keys are adjacent.
    struct HalfEdge {
        uint64_t key;
        uint32_t face;
        bool forward;
    };
    std::vector<HalfEdge> halfEdges;
    halfEdges.reserve(mesh.triangles.size() * 3);
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
        const Triangle& t = mesh.triangles[f];
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = t[k], b = t[(k + 1) % 3];
            halfEdges.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), f, a < b});
        }
    }
    std::sort(halfEdges.begin(), halfEdges.end(), [](const HalfEdge& x, const HalfEdge& y) {
        return x.key < y.key || (x.key == y.key && x.face < y.face);
    });
    std::vector<uint32_t> parent(mesh.triangles.size());
    std::iota(parent.begin(), parent.end(), 0u);
    auto find = [&](uint32_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    for (size_t i = 0; i < halfEdges.size();) {
        size_t j = i;
        int forward = 0;
        while (j < halfEdges.size() && halfEdges[j].key == halfEdges[i].key) {
            forward += halfEdges[j].forward ? 1 : 0;
            parent[find(halfEdges[j].face)] = find(halfEdges[i].face);
            ++j;
        }
        const size_t n = j - i;
        if (n == 1) ++report.boundaryEdges;
        if (n >= 3) ++report.nonManifoldEdges;
        if (n == 2 && forward != 1) ++report.misorientedEdges;
        i = j;
    }
    std::vector<uint32_t> ids(mesh.triangles.size(), UINT32_MAX);
    report.componentOfTriangle.resize(mesh.triangles.size());
    for (uint32_t f = 0; f < mesh.triangles.size(); ++f) {
        const uint32_t root = find(f);
        if (ids[root] == UINT32_MAX) ids[root] = uint32_t(report.components++);
        report.componentOfTriangle[f] = ids[root];
    }
    return report;
}

TriMesh extractComponent(const TriMesh& mesh, const EdgeReport& report, uint32_t c) {
    TriMesh out;
    out.positions = mesh.positions;
    for (size_t f = 0; f < mesh.triangles.size(); ++f)
        if (report.componentOfTriangle[f] == c) out.triangles.push_back(mesh.triangles[f]);
    return out;
}

}  // namespace zomefab::test
