// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Level-set benchmark (docs/benchmarks.md, "Level sets"; docs/sdf.md).
///
///   bench_sdf MESH --height-mm H [--up y] [--voxel-mm V] [--shell-mm T] [--field-voxel-mm F]
///       one run of the zf-sdf | zf-shell | zf-mesh steps in process: seconds per step, active
///       voxels, peak RSS (run one size per process: the peak only grows), interior-field query ns.
///   bench_sdf MESH --height-mm H [--up y] --accuracy
///       round-trip Hausdorff (95th percentile and max) for several voxel sizes, and the interior
///       field's depth and closest-point errors for several field voxels, against the exact
///       distance to the input triangles (--field-accuracy: only the interior field part).
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "mesh_distance.h"
#include "zomefab/core/error.h"
#include "zomefab/core/run_context.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/mesh/scale.h"
#include "zomefab/sdf/interior_field.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/sdf/vdb_file.h"

using namespace zomefab;

namespace {

struct Args {
    std::string mesh;
    double heightMm = 400;
    bool isYUp = false;
    double voxelMm = sdf::ObjectFieldOptions().voxelMm;
    double shellMm = Fabrication().wallMm;
    double fieldVoxelMm = sdf::ObjectFieldOptions().fieldVoxelMm;
    bool isAccuracy = false;
    bool isFieldOnly = false;  ///< --accuracy without the round trip
};

Args parse(int argc, char** argv) {
    Args a;
    for (int i = 1; i < argc; ++i) {
        const std::string s = argv[i];
        auto next = [&]() -> double {
            if (i + 1 >= argc) throw Error(ErrorCode::Usage, s + " needs a value");
            return std::atof(argv[++i]);
        };
        if (s == "--height-mm")
            a.heightMm = next();
        else if (s == "--voxel-mm")
            a.voxelMm = next();
        else if (s == "--shell-mm")
            a.shellMm = next();
        else if (s == "--field-voxel-mm")
            a.fieldVoxelMm = next();
        else if (s == "--up" && i + 1 < argc)
            a.isYUp = std::string(argv[++i]) == "y";
        else if (s == "--accuracy")
            a.isAccuracy = true;
        else if (s == "--field-accuracy")
            a.isAccuracy = a.isFieldOnly = true;
        else if (!s.empty() && s[0] != '-')
            a.mesh = s;
        else
            throw Error(ErrorCode::Usage, "unknown argument " + s);
    }
    if (a.mesh.empty())
        throw Error(ErrorCode::Usage, "usage: bench_sdf MESH --height-mm H [--up y] [--accuracy]");
    return a;
}

double megabytes(size_t bytes) { return double(bytes) / (1024.0 * 1024.0); }

/// CPU seconds of this process (all threads) or of the calling thread: unlike wall time, barely
/// affected when other jobs share the machine, so runs on a busy machine stay comparable.
double cpuSeconds(clockid_t clock = CLOCK_PROCESS_CPUTIME_ID) {
    timespec t{};
    clock_gettime(clock, &t);
    return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// Wall and CPU time of one step.
struct StepClock {
    Stopwatch wall;
    double cpu0 = cpuSeconds();
    double cpu() const { return cpuSeconds() - cpu0; }
};

/// Points inside the object at depths spread over [0, maxDepth], by rejection sampling in the box.
std::vector<Vec3d> interiorPoints(const sdf::InteriorField& field, size_t count, uint32_t seed) {
    const Box3d box = field.boundsMm();
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<Vec3d> points;
    while (points.size() < count) {
        const Vec3d p{box.min[0] + u(rng) * (box.max[0] - box.min[0]),
                      box.min[1] + u(rng) * (box.max[1] - box.min[1]),
                      box.min[2] + u(rng) * (box.max[2] - box.min[2])};
        if (field.isInside(p)) points.push_back(p);
    }
    return points;
}

void runSteps(const Args& args) {
    RunContext& context = RunContext::silent();
    const StepClock total;
    StepClock clock;
    mesh::ScaleOptions scale;
    scale.heightMm = args.heightMm;
    scale.up = args.isYUp ? mesh::UpAxis::Y : mesh::UpAxis::Z;
    const mesh::ScaledMesh scaled = mesh::scaleToMillimetres(
        mesh::validateClosedMesh(readMesh(args.mesh), {}, args.mesh, context), scale);
    const double readSeconds = clock.wall.seconds(), readCpu = clock.cpu();

    sdf::ObjectFieldOptions objectOptions;
    objectOptions.voxelMm = args.voxelMm;
    objectOptions.fieldVoxelMm = args.fieldVoxelMm;
    clock = StepClock();
    sdf::MeshToLevelSetOptions objectLevelSet;
    objectLevelSet.voxelMm = objectOptions.voxelMm;
    objectLevelSet.interiorBandMm = args.shellMm;
    const sdf::LevelSet object = sdf::meshToLevelSet(scaled.mesh, objectLevelSet, context);
    const double objectSeconds = clock.wall.seconds(), objectCpu = clock.cpu();

    clock = StepClock();
    sdf::MeshToLevelSetOptions interiorLevelSet;
    interiorLevelSet.voxelMm = objectOptions.fieldVoxelMm;
    interiorLevelSet.interiorBandMm = std::numeric_limits<double>::infinity();
    interiorLevelSet.exteriorBandMm = objectOptions.fieldExteriorMm;
    interiorLevelSet.name = "interior";
    const sdf::LevelSet interior = sdf::meshToLevelSet(scaled.mesh, interiorLevelSet, context);
    const double interiorSeconds = clock.wall.seconds(), interiorCpu = clock.cpu();

    clock = StepClock();
    const std::string objectBytes = sdf::serializeVdb({object, interior});
    const double writeSeconds = clock.wall.seconds(), writeCpu = clock.cpu();

    clock = StepClock();
    Fabrication fabrication;
    fabrication.wallMm = args.shellMm;
    const sdf::LevelSet shell = sdf::makeShell(object, fabrication, context);
    const double shellSeconds = clock.wall.seconds(), shellCpu = clock.cpu();

    clock = StepClock();
    const TriMesh shellMesh = sdf::levelSetToMesh(shell, {}, context);
    const double meshSeconds = clock.wall.seconds(), meshCpu = clock.cpu();
    const double pipelineSeconds = total.wall.seconds(), pipelineCpu = total.cpu();

    clock = StepClock();
    const sdf::InteriorField field = sdf::makeInteriorField(interior, context);
    const double fieldSeconds = clock.wall.seconds(), fieldCpu = clock.cpu();

    // Query cost, one thread, random points inside (the annealing's outermost nodes are inside).
    const std::vector<Vec3d> points = interiorPoints(field, 1 << 16, 9);
    const int rounds = 64;
    double sink = 0;
    double t0 = cpuSeconds(CLOCK_THREAD_CPUTIME_ID);
    for (int r = 0; r < rounds; ++r)
        for (const Vec3d& p : points) sink += field.signedDistanceMm(p);
    const double distanceNs =
        (cpuSeconds(CLOCK_THREAD_CPUTIME_ID) - t0) * 1e9 / (double(rounds) * double(points.size()));
    t0 = cpuSeconds(CLOCK_THREAD_CPUTIME_ID);
    for (int r = 0; r < rounds / 8; ++r)
        for (const Vec3d& p : points) sink += field.closestSurfacePointMm(p)[0];
    const double closestNs =
        (cpuSeconds(CLOCK_THREAD_CPUTIME_ID) - t0) * 1e9 / (double(rounds / 8) * double(points.size()));
    const double forbiddenSample = sdf::forbiddenZone(field.depthMm(points[0]));

    char load[64] = "?";
    if (FILE* f = std::fopen("/proc/loadavg", "r")) {
        if (!std::fgets(load, sizeof(load), f)) load[0] = 0;
        std::fclose(f);
    }
    std::printf("mesh %s at %.0f mm (%.1f x %.1f x %.1f mm), %zu triangles; load average %s",
                args.mesh.c_str(), args.heightMm, scaled.sizeMm[0], scaled.sizeMm[1], scaled.sizeMm[2],
                scaled.mesh.triangleCount(), load);
    std::printf("step                          wall s   CPU s\n");
    std::printf("read+validate+scale          %6.2f  %6.2f\n", readSeconds, readCpu);
    std::printf("object (%g mm, %g mm deep)   %6.2f  %6.2f  %10zu active voxels  %7.1f MB\n",
                object.info().voxelMm, args.shellMm, objectSeconds, objectCpu, object.activeVoxelCount(),
                megabytes(object.memoryBytes()));
    std::printf("interior (%g mm, whole)      %6.2f  %6.2f  %10zu active voxels  %7.1f MB\n",
                interior.info().voxelMm, interiorSeconds, interiorCpu, interior.activeVoxelCount(),
                megabytes(interior.memoryBytes()));
    std::printf("serialize object.vdb         %6.2f  %6.2f  %7.1f MB\n", writeSeconds, writeCpu,
                megabytes(objectBytes.size()));
    std::printf("shell (%g mm)                %6.2f  %6.2f  %10zu active voxels\n", args.shellMm,
                shellSeconds, shellCpu, shell.activeVoxelCount());
    std::printf("shell mesh                   %6.2f  %6.2f  %10zu triangles\n", meshSeconds, meshCpu,
                shellMesh.triangleCount());
    std::printf("mesh -> shell mesh total     %6.2f  %6.2f  (in process, incl. the interior grid)\n",
                pipelineSeconds, pipelineCpu);
    std::printf("interior field (dense)       %6.2f  %6.2f  %7.1f MB\n", fieldSeconds, fieldCpu,
                megabytes(field.memoryBytes()));
    std::printf(
        "query (thread CPU): signedDistanceMm %.1f ns, closestSurfacePointMm %.1f ns (F(p0) = %.1f, sink "
        "%g)\n",
        distanceNs, closestNs, forbiddenSample, sink > 0 ? 1.0 : 0.0);
    std::printf("peak RSS %.0f MB\n", megabytes(peakRssBytes()));
    std::printf(
        "| %.0f mm | %zu | %zu | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.2f / %.2f | %.1f "
        "/ %.1f | %.0f / %.0f | %.0f |\n",
        args.heightMm, object.activeVoxelCount(), interior.activeVoxelCount(), readSeconds, readCpu,
        objectSeconds, objectCpu, interiorSeconds, interiorCpu, writeSeconds + shellSeconds,
        writeCpu + shellCpu, meshSeconds, meshCpu, pipelineSeconds, pipelineCpu, distanceNs, closestNs,
        megabytes(peakRssBytes()));
}

void runAccuracy(const Args& args) {
    RunContext& context = RunContext::silent();
    mesh::ScaleOptions scale;
    scale.heightMm = args.heightMm;
    scale.up = args.isYUp ? mesh::UpAxis::Y : mesh::UpAxis::Z;
    const TriMesh input =
        mesh::scaleToMillimetres(mesh::validateClosedMesh(readMesh(args.mesh), {}, args.mesh, context), scale)
            .mesh;
    const test::MeshDistance toInput(input);
    const std::vector<Vec3d> inputSamples = test::sampleSurface(input, 20000, 1);

    std::printf("round trip mesh -> level set -> mesh, %s at %.0f mm (20000 samples each way)\n",
                args.mesh.c_str(), args.heightMm);
    std::printf(
        "| voxel mm | seconds | triangles | Hausdorff 95%% mm | 99%% mm | max mm "
        "|\n|---|---:|---:|---:|---:|---:|\n");
    for (double voxel : {0.5, 1.0, 1.5, 2.0, 3.0}) {
        if (args.isFieldOnly) break;
        Stopwatch clock;
        sdf::MeshToLevelSetOptions options;
        options.voxelMm = voxel;
        const TriMesh back = sdf::levelSetToMesh(sdf::meshToLevelSet(input, options, context), {}, context);
        const double seconds = clock.seconds();
        const test::MeshDistance toBack(back);
        std::vector<double> d = test::distancesTo(toBack, inputSamples);
        const std::vector<double> d2 = test::distancesTo(toInput, test::sampleSurface(back, 20000, 2));
        d.insert(d.end(), d2.begin(), d2.end());
        std::printf("| %.1f | %.2f | %zu | %.3f | %.3f | %.3f |\n", voxel, seconds, back.triangleCount(),
                    test::quantile(d, 0.95), test::quantile(d, 0.99), test::quantile(d, 1.0));
        std::fflush(stdout);
    }

    std::printf("\ninterior field vs exact distance to the input triangles (20000 inside points)\n");
    std::printf(
        "| field voxel mm | build s | MB | depth err 95%% mm | 99.9%% mm | max mm (at depth) | δ(p) off "
        "surface 95%% mm | ||p−δ(p)|| − depth 95%% mm |\n");
    std::printf("|---|---:|---:|---:|---:|---:|---:|---:|\n");
    for (double voxel : {1.0, 2.0, 3.0}) {
        Stopwatch clock;
        sdf::MeshToLevelSetOptions options;
        options.voxelMm = voxel;
        options.interiorBandMm = std::numeric_limits<double>::infinity();
        options.exteriorBandMm = 10.0;
        const sdf::InteriorField field =
            sdf::makeInteriorField(sdf::meshToLevelSet(input, options, context), context);
        const double seconds = clock.seconds();
        std::vector<double> depthErrors, offSurface, lengthErrors;
        double worst = -1, worstDepth = 0;
        for (const Vec3d& p : interiorPoints(field, 20000, 4)) {
            const double exact = toInput.distance(p);
            const double error = std::abs(field.depthMm(p) - exact);
            depthErrors.push_back(error);
            if (error > worst) worst = error, worstDepth = exact;
            // δ(p) is judged by what the energy uses: it must lie on the surface and as far from p
            // as the nearest surface point (near the medial axis several points qualify).
            const Vec3d q = field.closestSurfacePointMm(p);
            offSurface.push_back(toInput.distance(q));
            const double length = std::sqrt((q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                                            (q[2] - p[2]) * (q[2] - p[2]));
            lengthErrors.push_back(std::abs(length - exact));
        }
        std::printf("| %.0f | %.2f | %.0f | %.3f | %.3f | %.2f (%.1f) | %.3f | %.3f |\n", voxel, seconds,
                    megabytes(field.memoryBytes()), test::quantile(depthErrors, 0.95),
                    test::quantile(depthErrors, 0.999), worst, worstDepth, test::quantile(offSurface, 0.95),
                    test::quantile(lengthErrors, 0.95));
        std::fflush(stdout);
    }
}

}  // namespace

int main(int argc, char** argv) {
    try {
        const Args args = parse(argc, argv);
        if (args.isAccuracy)
            runAccuracy(args);
        else
            runSteps(args);
        return 0;
    } catch (const Error& e) {
        std::fprintf(stderr, "bench_sdf: error: %s\n", e.what());
        return exitCodeFor(e.code());
    }
}
