// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/mesh/mesh_check.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <vector>

#include "zomefab/core/disjoint_sets.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"

namespace zomefab::mesh {

namespace {

/// One use of an undirected edge by a triangle.
struct EdgeUse {
    uint64_t key;  ///< (min vertex << 32) | max vertex
    uint32_t triangle;
    bool forward;  ///< the triangle runs min -> max
    bool operator<(const EdgeUse& o) const {
        return key != o.key             ? key < o.key
               : triangle != o.triangle ? triangle < o.triangle
                                        : forward < o.forward;
    }
};

/// All edge uses of the triangles without a repeated index, sorted so uses of one edge are adjacent.
std::vector<EdgeUse> collectEdges(const TriMesh& mesh) {
    std::vector<EdgeUse> uses;
    uses.reserve(mesh.triangles.size() * 3);
    for (size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Triangle& tri = mesh.triangles[t];
        if (hasRepeatedIndex(tri)) continue;
        for (int e = 0; e < 3; ++e) {
            const uint32_t a = tri[e], b = tri[(e + 1) % 3];
            uses.push_back({(uint64_t(std::min(a, b)) << 32) | std::max(a, b), uint32_t(t), a < b});
        }
    }
    std::sort(uses.begin(), uses.end());
    return uses;
}

/// Calls @p f(first, count) for each run of uses of the same edge.
template <typename F>
void forEachEdge(const std::vector<EdgeUse>& uses, F&& f) {
    for (size_t i = 0; i < uses.size();) {
        size_t j = i + 1;
        while (j < uses.size() && uses[j].key == uses[i].key) ++j;
        f(i, j - i);
        i = j;
    }
}

void checkIndices(const TriMesh& mesh) {
    for (size_t t = 0; t < mesh.triangles.size(); ++t)
        for (uint32_t v : mesh.triangles[t])
            if (v >= mesh.positions.size())
                throw Error(ErrorCode::InvalidInput, "triangle " + std::to_string(t) + " refers to vertex " +
                                                         std::to_string(v) + " but there are " +
                                                         std::to_string(mesh.positions.size()) + " vertices");
}

/// Generalised winding number of @p triangles at @p p (Van Oosterom & Strackee solid angles):
/// +1 inside an outward closed surface, -1 inside an inward one, 0 outside.
double windingNumber(const TriMesh& mesh, const std::vector<uint32_t>& triangles, const Vec3d& p) {
    double sum = 0;
    for (uint32_t t : triangles) {
        const Triangle& tri = mesh.triangles[t];
        const Vec3d a = sub(toD(mesh.positions[tri[0]]), p);
        const Vec3d b = sub(toD(mesh.positions[tri[1]]), p);
        const Vec3d c = sub(toD(mesh.positions[tri[2]]), p);
        const double la = norm(a), lb = norm(b), lc = norm(c);
        const double num = dot(a, cross(b, c));
        const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        sum += 2.0 * std::atan2(num, den);
    }
    return sum / (4.0 * kPi);
}

double triangleArea(const TriMesh& mesh, uint32_t a, uint32_t b, uint32_t c) {
    const Vec3d pa = toD(mesh.positions[a]);
    return 0.5 * norm(cross(sub(toD(mesh.positions[b]), pa), sub(toD(mesh.positions[c]), pa)));
}

/// Minimum-area triangulation of the closed polygon @p loop (dynamic programming over sub-chains,
/// O(n^3), Barequet & Sharir 1995), never using a chord in @p existingEdges. Triangles keep the
/// loop's direction. Empty when no such triangulation exists.
std::vector<Triangle> fillLoop(const TriMesh& mesh, const std::vector<uint32_t>& loop,
                               const std::vector<uint64_t>& existingEdges) {
    const size_t n = loop.size();
    auto key = [](uint32_t a, uint32_t b) { return (uint64_t(std::min(a, b)) << 32) | std::max(a, b); };
    auto chordAllowed = [&](size_t i, size_t j) {
        if (j == i + 1 || (i == 0 && j == n - 1)) return true;  // a boundary edge of the hole
        return !std::binary_search(existingEdges.begin(), existingEdges.end(), key(loop[i], loop[j]));
    };
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<double> cost(n * n, inf);
    std::vector<uint32_t> split(n * n, 0);
    for (size_t i = 0; i + 1 < n; ++i) cost[i * n + i + 1] = 0;
    for (size_t len = 2; len < n; ++len)
        for (size_t i = 0; i + len < n; ++i) {
            const size_t j = i + len;
            if (!chordAllowed(i, j)) continue;
            for (size_t k = i + 1; k < j; ++k) {
                const double c =
                    cost[i * n + k] + cost[k * n + j] + triangleArea(mesh, loop[i], loop[k], loop[j]);
                if (c < cost[i * n + j]) {
                    cost[i * n + j] = c;
                    split[i * n + j] = uint32_t(k);
                }
            }
        }
    std::vector<Triangle> triangles;
    if (!(cost[n - 1] < inf)) return triangles;
    std::vector<std::pair<size_t, size_t>> stack{{0, n - 1}};
    while (!stack.empty()) {
        const auto [i, j] = stack.back();
        stack.pop_back();
        if (j < i + 2) continue;
        const size_t k = split[i * n + j];
        triangles.push_back({loop[i], loop[k], loop[j]});
        stack.push_back({i, k});
        stack.push_back({k, j});
    }
    return triangles;
}

/// Fills every simple boundary loop of at most @p maxEdges edges; returns {holes, triangles} added.
std::pair<size_t, size_t> fillHoles(TriMesh& mesh, size_t maxEdges, RunContext& context) {
    const std::vector<EdgeUse> uses = collectEdges(mesh);
    std::vector<uint64_t> existing;
    existing.reserve(uses.size() / 2 + 1);
    // The fill runs each boundary edge backwards: the edge a -> b of its triangle becomes b -> a.
    std::vector<std::pair<uint32_t, uint32_t>> fillEdges;
    forEachEdge(uses, [&](size_t first, size_t count) {
        existing.push_back(uses[first].key);
        if (count != 1) return;
        const uint32_t lo = uint32_t(uses[first].key >> 32), hi = uint32_t(uses[first].key & 0xffffffffu);
        fillEdges.push_back(uses[first].forward ? std::make_pair(hi, lo) : std::make_pair(lo, hi));
    });
    if (fillEdges.empty()) return {0, 0};
    std::sort(fillEdges.begin(), fillEdges.end());
    // A vertex with two outgoing fill edges is where a boundary touches itself: not a simple loop.
    std::vector<char> pinched(mesh.positions.size(), 0);
    std::vector<uint32_t> inCount(mesh.positions.size(), 0);
    for (size_t e = 0; e < fillEdges.size(); ++e) {
        if (e > 0 && fillEdges[e].first == fillEdges[e - 1].first) pinched[fillEdges[e].first] = 1;
        ++inCount[fillEdges[e].second];
    }
    for (uint32_t v = 0; v < inCount.size(); ++v)
        if (inCount[v] > 1) pinched[v] = 1;
    auto next = [&](uint32_t v) -> int64_t {
        const auto it = std::lower_bound(fillEdges.begin(), fillEdges.end(), std::make_pair(v, uint32_t(0)));
        return (it != fillEdges.end() && it->first == v) ? int64_t(it->second) : -1;
    };
    std::vector<char> visited(mesh.positions.size(), 0);
    size_t holes = 0, added = 0;
    for (const auto& [start, unused] : fillEdges) {
        if (visited[start]) continue;
        std::vector<uint32_t> loop;
        bool simple = true;
        for (int64_t v = start; v >= 0 && !visited[size_t(v)]; v = next(uint32_t(v))) {
            visited[size_t(v)] = 1;
            simple = simple && !pinched[size_t(v)];
            loop.push_back(uint32_t(v));
        }
        if (!simple || loop.size() < 3 || loop.size() > maxEdges || next(loop.back()) != int64_t(start))
            continue;
        context.throwIfCancelled();
        const std::vector<Triangle> patch = fillLoop(mesh, loop, existing);
        if (patch.empty()) continue;
        // Simple loops share no vertex, so one patch's chords can never be another's.
        mesh.triangles.insert(mesh.triangles.end(), patch.begin(), patch.end());
        if (!mesh.salientFaces.empty()) mesh.salientFaces.resize(mesh.triangles.size(), 0);
        ++holes;
        added += patch.size();
    }
    return {holes, added};
}

}  // namespace

MeshReport checkMesh(const TriMesh& mesh) {
    checkIndices(mesh);
    MeshReport r;
    r.vertexCount = mesh.positions.size();
    r.triangleCount = mesh.triangles.size();
    for (const Vec3f& p : mesh.positions) {
        if (std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]))
            r.bounds.expand(toD(p));
        else
            ++r.nonFiniteVertices;
    }
    std::vector<char> used(mesh.positions.size(), 0);
    const Vec3d origin = r.bounds.isEmpty() ? Vec3d{0, 0, 0}
                                            : Vec3d{(r.bounds.min[0] + r.bounds.max[0]) / 2,
                                                    (r.bounds.min[1] + r.bounds.max[1]) / 2,
                                                    (r.bounds.min[2] + r.bounds.max[2]) / 2};
    std::vector<uint32_t> all(mesh.triangles.size());
    std::iota(all.begin(), all.end(), uint32_t(0));
    r.volume = signedVolume(mesh, all, origin);

    std::vector<std::array<uint32_t, 3>> sortedTriangles;
    sortedTriangles.reserve(mesh.triangles.size());
    for (const Triangle& t : mesh.triangles) {
        for (uint32_t v : t) used[v] = 1;
        const Vec3d a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]),
                    c = toD(mesh.positions[t[2]]);
        r.area += 0.5 * norm(cross(sub(b, a), sub(c, a)));
        if (isDegenerate(mesh, t)) ++r.degenerateTriangles;
        std::array<uint32_t, 3> s = t;
        std::sort(s.begin(), s.end());
        sortedTriangles.push_back(s);
    }
    r.unreferencedVertices = size_t(std::count(used.begin(), used.end(), 0));
    std::sort(sortedTriangles.begin(), sortedTriangles.end());
    for (size_t i = 1; i < sortedTriangles.size(); ++i)
        if (sortedTriangles[i] == sortedTriangles[i - 1]) ++r.duplicateTriangles;

    // Edges: boundary (1 use), non-manifold (3+ uses), inconsistent (2 uses in the same direction).
    const std::vector<EdgeUse> uses = collectEdges(mesh);
    DisjointSets triangleSets(mesh.triangles.size());
    DisjointSets boundarySets(mesh.positions.size());
    std::vector<char> onBoundary(mesh.positions.size(), 0);
    forEachEdge(uses, [&](size_t first, size_t count) {
        const uint32_t a = uint32_t(uses[first].key >> 32), b = uint32_t(uses[first].key & 0xffffffffu);
        for (size_t k = 1; k < count; ++k) triangleSets.unite(uses[first].triangle, uses[first + k].triangle);
        if (count == 1) {
            ++r.boundaryEdges;
            r.boundaryBounds.expand(toD(mesh.positions[a]));
            r.boundaryBounds.expand(toD(mesh.positions[b]));
            boundarySets.unite(a, b);
            onBoundary[a] = onBoundary[b] = 1;
        } else if (count >= 3) {
            ++r.nonManifoldEdges;
            r.nonManifoldBounds.expand(toD(mesh.positions[a]));
            r.nonManifoldBounds.expand(toD(mesh.positions[b]));
        } else if (uses[first].forward == uses[first + 1].forward) {
            ++r.inconsistentEdges;
        }
    });
    for (uint32_t v = 0; v < onBoundary.size(); ++v)
        if (onBoundary[v] && boundarySets.find(v) == v) ++r.boundaryLoops;
    for (uint32_t t = 0; t < mesh.triangles.size(); ++t)
        if (!hasRepeatedIndex(mesh.triangles[t]) && triangleSets.find(t) == t) ++r.components;
    return r;
}

namespace {

/// Throws Error(InvalidInput) naming the mesh's file.
struct Failure {
    const std::string& sourceName;
    [[noreturn]] void operator()(const std::string& message) const {
        throw Error(ErrorCode::InvalidInput, message, sourceName);
    }
};

/// Rejects an empty mesh, indices out of range, mismatched salient flags and non-finite coordinates.
void checkBasics(const TriMesh& mesh, const std::string& sourceName) {
    const Failure fail{sourceName};
    if (mesh.triangles.empty()) fail("no triangles");
    try {
        checkIndices(mesh);
    } catch (const Error& e) {
        throw e.withFile(sourceName);
    }
    const bool hasSalient = !mesh.salientFaces.empty();
    if (hasSalient && mesh.salientFaces.size() != mesh.triangles.size())
        fail("salient-face flags (" + std::to_string(mesh.salientFaces.size()) + ") do not match the " +
             std::to_string(mesh.triangles.size()) + " triangles");
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
        const Vec3f& p = mesh.positions[v];
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            fail("vertex " + std::to_string(v) + " has a non-finite coordinate (NaN or infinity)");
    }
}

/// Drops triangles with a repeated index (no area, no proper edges) and repeated triangles (warning).
void dropDegenerate(TriMesh& mesh, const std::string& sourceName, const RunContext& context) {
    const Failure fail{sourceName};
    const bool hasSalient = !mesh.salientFaces.empty();
    {
        std::vector<std::pair<std::array<uint32_t, 3>, uint32_t>> keyed;
        keyed.reserve(mesh.triangles.size());
        size_t repeatedIndex = 0;
        std::vector<char> keep(mesh.triangles.size(), 1);
        for (uint32_t t = 0; t < mesh.triangles.size(); ++t) {
            if (hasRepeatedIndex(mesh.triangles[t])) {
                keep[t] = 0;
                ++repeatedIndex;
                continue;
            }
            std::array<uint32_t, 3> s = mesh.triangles[t];
            std::sort(s.begin(), s.end());
            keyed.push_back({s, t});
        }
        std::sort(keyed.begin(), keyed.end());
        size_t duplicates = 0;
        for (size_t i = 1; i < keyed.size(); ++i)
            if (keyed[i].first == keyed[i - 1].first) {
                keep[keyed[i].second] = 0;  // keeps the first occurrence
                ++duplicates;
            }
        if (repeatedIndex + duplicates > 0) {
            size_t out = 0;
            for (size_t t = 0; t < mesh.triangles.size(); ++t) {
                if (!keep[t]) continue;
                mesh.triangles[out] = mesh.triangles[t];
                if (hasSalient) mesh.salientFaces[out] = mesh.salientFaces[t];
                ++out;
            }
            mesh.triangles.resize(out);
            if (hasSalient) mesh.salientFaces.resize(out);
            if (repeatedIndex)
                context.warn(sourceName + ": dropped " + std::to_string(repeatedIndex) +
                             " degenerate triangles (a vertex used twice)");
            if (duplicates)
                context.warn(sourceName + ": dropped " + std::to_string(duplicates) + " duplicate triangles");
            if (mesh.triangles.empty()) fail("no triangles left after dropping degenerate ones");
        }
    }
}

/// Drops unreferenced vertices, keeping the order of the others.
void dropUnreferenced(TriMesh& mesh, const std::string& sourceName, const RunContext& context) {
    {
        std::vector<uint32_t> remap(mesh.positions.size(), UINT32_MAX);
        for (const Triangle& t : mesh.triangles)
            for (uint32_t v : t) remap[v] = 0;
        std::vector<Vec3f> kept;
        for (size_t v = 0; v < mesh.positions.size(); ++v)
            if (remap[v] == 0) {
                remap[v] = uint32_t(kept.size());
                kept.push_back(mesh.positions[v]);
            }
        if (kept.size() != mesh.positions.size()) {
            context.debug(sourceName + ": dropped " + std::to_string(mesh.positions.size() - kept.size()) +
                          " unreferenced vertices");
            for (Triangle& t : mesh.triangles)
                for (uint32_t& v : t) v = remap[v];
            mesh.positions = std::move(kept);
        }
    }
}

/// Rejects an open mesh (with the count, loops and box of its boundary edges) and non-manifold edges.
void requireClosed(const TriMesh& mesh, const std::vector<EdgeUse>& uses, const std::string& sourceName) {
    const Failure fail{sourceName};
    {
        size_t boundary = 0, nonManifold = 0;
        Box3d boundaryBox, nonManifoldBox;
        DisjointSets loops(mesh.positions.size());
        std::vector<char> onBoundary(mesh.positions.size(), 0);
        forEachEdge(uses, [&](size_t first, size_t count) {
            const uint32_t a = uint32_t(uses[first].key >> 32), b = uint32_t(uses[first].key & 0xffffffffu);
            if (count == 1) {
                ++boundary;
                boundaryBox.expand(toD(mesh.positions[a]));
                boundaryBox.expand(toD(mesh.positions[b]));
                loops.unite(a, b);
                onBoundary[a] = onBoundary[b] = 1;
            } else if (count >= 3) {
                ++nonManifold;
                nonManifoldBox.expand(toD(mesh.positions[a]));
                nonManifoldBox.expand(toD(mesh.positions[b]));
            }
        });
        if (boundary > 0) {
            size_t loopCount = 0;
            for (uint32_t v = 0; v < onBoundary.size(); ++v)
                if (onBoundary[v] && loops.find(v) == v) ++loopCount;
            fail("open mesh: " + std::to_string(boundary) + " boundary edges in " +
                 std::to_string(loopCount) + (loopCount == 1 ? " loop" : " loops") + ", between " +
                 formatNumbers("(%.4g, %.4g, %.4g)", boundaryBox.min[0], boundaryBox.min[1],
                               boundaryBox.min[2]) +
                 " and " +
                 formatNumbers("(%.4g, %.4g, %.4g)", boundaryBox.max[0], boundaryBox.max[1],
                               boundaryBox.max[2]) +
                 "; the later stages need a closed surface");
        }
        if (nonManifold > 0)
            fail("non-manifold mesh: " + std::to_string(nonManifold) +
                 " edges shared by three or more triangles, between " +
                 formatNumbers("(%.4g, %.4g, %.4g)", nonManifoldBox.min[0], nonManifoldBox.min[1],
                               nonManifoldBox.min[2]) +
                 " and " +
                 formatNumbers("(%.4g, %.4g, %.4g)", nonManifoldBox.max[0], nonManifoldBox.max[1],
                               nonManifoldBox.max[2]));
    }
}

/// Makes the orientation consistent within each component: walks each component across its
/// edges; two neighbours agree when they run their shared edge in opposite directions (a
/// conflict means a non-orientable surface). Keeps the majority of each component as it is and
/// flips the minority. Returns the components (sorted triangle lists).
std::vector<std::vector<uint32_t>> orientConsistently(TriMesh& mesh, const std::vector<EdgeUse>& uses,
                                                      const std::string& sourceName,
                                                      const RunContext& context) {
    const Failure fail{sourceName};
    const size_t triangleCount = mesh.triangles.size();
    std::vector<uint32_t> neighbourStart(triangleCount + 1, 0);
    struct Link {
        uint32_t other;
        bool sameDirection;
    };
    std::vector<std::pair<uint32_t, Link>> links;
    links.reserve(uses.size());
    forEachEdge(uses, [&](size_t first, size_t) {  // every edge has exactly two uses here
        const EdgeUse& u = uses[first];
        const EdgeUse& w = uses[first + 1];
        const bool same = u.forward == w.forward;
        links.push_back({u.triangle, {w.triangle, same}});
        links.push_back({w.triangle, {u.triangle, same}});
    });
    std::sort(links.begin(), links.end(), [](const auto& a, const auto& b) {
        return a.first != b.first ? a.first < b.first : a.second.other < b.second.other;
    });
    for (const auto& l : links) ++neighbourStart[l.first + 1];
    for (size_t t = 0; t < triangleCount; ++t) neighbourStart[t + 1] += neighbourStart[t];

    std::vector<int8_t> flip(triangleCount, -1);  // -1 unvisited, 0 keep, 1 flip
    std::vector<std::vector<uint32_t>> components;
    size_t flippedForConsistency = 0;
    std::vector<uint32_t> stack;
    for (uint32_t seed = 0; seed < triangleCount; ++seed) {
        if (flip[seed] >= 0) continue;
        components.emplace_back();
        std::vector<uint32_t>& component = components.back();
        flip[seed] = 0;
        stack.assign(1, seed);
        while (!stack.empty()) {
            const uint32_t t = stack.back();
            stack.pop_back();
            component.push_back(t);
            for (uint32_t k = neighbourStart[t]; k < neighbourStart[t + 1]; ++k) {
                const Link& link = links[k].second;
                const int8_t wanted = int8_t(flip[t] ^ (link.sameDirection ? 1 : 0));
                if (flip[link.other] < 0) {
                    flip[link.other] = wanted;
                    stack.push_back(link.other);
                } else if (flip[link.other] != wanted) {
                    fail(
                        "non-orientable surface (like a Moebius strip): its triangles cannot all face one "
                        "way");
                }
            }
        }
        std::sort(component.begin(), component.end());
        // Keep the majority of each component as it is; flip the minority.
        size_t flips = 0;
        for (uint32_t t : component) flips += size_t(flip[t]);
        if (2 * flips > component.size())
            for (uint32_t t : component) flip[t] = int8_t(1 - flip[t]);
        for (uint32_t t : component)
            if (flip[t]) {
                std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
                ++flippedForConsistency;
            }
    }
    if (flippedForConsistency)
        context.warn(sourceName + ": flipped " + std::to_string(flippedForConsistency) +
                     " triangles to make the orientation consistent");
    context.throwIfCancelled();

    return components;
}

/// Makes each component outward: its volume must be positive, unless it lies inside an odd number
/// of other components (then it bounds a cavity and must be negative). Returns the volumes.
std::vector<double> orientOutward(TriMesh& mesh, const std::vector<std::vector<uint32_t>>& components,
                                  const std::string& sourceName, const RunContext& context) {
    const Box3d box = boundingBox(mesh);
    const Vec3d centre{(box.min[0] + box.max[0]) / 2, (box.min[1] + box.max[1]) / 2,
                       (box.min[2] + box.max[2]) / 2};
    std::vector<double> volumes;
    std::vector<Box3d> boxes;
    for (const auto& component : components) {
        volumes.push_back(signedVolume(mesh, component, centre));
        Box3d b;
        for (uint32_t t : component)
            for (uint32_t v : mesh.triangles[t]) b.expand(toD(mesh.positions[v]));
        boxes.push_back(b);
    }
    // Nesting depth of each component: how many others contain a point of it (generalised winding
    // number, only for components whose bounding box contains the point). The work is capped so a
    // scan with thousands of loose fragments inside the main body stays fast; past the cap every
    // component is taken as a separate solid (depth 0).
    std::vector<Vec3d> probes(components.size(), Vec3d{0, 0, 0});
    std::vector<std::vector<uint32_t>> candidates(components.size());
    size_t work = 0;
    for (size_t c = 0; c < components.size() && components.size() > 1; ++c) {
        for (uint32_t v : mesh.triangles[components[c][0]])  // centroid of the component's first triangle
            for (int i = 0; i < 3; ++i) probes[c][i] += mesh.positions[v][i] / 3.0;
        for (size_t d = 0; d < components.size(); ++d) {
            const Box3d& b = boxes[d];
            const Vec3d& p = probes[c];
            if (d == c || volumes[d] == 0 || p[0] < b.min[0] || p[0] > b.max[0] || p[1] < b.min[1] ||
                p[1] > b.max[1] || p[2] < b.min[2] || p[2] > b.max[2])
                continue;
            candidates[c].push_back(uint32_t(d));
            work += components[d].size();
        }
    }
    constexpr size_t kMaxNestingWork = 50'000'000;  // triangle visits, about a second
    const bool checkNesting = work <= kMaxNestingWork;
    if (!checkNesting)
        context.info(
            sourceName + ": " + std::to_string(components.size()) +
            " components: too many overlapping bounding boxes to check nesting; each is oriented outward");
    std::vector<uint32_t> inverted;
    for (size_t c = 0; c < components.size(); ++c) {
        int depth = 0;
        if (checkNesting) {
            context.throwIfCancelled();
            for (uint32_t d : candidates[c])
                if (std::abs(windingNumber(mesh, components[d], probes[c])) > 0.5) ++depth;
        }
        const bool wantPositive = depth % 2 == 0;
        if (volumes[c] != 0 && (volumes[c] > 0) != wantPositive) inverted.push_back(uint32_t(c));
    }
    for (uint32_t c : inverted) {
        for (uint32_t t : components[c]) std::swap(mesh.triangles[t][1], mesh.triangles[t][2]);
        volumes[c] = -volumes[c];
    }
    if (!inverted.empty())
        context.warn(sourceName +
                     (components.size() == 1
                          ? std::string(": the mesh was inside out (negative volume); flipped it")
                          : ": " + std::to_string(inverted.size()) + " of " +
                                std::to_string(components.size()) +
                                " components were inside out; flipped them"));

    return volumes;
}

}  // namespace

TriMesh validateClosedMesh(TriMesh mesh, const ValidateOptions& options, const std::string& sourceName,
                           RunContext& context) {
    checkBasics(mesh, sourceName);
    context.throwIfCancelled();
    dropDegenerate(mesh, sourceName, context);
    dropUnreferenced(mesh, sourceName, context);
    context.throwIfCancelled();
    if (options.repair) {
        const auto [holes, added] = fillHoles(mesh, options.maxHoleEdges, context);
        if (holes > 0)
            context.warn(sourceName + ": filled " + std::to_string(holes) +
                         (holes == 1 ? " hole" : " holes") + " with " + std::to_string(added) + " triangles");
    }
    const std::vector<EdgeUse> uses = collectEdges(mesh);
    requireClosed(mesh, uses, sourceName);
    const std::vector<std::vector<uint32_t>> components = orientConsistently(mesh, uses, sourceName, context);
    context.throwIfCancelled();
    const std::vector<double> volumes = orientOutward(mesh, components, sourceName, context);
    const Failure fail{sourceName};
    const Box3d box = boundingBox(mesh);
    const double volume = std::accumulate(volumes.begin(), volumes.end(), 0.0);
    const Vec3d size = box.size();
    const double diagonal = std::sqrt(dot(size, size));
    if (!(volume > options.minRelativeVolume * diagonal * diagonal * diagonal))
        fail("zero volume: the closed surface encloses no space (flat or self-cancelling): volume " +
             formatNumber(volume, 4) + " for a bounding-box diagonal of " + formatNumber(diagonal, 4));
    return mesh;
}

CavityRemoval removeCavities(TriMesh& mesh, double maxVolumeMm3) {
    const VertexComponents components = vertexComponents(mesh);
    auto isSmallCavity = [&](uint32_t root) {
        return components.volume[root] < 0.0 && -components.volume[root] <= maxVolumeMm3;
    };
    CavityRemoval removal;
    for (uint32_t v = 0; v < mesh.vertexCount(); ++v)
        if (components.rootOf[v] == v && isSmallCavity(v))
            ++removal.cavities, removal.volumeMm3 -= components.volume[v];
    if (removal.cavities > 0)
        keepComponents(mesh, components, [&](uint32_t root) { return !isSmallCavity(root); });
    return removal;
}

}  // namespace zomefab::mesh
