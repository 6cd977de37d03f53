// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/tri_mesh.h"

#include <algorithm>
#include <cstring>
#include <unordered_map>

#include "zomefab/core/disjoint_sets.h"
#include "zomefab/core/vec.h"

namespace zomefab {

void Box3d::expand(const Vec3d& p) {
    for (int i = 0; i < 3; ++i) {
        min[i] = std::min(min[i], p[i]);
        max[i] = std::max(max[i], p[i]);
    }
}

Vec3d Box3d::size() const {
    if (isEmpty()) return {0, 0, 0};
    return {max[0] - min[0], max[1] - min[1], max[2] - min[2]};
}

void appendMesh(TriMesh& mesh, const TriMesh& other) {
    const uint32_t base = uint32_t(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), other.positions.begin(), other.positions.end());
    for (const Triangle& t : other.triangles)
        mesh.triangles.push_back({base + t[0], base + t[1], base + t[2]});
}

Box3d boundingBox(const TriMesh& mesh) {
    Box3d box;
    for (const Vec3f& p : mesh.positions) box.expand({p[0], p[1], p[2]});
    return box;
}

void weldIdenticalVertices(TriMesh& mesh) {
    struct KeyHash {
        size_t operator()(const std::array<uint32_t, 3>& k) const {
            uint64_t h = 1469598103934665603ull;
            for (uint32_t v : k) h = (h ^ v) * 1099511628211ull;
            return size_t(h ^ (h >> 29));
        }
    };
    std::unordered_map<std::array<uint32_t, 3>, uint32_t, KeyHash> index;
    index.reserve(mesh.positions.size());
    std::vector<Vec3f> welded;
    welded.reserve(mesh.positions.size() / 4 + 16);
    std::vector<uint32_t> remap(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        Vec3f p = mesh.positions[i];
        std::array<uint32_t, 3> key;
        for (int c = 0; c < 3; ++c) {
            if (p[c] == 0.0f) p[c] = 0.0f;  // -0 and +0 are the same point
            std::memcpy(&key[c], &p[c], sizeof(float));
        }
        auto [it, inserted] = index.emplace(key, uint32_t(welded.size()));
        if (inserted) welded.push_back(p);
        remap[i] = it->second;
    }
    for (Triangle& t : mesh.triangles)
        for (uint32_t& v : t) v = remap[v];
    mesh.positions = std::move(welded);
}

double signedVolume(const TriMesh& mesh, const std::vector<uint32_t>& triangles, const Vec3d& origin) {
    double sum = 0;
    for (uint32_t t : triangles) {
        const Triangle& tri = mesh.triangles[t];
        const Vec3d a = sub(toD(mesh.positions[tri[0]]), origin);
        const Vec3d b = sub(toD(mesh.positions[tri[1]]), origin);
        const Vec3d c = sub(toD(mesh.positions[tri[2]]), origin);
        sum += dot(a, cross(b, c));
    }
    return sum / 6.0;
}

double signedVolume(const TriMesh& mesh, const Vec3d& origin) {
    double sum = 0;
    for (const Triangle& tri : mesh.triangles) {
        const Vec3d a = sub(toD(mesh.positions[tri[0]]), origin);
        const Vec3d b = sub(toD(mesh.positions[tri[1]]), origin);
        const Vec3d c = sub(toD(mesh.positions[tri[2]]), origin);
        sum += dot(a, cross(b, c));
    }
    return sum / 6.0;
}

double surfaceArea(const TriMesh& mesh) {
    double sum = 0;
    for (const Triangle& tri : mesh.triangles) {
        const Vec3d a = toD(mesh.positions[tri[0]]);
        sum += 0.5 * norm(cross(sub(toD(mesh.positions[tri[1]]), a), sub(toD(mesh.positions[tri[2]]), a)));
    }
    return sum;
}

VertexComponents vertexComponents(const TriMesh& mesh) {
    const size_t nv = mesh.positions.size();
    DisjointSets sets(nv);
    for (const Triangle& t : mesh.triangles) {
        sets.unite(t[0], t[1]);
        sets.unite(t[0], t[2]);
    }
    VertexComponents c;
    c.rootOf.resize(nv);
    for (uint32_t v = 0; v < nv; ++v) c.rootOf[v] = sets.find(v);
    std::vector<double> volume6(nv, 0.0);
    for (const Triangle& t : mesh.triangles) {
        const uint32_t root = c.rootOf[t[0]];
        const Vec3d o = toD(mesh.positions[root]);
        const Vec3d a = sub(toD(mesh.positions[t[0]]), o), b = sub(toD(mesh.positions[t[1]]), o),
                    d = sub(toD(mesh.positions[t[2]]), o);
        volume6[root] += dot(a, cross(b, d));
    }
    c.volume.resize(nv);
    for (size_t v = 0; v < nv; ++v) c.volume[v] = volume6[v] / 6.0;
    return c;
}

size_t keepComponents(TriMesh& mesh, const VertexComponents& components,
                      const std::function<bool(uint32_t root)>& isKept) {
    const size_t nv = mesh.positions.size();
    std::vector<uint8_t> verdict(nv, 2);  // per root: 2 unknown, 1 kept, 0 dropped
    size_t dropped = 0;
    for (const Triangle& t : mesh.triangles) {
        const uint32_t root = components.rootOf[t[0]];
        if (verdict[root] == 2) {
            verdict[root] = isKept(root) ? 1 : 0;
            dropped += verdict[root] == 0;
        }
    }
    if (dropped == 0) return 0;
    constexpr uint32_t kUnused = 0xFFFFFFFFu;
    std::vector<uint32_t> index(nv, kUnused);
    TriMesh kept;
    kept.triangles.reserve(mesh.triangles.size());
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        Triangle t = mesh.triangles[i];
        if (verdict[components.rootOf[t[0]]] == 0) continue;
        for (uint32_t& v : t) {
            if (index[v] == kUnused)
                index[v] = uint32_t(kept.positions.size()), kept.positions.push_back(mesh.positions[v]);
            v = index[v];
        }
        kept.triangles.push_back(t);
        if (!mesh.salientFaces.empty()) kept.salientFaces.push_back(mesh.salientFaces[i]);
    }
    mesh = std::move(kept);
    return dropped;
}

}  // namespace zomefab
