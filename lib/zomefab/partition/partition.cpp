// SPDX-License-Identifier: GPL-3.0-or-later
// The partition stage (paper §5), step by step: detail/stage.h lists the steps and their files.
#include "zomefab/partition/partition.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/fabrication.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/detail/stage.h"

namespace zomefab::partition {

using namespace detail;

void checkPartitionOptions(const PartitionOptions& o, const Fabrication& fab, const zome::ZomeScale& scale) {
    auto usage = [](const std::string& m) { throw Error(ErrorCode::Usage, m); };
    checkFabrication(fab);
    const Vec3d box = fab.pieceBoxMm();
    const double minSide = std::min({box[0], box[1], box[2]});
    if (minSide < scale.ballDiameterMm + 2.0 * fab.fitMarginMm)
        usage("printer volume " + sizeText(box) +
              " (the bed less its margins) is smaller than a Zome ball (" +
              formatNumbers("%.1f mm across", scale.ballDiameterMm) +
              (fab.fitMarginMm > 0 ? formatNumbers(" plus 2 x %.1f mm margin", fab.fitMarginMm)
                                   : std::string()) +
              ")");
    if (o.candidateCount < 1) usage("k (candidate labels per triangle) must be >= 1");
    if (!(o.dataWeight > 0.0) || !std::isfinite(o.dataWeight)) usage("w_data must be > 0");
    if (!(o.saliencyWeight >= 0.0) || !std::isfinite(o.saliencyWeight)) usage("w_saliency must be >= 0");
    if (!(o.smoothnessStart >= 0.0) || !std::isfinite(o.smoothnessStart)) usage("w_smoothness must be >= 0");
    if (!(o.smoothnessFactor > 0.0 && o.smoothnessFactor < 1.0))
        usage("the w_smoothness factor must be in (0, 1)");
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
            throw Error(ErrorCode::Usage, "salient face index " + std::to_string(i) +
                                              " is out of range (the mesh has " + std::to_string(n) +
                                              " faces)");
        flags[i] = 1;
    }
    if (!spheres.empty()) {
        tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 4096), [&](const tbb::blocked_range<size_t>& r) {
            for (size_t f = r.begin(); f < r.end(); ++f) {
                const auto& t = mesh.triangles[f];
                const Vec3d a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]),
                            c = toD(mesh.positions[t[2]]);
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

PartitionResult partitionSurface(const TriMesh& meshMm, const zome::Structure& frame,
                                 const std::vector<zome::BallId>& labelBalls, const Fabrication& fabrication,
                                 const PartitionOptions& options, const RunContext& context) {
    const Stopwatch total;
    PartitionResult res;
    Surface surface(meshMm, labelBalls, frame.scale().b0Mm);
    checkInputs(frame, fabrication, options, surface, res);
    context.progress("partition", 0.0);
    prepareSurface(surface, options, res);
    const Problems problems = prepareProblems(surface, options, res, context);
    context.throwIfCancelled();
    FitTester fits{
        meshMm, surface.graph, fabrication, context, std::vector<uint32_t>(meshMm.positions.size(), 0), 0};
    if (options.mountBlockedShare >= 0.0) {
        // The wall's inside, where it first meets the frame: the wall's thickness behind the
        // surface, but never deeper than the frame's nearest ball comes (a frame built for a
        // thinner wall than the one asked of this stage).
        double nearestBallMm = std::numeric_limits<double>::infinity();
        for (size_t f = 0; f < surface.faceCount; ++f)
            nearestBallMm = std::min(nearestBallMm, surface.near.distancesMm[f * size_t(surface.k)]);
        const double innerMm = std::clamp(nearestBallMm - frame.scale().ballRadiusMm() - kMountMarginMm, 0.0,
                                          fabrication.wallMm);
        fits.blocked = frameBlockedDirections(meshMm, surface.graph, frame, innerMm, kMountMarginMm);
        fits.blockedShare = options.mountBlockedShare;
    }
    Classes classes;
    runSchedule(surface, problems, options, fits, classes, res, context);
    mergeRegions(surface, fits, options, classes, res, context);
    cutAndMakePieces(surface, classes, fabrication, options, fits, res, context);
    res.secondsTotal = total.seconds();
    context.progress("partition", 1.0);
    return res;
}

}  // namespace zomefab::partition
