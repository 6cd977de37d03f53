// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The partition's mountability test (docs/partition.md §4, "Mountable"): which directions
/// push a face's wall into the frame, the additive profile of a region, and the cut of a region
/// that no direction mounts. A sphere around one ball: a cap can be pushed off outward, the
/// whole sphere in no direction.
#include <doctest/doctest.h>

#include <algorithm>

#include "test_util.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/detail/stage.h"
#include "zomefab/zome/holes.h"

using namespace zomefab;
using namespace zomefab::partition;
using namespace zomefab::partition::detail;

namespace {

struct Sphere {
    TriMesh mesh = zomefab::test::makeSphere({0, 0, 0}, 100.0, 24, 48);
    FaceGraph graph = buildFaceGraph(mesh);
    zome::Structure frame;
    std::vector<uint64_t> blocked;
    Sphere() {
        frame.addBall({zome::Golden{0, 0}, zome::Golden{0, 0}, zome::Golden{0, 0}});
        blocked = frameBlockedDirections(mesh, graph, frame, 16.0, 2.0);
    }
    /// The faces whose normal is within @p maxDeg of @p axis.
    std::vector<uint32_t> cap(const Vec3d& axis, double maxDeg) const {
        std::vector<uint32_t> faces;
        for (uint32_t f = 0; f < graph.faceCount(); ++f)
            if (dot(graph.normals[f], axis) >= std::cos(maxDeg * kPi / 180.0)) faces.push_back(f);
        return faces;
    }
};

const Sphere& sphere() {
    static const Sphere s;
    return s;
}

}  // namespace

TEST_CASE("mountable: a face's wall runs into the ball behind it, not into what is beside it") {
    const Sphere& s = sphere();
    REQUIRE(s.frame.ballCount() == 1);
    const int down = zome::nearestHole({0, 0, -1}), up = zome::nearestHole({0, 0, 1});
    const int right = zome::nearestHole({1, 0, 0});
    // The face at the north pole: pushed down it passes through the centre ball; up or sideways it
    // leaves the ball (radius 8.85 + 2 mm margin) alone.
    uint32_t pole = 0;
    for (uint32_t f = 1; f < s.graph.faceCount(); ++f)
        if (s.graph.centroidsMm[f][2] > s.graph.centroidsMm[pole][2]) pole = f;
    CHECK(((s.blocked[pole] >> down) & 1) == 1);
    CHECK(((s.blocked[pole] >> up) & 1) == 0);
    CHECK(((s.blocked[pole] >> right) & 1) == 0);
    // No face is blocked upward unless it lies below the ball's reach.
    for (uint32_t f = 0; f < s.graph.faceCount(); ++f)
        if (s.graph.centroidsMm[f][2] > 20.0) CHECK(((s.blocked[f] >> up) & 1) == 0);
}

TEST_CASE("mountable: a cap goes off outward, and its best direction is its own") {
    const Sphere& s = sphere();
    FitTester cx{s.mesh, s.graph, Fabrication{}, RunContext::silent(), std::vector<uint32_t>(s.mesh.positions.size(), 0), 0};
    cx.blocked = s.blocked;
    const std::vector<uint32_t> top = s.cap({0, 0, 1}, 60.0);
    CHECK(cx.isMountable(top));
    const MountProfile p = cx.profileOf(top);
    CHECK(p.blockedMm2[size_t(p.freestHole())] == 0.0);
    // Sideways is free too (the ball is small), but straight out is the one tenons can use.
    CHECK(dot(zome::holeDirection(p.freestHole()), Vec3d{0, 0, 1}) > 0.99);
    std::vector<uint32_t> all(s.graph.faceCount());
    for (uint32_t f = 0; f < all.size(); ++f) all[f] = f;
    CHECK_FALSE(cx.isMountable(all));
    // The profile is additive: the two halves of the sphere add up to the sphere.
    MountProfile both = cx.profileOf(top);
    both.add(cx.profileOf(s.cap({0, 0, -1}, 120.0)));
    CHECK_FALSE(both.isMountable(0.0));
}

TEST_CASE("mountable: a region no direction mounts is cut until every part mounts") {
    // A small sphere round the ball, wall 16 mm: a ball pushed against from every side but a 20° cap.
    const TriMesh mesh = zomefab::test::makeSphere({0, 0, 0}, 40.0, 24, 48);
    const FaceGraph graph = buildFaceGraph(mesh);
    zome::Structure frame;
    frame.addBall({zome::Golden{0, 0}, zome::Golden{0, 0}, zome::Golden{0, 0}});
    FitTester cx{mesh, graph, Fabrication{}, RunContext::silent(), std::vector<uint32_t>(mesh.positions.size(), 0), 0};
    cx.blocked = frameBlockedDirections(mesh, graph, frame, 16.0, 2.0);
    std::vector<uint32_t> wide;
    for (uint32_t f = 0; f < graph.faceCount(); ++f)
        if (graph.normals[f][2] < std::cos(20.0 * kPi / 180.0)) wide.push_back(f);
    REQUIRE_FALSE(cx.isMountable(wide));
    std::vector<uint32_t> lo, hi;
    REQUIRE(splitUnmountable(cx, wide, lo, hi));
    CHECK(lo.size() + hi.size() == wide.size());
    CHECK(!lo.empty());
    CHECK(!hi.empty());
    std::vector<std::vector<uint32_t>> parts;
    bisectUntilFit(cx, wide, std::vector<uint32_t>(graph.faceCount(), kNone), parts, 0);
    CHECK(parts.size() >= 2);
    size_t faces = 0;
    for (const auto& part : parts) {
        CHECK(cx.isMountable(part));
        faces += part.size();
    }
    CHECK(faces == wide.size());
}
