// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Timings and energies of the frame stage (docs/benchmarks.md, "Frame"): the lattice search,
/// τ, one chain of the paper's schedule, and parallel chains of a slower schedule with 1 and 2
/// threads (speed-up, proposed moves per second per core, energies), plus the parts list.
///
/// Usage: bench_frame OBJECT.vdb [chains, default 8] [cooling interval of the parallel run,
///        default 1000] [seed, default 1]
/// OBJECT.vdb comes from zf-sdf, e.g. `zf-sdf data/bunny_cgal_75k.stl --height-mm 400 --up y -o bunny400.vdb`.
#include <tbb/global_control.h>

#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/frame/frame.h"
#include "zomefab/io/file_io.h"
#include "zomefab/sdf/vdb_file.h"
#include "zomefab/zome/parts.h"

using namespace zomefab;

namespace {

struct Run {
    std::vector<frame::ChainResult> chains;
    size_t best = 0;
    double wallSeconds = 0;
    uint64_t iterations = 0;
    double cpuSeconds = 0;  ///< summed over the chains' threads
};

Run runChains(const frame::LatticeResult& lattice, const frame::FrameField& field,
              const frame::EnergyOptions& energy, const frame::AnnealOptions& anneal, int chains,
              uint64_t seed, int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
    Run run;
    const Stopwatch clock;
    run.chains = frame::annealChains(lattice.structure, field, energy, anneal, chains, seed, RunContext::silent());
    run.wallSeconds = clock.seconds();
    run.best = frame::bestChain(run.chains);
    for (const frame::ChainResult& c : run.chains) {
        run.iterations += c.stats.iterations;
        run.cpuSeconds += c.stats.cpuSeconds;
    }
    return run;
}

void printEnergy(const char* label, const frame::EnergyTerms& e) {
    std::printf("%-34s E %9.4f  (fid %.4f, reg %.4f, val %.4f, sim %.4f; %zu balls, %zu struts)\n", label,
                e.total, e.fidelity, e.regularity, e.valence, e.simplicity, e.balls, e.struts);
}

}  // namespace

int main(int argc, char** argv) {
    if (argc < 2) {
        std::fprintf(stderr, "usage: bench_frame OBJECT.vdb [chains] [cooling interval] [seed]\n");
        return 1;
    }
    const std::string path = argv[1];
    const int chains = argc > 2 ? std::atoi(argv[2]) : 8;
    const uint64_t interval = argc > 3 ? std::strtoull(argv[3], nullptr, 10) : 1000;
    const uint64_t seed = argc > 4 ? std::strtoull(argv[4], nullptr, 10) : 1;
    try {
        RunContext& ctx = RunContext::silent();
        const std::vector<sdf::LevelSet> grids = sdf::parseVdb(readInputBytes(path), path, ctx);
        const sdf::InteriorField field = sdf::makeInteriorField(sdf::findLevelSet(grids, "interior", path), ctx);

        frame::LatticeOptions latticeOptions;
        Stopwatch clock;
        const frame::LatticeResult lattice = frame::initialLattice(field, latticeOptions, ctx);
        const double latticeSeconds = clock.seconds();
        frame::LatticeOptions rotated = latticeOptions;
        rotated.searchRotation = true;
        clock = Stopwatch();
        const frame::LatticeResult withRotation = frame::initialLattice(field, rotated, ctx);
        const double rotationSeconds = clock.seconds();
        std::printf("lattice: %zu cubes (first placement %zu) over %zu offsets in %.3f s; with rotation search "
                    "%zu cubes at %.1f deg over %zu placements in %.3f s\n",
                    lattice.cubes, lattice.firstPlacementCubes, lattice.placementsTried, latticeSeconds,
                    withRotation.cubes, withRotation.rotationDeg, withRotation.placementsTried, rotationSeconds);

        const frame::FrameField ff(field, lattice.rotationDeg, lattice.structure.scale(), latticeOptions.zone);
        clock = Stopwatch();
        const frame::TargetCountResult target = frame::estimateTargetCount(lattice.structure, ff, {}, seed, ctx);
        std::printf("tau: %.1f from %zu runs in %.3f s (initial coverage %.3f)\n", target.targetItemCount,
                    target.runItems.size(), clock.seconds(), target.initialCoverage);
        frame::EnergyOptions energy;
        energy.targetItemCount = target.targetItemCount;
        printEnergy("initial lattice", frame::frameEnergy(lattice.structure, ff, energy));

        // One chain of the paper's schedule (T 1 -> 1e-3, x0.99 every 100 iterations), one thread.
        frame::AnnealOptions paper;
        const Run single = runChains(lattice, ff, energy, paper, 1, seed, 1);
        printEnergy("single chain, paper schedule", single.chains[0].energy);
        std::printf("  %llu iterations in %.3f s wall, %.3f s CPU: %.0f proposed moves per CPU second\n",
                    (unsigned long long)single.iterations, single.wallSeconds, single.cpuSeconds,
                    double(single.iterations) / single.cpuSeconds);

        // Parallel chains of a slower schedule, with 2 threads and with 1.
        frame::AnnealOptions slow = paper;
        slow.coolingIntervalIterations = interval;
        const Run one = runChains(lattice, ff, energy, slow, chains, seed, 1);
        const Run two = runChains(lattice, ff, energy, slow, chains, seed, 2);
        char label[96];
        std::snprintf(label, sizeof label, "%d chains, x0.99 every %llu, best", chains, (unsigned long long)interval);
        printEnergy(label, two.chains[two.best].energy);
        std::printf("  best chain %zu; %llu iterations: 2 threads %.3f s (%.0f moves/s per core), 1 thread %.3f s "
                    "(%.0f moves/s); speed-up %.2f; same best energy: %s\n",
                    two.best, (unsigned long long)two.iterations, two.wallSeconds,
                    double(two.iterations) / two.wallSeconds / 2.0, one.wallSeconds,
                    double(one.iterations) / one.wallSeconds, one.wallSeconds / two.wallSeconds,
                    one.chains[one.best].energy.total == two.chains[two.best].energy.total ? "yes" : "NO");
        uint64_t feasible = 0;
        for (const frame::ChainResult& c : two.chains) feasible += c.stats.feasible;
        std::printf("  proposed moves per CPU second (chain threads): %.0f with 2 threads, %.0f with 1\n",
                    double(two.iterations) / two.cpuSeconds, double(one.iterations) / one.cpuSeconds);
        std::printf("  feasible proposals (dE evaluated): %.1f%% of the proposed moves\n",
                    100.0 * double(feasible) / double(two.iterations));

        const zome::Structure best = two.chains[two.best].structure.compacted();
        const frame::FrameMetrics m = frame::measureFrame(best, ff, 6.0);
        std::printf("parts of the best frame:\n%s", zome::partsTable(m.parts).c_str());
        std::printf("outermost clearance %.1f..%.1f mm, min clearance %.1f mm, largest gap %.1f mm "
                    "(reachable %.1f mm), coverage %.3f\n",
                    m.outermostClearanceMinMm, m.outermostClearanceMaxMm, m.minClearanceMm, m.largestGapMm,
                    m.largestReachableGapMm, m.coverage);
        std::printf("paper Table 2, bunny: B0 215, Y0 266, 481 struts, 126 balls\n");
    } catch (const Error& e) {
        std::fprintf(stderr, "bench_frame: %s\n", e.what());
        return 1;
    }
    return 0;
}
