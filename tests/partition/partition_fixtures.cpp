// SPDX-License-Identifier: GPL-3.0-or-later
#include "partition_fixtures.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <unordered_map>

#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/scale.h"

namespace zomefab::partition::test {

namespace {

Vec3d toD(const Vec3f& p) { return {double(p[0]), double(p[1]), double(p[2])}; }

double pointTriangleDist2(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    // Minimum over a fine barycentric sampling is not exact; use the exact projection instead.
    auto sub = [](const Vec3d& x, const Vec3d& y) { return Vec3d{x[0] - y[0], x[1] - y[1], x[2] - y[2]}; };
    auto dot = [](const Vec3d& x, const Vec3d& y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; };
    auto d2 = [&](const Vec3d& x) { const Vec3d d = sub(p, x); return dot(d, d); };
    auto segment = [&](const Vec3d& s, const Vec3d& e) {
        const Vec3d se = sub(e, s);
        const double len2 = dot(se, se);
        const double t = len2 > 0 ? std::clamp(dot(sub(p, s), se) / len2, 0.0, 1.0) : 0.0;
        return d2({s[0] + t * se[0], s[1] + t * se[1], s[2] + t * se[2]});
    };
    const Vec3d ab = sub(b, a), ac = sub(c, a);
    const Vec3d n{ab[1] * ac[2] - ab[2] * ac[1], ab[2] * ac[0] - ab[0] * ac[2], ab[0] * ac[1] - ab[1] * ac[0]};
    const double nn = dot(n, n);
    if (nn > 0) {
        const double t = dot(sub(p, a), n) / nn;
        const Vec3d q{p[0] - t * n[0], p[1] - t * n[1], p[2] - t * n[2]};
        // Inside test by the signs of the sub-triangle normals.
        auto side = [&](const Vec3d& u, const Vec3d& v) {
            const Vec3d e = sub(v, u), w = sub(q, u);
            const Vec3d c2{e[1] * w[2] - e[2] * w[1], e[2] * w[0] - e[0] * w[2], e[0] * w[1] - e[1] * w[0]};
            return dot(c2, n);
        };
        if (side(a, b) >= 0 && side(b, c) >= 0 && side(c, a) >= 0) return d2(q);
    }
    return std::min({segment(a, b), segment(b, c), segment(c, a)});
}

}  // namespace

MeshMm loadMeshMm(const std::string& path, double heightMm, bool isYUp) {
    mesh::ScaleOptions o;
    o.heightMm = heightMm;
    o.up = isYUp ? mesh::UpAxis::Y : mesh::UpAxis::Z;
    mesh::ScaledMesh s = mesh::scaleToMillimetres(readMesh(path), o);
    return {std::move(s.mesh), s.transformMm};
}

namespace {

/// x coordinates where the line {(x, y, z) : x ∈ R} crosses the mesh, sorted.
std::vector<double> lineCrossings(const TriMesh& m, double y, double z) {
    std::vector<double> xs;
    for (const auto& t : m.triangles) {
        const Vec3d a = toD(m.positions[t[0]]), b = toD(m.positions[t[1]]), c = toD(m.positions[t[2]]);
        const double d = (b[1] - a[1]) * (c[2] - a[2]) - (b[2] - a[2]) * (c[1] - a[1]);
        if (d == 0) continue;
        const double u = ((y - a[1]) * (c[2] - a[2]) - (z - a[2]) * (c[1] - a[1])) / d;
        const double v = ((b[1] - a[1]) * (z - a[2]) - (b[2] - a[2]) * (y - a[1])) / d;
        if (u < 0 || v < 0 || u + v > 1) continue;
        xs.push_back(a[0] + u * (b[0] - a[0]) + v * (c[0] - a[0]));
    }
    std::sort(xs.begin(), xs.end());
    return xs;
}

bool isInsideGivenCrossings(const std::vector<double>& xs, double x) {
    return (xs.end() - std::upper_bound(xs.begin(), xs.end(), x)) % 2 == 1;
}

}  // namespace

bool isInside(const TriMesh& m, const Vec3d& p) { return isInsideGivenCrossings(lineCrossings(m, p[1], p[2]), p[0]); }

LatticeFrame makeLatticeFrame(const TriMesh& m, double minDepthMm, double b0Mm) {
    const Box3d box = boundingBox(m);
    zome::ZomeScale scale;
    scale.b0Mm = b0Mm;
    // Lattice through the box centre.
    Vec3d centre{0.5 * (box.min[0] + box.max[0]), 0.5 * (box.min[1] + box.max[1]), 0.5 * (box.min[2] + box.max[2])};
    std::array<int, 3> n{};
    for (int a = 0; a < 3; ++a) n[size_t(a)] = int(std::ceil(0.5 * (box.max[size_t(a)] - box.min[size_t(a)]) / b0Mm));
    scale.originMm = centre;
    LatticeFrame frame{zome::Structure(scale), {}};
    std::map<std::array<int, 3>, zome::BallId> ids;
    for (int k = -n[2]; k <= n[2]; ++k)
        for (int j = -n[1]; j <= n[1]; ++j) {
            const std::vector<double> xs = lineCrossings(m, centre[1] + j * b0Mm, centre[2] + k * b0Mm);
            for (int i = -n[0]; i <= n[0]; ++i) {
                const Vec3d p{centre[0] + i * b0Mm, centre[1] + j * b0Mm, centre[2] + k * b0Mm};
                if (!isInsideGivenCrossings(xs, p[0])) continue;
                double best = 1e300;
                for (const auto& t : m.triangles)
                    best = std::min(best, pointTriangleDist2(p, toD(m.positions[t[0]]), toD(m.positions[t[1]]),
                                                             toD(m.positions[t[2]])));
                if (std::sqrt(best) < minDepthMm) continue;
                const zome::GoldenVector3 exact{zome::Golden{2 * i, 2 * i}, zome::Golden{2 * j, 2 * j},
                                                zome::Golden{2 * k, 2 * k}};
                ids[{i, j, k}] = frame.structure.addBall(exact);
            }
        }
    for (const auto& [key, id] : ids) {
        int neighbours = 0;
        for (int a = 0; a < 3; ++a)
            for (int s : {-1, 1}) {
                std::array<int, 3> q = key;
                q[size_t(a)] += s;
                auto it = ids.find(q);
                if (it == ids.end()) continue;
                ++neighbours;
                if (s == 1) frame.structure.addStrut(id, it->second);
            }
        if (neighbours < 6) frame.outermost.push_back(id);
    }
    std::sort(frame.outermost.begin(), frame.outermost.end());
    return frame;
}

TriMesh subdivide(const TriMesh& mesh, int levels) {
    TriMesh m = mesh;
    for (int level = 0; level < levels; ++level) {
        TriMesh out;
        out.positions = m.positions;
        std::unordered_map<uint64_t, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            const Vec3f& p = m.positions[a];
            const Vec3f& q = m.positions[b];
            out.positions.push_back({0.5f * (p[0] + q[0]), 0.5f * (p[1] + q[1]), 0.5f * (p[2] + q[2])});
            const uint32_t id = uint32_t(out.positions.size() - 1);
            mid.emplace(key, id);
            return id;
        };
        for (const auto& t : m.triangles) {
            const uint32_t ab = midpoint(t[0], t[1]), bc = midpoint(t[1], t[2]), ca = midpoint(t[2], t[0]);
            out.triangles.push_back({t[0], ab, ca});
            out.triangles.push_back({ab, t[1], bc});
            out.triangles.push_back({ca, bc, t[2]});
            out.triangles.push_back({ab, bc, ca});
        }
        m = std::move(out);
    }
    return m;
}

}  // namespace zomefab::partition::test
