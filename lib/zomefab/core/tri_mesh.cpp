// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/tri_mesh.h"

#include <algorithm>
#include <cstring>
#include <map>
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

namespace {

uint64_t edgeKey(uint32_t from, uint32_t to) { return (uint64_t(from) << 32) | to; }

Vec3d pointOf(const TriMesh& mesh, uint32_t v) {
    const Vec3f& p = mesh.positions[v];
    return {p[0], p[1], p[2]};
}

/// The corner of @p t opposite its longest edge: 0, 1 or 2.
int cornerOppositeLongest(const TriMesh& mesh, const Triangle& t) {
    int best = 0;
    double longest = -1;
    for (int k = 0; k < 3; ++k) {
        const Vec3d e = sub(pointOf(mesh, t[size_t((k + 1) % 3)]), pointOf(mesh, t[size_t((k + 2) % 3)]));
        if (dot(e, e) > longest) longest = dot(e, e), best = k;
    }
    return best;
}

}  // namespace

bool isDegenerate(const TriMesh& mesh, const Triangle& t) {
    if (hasRepeatedIndex(t)) return true;
    const Vec3d a = pointOf(mesh, t[0]), b = pointOf(mesh, t[1]), c = pointOf(mesh, t[2]);
    const double longest =
        std::max({dot(sub(b, a), sub(b, a)), dot(sub(c, b), sub(c, b)), dot(sub(a, c), sub(a, c))});
    return norm(cross(sub(b, a), sub(c, a))) <= 1e-9 * longest;
}

size_t collapseShortEdges(TriMesh& mesh, double maxEdge) {
    DisjointSets merged(uint32_t(mesh.positions.size()));
    bool isAny = false;
    for (const Triangle& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const uint32_t a = t[size_t(k)], b = t[size_t((k + 1) % 3)];
            const Vec3d e = sub(pointOf(mesh, a), pointOf(mesh, b));
            if (a == b || dot(e, e) > maxEdge * maxEdge) continue;
            merged.unite(a, b);
            isAny = true;
        }
    if (!isAny) return 0;
    for (Triangle& t : mesh.triangles)
        for (uint32_t& v : t) v = merged.find(v);
    // Keep the triangles that name three vertices and are not one of a face-to-face pair (the same
    // corners: as two faces of a closed mesh, opposite).
    std::map<Triangle, std::vector<uint32_t>> byCorners;
    std::vector<uint8_t> isKept(mesh.triangles.size(), 0);
    for (uint32_t i = 0; i < mesh.triangles.size(); ++i) {
        if (hasRepeatedIndex(mesh.triangles[i])) continue;
        isKept[i] = 1;
        Triangle s = mesh.triangles[i];
        std::sort(s.begin(), s.end());
        byCorners[s].push_back(i);
    }
    for (const auto& [corners, list] : byCorners)
        for (size_t x = 0; x + 1 < list.size(); x += 2) isKept[list[x]] = isKept[list[x + 1]] = 0;
    const size_t before = mesh.triangles.size();
    size_t out = 0;
    for (size_t i = 0; i < before; ++i)
        if (isKept[i]) {
            if (!mesh.salientFaces.empty()) mesh.salientFaces[out] = mesh.salientFaces[i];
            mesh.triangles[out++] = mesh.triangles[i];
        }
    mesh.triangles.resize(out);
    if (!mesh.salientFaces.empty()) mesh.salientFaces.resize(out);
    return before - out;
}

size_t flipNeedles(TriMesh& mesh) {
    std::vector<uint32_t> needles;
    for (uint32_t i = 0; i < mesh.triangles.size(); ++i)
        if (!hasRepeatedIndex(mesh.triangles[i]) && isDegenerate(mesh, mesh.triangles[i]))
            needles.push_back(i);
    if (needles.empty()) return 0;
    // Directed edge -> its triangle; UINT32_MAX where an edge is used twice the same way.
    std::unordered_map<uint64_t, uint32_t> owner;
    owner.reserve(3 * mesh.triangles.size());
    auto setEdges = [&](uint32_t i, bool isAdding) {
        const Triangle& t = mesh.triangles[i];
        for (int k = 0; k < 3; ++k) {
            const uint64_t key = edgeKey(t[size_t(k)], t[size_t((k + 1) % 3)]);
            if (!isAdding) {
                owner.erase(key);
                continue;
            }
            auto [it, inserted] = owner.emplace(key, i);
            if (!inserted) it->second = UINT32_MAX;
        }
    };
    for (uint32_t i = 0; i < mesh.triangles.size(); ++i) setEdges(i, true);
    size_t flipped = 0;
    for (const uint32_t i : needles) {
        const Triangle t = mesh.triangles[i];
        if (!isDegenerate(mesh, t)) continue;  // an earlier flip mended it
        const int k = cornerOppositeLongest(mesh, t);
        const uint32_t c = t[size_t(k)], a = t[size_t((k + 1) % 3)], b = t[size_t((k + 2) % 3)];
        const auto across = owner.find(edgeKey(b, a));
        if (across == owner.end() || across->second == UINT32_MAX) continue;
        const uint32_t n = across->second;
        const Triangle m = mesh.triangles[n];
        uint32_t d = m[0];
        for (uint32_t v : m)
            if (v != a && v != b) d = v;
        if (d == c || owner.count(edgeKey(c, d)) || owner.count(edgeKey(d, c))) continue;
        const Triangle first{a, d, c}, second{d, b, c};
        if (isDegenerate(mesh, first) || isDegenerate(mesh, second)) continue;
        setEdges(i, false);
        setEdges(n, false);
        mesh.triangles[i] = first;
        mesh.triangles[n] = second;
        setEdges(i, true);
        setEdges(n, true);
        ++flipped;
    }
    return flipped;
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
