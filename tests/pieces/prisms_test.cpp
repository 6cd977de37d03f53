// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tunnels that cross (docs/mounting.md, "Tunnels that cross"): the prisms of two crossing
/// tunnels, a wall round their cores and ending inside the mouths; none where three cross at one
/// point; where two prisms overlap the earlier axis keeps the voxel; the signed distance is negative
/// inside the prism, positive outside, and agrees with the voxel test.
#include "zomefab/pieces/detail/prisms.h"

#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <vector>

#include "tunnel_fixtures.h"

using namespace zomefab;
using namespace zomefab::pieces::detail;

TEST_CASE("crossingPrisms: two crossing tunnels get prisms round their cores; three through one point none") {
    // A 64 mm cube (1 mm voxels) with round tunnels of radius 10 along x and y through its middle.
    const VoxelField two = cubeWithTunnels(64, 10.0, {0, 1}, 4.0);
    bool isTriple = true;
    const std::vector<TunnelPrism> prisms = crossingPrisms(two, 8.0, 6.0, 5.0, &isTriple);
    CHECK_FALSE(isTriple);
    REQUIRE(prisms.size() == 2);
    CHECK(prisms[0].axis == 0);
    CHECK(prisms[1].axis == 1);
    const double c = 31.5;  // the tunnels' axes, grid mm (voxel centres at integers)
    for (const TunnelPrism& p : prisms) {
        CHECK(p.radiusMm == 6.0);
        // The object's voxels along its lines run from 0 to 63; the ends 5 mm inside.
        CHECK(p.loMm == doctest::Approx(5.0));
        CHECK(p.hiMm == doctest::Approx(58.0));
        Vec3d onAxis{c, c, c}, inLining{c, c, c}, pastLining{c, c, c}, pastEnd{c, c, c};
        const size_t u = size_t(p.axis + 1) % 3, a = size_t(p.axis);
        onAxis[a] = 20.0, inLining[a] = 20.0, pastLining[a] = 20.0, pastEnd[a] = 61.0;
        inLining[u] += 13.0;    // 3 mm into the wall
        pastLining[u] += 20.0;  // 10 mm into it: past the radius
        CHECK(p.signedDistanceMm(onAxis) < 0.0);
        CHECK(p.signedDistanceMm(inLining) < 0.0);
        CHECK(p.signedDistanceMm(pastLining) > 0.0);
        CHECK(p.signedDistanceMm(pastEnd) == doctest::Approx(3.0).epsilon(0.05));
        // The voxel test agrees with the sign: voxel (20, c + 13 …) is in, (… c + 20 …) is not.
        Coord in(0, 0, 0), out(0, 0, 0);
        for (int k = 0; k < 3; ++k)
            in[k] = int(std::floor(inLining[size_t(k)])), out[k] = int(std::floor(pastLining[size_t(k)]));
        CHECK(p.contains(in));
        CHECK_FALSE(p.contains(out));
    }
    const VoxelField three = cubeWithTunnels(64, 10.0, {0, 1, 2}, 4.0);
    CHECK(crossingPrisms(three, 8.0, 6.0, 5.0, &isTriple).empty());
    CHECK(isTriple);
    const VoxelField one = cubeWithTunnels(64, 10.0, {0}, 4.0);
    CHECK(crossingPrisms(one, 8.0, 6.0, 5.0, &isTriple).empty());  // a tunnel no other crosses
    CHECK_FALSE(isTriple);
}

TEST_CASE("prismOwners: where two prisms overlap (round the crossing) the earlier axis keeps the voxel") {
    const VoxelField two = cubeWithTunnels(64, 10.0, {0, 1}, 4.0);
    bool isTriple = false;
    const std::vector<TunnelPrism> prisms = crossingPrisms(two, 8.0, 6.0, 5.0, &isTriple);
    REQUIRE(prisms.size() == 2);
    const std::vector<uint32_t> owner = prismOwners(two, prisms);
    size_t both = 0, onlyY = 0, none = 0;
    for (size_t s = 0; s < owner.size(); ++s) {
        if (!two.isInside(s)) continue;
        const Coord ijk = two.coordOf(s);
        const bool inX = prisms[0].contains(ijk), inY = prisms[1].contains(ijk);
        const uint32_t expected = inX ? 0 : inY ? 1 : kNone;
        both += inX && inY, onlyY += !inX && inY, none += !inX && !inY;
        if (owner[s] != expected) FAIL_CHECK("voxel owned by " << owner[s] << ", expected " << expected);
    }
    CHECK(both > 100);  // the ridges round the crossing
    CHECK(onlyY > 1000);
    CHECK(none > 10000);
}

TEST_CASE(
    "crossingPrisms: three tunnels through one point get staved prisms; the later axis keeps the overlap") {
    const VoxelField three = cubeWithTunnels(64, 10.0, {0, 1, 2}, 4.0);
    bool isTriple = false;
    const std::vector<TunnelPrism> prisms = crossingPrisms(three, 8.0, 6.0, 5.0, &isTriple, true);
    CHECK(isTriple);
    REQUIRE(prisms.size() == 3);
    for (const TunnelPrism& p : prisms) {
        CHECK(p.isStaved);
        // Staves slide out through the mouths: the prism runs to the object's last voxels.
        CHECK(p.loMm == doctest::Approx(0.0));
        CHECK(p.hiMm == doctest::Approx(63.0));
        CHECK(p.centerUMm == doctest::Approx(31.5).epsilon(0.02));
        CHECK(p.centerVMm == doctest::Approx(31.5).epsilon(0.02));
        CHECK(p.coreRadiusMm == doctest::Approx(10.0).epsilon(0.15));
    }
    // Each inside voxel owned by the prism of the highest priority holding it (@p order: lowest
    // first); returns how many of them the x prism holds with the z prism and @p keeper owns.
    auto checkOwners = [&](const std::vector<TunnelPrism>& list, const std::array<uint32_t, 3>& order,
                           uint32_t keeper) {
        const std::vector<uint32_t> owner = prismOwners(three, list, true);
        size_t shared = 0;
        for (size_t s = 0; s < owner.size(); ++s) {
            if (!three.isInside(s)) continue;
            const Coord ijk = three.coordOf(s);
            uint32_t expected = kNone;
            for (uint32_t k : order)
                if (list[k].contains(ijk)) expected = k;
            shared += owner[s] == keeper && list[0].contains(ijk) && list[2].contains(ijk);
            if (owner[s] != expected) FAIL_CHECK("voxel owned by " << owner[s] << ", expected " << expected);
        }
        return shared;
    };
    CHECK(checkOwners(prisms, {0, 1, 2}, 2) > 100);  // the latest axis keeps the ridges
    // The x tunnel made late (a second attempt): it keeps every overlap, the others as before.
    std::vector<TunnelPrism> late = prisms;
    const TunnelKey x{0, prisms[0].centerUMm + 0.5, prisms[0].centerVMm - 0.5};
    CHECK(isTunnelOf(x, late[0], 1.0));
    CHECK_FALSE(isTunnelOf(x, late[0], 0.25));
    CHECK_FALSE(isTunnelOf({1, x.centerUMm, x.centerVMm}, late[0], 1.0));
    late[0].priority = late[0].axis + kLatePriority;
    CHECK(checkOwners(late, {1, 2, 0}, 0) > 100);
}
