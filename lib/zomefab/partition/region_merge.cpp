// SPDX-License-Identifier: GPL-3.0-or-later
// The region merge (PartitionOptions::mergeSmallRegions, docs/partition.md §4).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <set>

#include "zomefab/core/disjoint_sets.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/detail/stage.h"

namespace zomefab::partition {

namespace detail {

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

/// PartitionOptions::mergeSmallRegions (docs/partition.md §4): the regions are the connected
/// regions of one training class (after any bisection); merged regions keep their classes, so
/// the SVM still sees each as it was cut, and form one group, which makePieces turns into one
/// piece of several cells.
void mergeRegions(const Surface& S, const FitTester& fits, const PartitionOptions& opt, Classes& C,
                  PartitionResult& res, const RunContext& run) {
    const Fabrication& fab = fits.fab;
    if (!opt.mergeSmallRegions) return;
    run.throwIfCancelled();
    const Stopwatch clock;
    std::vector<uint32_t> regionOf;
    const uint32_t regionCount = labelComponents(S.graph, C.trainClass, regionOf);
    const RegionMerge m = mergeRegionsThatFit(S.mesh, S.graph, regionOf, regionCount, fab.pieceBoxMm(),
                                              fab.fitMarginMm, fits.blocked, fits.blockedShare);
    C.faceGroup.resize(S.faceCount);
    for (uint32_t f = 0; f < S.faceCount; ++f) C.faceGroup[f] = m.groupOf[regionOf[f]];
    C.groupCount = m.groupCount;
    res.regionMerges = m.merges;
    run.detail(std::to_string(regionCount) + " regions, " + std::to_string(m.merges) +
               " merged into a neighbour they fit the printer with: " + std::to_string(m.groupCount) +
               " regions");
    run.debug(formatNumbers("region merge: %.3f s", clock.seconds()));
}

}  // namespace detail

using namespace detail;

RegionMerge mergeRegionsThatFit(const TriMesh& meshMm, const FaceGraph& graph,
                                const std::vector<uint32_t>& regionOf, uint32_t regionCount,
                                const Vec3d& printerMm, double marginMm,
                                const std::vector<uint64_t>& blockedDirections, double blockedShare) {
    const size_t faceCount = graph.faceCount();
    if (regionOf.size() != faceCount)
        throw Error(ErrorCode::Usage, "region merge: " + std::to_string(regionOf.size()) +
                                          " region ids for " + std::to_string(faceCount) + " faces");
    // Per region (indexed by its union-find root): area, vertices (each once per region; a vertex on
    // a seam appears in both, which does not change a box), and the seam length to each neighbour.
    std::vector<double> area(regionCount, 0.0);
    std::vector<std::vector<Vec3d>> pts(regionCount);
    std::vector<MountProfile> profile(blockedDirections.empty() ? 0 : regionCount);
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
        if (!profile.empty())
            profile[regionOf[f]].addFace(graph.areasMm2[f], graph.normals[f], blockedDirections[f]);
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
                if (!profile.empty()) {
                    MountProfile joined = profile[r];
                    joined.add(profile[byLength[i].second]);
                    if (!joined.isMountable(blockedShare)) return;  // no direction would mount it
                }
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
            if (!profile.empty()) profile[root].add(profile[gone]);
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

}  // namespace zomefab::partition
