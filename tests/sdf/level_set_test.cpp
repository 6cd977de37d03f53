// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/sdf/level_set.h"

#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <atomic>
#include <cmath>
#include <limits>

#include "mesh_distance.h"
#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/scale.h"
#include "zomefab/sdf/vdb_file.h"

using namespace zomefab;
using namespace zomefab::sdf;

namespace {

double radius(const Vec3f& p, const Vec3d& c) {
    return std::sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                     (p[2] - c[2]) * (p[2] - c[2]));
}

/// Distance from @p p to the boundary of the box [lo, hi] (unsigned).
double boxSurfaceDistance(const Vec3f& p, const Vec3d& lo, const Vec3d& hi) {
    double outside2 = 0, inside = 1e300;
    for (int a = 0; a < 3; ++a) {
        const double d = std::max(lo[a] - p[a], p[a] - hi[a]);
        if (d > 0) outside2 += d * d;
        inside = std::min(inside, -d);
    }
    return outside2 > 0 ? std::sqrt(outside2) : inside;
}

}  // namespace

TEST_CASE("level_set: sphere volume within 1% and surface within half a voxel") {
    const Vec3d c{3.3, -2.1, 41.7};
    const double r = 40.0;
    // Fine enough that the polygon's chord error (r·(1 − cos(π/128)) = 0.012 mm) is negligible.
    const TriMesh sphere = test::makeSphere(c, r, 128, 256);
    MeshToLevelSetOptions options;  // default voxel: 1 mm
    const LevelSet ls = meshToLevelSet(sphere, options, RunContext::silent());
    const double voxel = ls.info().voxelMm;
    CHECK(voxel == 1.0);
    CHECK(ls.info().name == "object");

    // φ is the signed distance within the band.
    for (const Vec3d& p : {Vec3d{c[0] + r - 1.5, c[1], c[2]}, Vec3d{c[0], c[1] + r + 2.2, c[2]},
                           Vec3d{c[0] + 0.5, c[1] - 0.3, c[2] - r + 0.7}}) {
        const double analytic = std::sqrt((p[0] - c[0]) * (p[0] - c[0]) + (p[1] - c[1]) * (p[1] - c[1]) +
                                          (p[2] - c[2]) * (p[2] - c[2])) -
                                r;
        CHECK(std::abs(ls.valueMm(p) - analytic) < 0.1);
    }
    const double analyticVolume = 4.0 / 3.0 * kPi * r * r * r;
    CHECK(std::abs(ls.insideVolumeMm3() / analyticVolume - 1) < 0.01);

    const TriMesh mesh = levelSetToMesh(ls, {}, RunContext::silent());
    CHECK(std::abs(signedVolume(mesh) / analyticVolume - 1) < 0.01);
    double worst = 0;
    for (const Vec3f& p : mesh.positions) worst = std::max(worst, std::abs(radius(p, c) - r));
    CHECK(worst < 0.5 * voxel);
}

TEST_CASE("level_set: box volume within 1% and surface within half a voxel") {
    // Off the voxel lattice on purpose: faces at fractional voxel positions.
    const Vec3d lo{-30.3, -20.45, 0.2}, hi{29.9, 19.65, 30.55};
    const TriMesh box = test::makeBox(lo, hi);
    const LevelSet ls = meshToLevelSet(box, {}, RunContext::silent());
    const double analyticVolume = (hi[0] - lo[0]) * (hi[1] - lo[1]) * (hi[2] - lo[2]);
    const TriMesh mesh = levelSetToMesh(ls, {}, RunContext::silent());
    CHECK(std::abs(signedVolume(mesh) / analyticVolume - 1) < 0.01);
    double worst = 0;
    for (const Vec3f& p : mesh.positions) worst = std::max(worst, boxSurfaceDistance(p, lo, hi));
    CHECK(worst < 0.5 * ls.info().voxelMm);
}

TEST_CASE("level_set: meshing gives a closed, outward, consistently oriented surface") {
    const TriMesh sphere = test::makeSphere({0, 0, 0}, 20.0, 48, 96);
    MeshToLevelSetOptions options;
    options.voxelMm = 0.5;
    const LevelSet ls = meshToLevelSet(sphere, options, RunContext::silent());
    for (double adaptivity : {0.0, 0.5}) {
        CAPTURE(adaptivity);
        LevelSetToMeshOptions meshing;
        meshing.adaptivity = adaptivity;
        const TriMesh mesh = levelSetToMesh(ls, meshing, RunContext::silent());
        const test::EdgeReport edges = test::edgeReport(mesh);
        CHECK(edges.boundaryEdges == 0);
        CHECK(edges.nonManifoldEdges == 0);
        CHECK(edges.misorientedEdges == 0);
        CHECK(edges.components == 1);
        CHECK(signedVolume(mesh) > 0);
    }
    LevelSetToMeshOptions adaptive;
    adaptive.adaptivity = 0.5;
    CHECK(levelSetToMesh(ls, adaptive, RunContext::silent()).triangleCount() <
          levelSetToMesh(ls, {}, RunContext::silent()).triangleCount());
}

TEST_CASE("level_set: an inset iso-surface lies that far inside") {
    const Vec3d c{0, 0, 0};
    const TriMesh sphere = test::makeSphere(c, 30.0, 96, 192);
    MeshToLevelSetOptions options;
    options.interiorBandMm = 5;
    const LevelSet ls = meshToLevelSet(sphere, options, RunContext::silent());
    LevelSetToMeshOptions meshing;
    meshing.isoMm = -4.0;
    const TriMesh mesh = levelSetToMesh(ls, meshing, RunContext::silent());
    double worst = 0;
    for (const Vec3f& p : mesh.positions) worst = std::max(worst, std::abs(radius(p, c) - 26.0));
    CHECK(worst < 0.5);
    meshing.isoMm = -20.0;  // beyond the 5 mm band (+ half width)
    CHECK(test::errorCodeOf([&] { levelSetToMesh(ls, meshing, RunContext::silent()); }) == ErrorCode::Usage);
    meshing.isoMm = 0;
    meshing.adaptivity = 1.5;
    CHECK(test::errorCodeOf([&] { levelSetToMesh(ls, meshing, RunContext::silent()); }) == ErrorCode::Usage);
}

TEST_CASE("level_set: the whole interior band holds exact depths") {
    const Vec3d c{0, 0, 0};
    const TriMesh sphere = test::makeSphere(c, 25.0, 96, 192);
    MeshToLevelSetOptions options;
    options.voxelMm = 2.0;
    options.interiorBandMm = std::numeric_limits<double>::infinity();
    const LevelSet ls = meshToLevelSet(sphere, options, RunContext::silent());
    CHECK(std::abs(ls.valueMm({0, 0, 0}) + 25.0) < 0.2);
    CHECK(std::abs(ls.valueMm({6, 4, -2}) - (std::sqrt(56.0) - 25.0)) < 0.2);
}

TEST_CASE("level_set: open inputs fail instead of giving garbage") {
    SUBCASE("a box without its top face has no inside") {
        TriMesh box = test::makeBox({0, 0, 0}, {40, 30, 20});
        box.triangles.erase(box.triangles.begin() + 2, box.triangles.begin() + 4);
        try {
            meshToLevelSet(box, {}, RunContext::silent());
            FAIL("no error");
        } catch (const Error& e) {
            CHECK(e.code() == ErrorCode::ProcessingFailed);
            CHECK(std::string(e.what()).find("not closed") != std::string::npos);
        }
    }
    SUBCASE("the open Stanford scan") {
        // The scan has five holes (data/README.md); its inside leaks out.
        const std::string path = test::dataPath("bunny_stanford_open_69k.stl");
        mesh::ScaleOptions scale;
        scale.heightMm = 120.0;
        scale.up = mesh::UpAxis::Y;
        const TriMesh mesh = mesh::scaleToMillimetres(readMesh(path), scale).mesh;
        CHECK(test::errorCodeOf([&] { meshToLevelSet(mesh, {}, RunContext::silent()); }) ==
              ErrorCode::ProcessingFailed);
    }
}

TEST_CASE("level_set: bad options and inputs give the documented error codes") {
    const TriMesh box = test::makeBox({0, 0, 0}, {10, 10, 10});
    MeshToLevelSetOptions options;
    options.voxelMm = 0;
    CHECK(test::errorCodeOf([&] { meshToLevelSet(box, options, RunContext::silent()); }) == ErrorCode::Usage);
    options.voxelMm = std::nan("");
    CHECK(test::errorCodeOf([&] { meshToLevelSet(box, options, RunContext::silent()); }) == ErrorCode::Usage);
    options.voxelMm = 1e-5;  // would need ~10^14 voxels
    CHECK(test::errorCodeOf([&] { meshToLevelSet(box, options, RunContext::silent()); }) == ErrorCode::Usage);
    CHECK(test::errorCodeOf([&] { meshToLevelSet(TriMesh{}, {}, RunContext::silent()); }) ==
          ErrorCode::InvalidInput);
    TriMesh broken = box;
    broken.triangles[3][1] = 99;
    CHECK(test::errorCodeOf([&] { meshToLevelSet(broken, {}, RunContext::silent()); }) ==
          ErrorCode::InvalidInput);
    broken = box;
    broken.positions[2][0] = std::numeric_limits<float>::infinity();
    CHECK(test::errorCodeOf([&] { meshToLevelSet(broken, {}, RunContext::silent()); }) ==
          ErrorCode::InvalidInput);
}

TEST_CASE("level_set: a cancelled context stops the conversion with Cancelled") {
    std::atomic<bool> cancel{true};
    RunContext context({}, {}, &cancel);
    const TriMesh sphere = test::makeSphere({0, 0, 0}, 30.0);
    CHECK(test::errorCodeOf([&] { meshToLevelSet(sphere, {}, context); }) == ErrorCode::Cancelled);
}

TEST_CASE("level_set: the same input gives the same grid bytes with 1 or 2 threads") {
    const TriMesh sphere = test::makeSphere({1, 2, 3}, 25.0);
    std::string one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = serializeVdb({meshToLevelSet(sphere, {}, RunContext::silent())});
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = serializeVdb({meshToLevelSet(sphere, {}, RunContext::silent())});
    }
    CHECK(one.size() > 1000);
    CHECK(one == two);
}

TEST_CASE("estimateRunBytes: the object band and interior grid as built, within a factor of two") {
    // A 100 mm sphere: the estimate comes from its area and volume before any grid exists.
    const TriMesh sphere = test::makeSphere({0, 0, 0}, 50.0, 48, 96);
    Fabrication fabrication;
    ObjectFieldOptions options;
    options.voxelMm = 1.5;
    options.fieldVoxelMm = 3.0;
    const MemoryEstimate e = estimateRunBytes(sphere, fabrication, options);
    const ObjectField field = makeObjectField(sphere, fabrication, options, RunContext::silent());
    const double object = double(field.object.activeVoxelCount()),
                 interior = double(field.interior.activeVoxelCount());
    CHECK(e.objectVoxels > 0.5 * object);
    CHECK(e.objectVoxels < 2.0 * object);
    CHECK(e.interiorVoxels > 0.5 * interior);
    CHECK(e.interiorVoxels < 2.0 * interior);
    CHECK(e.bytes == doctest::Approx(40.0 * (e.objectVoxels + e.interiorVoxels)));
    // Over the budget: refused before anything is built, naming the options that lower it.
    options.maxMemoryGb = e.bytes / 2e9;
    try {
        makeObjectField(sphere, fabrication, options, RunContext::silent());
        FAIL("no error");
    } catch (const Error& err) {
        CHECK(err.code() == ErrorCode::ProcessingFailed);
        CHECK(std::string(err.what()).find("--voxel-mm") != std::string::npos);
    }
    CHECK(memoryBudgetBytes(2.5) == doctest::Approx(2.5e9));
    CHECK(memoryBudgetBytes(0) > 1e8);  // a share of this machine's memory
}
