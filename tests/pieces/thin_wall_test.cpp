// SPDX-License-Identifier: GPL-3.0-or-later
// Pieces printed with a wall thinner than the shell's (lib/zomefab/pieces/thin_wall.cpp): on a
// 200 mm spherical shell of 8 mm with a B0 cube lattice inside, the plan made with the 8 mm wall,
// the pieces printed with the default thin wall (1.8 mm) where their pegs reach through it.
#include "zomefab/pieces/detail/thin_wall.h"

#include <doctest/doctest.h>

#include <cmath>
#include <set>

#include "pieces_fixtures.h"
#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/pieces_io.h"

using namespace zomefab;
using namespace zomefab::pieces;
using namespace zomefab::pieces::test;

namespace {

constexpr double kThin = kDefaultPrintWallMm;

constexpr double kRadius = kSphereRadiusMm, kShell = kSphereShellMm;

const sdf::LevelSet& shell() { return sphereShell(); }
const zome::Structure& frame() { return sphereFrame(); }

Fabrication sphereFabrication() {
    Fabrication f = printerOf({200, 200, 200});
    f.wallMm = kShell;
    return f;
}

Pieces cutSphere(double printWallMm) {
    PiecesOptions o;
    o.printWallMm = printWallMm;
    return makePieces(shell(), frame(), Transform4d::identity(), quadrantCells(-15.3, 20.4),
                      sphereFabrication(), o, RunContext::silent());
}

/// The distance from @p p to the nearest tenon axis of @p piece, from its peg's tip on.
double distanceToStems(const Piece& piece, const Vec3d& p, const TenonOptions& o) {
    double best = 1e300;
    for (const Tenon& t : piece.tenons) {
        const double along = dot(sub(p, t.ballCenterGridMm), t.axisGrid);
        if (along < t.shoulderMm - o.pegDepthMm - 0.01) continue;
        best = std::min(best, norm(sub(p, t.pointAt(along))));
    }
    return best;
}

}  // namespace

TEST_CASE("thin wall: the plan of the shell's wall, each piece printed 1.8 mm thin where its pegs reach") {
    const Pieces thick = cutSphere(0), thin = cutSphere(kThin);
    REQUIRE(thick.pieces.size() == thin.pieces.size());
    // The plan is the shell's: the same directions and steps.
    CHECK(thin.plan.holeOfPiece == thick.plan.holeOfPiece);
    REQUIRE(thin.plan.steps.size() == thick.plan.steps.size());
    for (size_t s = 0; s < thin.plan.steps.size(); ++s)
        CHECK(thin.plan.steps[s].pieces == thick.plan.steps[s].pieces);
    CHECK(thick.thinPieces == 0);
    CHECK(thin.thinPieces >= thin.pieces.size() / 2);
    size_t counted = 0;
    for (size_t i = 0; i < thin.pieces.size(); ++i) {
        const Piece &p = thin.pieces[i], &q = thick.pieces[i];
        INFO("piece " << i);
        CHECK(q.wallMm == kShell);
        CHECK(!q.isThinWall);
        const mesh::MeshReport r = mesh::checkMesh(p.mesh);
        CHECK(r.boundaryEdges == 0);
        CHECK(r.nonManifoldEdges == 0);
        CHECK(r.volume > 0);
        if (!p.isThinWall) {
            CHECK(p.wallMm == kShell);
            continue;
        }
        ++counted;
        CHECK(p.wallMm == kThin);
        // The same pegs: every tenon on the same ball and hole, through the thin wall.
        REQUIRE(p.tenons.size() == q.tenons.size());
        std::set<std::pair<zome::BallId, int>> pegs;
        for (const Tenon& t : q.tenons) pegs.insert({t.ball, t.hole});
        for (const Tenon& t : p.tenons) {
            CHECK(pegs.count({t.ball, t.hole}) == 1);
            CHECK(t.baseMm > q.tenons.front().shoulderMm);
        }
        // A wall about 1.8/8 of the thick one's plastic, stems included.
        CHECK(p.volumeMm3 < 0.55 * q.volumeMm3);
        // Away from the stems the piece lies between the outer surface and 1.8 mm inside it, and
        // nothing of it is outside the sphere.
        const TriMesh m = gridMesh(p);
        size_t wall = 0, off = 0;
        for (const Vec3f& v : m.positions) {
            const Vec3d x = toD(v);
            const double radius = norm(x);
            CHECK(radius <= kRadius + 0.3);
            if (distanceToStems(p, x, thin.options.tenons) < 12.0 ||
                (p.label && norm(sub(x, p.label->centerGridMm)) < 20.0))
                continue;
            ++wall;
            off += radius < kRadius - kThin - 0.4 ? 1 : 0;
        }
        CHECK(wall > 100);
        CHECK(off == 0);
    }
    CHECK(counted == thin.thinPieces);
    // pieces.json keeps the printed wall.
    const Pieces back = piecesFromJson(piecesToJson(thin, {"shell.vdb", "frame.json", "partition.json"}), "");
    CHECK(back.options.printWallMm == kThin);
    for (size_t i = 0; i < thin.pieces.size(); ++i) {
        CHECK(back.pieces[i].wallMm == thin.pieces[i].wallMm);
        CHECK(back.pieces[i].isThinWall == thin.pieces[i].isThinWall);
    }
}

TEST_CASE("thin wall: a wall the shell's band or wall cannot give is refused, naming the option") {
    CHECK_THROWS_WITH_AS(cutSphere(3.0),
                         doctest::Contains("--print-wall-mm 3 is deeper than the shell's band"), Error);
    CHECK_THROWS_WITH_AS(cutSphere(0.5), doctest::Contains("--print-wall-mm must be auto, 0"), Error);
    CHECK_THROWS_WITH_AS(cutSphere(-2), doctest::Contains("--print-wall-mm must be auto, 0"), Error);
    CHECK_THROWS_AS(detail::checkPrintWall(2.4, 6.0, 3.0, 1.0), Error);  // bands of a 6 mm wall touch
    CHECK_NOTHROW(detail::checkPrintWall(2.4, 7.0, 3.0, 1.0));
    CHECK_NOTHROW(detail::checkPrintWall(0.0, 4.0, 3.0, 1.0));  // off
}

TEST_CASE("thin wall: by default 1.8 mm where the shell allows it, else the shell's wall") {
    using detail::resolvePrintWallMm;
    CHECK(PiecesOptions{}.printWallMm == kPrintWallAuto);
    CHECK(resolvePrintWallMm(kPrintWallAuto, 16.0, 3.0, 1.0) == kDefaultPrintWallMm);
    CHECK(resolvePrintWallMm(kPrintWallAuto, 7.0, 3.0, 1.0) == kDefaultPrintWallMm);
    CHECK(resolvePrintWallMm(kPrintWallAuto, 6.0, 3.0, 1.0) == 0);   // a thin shell is printed as it is
    CHECK(resolvePrintWallMm(kPrintWallAuto, 16.0, 1.5, 0.5) == 0);  // a 1.5 mm band cannot hold 1.8
    CHECK(resolvePrintWallMm(kPrintWallAuto, 16.0, 2.16, 0.72) == kDefaultPrintWallMm);
    CHECK(resolvePrintWallMm(kPrintWallAuto, 16.0, 2.1, 0.7) == 0);
    CHECK(resolvePrintWallMm(kPrintWallAuto, 16.0, 2.91, 0.97) == kDefaultPrintWallMm);
    CHECK(resolvePrintWallMm(0, 16.0, 3.0, 1.0) == 0);
    CHECK(resolvePrintWallMm(2.0, 16.0, 3.0, 1.0) == 2.0);
    CHECK_THROWS_AS(resolvePrintWallMm(2.4, 16.0, 1.5, 0.5), Error);  // asked for: refused, not ignored
    // The sphere's 8 mm shell at 1 mm voxels: the default is the 1.8 mm run.
    const Pieces byDefault = cutSphere(kPrintWallAuto), thin = cutSphere(kThin);
    CHECK(byDefault.options.printWallMm == kThin);
    CHECK(byDefault.thinPieces == thin.thinPieces);
    CHECK(byDefault.thinPieces > 0);
    REQUIRE(byDefault.pieces.size() == thin.pieces.size());
    for (size_t i = 0; i < thin.pieces.size(); ++i)
        CHECK(byDefault.pieces[i].volumeMm3 == doctest::Approx(thin.pieces[i].volumeMm3));
}

TEST_CASE(
    "thin wall: a stem grown again may run as much longer as the thin wall's inner surface lies deeper") {
    TenonOptions o;  // 60 mm, tilt up to 60°: along a stem that steep, 14.2 mm deeper is 28.4 mm longer
    const TenonOptions thin = detail::thinTenonOptions(o, 16.0, 1.8);
    CHECK(thin.maxLengthMm == doctest::Approx(60.0 + 2 * 14.2));
    CHECK(thin.maxTiltDeg == o.maxTiltDeg);
    CHECK(detail::thinTenonOptions(o, 16.0, 16.0).maxLengthMm == doctest::Approx(60.0));
    o.maxTiltDeg = 0;
    CHECK(detail::thinTenonOptions(o, 8.0, 2.0).maxLengthMm == doctest::Approx(66.0));
}
