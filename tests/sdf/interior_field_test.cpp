// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/sdf/interior_field.h"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>
#include <random>

#include "mesh_distance.h"
#include "test_util.h"
#include "zomefab/core/error.h"

using namespace zomefab;
using namespace zomefab::sdf;

TEST_CASE("forbidden zone: the paper's plateaus and a quadratic from 0 at dMin to fMax at dMax") {
    const ForbiddenZoneOptions o;           // dMin 16, dMax 47.3, fThick 90, fMax 70
    CHECK(forbiddenZone(-5.0, o) == 90.0);  // outside the object
    CHECK(forbiddenZone(0.0, o) == 90.0);
    CHECK(forbiddenZone(15.999, o) == 90.0);
    CHECK(forbiddenZone(16.0, o) == 0.0);
    CHECK(forbiddenZone((16.0 + 47.3) / 2, o) == doctest::Approx(70.0 / 4));
    CHECK(forbiddenZone(47.3 - 1e-9, o) == doctest::Approx(70.0));
    CHECK(forbiddenZone(47.3, o) == 70.0);
    CHECK(forbiddenZone(500.0, o) == 70.0);
    CHECK(forbiddenZone(std::nan(""), o) == 90.0);
    // Monotone between the plateaus.
    double previous = -1;
    for (double d = 16.0; d <= 47.3; d += 0.5) {
        CHECK(forbiddenZone(d, o) >= previous);
        previous = forbiddenZone(d, o);
    }
}

TEST_CASE("interior field: a sphere's depth, inside test and closest points match the analytic ones") {
    const Vec3d c{2.5, -1.5, 60.0};
    const double r = 60.0;
    const TriMesh sphere = test::makeSphere(c, r, 128, 256);
    ObjectFieldOptions options;  // fieldVoxelMm = 2 mm, whole interior
    MeshToLevelSetOptions levelSet;
    levelSet.voxelMm = options.fieldVoxelMm;
    levelSet.interiorBandMm = std::numeric_limits<double>::infinity();
    levelSet.exteriorBandMm = options.fieldExteriorMm;
    levelSet.name = "interior";
    const InteriorField field =
        makeInteriorField(meshToLevelSet(sphere, levelSet, RunContext::silent()), RunContext::silent());
    CHECK(field.voxelMm() == 2.0);
    CHECK(std::isinf(field.interiorBandMm()));
    const Box3d box = field.boundsMm();
    CHECK(box.min[0] < c[0] - r - 9.0);  // covers the exterior band
    CHECK(box.max[2] > c[2] + r + 9.0);

    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    double worstDepth = 0, worstClosest = 0, worstOffSurface = 0;
    int checked = 0;
    while (checked < 2000) {
        const Vec3d d{u(rng), u(rng), u(rng)};
        const double n = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (n > 1 || n < 1e-3) continue;
        // Radii from 8 mm (depth 52, beyond dMax) to 8 mm outside.
        const double radius = 8.0 + (r + 8.0 - 8.0) * std::abs(u(rng));
        const Vec3d p{c[0] + d[0] / n * radius, c[1] + d[1] / n * radius, c[2] + d[2] / n * radius};
        worstDepth = std::max(worstDepth, std::abs(field.depthMm(p) - (r - radius)));
        if (std::abs(radius - r) > 0.5) CHECK(field.isInside(p) == (radius < r));
        const Vec3d q = field.closestSurfacePointMm(p);
        const Vec3d exact{c[0] + d[0] / n * r, c[1] + d[1] / n * r, c[2] + d[2] / n * r};
        const Vec3d e{q[0] - exact[0], q[1] - exact[1], q[2] - exact[2]};
        const Vec3d fromCentre{q[0] - c[0], q[1] - c[1], q[2] - c[2]};
        // δ(p) is on the surface everywhere...
        worstOffSurface =
            std::max(worstOffSurface,
                     std::abs(std::sqrt(fromCentre[0] * fromCentre[0] + fromCentre[1] * fromCentre[1] +
                                        fromCentre[2] * fromCentre[2]) -
                              r));
        // ...and the right surface point away from the centre, where every surface point is nearly
        // as close (the medial singularity; the 2 mm field's values decide there).
        if (radius >= 20.0)
            worstClosest = std::max(worstClosest, std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]));
        ++checked;
    }
    MESSAGE("sphere, 2 mm field: worst depth error " << worstDepth << " mm, closest point " << worstClosest
                                                     << " mm (depth <= 40 mm), off the surface "
                                                     << worstOffSurface << " mm");
    CHECK(worstDepth < 0.25);
    CHECK(worstClosest < 1.0);
    CHECK(worstOffSurface < 0.25);
    CHECK(field.isInside(c));
    CHECK_FALSE(field.isInside({c[0] + r + 1, c[1], c[2]}));
    // Far outside the box the distance keeps growing with the distance to the box.
    const double far = field.signedDistanceMm({c[0] + r + 200, c[1], c[2]});
    CHECK(far > 150);
    // ... and its nearest surface point is the one nearest to the box (the border cells' path).
    const Vec3d farFoot = field.closestSurfacePointMm({c[0] + r + 200, c[1] + 0.3, c[2] - 0.2});
    CHECK(std::abs(farFoot[0] - (c[0] + r)) < 0.3);
    CHECK(std::abs(farFoot[1] - c[1]) < 0.5);
    CHECK(std::abs(farFoot[2] - c[2]) < 0.5);
}

TEST_CASE("interior field: a box's depths match the exact mesh distance") {
    // Exact reference: the nearest point of the input triangles (tests/sdf/mesh_distance.h).
    const TriMesh box = test::makeBox({0, 0, 0}, {120, 80, 60});
    MeshToLevelSetOptions levelSet;
    levelSet.voxelMm = 2.0;
    levelSet.interiorBandMm = std::numeric_limits<double>::infinity();
    levelSet.exteriorBandMm = 10.0;
    const InteriorField field =
        makeInteriorField(meshToLevelSet(box, levelSet, RunContext::silent()), RunContext::silent());
    const test::MeshDistance exact(box);
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> x(1, 119), y(1, 79), z(1, 59);
    std::vector<double> errors;
    for (int i = 0; i < 2000; ++i) {
        const Vec3d p{x(rng), y(rng), z(rng)};
        errors.push_back(std::abs(field.depthMm(p) - exact.distance(p)));
    }
    MESSAGE("box, 2 mm field: depth error 95% " << test::quantile(errors, 0.95) << " max "
                                                << test::quantile(errors, 1.0));
    // Trilinear interpolation is exact for a plane; errors only near the box's medial creases.
    CHECK(test::quantile(errors, 0.95) < 0.1);
    CHECK(test::quantile(errors, 1.0) < 1.0);
}

TEST_CASE("interior field: an empty level set is refused") {
    CHECK_THROWS_AS(makeInteriorField(LevelSet{}, RunContext::silent()), Error);
    const InteriorField empty;
    CHECK(empty.empty());
    CHECK(empty.signedDistanceMm({1, 2, 3}) == 0);
}
