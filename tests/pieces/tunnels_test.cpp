// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tunnel linings (docs/mounting.md, "Tunnels"): the pieces free of the frame along a tunnel's
/// axis both ways make it a tunnel's, the pieces free along it one way (round a mouth) join them, a
/// limb (free outward only) is no tunnel; slabs are cut at the same offsets in every piece and
/// never leave a sliver.
#include "zomefab/pieces/detail/tunnels.h"

#include <doctest/doctest.h>

#include <vector>

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
