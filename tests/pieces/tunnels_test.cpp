// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tunnel linings (docs/mounting.md, "Tunnels"): the pieces free of the frame along a tunnel's
/// axis both ways make it a tunnel's, the pieces free along it one way (round a mouth) join them, a
/// limb (free outward only) is no tunnel; slabs are cut at the same offsets in every piece and
/// never leave a sliver. Tunnels that cross: their cores (free lines enclosed by the object), which
/// cross, and the pieces lining them, said when a plan places them nowhere.
#include "zomefab/pieces/detail/tunnels.h"

#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "tunnel_fixtures.h"

using namespace zomefab;
using namespace zomefab::pieces::detail;

namespace {
const Vec3d kX{1, 0, 0}, kMinusX{-1, 0, 0}, kY{0, 1, 0}, kMinusY{0, -1, 0}, kZ{0, 0, 1};
}  // namespace

TEST_CASE("tunnelGroups: pieces free along an axis both ways make a tunnel; one-way pieces join it") {
    // 10, 11: free along ±x (the lining); 12: +x only (round the mouth); 13: +z only; 14: ±y alone.
    const std::vector<uint32_t> pieces{10, 11, 12, 13, 14};
    const std::vector<std::vector<Vec3d>> free{{kX, kMinusX, kZ}, {kMinusX, kX}, {kX}, {kZ}, {kY, kMinusY}};
    const std::vector<TunnelGroup> groups = tunnelGroups(pieces, free);
    REQUIRE(groups.size() == 1);
    CHECK(groups[0].pieces == std::vector<uint32_t>{10, 11, 12});
    CHECK(groups[0].lining == 3);
    CHECK(std::abs(std::abs(groups[0].axis[0]) - 1.0) < 1e-12);
    // 14 alone lines ±y: one piece is no tunnel of its own at the default minimum of two.
    CHECK(tunnelGroups({14}, {{kY, kMinusY}}).empty());
    CHECK(tunnelGroups({14}, {{kY, kMinusY}}, 1).size() == 1);
}

TEST_CASE("tunnelGroups: a limb whose pieces are free outward only is no tunnel") {
    const std::vector<std::vector<Vec3d>> free{{kX}, {kX, kZ}, {kX}};
    CHECK(tunnelGroups({1, 2, 3}, free).empty());
}

TEST_CASE("tunnelGroups: two tunnels, each piece in one group, the larger first") {
    const std::vector<std::vector<Vec3d>> free{{kY, kMinusY}, {kX, kMinusX, kY, kMinusY},
                                               {kX, kMinusX}, {kX, kMinusX},
                                               {kY, kMinusY}, {kY, kMinusY}};
    const std::vector<TunnelGroup> groups = tunnelGroups({0, 1, 2, 3, 4, 5}, free);
    REQUIRE(groups.size() == 2);
    CHECK(groups[0].pieces == std::vector<uint32_t>{0, 1, 4, 5});  // ±y: four pieces
    CHECK(groups[1].pieces == std::vector<uint32_t>{2, 3});        // ±x: what is left
}

TEST_CASE("slabOffsets: planes at the multiples of the slab length, none that leaves a sliver") {
    std::vector<double> t;
    for (int k = 0; k <= 300; ++k) t.push_back(-150.0 + k);  // a lining from −150 to 150 mm
    CHECK(slabOffsets(t, 80.0, 10) == std::vector<double>{-80.0, 0.0, 80.0});
    std::vector<double> u;
    for (int k = 0; k <= 90; ++k) u.push_back(-5.0 + k);           // −5 … 85
    CHECK(slabOffsets(u, 80.0, 10) == std::vector<double>{});      // 0: 5 below; 80: 5 above
    CHECK(slabOffsets(u, 40.0, 10) == std::vector<double>{40.0});  // 0 and 80 too near the ends
    CHECK(slabOffsets({}, 80.0, 1).empty());
    CHECK(slabOffsets(t, 0.0, 1).empty());
}

TEST_CASE(
    "tunnelGroups: the axis most pieces are free along both ways wins, not the one most reach one way") {
    // 0, 1: the lining, free along ±x; 2–5: pieces outside, free outward along a diagonal only
    // (0 and 1 too: the diagonal leaves the tunnel's mouth).
    const Vec3d diag = normalized(Vec3d{1, 1, -1});
    const std::vector<std::vector<Vec3d>> free{
        {kX, kMinusX, diag}, {kX, kMinusX, diag, scale(diag, -1.0)}, {diag}, {diag}, {diag}, {diag}};
    const std::vector<TunnelGroup> groups = tunnelGroups({0, 1, 2, 3, 4, 5}, free, 1);
    REQUIRE(!groups.empty());
    CHECK(std::abs(groups[0].axis[0]) > 0.99);
    CHECK(groups[0].pieces == std::vector<uint32_t>{0, 1});
}

TEST_CASE("tunnelCores: the free lines enclosed by the object, not those round it, and none too narrow") {
    AxisShadow shadow = emptyShadow(0, Coord(0, 0, 0), Coord(40, 40, 40));
    for (int j = 0; j <= 40; ++j)
        for (int k = 0; k <= 40; ++k)
            if ((j - 20) * (j - 20) + (k - 20) * (k - 20) > 64) markHit(shadow, Coord(5, j, k));
    const std::vector<TunnelCore> cores = tunnelCores(shadow, 2.0, 10.0);
    REQUIRE(cores.size() == 1);  // the hole; the ring of columns round the cube reaches the border
    CHECK(cores[0].axis == 0);
    CHECK(cores[0].diameterMm == doctest::Approx(2.0 * 2.0 * 8.0).epsilon(0.1));  // 8 voxels of 2 mm
    CHECK(std::binary_search(cores[0].columns.begin(), cores[0].columns.end(), std::array<int, 2>{20, 20}));
    CHECK(tunnelCores(shadow, 2.0, 40.0).empty());  // narrower than asked
    CHECK(shadow.isHitAt(0, 0));
    CHECK_FALSE(shadow.isHitAt(20, 20));
    CHECK_FALSE(shadow.isHitAt(-100, 20));  // off the shadow: nothing there
}

TEST_CASE("coresCross: prisms along two axes meet where they share the third axis's values") {
    TunnelCore x{0, {{10, 10}, {10, 11}, {11, 10}}, 5.0};  // along x: (y, z), z ∈ {10, 11}
    TunnelCore y{1, {{11, 30}, {12, 30}}, 5.0};            // along y: (z, x), z ∈ {11, 12}
    TunnelCore high{1, {{40, 30}}, 5.0};                   // along y at z = 40
    TunnelCore other{0, {{30, 11}}, 5.0};                  // along x too
    CHECK(coresCross(x, y));
    CHECK(coresCross(y, x));
    CHECK_FALSE(coresCross(x, high));
    CHECK_FALSE(coresCross(x, other));  // parallel prisms do not cross
}

TEST_CASE(
    "crossingTunnels: tunnels along x and y that cross; their lining pieces; one tunnel alone crosses none") {
    const VoxelField crossing = cubeWithTunnels(64, 10.0, {0, 1}, 4.0);
    const CrossingTunnels both = crossingTunnels(crossing, 2, 8.0, 6.0);
    CHECK(both.tunnels == 2);
    CHECK(both.crossings == 1);
    CHECK(both.meanDiameterMm == doctest::Approx(20.0).epsilon(0.1));
    REQUIRE(both.liningShare.size() == 2);
    CHECK(both.liningShare[0] > 0.95);  // the lining
    CHECK(both.liningShare[1] < 0.4);   // the rest of the cube: only round the mouths
    const VoxelField single = cubeWithTunnels(64, 10.0, {0}, 4.0);
    const CrossingTunnels one = crossingTunnels(single, 2, 8.0, 6.0);
    CHECK(one.tunnels == 0);
    CHECK(one.crossings == 0);
    CHECK(one.liningShare[0] == 0.0);
}

TEST_CASE("crossingTunnelNote: said when most of the pieces placed nowhere line crossing tunnels") {
    CrossingTunnels t;
    t.tunnels = 4, t.crossings = 4, t.meanDiameterMm = 84.0;
    t.liningShare = {0.9, 0.8, 0.7, 0.6, 0.1, 0.2, 0.95};
    size_t lining = 99;
    const std::string note = crossingTunnelNote(t, {0, 1, 2, 3, 4, 5}, 4, &lining);
    CHECK(lining == 4);
    CHECK(note.find("4 of the 6 pieces placed nowhere line tunnels") == 0);
    CHECK(note.find("4 straight tunnels about 84 mm across, 4 pairs of them crossing)") != std::string::npos);
    CHECK(crossingTunnelNote(t, {0, 4, 5}, 1, &lining).empty());  // 1 of 3: not most
    CHECK(lining == 0);
    CHECK(crossingTunnelNote(t, {0, 1, 6}, 4, &lining).empty());  // all 3, fewer than 4
    CHECK(crossingTunnelNote(t, {0, 1, 2, 3, 4, 5, 6}, 4, nullptr).find("5 of the 7") == 0);
}
