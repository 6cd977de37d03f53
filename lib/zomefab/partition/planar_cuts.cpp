// SPDX-License-Identifier: GPL-3.0-or-later
// The planar cuts (paper §5.2): training samples, the SVM cells, salient regions crossed (docs/partition.md
// §5).
#include <algorithm>

#include "zomefab/core/vec.h"
#include "zomefab/partition/detail/stage.h"

namespace zomefab::partition::detail {

/// Training samples: face centroids. On large meshes, at most half the budget goes to the
/// faces within two rings of a class boundary (where the planes are decided) and the rest to
/// the other faces, each set thinned evenly in face order.
void trainingSamples(const Surface& S, const Classes& C, const PartitionOptions& opt,
                     std::vector<Vec3d>& samples, std::vector<uint32_t>& classes) {
    std::vector<char> keep(S.faceCount, 1);
    if (S.faceCount > opt.svmMaxSamples) {
        std::vector<char> band(S.faceCount, 0);
        for (uint32_t f = 0; f < S.faceCount; ++f)
            for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i)
                if (C.trainClass[S.graph.neighbors[i]] != C.trainClass[f]) band[f] = 1;
        std::vector<char> band2(band);
        for (uint32_t f = 0; f < S.faceCount; ++f)
            if (band[f])
                for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i)
                    band2[S.graph.neighbors[i]] = 1;
        const size_t bandCount = size_t(std::count(band2.begin(), band2.end(), char(1)));
        const size_t restCount = S.faceCount - bandCount;
        const size_t bandBudget = std::min(bandCount, opt.svmMaxSamples / 2);
        const size_t restBudget = std::max<size_t>(1, opt.svmMaxSamples - bandBudget);
        auto strideFor = [](size_t count, size_t budget) {
            return budget == 0 ? count + 1 : std::max<size_t>(1, (count + budget - 1) / budget);
        };
        const size_t bandStride = strideFor(bandCount, bandBudget),
                     restStride = strideFor(restCount, restBudget);
        size_t bi = 0, ri = 0;
        for (uint32_t f = 0; f < S.faceCount; ++f)
            keep[f] = band2[f] ? ((bi++ % bandStride) == 0) : ((ri++ % restStride) == 0);
    }
    samples.clear();
    classes.clear();
    for (uint32_t f = 0; f < S.faceCount; ++f)
        if (keep[f]) samples.push_back(S.graph.centroidsMm[f]), classes.push_back(C.trainClass[f]);
}

/// The salient regions some of whose corners lie in another cell than the others.
std::vector<uint32_t> crossedRegions(const Surface& S, const PartitionResult& res, const LinearCells& cells) {
    std::vector<uint32_t> crossed;
    for (uint32_t r = 0; r < res.salientRegions; ++r) {
        uint32_t first = kNone;
        bool isCrossed = false;
        for (uint32_t f : S.salientFacesOf[r]) {
            for (uint32_t v : S.mesh.triangles[f]) {
                const uint32_t cell = cells.cellAt(toD(S.mesh.positions[v]));
                if (first == kNone) first = cell;
                if (cell != first) isCrossed = true;
            }
            if (isCrossed) break;
        }
        if (isCrossed) crossed.push_back(r);
    }
    return crossed;
}

/// Trains the cells; retrains with the corners of crossed salient regions weighted up.
LinearCells trainCells(const Surface& S, const Classes& C, const Fabrication& fab,
                       const PartitionOptions& opt, PartitionResult& res, const RunContext& run,
                       std::vector<uint32_t>& crossed) {
    std::vector<Vec3d> samples;
    std::vector<uint32_t> classes;
    trainingSamples(S, C, opt, samples, classes);
    CellTrainingOptions so = opt.svm;
    so.seed = seedFor(fab, SeedStream::Partition);
    LinearCells cells = trainLinearCells(samples, classes, so);
    crossed = crossedRegions(S, res, cells);
    for (int retry = 0; retry < opt.salientRetries && !crossed.empty(); ++retry) {
        // Their corners as extra samples of their class, repeated 4^retry times.
        const int repeat = 1 << (2 * retry);
        for (uint32_t r : crossed)
            for (uint32_t f : S.salientFacesOf[r])
                for (uint32_t v : S.mesh.triangles[f])
                    for (int i = 0; i < repeat; ++i) {
                        samples.push_back(toD(S.mesh.positions[v]));
                        classes.push_back(C.trainClass[f]);
                    }
        run.debug("retraining: " + std::to_string(crossed.size()) + " salient region(s) crossed by a cut");
        cells = trainLinearCells(samples, classes, so);
        crossed = crossedRegions(S, res, cells);
    }
    res.svmSamples = samples.size();
    return cells;
}

}  // namespace zomefab::partition::detail
