// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/mesh_clip.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <unordered_map>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"

namespace zomefab::report {

namespace {

/// A vertex of a cap polygon in the cap's 2-D frame, with its index in the output mesh.
struct CapVertex {
    double u = 0.0, v = 0.0;
    uint32_t id = 0;
};

double cross(const CapVertex& o, const CapVertex& a, const CapVertex& b) {
    return (a.u - o.u) * (b.v - o.v) - (a.v - o.v) * (b.u - o.u);
}

double signedArea(const std::vector<CapVertex>& loop) {
    double s = 0.0;
    for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++)
        s += loop[j].u * loop[i].v - loop[i].u * loop[j].v;
    return 0.5 * s;
}

bool samePoint(const CapVertex& a, const CapVertex& b) { return a.id == b.id || (a.u == b.u && a.v == b.v); }

/// Even-odd point-in-polygon test.
bool contains(const std::vector<CapVertex>& loop, double u, double v) {
    bool inside = false;
    for (size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++) {
        const CapVertex &a = loop[i], &b = loop[j];
        if ((a.v > v) != (b.v > v) && u < (b.u - a.u) * (v - a.v) / (b.v - a.v) + a.u) inside = !inside;
    }
    return inside;
}

/// p inside or on the triangle (a, b, c), counter-clockwise.
bool inTriangle(const CapVertex& p, const CapVertex& a, const CapVertex& b, const CapVertex& c) {
    return cross(a, b, p) >= 0.0 && cross(b, c, p) >= 0.0 && cross(c, a, p) >= 0.0;
}

[[noreturn]] void capFailed(const std::string& why) {
    throw Error(ErrorCode::ProcessingFailed, "cannot close a planar cut of the mesh: " + why);
}

/// Splices @p hole (clockwise) into @p outer (counter-clockwise) through a bridge from the hole's
/// rightmost vertex to a vertex of @p outer it can see (D. Eberly, "Triangulation by Ear
/// Clipping", §3), so the result is one weakly simple counter-clockwise polygon.
void bridgeHole(std::vector<CapVertex>& outer, const std::vector<CapVertex>& hole) {
    size_t m = 0;
    for (size_t i = 1; i < hole.size(); ++i)
        if (hole[i].u > hole[m].u || (hole[i].u == hole[m].u && hole[i].v < hole[m].v)) m = i;
    const CapVertex& M = hole[m];
    // Nearest crossing of the ray M + t·(1, 0), t ≥ 0, with an edge of the outer polygon.
    double bestU = 1e300;
    size_t bestEdge = outer.size();
    for (size_t i = 0; i < outer.size(); ++i) {
        const CapVertex &a = outer[i], &b = outer[(i + 1) % outer.size()];
        if ((a.v > M.v) == (b.v > M.v)) continue;
        const double u = a.u + (M.v - a.v) * (b.u - a.u) / (b.v - a.v);
        if (u >= M.u && u < bestU) bestU = u, bestEdge = i;
    }
    if (bestEdge == outer.size()) capFailed("a hole of the cross-section lies outside every outer loop");
    size_t p = bestEdge;
    const size_t pNext = (bestEdge + 1) % outer.size();
    if (outer[pNext].u > outer[p].u) p = pNext;
    // A reflex vertex inside the triangle (M, I, P) would block the view: take the one closest in
    // angle to the ray instead.
    const CapVertex I{bestU, M.v, 0};
    const CapVertex P = outer[p];
    const bool isCcw = cross(M, I, P) > 0.0;
    double bestCos = -2.0, bestDist = 1e300;
    for (size_t i = 0; i < outer.size(); ++i) {
        const CapVertex& r = outer[i];
        if (i == p || r.u < M.u) continue;
        const CapVertex &prev = outer[(i + outer.size() - 1) % outer.size()],
                        &next = outer[(i + 1) % outer.size()];
        if (cross(prev, r, next) > 0.0) continue;  // convex vertices cannot block
        const bool inside = isCcw ? inTriangle(r, M, I, P) : inTriangle(r, M, P, I);
        if (!inside) continue;
        const double du = r.u - M.u, dv = r.v - M.v, dist = std::sqrt(du * du + dv * dv);
        if (dist == 0.0) continue;
        const double c = du / dist;
        if (c > bestCos || (c == bestCos && dist < bestDist)) bestCos = c, bestDist = dist, p = i;
    }
    std::vector<CapVertex> merged;
    merged.reserve(outer.size() + hole.size() + 2);
    merged.insert(merged.end(), outer.begin(), outer.begin() + std::ptrdiff_t(p) + 1);
    for (size_t k = 0; k <= hole.size(); ++k) merged.push_back(hole[(m + k) % hole.size()]);
    merged.push_back(outer[p]);
    merged.insert(merged.end(), outer.begin() + std::ptrdiff_t(p) + 1, outer.end());
    outer.swap(merged);
}

/// Ear clipping of a counter-clockwise, weakly simple polygon into @p out (O(n²) typical).
void earClip(const std::vector<CapVertex>& poly, std::vector<Triangle>& out) {
    const size_t n = poly.size();
    if (n < 3) return;
    std::vector<size_t> prev(n), next(n);
    for (size_t i = 0; i < n; ++i) prev[i] = (i + n - 1) % n, next[i] = (i + 1) % n;
    size_t remaining = n, i = 0, sinceLastEar = 0;
    auto isEar = [&](size_t b) {
        const CapVertex &A = poly[prev[b]], &B = poly[b], &C = poly[next[b]];
        if (cross(A, B, C) <= 0.0) return false;
        const double minU = std::min({A.u, B.u, C.u}), maxU = std::max({A.u, B.u, C.u});
        const double minV = std::min({A.v, B.v, C.v}), maxV = std::max({A.v, B.v, C.v});
        for (size_t k = next[next[b]]; k != prev[b]; k = next[k]) {
            const CapVertex& P = poly[k];
            if (P.u < minU || P.u > maxU || P.v < minV || P.v > maxV) continue;
            if (samePoint(P, A) || samePoint(P, B) || samePoint(P, C)) continue;
            if (inTriangle(P, A, B, C)) return false;
        }
        return true;
    };
    while (remaining > 3) {
        bool clip = isEar(i);
        if (!clip && sinceLastEar > remaining) {
            // No ear in a whole turn: only degenerate (collinear or touching) vertices are left.
            // Clipping the flattest vertex keeps the cap closed; its triangle has (nearly) zero area.
            size_t best = i;
            double bestArea = 1e300;
            for (size_t k = 0, j = i; k < remaining; ++k, j = next[j]) {
                const double a = std::abs(cross(poly[prev[j]], poly[j], poly[next[j]]));
                if (a < bestArea) bestArea = a, best = j;
            }
            i = best;
            clip = true;
        }
        if (clip) {
            out.push_back({poly[prev[i]].id, poly[i].id, poly[next[i]].id});
            next[prev[i]] = next[i];
            prev[next[i]] = prev[i];
            --remaining;
            i = prev[i];  // the neighbours' ear status changed
            sinceLastEar = 0;
        } else {
            i = next[i];
            ++sinceLastEar;
        }
    }
    out.push_back({poly[prev[i]].id, poly[i].id, poly[next[i]].id});
}

/// Closes the cut with caps: chains the cap edges (from → to, cut vertices numbered from
/// @p firstCut in @p out) into loops, sorts them into outer loops and holes in the plane's 2-D
/// frame, bridges each hole into the smallest outer loop holding it, and ear-clips.
/// @throw Error(InvalidInput) when the cut does not close into loops.
void capCut(TriMesh& out, const std::vector<std::pair<uint32_t, uint32_t>>& capEdges, uint32_t firstCut,
            int axis, double c, bool keepBelow) {
    // Chain the cap edges into loops: every cut vertex starts exactly one edge and ends one.
    const size_t cutCount = out.positions.size() - firstCut;
    std::vector<uint32_t> nextOf(cutCount, UINT32_MAX);
    std::vector<uint32_t> incoming(cutCount, 0);
    auto openCut = [&](const char* why) {
        throw Error(ErrorCode::InvalidInput, std::string("mesh is not closed: ") + why + " (cut at " +
                                                 "xyz"[axis] + formatNumbers(" = %.4f mm)", c));
    };
    for (const auto& [from, to] : capEdges) {
        if (nextOf[from - firstCut] != UINT32_MAX) openCut("a cut edge is shared by more than two triangles");
        nextOf[from - firstCut] = to;
        ++incoming[to - firstCut];
    }
    for (size_t i = 0; i < cutCount; ++i)
        if (nextOf[i] == UINT32_MAX || incoming[i] != 1) openCut("the cut does not close into loops");

    // 2-D frame of the cap in which its outward normal (towards the removed side) points at the
    // viewer, so outer loops run counter-clockwise and holes clockwise.
    const int ua = (axis + 1) % 3, va = (axis + 2) % 3;
    const bool swapUv = !keepBelow;
    std::vector<std::vector<CapVertex>> outers, holes;
    std::vector<double> outerAreas;
    std::vector<char> visited(cutCount, 0);
    for (size_t start = 0; start < cutCount; ++start) {
        if (visited[start]) continue;
        std::vector<CapVertex> loop;
        for (uint32_t at = uint32_t(start); !visited[at]; at = nextOf[at] - firstCut) {
            visited[at] = 1;
            const Vec3f& p = out.positions[firstCut + at];
            double u = p[size_t(ua)], v = p[size_t(va)];
            if (swapUv) std::swap(u, v);
            loop.push_back({u, v, firstCut + at});
        }
        const double area = signedArea(loop);
        if (loop.size() < 3 || area == 0.0) {
            // A sliver loop with no area: fan it so its edges are still matched.
            for (size_t k = 1; k + 1 < loop.size(); ++k)
                out.triangles.push_back({loop[0].id, loop[k].id, loop[k + 1].id});
            continue;
        }
        if (area > 0.0) {
            outers.push_back(std::move(loop));
            outerAreas.push_back(area);
        } else {
            holes.push_back(std::move(loop));
        }
    }
    // Each hole goes into the smallest outer loop that contains it; then holes are bridged in
    // order of their rightmost vertex, rightmost first (Eberly §5).
    std::vector<std::vector<size_t>> holesOf(outers.size());
    for (size_t h = 0; h < holes.size(); ++h) {
        size_t best = outers.size();
        const CapVertex& probe = holes[h][0];
        for (size_t o = 0; o < outers.size(); ++o)
            if ((best == outers.size() || outerAreas[o] < outerAreas[best]) &&
                contains(outers[o], probe.u, probe.v))
                best = o;
        if (best == outers.size()) capFailed("a hole of the cross-section lies outside every outer loop");
        holesOf[best].push_back(h);
    }
    auto rightmost = [](const std::vector<CapVertex>& loop) {
        double u = -1e300;
        for (const CapVertex& p : loop) u = std::max(u, p.u);
        return u;
    };
    for (size_t o = 0; o < outers.size(); ++o) {
        std::vector<size_t>& hs = holesOf[o];
        std::stable_sort(hs.begin(), hs.end(),
                         [&](size_t a, size_t b) { return rightmost(holes[a]) > rightmost(holes[b]); });
        for (size_t h : hs) bridgeHole(outers[o], holes[h]);
        earClip(outers[o], out.triangles);
    }
}

}  // namespace

TriMesh clipByPlane(const TriMesh& mesh, int axis, double coordMm, bool keepBelow) {
    if (axis < 0 || axis > 2) throw Error(ErrorCode::Usage, "clipByPlane: axis must be 0, 1 or 2");
    // Move the plane off the vertices so every edge crosses it at an interior point.
    const double kOnPlaneMm = 1e-4;
    double c = coordMm;
    for (int attempt = 1; attempt <= 12; ++attempt) {
        bool isClear = true;
        for (const Vec3f& p : mesh.positions)
            if (std::abs(double(p[size_t(axis)]) - c) < kOnPlaneMm) {
                isClear = false;
                break;
            }
        if (isClear) break;
        // ±0.0008, ±0.0016, ... mm, alternating sides: at most 0.01 mm from the request.
        c = coordMm + (attempt % 2 ? 1.0 : -1.0) * 0.0008 * double((attempt + 1) / 2);
    }
    const float cf = float(c);

    const size_t nv = mesh.positions.size();
    std::vector<char> kept(nv);
    for (size_t v = 0; v < nv; ++v) {
        const double s = double(mesh.positions[v][size_t(axis)]) - c;
        kept[v] = keepBelow ? s < 0.0 : s > 0.0;
    }
    TriMesh out;
    std::vector<uint32_t> remap(nv, UINT32_MAX);
    // Kept vertices first, in input order, so the result does not depend on triangle order.
    for (const Triangle& t : mesh.triangles)
        for (uint32_t v : t)
            if (kept[v]) remap[v] = 0;
    for (size_t v = 0; v < nv; ++v)
        if (remap[v] == 0) {
            remap[v] = uint32_t(out.positions.size());
            out.positions.push_back(mesh.positions[v]);
        }
    const uint32_t firstCut = uint32_t(out.positions.size());
    std::unordered_map<uint64_t, uint32_t> cutVertex;
    auto crossing = [&](uint32_t a, uint32_t b) {
        const uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
        const auto it = cutVertex.find(key);
        if (it != cutVertex.end()) return it->second;
        const Vec3f &pa = mesh.positions[std::min(a, b)], &pb = mesh.positions[std::max(a, b)];
        const double sa = double(pa[size_t(axis)]) - c, sb = double(pb[size_t(axis)]) - c;
        const double t = sa / (sa - sb);
        Vec3f p;
        for (int k = 0; k < 3; ++k) p[k] = float(double(pa[k]) + t * (double(pb[k]) - double(pa[k])));
        p[size_t(axis)] = cf;
        const uint32_t id = uint32_t(out.positions.size());
        out.positions.push_back(p);
        cutVertex.emplace(key, id);
        return id;
    };
    // Cap edges q -> p: the reverse of the kept surface's boundary along the cut.
    std::vector<std::pair<uint32_t, uint32_t>> capEdges;
    for (const Triangle& t : mesh.triangles) {
        const int k = int(kept[t[0]]) + int(kept[t[1]]) + int(kept[t[2]]);
        if (k == 0) continue;
        if (k == 3) {
            out.triangles.push_back({remap[t[0]], remap[t[1]], remap[t[2]]});
            continue;
        }
        // k == 1: i = the kept corner; k == 2: i = the removed corner.
        int i = 0;
        while (bool(kept[t[size_t(i)]]) != (k == 1)) ++i;
        if (k == 1) {
            const uint32_t a = t[size_t(i)], b = t[size_t((i + 1) % 3)], cc = t[size_t((i + 2) % 3)];
            const uint32_t p = crossing(a, b), q = crossing(cc, a);
            out.triangles.push_back({remap[a], p, q});
            capEdges.emplace_back(q, p);
        } else {
            const uint32_t a = t[size_t((i + 1) % 3)], b = t[size_t((i + 2) % 3)], cc = t[size_t(i)];
            const uint32_t p = crossing(b, cc), q = crossing(cc, a);
            out.triangles.push_back({remap[a], remap[b], p});
            out.triangles.push_back({remap[a], p, q});
            capEdges.emplace_back(q, p);
        }
    }
    if (capEdges.empty()) return out;

    capCut(out, capEdges, firstCut, axis, c, keepBelow);
    return out;
}

TriMesh clipToBox(const TriMesh& mesh, const Box3d& box) {
    TriMesh part = mesh;
    for (int axis = 0; axis < 3; ++axis) {
        if (part.triangles.empty()) break;
        const Box3d b = boundingBox(part);
        if (b.min[size_t(axis)] < box.min[size_t(axis)])
            part = clipByPlane(part, axis, box.min[size_t(axis)], false);
        if (part.triangles.empty()) break;
        if (b.max[size_t(axis)] > box.max[size_t(axis)])
            part = clipByPlane(part, axis, box.max[size_t(axis)], true);
    }
    return part;
}

}  // namespace zomefab::report
