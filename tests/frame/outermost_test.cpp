// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include "frame_fixtures.h"
#include "zomefab/frame/outermost.h"

using namespace zomefab;
using frame::isOutermostMask;

namespace {
/// The hole of the size-0 strut along exact @p v (direction only).
int holeAlong(const zome::GoldenVector3& v) { return *zome::parallelHole(v); }
uint64_t bit(int h) { return uint64_t(1) << h; }
const zome::Golden kOne(1);
}  // namespace

TEST_CASE("outermost: the centre of a 3x3x3 cube grid is the only internal ball") {
    const zome::Structure s = test::cubeGrid(3);
    const std::vector<zome::BallId> out = frame::outermostBalls(s);
    CHECK(out.size() == 26);
    CHECK(std::is_sorted(out.begin(), out.end()));
    // The centre ball (1,1,1) has index 13 in lattice order and is missing from N_out.
    CHECK(std::find(out.begin(), out.end(), zome::BallId(13)) == out.end());
    CHECK(s.ball(13).valence == 6);
}

TEST_CASE("outermost: half-space test on hole masks") {
    const int px = holeAlong({kOne, 0, 0}), mx = holeAlong({-kOne, 0, 0});
    const int py = holeAlong({0, kOne, 0}), my = holeAlong({0, -kOne, 0});
    const int pz = holeAlong({0, 0, kOne}), mz = holeAlong({0, 0, -kOne});
    const uint64_t cube = bit(px) | bit(mx) | bit(py) | bit(my) | bit(pz) | bit(mz);
    CHECK_FALSE(isOutermostMask(cube));
    // Any missing cube strut leaves a free half-space.
    for (int h : {px, mx, py, my, pz, mz}) CHECK(isOutermostMask(cube & ~bit(h)));
    // A yellow strut into the free side closes it: ±x, ±y, −z and (1,1,1) positively span R³.
    const int y111 = holeAlong({kOne, kOne, kOne});
    CHECK_FALSE(isOutermostMask((cube & ~bit(pz)) | bit(y111)));
    // A planar star of struts is outermost whatever its size.
    CHECK(isOutermostMask(bit(px) | bit(mx) | bit(py) | bit(my)));
    // Fewer than four struts: always outermost; a regular tetrahedron of yellows is internal.
    CHECK(isOutermostMask(bit(px) | bit(py) | bit(pz)));
    const uint64_t tetra = bit(y111) | bit(holeAlong({kOne, -kOne, -kOne})) |
                           bit(holeAlong({-kOne, kOne, -kOne})) | bit(holeAlong({-kOne, -kOne, kOne}));
    CHECK_FALSE(isOutermostMask(tetra));
    CHECK(isOutermostMask(0));
}

TEST_CASE("outermost: holeMask reads the structure") {
    const zome::Structure s = test::cubeGrid(2);
    for (zome::BallId id : s.ballIds()) CHECK(__builtin_popcountll(frame::holeMask(s.ball(id))) == 3);
}
