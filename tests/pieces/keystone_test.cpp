// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Keystones (docs/mounting.md, "Keystones"): a piece whose cut faces with its neighbours
/// meet toward its direction, like a stone of an arch taken out inward, gets planes parallel to
/// that direction in place of those faces, and none where a neighbour lies straight ahead or the
/// keystone would keep no tenon.
#include "zomefab/pieces/detail/keystone.h"

#include <doctest/doctest.h>

#include <cmath>
#include <vector>

#include "zomefab/pieces/tenons.h"
#include "zomefab/zome/holes.h"

using namespace zomefab;
using namespace zomefab::pieces;
using namespace zomefab::pieces::detail;

namespace {

const int kUp = zome::nearestHole({0, 0, 1});

/// Piece 1: a trapezoid of 1 mm voxels, |x| ≤ 20 − z/2 for z in [0, 20], y in [0, 10], narrowing
/// upward, between piece 0 (x below it) and piece 2 (x above it): taken off upward it would go
/// into both. The voxels touching each neighbour are its two slanted rims.
struct Wedge {
    std::vector<Vec3d> voxels;
    std::map<uint32_t, std::vector<Vec3d>> touching;
    FaceContacts faces;
    MountBody body;
};

Wedge wedge() {
    Wedge w;
    for (int z = 0; z <= 20; ++z) {
        const int half = int(std::floor(20 - 0.5 * z));
        for (int y = 0; y <= 10; ++y)
            for (int x = -half; x <= half; ++x) {
                w.voxels.push_back({double(x), double(y), double(z)});
                if (x == -half) w.touching[0].push_back(w.voxels.back());
                if (x == half) w.touching[2].push_back(w.voxels.back());
            }
    }
    // Stored from the lower piece into the higher: 0 → 1 and 1 → 2.
    w.faces[{0, 1}] = {CutContact{normalized(Vec3d{1, 0, -0.5}), 200}};
    w.faces[{1, 2}] = {CutContact{normalized(Vec3d{1, 0, 0.5}), 200}};
    w.body.pieces = {1};
    DirectionOption up;
    up.hole = kUp;
    up.tenons = 1;
    up.isTested = up.isFree = true;
    w.body.options = {up};
    return w;
}

/// A tenon candidate along hole @p hole whose wall point is @p wallMm.
TenonCandidate candidateAt(int hole, const Vec3d& wallMm) {
    TenonCandidate c;
    c.piece = 1;
    c.tenon.hole = hole;
    c.tenon.axisGrid = {0, 0, 1};
    c.tenon.baseMm = 20.0;
    c.tenon.ballCenterGridMm = {wallMm[0], wallMm[1], wallMm[2] - 20.0};
    return c;
}

SplitSearch smallSearch() {
    SplitSearch s;
    s.voxelMm = 1.0;
    s.minVolumeMm3 = 500.0;
    s.edgeMarginMm = 4.0;
    return s;
}

}  // namespace

TEST_CASE("keystone: the faces that meet above a piece taken off upward become planes parallel to it") {
    const Wedge w = wedge();
    const TenonCandidate c = candidateAt(kUp, {0, 5, 0});
    const auto key =
        findKeystone(1, w.voxels, w.touching, w.body, w.faces, {&c}, Transform4d::identity(), smallSearch());
    REQUIRE(key);
    CHECK(key->piece == 1);
    CHECK(key->hole == kUp);
    REQUIRE(key->planes.size() == 2);
    // Left of the keystone: x > -9.5 (the rim's last voxel at z = 20 is x = -10); right: x < 9.5.
    CHECK(key->planes[0].normal[0] == doctest::Approx(1.0));
    CHECK(key->planes[0].offsetMm == doctest::Approx(-9.5));
    CHECK(key->planes[1].normal[0] == doctest::Approx(-1.0));
    CHECK(key->planes[1].offsetMm == doctest::Approx(-9.5));
    for (const SplitPlane& p : key->planes) CHECK(std::abs(p.normal[2]) < 1e-12);
}

TEST_CASE("keystone: none where the piece's tenons would all fall into a wedge") {
    const Wedge w = wedge();
    const TenonCandidate c = candidateAt(kUp, {-15, 5, 0});
    CHECK_FALSE(
        findKeystone(1, w.voxels, w.touching, w.body, w.faces, {&c}, Transform4d::identity(), smallSearch()));
}

TEST_CASE("keystone: none where a neighbour lies straight ahead, or where no face is in the way") {
    Wedge w = wedge();
    const TenonCandidate c = candidateAt(kUp, {0, 5, 0});
    // A lid above the piece (stored from piece 1 into piece 3: up): the face's normal into the
    // piece points straight down, against the direction.
    FaceContacts lid = w.faces;
    lid[{1, 3}] = {CutContact{{0, 0, 1}, 200}};
    w.touching[3] = {{0, 5, 20}};
    CHECK_FALSE(
        findKeystone(1, w.voxels, w.touching, w.body, lid, {&c}, Transform4d::identity(), smallSearch()));
    // Faces that open upward (the piece widens as it rises): it slides off without a keystone.
    FaceContacts open;
    open[{0, 1}] = {CutContact{normalized(Vec3d{1, 0, 0.5}), 200}};
    open[{1, 2}] = {CutContact{normalized(Vec3d{1, 0, -0.5}), 200}};
    CHECK_FALSE(
        findKeystone(1, w.voxels, w.touching, w.body, open, {&c}, Transform4d::identity(), smallSearch()));
}
