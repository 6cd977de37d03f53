// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include <cmath>

#include "mesh_distance.h"
#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/scale.h"
#include "zomefab/sdf/level_set.h"

using namespace zomefab;
using namespace zomefab::sdf;

namespace {

TriMesh bunnyMm(const std::string& file, double heightMm) {
    mesh::ScaleOptions scale;
    scale.heightMm = heightMm;
    scale.up = mesh::UpAxis::Y;
    return mesh::scaleToMillimetres(readMesh(test::dataPath(file)), scale).mesh;
}

/// The shell mesh's components, outer (largest volume) first.
struct ShellParts {
    TriMesh outer, inner;
    test::EdgeReport edges;
};

ShellParts splitShell(const TriMesh& shell) {
    ShellParts parts;
    parts.edges = test::edgeReport(shell);
    double best = -1e300;
    uint32_t outerId = 0;
    for (uint32_t c = 0; c < parts.edges.components; ++c) {
        const double v = signedVolume(test::extractComponent(shell, parts.edges, c));
        if (v > best) best = v, outerId = c;
    }
    parts.outer = test::extractComponent(shell, parts.edges, outerId);
    parts.inner.positions = shell.positions;
    for (size_t f = 0; f < shell.triangles.size(); ++f)
        if (parts.edges.componentOfTriangle[f] != outerId)
            parts.inner.triangles.push_back(shell.triangles[f]);
    return parts;
}

}  // namespace

TEST_CASE("shell: a sphere's shell is two closed walls shellMm apart") {
    const Vec3d c{0.4, -0.7, 40.2};
    const double r = 40.0;
    const TriMesh sphere = test::makeSphere(c, r, 96, 192);
    MeshToLevelSetOptions options;
    options.interiorBandMm = 16.0;
    const LevelSet object = meshToLevelSet(sphere, options, RunContext::silent());
    const LevelSet shell = makeShell(object, Fabrication{}, RunContext::silent());  // default: 16 mm
    CHECK(shell.info().name == "shell");
    CHECK(shell.info().shellMm == 16.0);
    const double voxel = shell.info().voxelMm;

    const TriMesh mesh = levelSetToMesh(shell, {}, RunContext::silent());
    const ShellParts parts = splitShell(mesh);
    CHECK(parts.edges.components == 2);
    CHECK(parts.edges.boundaryEdges == 0);
    CHECK(parts.edges.nonManifoldEdges == 0);
    CHECK(parts.edges.misorientedEdges == 0);
    // The outer wall faces out, the inner wall faces the cavity (negative volume).
    const double ri = r - 16.0;
    CHECK(std::abs(signedVolume(parts.outer) / (4.0 / 3.0 * kPi * r * r * r) - 1) < 0.01);
    CHECK(std::abs(-signedVolume(parts.inner) / (4.0 / 3.0 * kPi * ri * ri * ri) - 1) < 0.01);

    // Thickness measured on the result: outer samples to the inner wall.
    const test::MeshDistance inner(parts.inner);
    const std::vector<double> thickness = test::distancesTo(inner, test::sampleSurface(parts.outer, 2000, 7));
    CHECK(test::quantile(thickness, 0.0) > 16.0 - 0.5 * voxel);
    CHECK(test::quantile(thickness, 1.0) < 16.0 + 0.5 * voxel);
}

TEST_CASE("shell: the bunny's wall is shellMm thick and closed") {
    // The low-resolution bunny at 250 mm, 1 mm voxels, an 8 mm wall: seconds, and the ears stay hollow.
    const TriMesh bunny = bunnyMm("bunny_npm_3674.stl", 250.0);
    MeshToLevelSetOptions levelSet;
    levelSet.interiorBandMm = 8.0;
    const LevelSet object = meshToLevelSet(bunny, levelSet, RunContext::silent());
    Fabrication wall;
    wall.wallMm = 8.0;
    const LevelSet shell = makeShell(object, wall, RunContext::silent());
    const TriMesh mesh = levelSetToMesh(shell, {}, RunContext::silent());
    const ShellParts parts = splitShell(mesh);
    CHECK(parts.edges.components == 2);
    CHECK(parts.edges.boundaryEdges == 0);
    CHECK(parts.edges.misorientedEdges == 0);
    const test::MeshDistance inner(parts.inner);
    const std::vector<double> thickness =
        test::distancesTo(inner, test::sampleSurface(parts.outer, 3000, 11));
    const double voxel = shell.info().voxelMm;
    MESSAGE("thickness min " << test::quantile(thickness, 0) << " median " << test::quantile(thickness, 0.5)
                             << " 90% " << test::quantile(thickness, 0.9) << " max "
                             << test::quantile(thickness, 1));
    // Nowhere thinner than the wall; where the surface is convex or flat (most of it) exactly the
    // wall. Concave creases and parts thinner than two walls are legitimately thicker.
    CHECK(test::quantile(thickness, 0.0) > 8.0 - 0.5 * voxel);
    CHECK(test::quantile(thickness, 0.5) < 8.0 + 0.5 * voxel);
}

TEST_CASE("shell: options outside the allowed range are usage errors") {
    const TriMesh sphere = test::makeSphere({0, 0, 0}, 20.0);
    MeshToLevelSetOptions options;
    options.interiorBandMm = 5.0;
    const LevelSet object = meshToLevelSet(sphere, options, RunContext::silent());
    Fabrication shell;
    shell.wallMm = 0.5;
    CHECK(test::errorCodeOf([&] { makeShell(object, shell, RunContext::silent()); }) == ErrorCode::Usage);
    shell.wallMm = 6.0;  // deeper than the 5 mm band
    CHECK(test::errorCodeOf([&] { makeShell(object, shell, RunContext::silent()); }) == ErrorCode::Usage);
    shell.wallMm = 5.0;
    CHECK(makeShell(object, shell, RunContext::silent()).activeVoxelCount() > 0);
}

TEST_CASE("shell: a thin object gives a solid piece where it is thinner than two walls") {
    // A 6 mm slab with a 4 mm wall: the offset is empty, the shell is the whole slab.
    const TriMesh slab = test::makeBox({0, 0, 0}, {40, 40, 6});
    MeshToLevelSetOptions options;
    options.interiorBandMm = 4.0;
    const LevelSet object = meshToLevelSet(slab, options, RunContext::silent());
    Fabrication shell;
    shell.wallMm = 4.0;
    const TriMesh mesh =
        levelSetToMesh(makeShell(object, shell, RunContext::silent()), {}, RunContext::silent());
    CHECK(test::edgeReport(mesh).components == 1);
    CHECK(std::abs(signedVolume(mesh) / (40.0 * 40.0 * 6.0) - 1) < 0.02);
}

TEST_CASE("round trip: bunny at 400 mm, two-sided Hausdorff 95th percentile <= 0.5 mm") {
    const TriMesh bunny = bunnyMm("bunny_cgal_75k.stl", 400.0);
    const LevelSet ls = meshToLevelSet(bunny, {}, RunContext::silent());  // default voxel
    const TriMesh back = levelSetToMesh(ls, {}, RunContext::silent());
    const test::MeshDistance toInput(bunny), toOutput(back);
    const double forward =
        test::quantile(test::distancesTo(toOutput, test::sampleSurface(bunny, 5000, 1)), 0.95);
    const double backward =
        test::quantile(test::distancesTo(toInput, test::sampleSurface(back, 5000, 2)), 0.95);
    MESSAGE("Hausdorff 95%: input->output " << forward << " mm, output->input " << backward << " mm");
    CHECK(std::max(forward, backward) <= 0.5);
}
