// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Benchmark of the surface partition (paper §5): the bunny's 75k-face surface at 400 mm and
/// the same bunny subdivided to 1.2 million faces, on a B0 cube-lattice frame built in code (the
/// frame stage's stand-in, tests/partition/partition_fixtures.h). Prints faces × labels, timings
/// and piece counts; `compare` / `compare-million` also run with other graph sizes
/// (--compare-graph-nodes / --compare-refine-nodes; 0 = one level / faces) and measure how far the
/// seams move (docs/benchmarks.md, "Partition").
///
///   bench_partition [bunny|million|compare|compare-million|all] [--compare-graph-nodes G]
///                   [--compare-refine-nodes R] [--compare-w-smoothness W] [--threads N] [--k K] [--svm-cost
///                   C] [--svm-eps E]
///                   [--svm-max-samples N] [--graph-nodes N] [--refine-nodes N] [--whole-surface-schedule]
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "../tests/partition/partition_fixtures.h"
#include "zomefab/core/run_context.h"
#include "zomefab/partition/face_graph.h"
#include "zomefab/partition/partition.h"

using namespace zomefab;
using namespace zomefab::partition;

namespace {

std::string dataFile(const char* name) { return std::string(ZOMEFAB_DATA_DIR) + "/" + name; }

/// Process CPU time (all threads), seconds.
double cpuSeconds() { return double(std::clock()) / CLOCKS_PER_SEC; }

void report(const char* title, const TriMesh& mesh, const std::vector<zome::BallId>& labels,
            const PartitionResult& r, double seconds, double cpu) {
    std::printf("%s\n", title);
    std::printf(
        "  faces %zu, labels %zu (outermost balls), k-nearest candidates: %zu graph nodes x labels = %zu "
        "pairs\n",
        mesh.triangles.size(), labels.size(), r.graphNodes, r.candidatePairs);
    for (const ScheduleStep& s : r.schedule) {
        std::printf(
            "  w_smoothness %-8g faces %zu  E %.6g -> %.6g  partitions %zu  kept %zu  oversized %zu  sweeps "
            "%d  "
            "expansions %d  %.2f s\n",
            s.smoothnessWeight, s.faces, s.energyNearest, s.energyGraphCut, s.partitions, s.kept, s.oversized,
            s.sweeps, s.expansions, s.seconds);
        if (s.bandNodes > 0)
            std::printf(
                "    clusters: E %.6g after %d sweeps, %d expansions; refinement band %zu of %zu nodes\n",
                s.energyClusters, s.clusterSweeps, s.clusterExpansions, s.bandNodes, r.refineNodes);
    }
    std::printf(
        "  partitions: nearest ball %zu, graph cut %zu; cells %zu, pieces %zu (splits %zu, merges %zu)\n",
        r.nearestPartitions, r.graphCutPartitions, r.cells.cellCount(), r.pieces.size(), r.splits, r.merges);
    double worst = 0.0;
    for (const Piece& p : r.pieces) worst = std::max(worst, p.fit.ratio);
    std::printf("  svm samples %zu, agreement %.4f; largest piece fit ratio %.3f\n", r.svmSamples,
                r.svmAgreement, worst);
    std::printf(
        "  seconds: graph cut + fit schedule %.2f, svm + pieces %.2f, partitionSurface %.2f wall, %.2f CPU\n",
        r.secondsGraphCut, r.secondsSvm, seconds, cpu);
}

/// Seam faces: faces with a neighbour in another piece.
std::vector<uint32_t> seamFaces(const FaceGraph& g, const std::vector<uint32_t>& pieces) {
    std::vector<uint32_t> out;
    for (uint32_t f = 0; f < g.faceCount(); ++f)
        for (uint32_t i = g.offsets[f]; i < g.offsets[f + 1]; ++i)
            if (pieces[g.neighbors[i]] != pieces[f]) {
                out.push_back(f);
                break;
            }
    return out;
}

/// Mean and max distance from seam faces of @p a to the nearest seam face of @p b (mm), by a grid.
std::pair<double, double> seamDistance(const FaceGraph& g, const std::vector<uint32_t>& a,
                                       const std::vector<uint32_t>& b) {
    const double cell = 10.0;
    std::map<std::array<int, 3>, std::vector<uint32_t>> grid;
    auto key = [&](const Vec3d& p) {
        return std::array<int, 3>{int(std::floor(p[0] / cell)), int(std::floor(p[1] / cell)),
                                  int(std::floor(p[2] / cell))};
    };
    for (uint32_t f : b) grid[key(g.centroidsMm[f])].push_back(f);
    double sum = 0.0, worst = 0.0;
    for (uint32_t f : a) {
        const Vec3d& p = g.centroidsMm[f];
        const auto k = key(p);
        double best = 1e300;
        for (int ring = 0; ring < 40 && best > (ring - 1) * cell * std::max(0, ring - 1) * cell; ++ring)
            for (int z = -ring; z <= ring; ++z)
                for (int y = -ring; y <= ring; ++y)
                    for (int x = -ring; x <= ring; ++x) {
                        if (std::max({std::abs(x), std::abs(y), std::abs(z)}) != ring) continue;
                        auto it = grid.find({k[0] + x, k[1] + y, k[2] + z});
                        if (it == grid.end()) continue;
                        for (uint32_t h : it->second) {
                            const Vec3d& q = g.centroidsMm[h];
                            best =
                                std::min(best, (p[0] - q[0]) * (p[0] - q[0]) + (p[1] - q[1]) * (p[1] - q[1]) +
                                                   (p[2] - q[2]) * (p[2] - q[2]));
                        }
                    }
        const double d = std::sqrt(best);
        sum += d;
        worst = std::max(worst, d);
    }
    return {a.empty() ? 0.0 : sum / double(a.size()), worst};
}

}  // namespace

int main(int argc, char** argv) {
    std::string mode = "all";
    int threads = 0;
    PartitionOptions o;
    size_t compareGraphNodes = 0, compareRefineNodes = 0;
    double compareSmoothness = 0.0;
    for (int i = 1; i < argc; ++i) {
        auto is = [&](const char* flag) { return std::strcmp(argv[i], flag) == 0 && i + 1 < argc; };
        if (is("--threads"))
            threads = std::atoi(argv[++i]);
        else if (is("--k"))
            o.candidateCount = std::atoi(argv[++i]);
        else if (is("--svm-cost"))
            o.svm.cost = std::atof(argv[++i]);
        else if (is("--svm-eps"))
            o.svm.tolerance = std::atof(argv[++i]);
        else if (is("--svm-max-samples"))
            o.svmMaxSamples = size_t(std::atol(argv[++i]));
        else if (is("--compare-graph-nodes"))
            compareGraphNodes = size_t(std::atol(argv[++i]));
        else if (is("--compare-w-smoothness"))
            compareSmoothness = std::atof(argv[++i]);
        else if (is("--compare-refine-nodes"))
            compareRefineNodes = size_t(std::atol(argv[++i]));
        else if (is("--refine-nodes"))
            o.refineNodeTarget = size_t(std::atol(argv[++i]));
        else if (is("--graph-nodes"))
            o.graphNodeTarget = size_t(std::atol(argv[++i]));
        else if (std::strcmp(argv[i], "--whole-surface-schedule") == 0)
            o.refineOversizedOnly = false;  // the paper's schedule: every step re-cuts the whole surface
        else
            mode = argv[i];
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

    const test::MeshMm bunny = test::loadMeshMm(dataFile("bunny_cgal_75k.stl"), 400.0, true);
    const test::LatticeFrame frame = test::makeLatticeFrame(bunny.mesh, 12.0);
    std::printf("frame: %zu balls, %zu outermost (B0 cube lattice, balls >= 12 mm inside the surface)\n",
                frame.structure.ballCount(), frame.outermost.size());
    auto compare = [&](const char* what, const TriMesh& mesh) {
        // The default run against one with other graph sizes or another first w_smoothness.
        double cpu = cpuSeconds();
        const Stopwatch w;
        const PartitionResult r =
            partitionSurface(mesh, frame.structure, frame.outermost, Fabrication{}, o, RunContext::silent());
        report(what, mesh, frame.outermost, r, w.seconds(), cpuSeconds() - cpu);
        PartitionOptions fine = o;
        fine.graphNodeTarget = compareGraphNodes;
        fine.refineNodeTarget = compareRefineNodes;
        if (compareSmoothness > 0) fine.smoothnessStart = compareSmoothness;
        cpu = cpuSeconds();
        const Stopwatch w2;
        const PartitionResult rf = partitionSurface(mesh, frame.structure, frame.outermost, Fabrication{},
                                                    fine, RunContext::silent());
        std::printf(
            "comparison run: graph nodes %zu, refinement nodes %zu (0 = faces / one level), w_smoothness "
            "%g\n",
            fine.graphNodeTarget, fine.refineNodeTarget, fine.smoothnessStart);
        report("same, comparison run", mesh, frame.outermost, rf, w2.seconds(), cpuSeconds() - cpu);
        const FaceGraph g = buildFaceGraph(mesh);
        size_t differLabels = 0, differCells = 0;
        for (size_t f = 0; f < mesh.triangles.size(); ++f) {
            differLabels += r.graphCutLabels[f] != rf.graphCutLabels[f] ? 1 : 0;
            differCells += r.cellBalls[r.faceCells[f]] != rf.cellBalls[rf.faceCells[f]] ? 1 : 0;
        }
        const auto sa = seamFaces(g, r.facePieces), sb = seamFaces(g, rf.facePieces);
        const auto [mean1, max1] = seamDistance(g, sa, sb);
        const auto [mean2, max2] = seamDistance(g, sb, sa);
        std::printf(
            "default vs finer: graph-cut labels differ on %.2f%% of faces, final cell balls on %.2f%%; "
            "final seams: default -> finer mean %.2f mm max %.2f mm, finer -> default mean %.2f mm max %.2f "
            "mm\n",
            100.0 * double(differLabels) / double(mesh.triangles.size()),
            100.0 * double(differCells) / double(mesh.triangles.size()), mean1, max1, mean2, max2);
    };
    if (mode == "bunny" || mode == "all") {
        const double cpu = cpuSeconds();
        const Stopwatch w;
        const PartitionResult r = partitionSurface(bunny.mesh, frame.structure, frame.outermost,
                                                   Fabrication{}, o, RunContext::silent());
        report("bunny_cgal_75k at 400 mm, printer 200 mm^3", bunny.mesh, frame.outermost, r, w.seconds(),
               cpuSeconds() - cpu);
    }
    if (mode == "compare") compare("bunny_cgal_75k at 400 mm, printer 200 mm^3", bunny.mesh);
    if (mode == "million" || mode == "compare-million" || mode == "all") {
        const TriMesh fine = test::subdivide(bunny.mesh, 2);
        if (mode == "compare-million") {
            compare("bunny_cgal_75k subdivided twice (1-to-4 midpoint), 400 mm", fine);
        } else {
            const double cpu = cpuSeconds();
            const Stopwatch w;
            const PartitionResult r = partitionSurface(fine, frame.structure, frame.outermost, Fabrication{},
                                                       o, RunContext::silent());
            report("bunny_cgal_75k subdivided twice (1-to-4 midpoint), 400 mm", fine, frame.outermost, r,
                   w.seconds(), cpuSeconds() - cpu);
        }
    }
    return 0;
}
