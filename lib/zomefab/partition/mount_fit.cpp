// SPDX-License-Identifier: GPL-3.0-or-later
// Can a region be pushed onto the frame along one direction? (docs/partition.md §4, "Mountable")
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>

#include "zomefab/core/vec.h"
#include "zomefab/mount/sweep.h"
#include "zomefab/partition/detail/stage.h"
#include "zomefab/zome/holes.h"

namespace zomefab::partition::detail {

namespace {

/// Points of triangle @p f on a barycentric grid about @p spacingMm apart (its centroid alone when
/// it is small), each moved @p wallMm behind the surface: where the wall's inside is.
void innerSamples(const TriMesh& mesh, const FaceGraph& graph, size_t f, double wallMm, double spacingMm,
                  std::vector<Vec3d>& out) {
    const Vec3d back = scale(graph.normals[f], -wallMm);
    const double edge = std::sqrt(2.0 * graph.areasMm2[f]);  // a typical side length
    const int n = std::clamp(int(std::ceil(edge / spacingMm)), 1, 16);
    if (n == 1) {
        out.push_back(add(graph.centroidsMm[f], back));
        return;
    }
    const auto& t = mesh.triangles[f];
    const Vec3d a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]), c = toD(mesh.positions[t[2]]);
    for (int i = 0; i < n; ++i)
        for (int j = 0; i + j < n; ++j) {
            const double u = (i + 1.0 / 3.0) / n, v = (j + 1.0 / 3.0) / n;
            out.push_back(add(madd(madd(scale(a, 1.0 - u - v), u, b), v, c), back));
        }
}

}  // namespace

std::vector<uint64_t> frameBlockedDirections(const TriMesh& mesh, const FaceGraph& graph,
                                             const zome::Structure& frame, double wallMm, double marginMm,
                                             double pixelMm) {
    const size_t faceCount = graph.faceCount();
    std::vector<uint64_t> blocked(faceCount, 0);
    if (frame.ballCount() == 0 || faceCount == 0) return blocked;
    // The wall's inner points, a few per face (pixelMm apart) so that a large triangle does not
    // let a ball slip between its samples: what meets the frame first when a piece is pushed off.
    std::vector<Vec3d> inner;
    std::vector<uint32_t> faceOf;
    Box3d bounds;
    for (size_t f = 0; f < faceCount; ++f) {
        const size_t before = inner.size();
        innerSamples(mesh, graph, f, wallMm, pixelMm, inner);
        faceOf.resize(inner.size(), uint32_t(f));
        for (size_t k = before; k < inner.size(); ++k) bounds.expand(inner[k]);
        bounds.expand(graph.centroidsMm[f]);
    }
    const size_t sampleCount = inner.size();
    const zome::ZomeScale& scale = frame.scale();
    for (zome::BallId id : frame.ballIds()) bounds.expand(frame.ball(id).positionMm);
    const size_t words = (faceCount + 63) / 64;
    std::vector<uint64_t> bits(size_t(zome::kHoleCount) * words, 0);
    tbb::parallel_for(0, zome::kHoleCount, [&](int hole) {
        const mount::SweepAxes axes(zome::holeDirection(hole));
        mount::DepthRaster r(axes, bounds, pixelMm, true, scale.ballRadiusMm() + marginMm);
        for (zome::BallId id : frame.ballIds())
            r.addSphere(frame.ball(id).positionMm, scale.ballRadiusMm(), marginMm, id);
        for (zome::StrutId id : frame.strutIds()) {
            const zome::Strut& s = frame.strut(id);
            r.addCapsule(s.startMm, s.endMm, scale.strutRadiusMm(s.color), marginMm, id);
        }
        uint64_t* row = bits.data() + size_t(hole) * words;
        for (size_t k = 0; k < sampleCount; ++k) {
            const Vec3d& p = inner[k];
            const uint32_t f = faceOf[k];
            const int i = int(std::floor((dot(p, axes.u) - r.u0()) / r.pixelMm()));
            const int j = int(std::floor((dot(p, axes.v) - r.v0()) / r.pixelMm()));
            if (i < 0 || j < 0 || i >= r.width() || j >= r.height()) continue;
            // Something of the frame lies ahead of the point along +d on its line: it runs into it.
            if (double(r.depth(i, j)) > dot(p, axes.d)) row[f / 64] |= uint64_t(1) << (f % 64);
        }
    });
    for (int hole = 0; hole < zome::kHoleCount; ++hole) {
        const uint64_t* row = bits.data() + size_t(hole) * words;
        for (size_t f = 0; f < faceCount; ++f)
            if ((row[f / 64] >> (f % 64)) & 1) blocked[f] |= uint64_t(1) << hole;
    }
    return blocked;
}

void MountProfile::addFace(double areaMm2, const Vec3d& normal, uint64_t blockedHoles) {
    areaMm2Total += areaMm2;
    normalMm2 = madd(normalMm2, areaMm2, normal);
    for (int h = 0; h < zome::kHoleCount; ++h)
        if ((blockedHoles >> h) & 1) blockedMm2[size_t(h)] += areaMm2;
}

void MountProfile::add(const MountProfile& o) {
    areaMm2Total += o.areaMm2Total;
    normalMm2 = zomefab::add(normalMm2, o.normalMm2);
    for (size_t h = 0; h < blockedMm2.size(); ++h) blockedMm2[h] += o.blockedMm2[h];
}

int MountProfile::freestHole() const {
    int best = 0;
    for (int h = 1; h < zome::kHoleCount; ++h) {
        const double a = blockedMm2[size_t(h)], b = blockedMm2[size_t(best)];
        if (a < b || (a == b && dot(zome::holeDirection(h), normalMm2) > dot(zome::holeDirection(best), normalMm2)))
            best = h;
    }
    return best;
}

bool MountProfile::isMountable(double share) const {
    return blockedMm2[size_t(freestHole())] <= share * areaMm2Total;
}

MountProfile FitTester::profileOf(const std::vector<uint32_t>& faces) const {
    MountProfile p;
    if (blocked.empty()) return p;
    for (uint32_t f : faces) p.addFace(graph.areasMm2[f], graph.normals[f], blocked[f]);
    return p;
}

bool FitTester::isMountable(const std::vector<uint32_t>& faces) const {
    return blocked.empty() || profileOf(faces).isMountable(blockedShare);
}

bool splitUnmountable(const FitTester& cx, const std::vector<uint32_t>& faces, std::vector<uint32_t>& lo,
                      std::vector<uint32_t>& hi) {
    const MountProfile profile = cx.profileOf(faces);
    const int hole = profile.freestHole();
    // The faces its best direction cannot take and the others: cut between them.
    Vec3d blockedSum{0, 0, 0}, freeSum{0, 0, 0};
    double blockedArea = 0.0, freeArea = 0.0;
    for (uint32_t f : faces) {
        const double a = cx.graph.areasMm2[f];
        if ((cx.blocked[f] >> hole) & 1)
            blockedSum = madd(blockedSum, a, cx.graph.centroidsMm[f]), blockedArea += a;
        else
            freeSum = madd(freeSum, a, cx.graph.centroidsMm[f]), freeArea += a;
    }
    if (blockedArea <= 0.0 || freeArea <= 0.0) return false;
    const Vec3d cb = scale(blockedSum, 1.0 / blockedArea), cf = scale(freeSum, 1.0 / freeArea);
    const Vec3d axis = sub(cb, cf);
    if (norm(axis) < 1e-9) return false;
    const double mid = 0.5 * (dot(axis, cb) + dot(axis, cf));
    for (uint32_t f : faces) (dot(axis, cx.graph.centroidsMm[f]) >= mid ? hi : lo).push_back(f);
    return !lo.empty() && !hi.empty();
}

}  // namespace zomefab::partition::detail
