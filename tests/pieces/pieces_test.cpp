// SPDX-License-Identifier: GPL-3.0-or-later
// makePieces end to end on a 200 mm spherical shell with a B0 cube lattice inside: the pieces'
// union is the shell, every mesh is closed and fits the printer, tenons are exact and clear of the
// frame, slivers are merged, the number is engraved, and results do not depend on the threads.
#include "zomefab/pieces/pieces.h"

#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "pieces_fixtures.h"
#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/merges.h"
#include "zomefab/pieces/detail/replan.h"
#include "zomefab/pieces/detail/splits.h"
#include "zomefab/pieces/detail/stages.h"
#include "zomefab/pieces/detail/support.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/orientation.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/sdf/level_set_grid.h"
#include "zomefab/zome/holes.h"
#include "zomefab/zome/zome_system.h"

using namespace zomefab;
using namespace zomefab::pieces;
using namespace zomefab::pieces::detail;
using namespace zomefab::pieces::test;

namespace {

constexpr double kRadius = kSphereRadiusMm, kShell = kSphereShellMm, kVoxel = 1.0;

const sdf::LevelSet& shell() { return sphereShell(); }
const zome::Structure& frame() { return sphereFrame(); }

PiecesOptions plainOptions() {
    PiecesOptions o;
    o.tenons.maxPerPiece = 0;
    o.tenons.minPerPiece = 0;
    o.label.isEnabled = false;
    return o;
}

double meshVolume(const TriMesh& m) { return mesh::checkMesh(m).volume; }

/// Shell mesh volume at the same voxel (the reference for the union).
double shellVolume() {
    static const double v = meshVolume(sdf::levelSetToMesh(shell(), {}, RunContext::silent()));
    return v;
}

void checkClosedAndFits(const Pieces& result) {
    for (const Piece& p : result.pieces) {
        INFO("piece " << p.id);
        const mesh::MeshReport r = mesh::checkMesh(p.mesh);
        CHECK(r.boundaryEdges == 0);
        CHECK(r.nonManifoldEdges == 0);
        CHECK(r.inconsistentEdges == 0);
        CHECK(r.degenerateTriangles == 0);
        CHECK(r.volume > 0);
        CHECK(p.volumeMm3 == doctest::Approx(r.volume));
        for (int a = 0; a < 3; ++a) {
            CHECK(r.bounds.min[size_t(a)] >= -1e-3);
            CHECK(r.bounds.max[size_t(a)] <= result.printerMm[size_t(a)] + 1e-3);
        }
        CHECK(r.bounds.min[2] == doctest::Approx(0).epsilon(1e-3));
        // A cut face down means flat triangles on the bed facing down.
        double bedArea = 0;
        for (const Triangle& t : p.mesh.triangles) {
            const Vec3d a = toD(p.mesh.positions[t[0]]), b = toD(p.mesh.positions[t[1]]),
                        c = toD(p.mesh.positions[t[2]]);
            if (std::max({a[2], b[2], c[2]}) > 1e-3) continue;
            const Vec3d n = cross(sub(b, a), sub(c, a));
            if (n[2] < 0) bedArea += 0.5 * norm(n);
        }
        if (p.isCutFaceDown) CHECK(bedArea > 50.0);
        // Every piece, cut face down or not, stands on a base the first layer can print (a piece
        // on a point or an edge is what PrusaSlicer refuses: "no extrusions in the first layer"),
        // or on its supports, enough of which stand on the bed to hold it (docs/pieces.md).
        const double baseMm2 = baseAreaMm2(p.mesh, {0, 0, -1});
        const double onBedMm2 = detail::supportColumns(detail::MeshD(p.mesh), {0, 0, -1}).bedMm2;
        INFO("base " << baseMm2 << " mm², supports on the bed " << onBedMm2 << " mm²");
        if (p.isOnSupports)
            CHECK(baseMm2 + onBedMm2 >= 400.0);  // kMinHoldMm2
        else
            CHECK(baseMm2 >= 25.0);  // kMinBaseMm2
        CHECK(p.baseAreaMm2 == doctest::Approx(baseMm2).epsilon(1e-6).scale(100));
    }
}

/// The shell's voxels grouped into the four pieces of quadrantCells(−5.3, 10.4).
struct QuadrantPieces {
    VoxelField field;
    GridCells cells;
    Grouping grouping;
};
QuadrantPieces quadrantPieces() {
    QuadrantPieces q{buildField(*sdf::levelSetGrid(shell())), {}, {}};
    const partition::PartitionResult quadrants = quadrantCells(-5.3, 10.4);
    q.cells = toGridCells(quadrants.cells, Transform4d::identity());
    labelCells(q.field, q.cells);
    q.grouping = groupPieces(q.field, q.cells, quadrants.pieces, Transform4d::identity(), 10.0, 0.0,
                             RunContext::silent());
    return q;
}

}  // namespace

TEST_CASE("pieces: the union of the pieces is the shell (volume and sampled points)") {
    const partition::PartitionResult cells = quadrantCells(-15.3, 20.4);
    const Pieces result = makePieces(shell(), frame(), Transform4d::identity(), cells,
                                     printerOf({200, 200, 200}), plainOptions(), RunContext::silent());
    REQUIRE(result.pieces.size() == 4);
    checkClosedAndFits(result);
    double total = 0;
    for (const Piece& p : result.pieces) {
        total += p.volumeMm3;
        // orientForPrinter's smallest first layer, unless it stands on its supports: on the sphere
        // a quadrant tilted onto its edge needs 3 cm³ of support columns and 23,600 s, lying on its
        // rim 86 cm³ and 27,800 s (the time model, PrintTimeModel).
        CHECK((p.baseAreaMm2 >= 25.0 || p.isOnSupports));
        CHECK(p.isBrimAdvised == (p.baseAreaMm2 < kBrimBelowMm2));
        CHECK(p.cells.size() == 1);
        CHECK(p.requests == p.cells);
    }
    CHECK(total == doctest::Approx(shellVolume()).epsilon(0.01));
    CHECK(result.shellVolumeMm3 == doctest::Approx(shellVolume()).epsilon(0.01));
    // Neighbours: the quadrants x ≶ −15.3 and z ≶ 20.4; diagonal ones touch only along a line.
    for (const Piece& p : result.pieces) CHECK(p.neighbors.size() == 2);

    // Sampled points: inside the shell ⇒ in exactly one piece; outside ⇒ in none. Points within
    // a voxel of a surface or a cut plane are skipped (the mesh is accurate to a fraction of one).
    std::vector<TriMesh> meshes;
    for (const Piece& p : result.pieces) meshes.push_back(gridMesh(p));
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(-kRadius - 5, kRadius + 5);
    int inside = 0, outside = 0;
    for (int i = 0; i < 600; ++i) {
        const Vec3d x{u(rng), u(rng), u(rng)};
        const double r = norm(x);
        if (std::abs(r - kRadius) < kVoxel || std::abs(r - (kRadius - kShell)) < kVoxel) continue;
        if (std::abs(x[0] + 15.3) < kVoxel || std::abs(x[2] - 20.4) < kVoxel) continue;
        const bool isInShell = r < kRadius && r > kRadius - kShell;
        int count = 0;
        for (const TriMesh& m : meshes) count += isInsideMesh(m, x) ? 1 : 0;
        INFO("point " << x[0] << " " << x[1] << " " << x[2]);
        CHECK(count == (isInShell ? 1 : 0));
        (isInShell ? inside : outside) += 1;
    }
    CHECK(inside > 10);
    CHECK(outside > 300);
}

/// How far (x, y) lies inside the convex counter-clockwise polygon (negative: outside).
double insidePolygon(const std::vector<std::array<double, 2>>& poly, double x, double y) {
    double inside = 1e300;
    for (size_t k = 0; k < poly.size(); ++k) {
        const auto& a = poly[k];
        const auto& b = poly[(k + 1) % poly.size()];
        inside = std::min(inside, ((b[0] - a[0]) * (y - a[1]) - (b[1] - a[1]) * (x - a[0])) /
                                      std::hypot(b[0] - a[0], b[1] - a[1]));
    }
    return inside;
}

TEST_CASE("pieces: every piece's tenons are parallel, in free holes, their pegs exact, clear of the frame") {
    const partition::PartitionResult cells = quadrantCells(-15.3, 20.4);
    PiecesOptions o;
    o.label.isEnabled = false;
    o.tenons.maxTiltDeg = 35;
    const Pieces result = makePieces(shell(), frame(), Transform4d::identity(), cells,
                                     printerOf({200, 200, 200}), o, RunContext::silent());
    checkClosedAndFits(result);
    CHECK(result.plan.isBuildable());
    const zome::Structure& f = frame();
    const double ballRadius = f.scale().ballRadiusMm();
    std::map<std::pair<zome::BallId, int>, int> used;
    size_t total = 0;
    for (const Piece& p : result.pieces) {
        INFO("piece " << p.id);
        CHECK(p.hole >= 0);
        CHECK(result.plan.stepOf(p.id) >= 0);
        if (p.tenons.size() < 2) CHECK(!p.tenonShortfall.empty());
        const TriMesh m = gridMesh(p);
        for (const Tenon& t : p.tenons) {
            ++total;
            CHECK(t.hole == p.hole);  // one direction per piece: every peg parallel
            CHECK(++used[{t.ball, t.hole}] == 1);
            CHECK(t.axisFrame == zome::holeDirection(t.hole));  // exact table direction
            CHECK(f.isHoleFree(t.ball, t.hole));
            CHECK(t.piece == p.id);
            const Vec3d c = f.ball(t.ball).positionMm;  // frame = grid here
            const double face = ballRadius * zome::holeFaceRatio(zome::holeColor(t.hole));
            CHECK(norm(sub(t.pointAt(t.shoulderMm), c)) == doctest::Approx(face).epsilon(1e-9));
            CHECK(t.tiltDeg <= 35.0);
            CHECK(t.lengthMm() <= o.tenons.maxLengthMm);
            // Along the axis the first surface is the peg's tip, exactly (the peg is a mesh of its own).
            const auto tip = firstHit(m, c, t.axisGrid);
            REQUIRE(tip);
            CHECK(*tip == doctest::Approx(face - o.tenons.pegDepthMm).epsilon(1e-4));
        }
        // No vertex of the piece inside a strut's capsule; inside a ball only the peg of a tenon
        // into it, within the peg's section.
        for (const Vec3f& v : m.positions) {
            const Vec3d x = toD(v);
            for (zome::StrutId s : f.strutIds()) {
                const zome::Strut& strut = f.strut(s);
                CHECK(zome::pointSegmentDistanceSq(x, strut.startMm, strut.endMm) >=
                      std::pow(f.scale().strutRadiusMm(strut.color) - 0.05, 2));
            }
            for (zome::BallId b : f.ballIds()) {
                const Vec3d q = sub(x, f.ball(b).positionMm);
                if (norm(q) >= ballRadius - 1e-3) continue;
                bool isPeg = false;
                for (const Tenon& t : p.tenons) {
                    if (t.ball != b) continue;
                    const Vec3d side = cross(t.axisGrid, t.longSideGrid);
                    isPeg = insidePolygon(pegSectionMm(t.hole, o.tenons), dot(q, t.longSideGrid),
                                          dot(q, side)) > -1e-3;
                }
                CHECK(isPeg);
            }
        }
    }
    CHECK(total >= 6);
}

TEST_CASE("pieces: slivers are merged into a neighbour, never dropped") {
    // A plane 1.5 mm inside the outer surface cuts off a ~700 mm³ cap of the wall.
    const partition::PartitionResult cells = halfSpaceCells({1, 0, 0}, kRadius - 1.5);
    const Pieces result = makePieces(shell(), frame(), Transform4d::identity(), cells,
                                     printerOf({200, 200, 200}), plainOptions(), RunContext::silent());
    REQUIRE(result.pieces.size() == 1);
    CHECK(result.sliversMerged == 1);
    CHECK(result.pieces[0].sliversMerged == 1);
    CHECK(result.pieces[0].cells == std::vector<uint32_t>{0, 1});
    checkClosedAndFits(result);
    CHECK(result.pieces[0].volumeMm3 == doctest::Approx(shellVolume()).epsilon(0.01));

    // With no minimum the cap is a piece of its own.
    PiecesOptions keep = plainOptions();
    keep.minPieceVolumeMm3 = 0;
    const Pieces two = makePieces(shell(), frame(), Transform4d::identity(), cells,
                                  printerOf({200, 200, 200}), keep, RunContext::silent());
    REQUIRE(two.pieces.size() == 2);
    CHECK(two.pieces[0].volumeMm3 + two.pieces[1].volumeMm3 == doctest::Approx(shellVolume()).epsilon(0.01));
    CHECK(std::min(two.pieces[0].volumeMm3, two.pieces[1].volumeMm3) < 1500);
}

TEST_CASE("pieces: a speck of shell that touches nothing is dropped, not joined to a piece far away") {
    // One inside voxel in the hollow, 60 mm from the wall: an island no piece touches (the dino
    // at 450 mm had two; joined to the largest piece of their cell they left it no free direction).
    openvdb::FloatGrid::Ptr grid = sdf::levelSetGrid(shell())->deepCopy();
    const openvdb::Coord speck(int(std::lround(30.0 / kVoxel)), 0, 0);
    REQUIRE(grid->tree().getValue(speck) > 0);
    grid->tree().setValueOn(speck, -0.3f);
    VoxelField field = buildField(*grid);
    const size_t slot = field.slotAt({30.0, 0, 0});
    REQUIRE(slot != SIZE_MAX);
    REQUIRE(field.isInside(slot));
    const partition::PartitionResult quadrants = quadrantCells(-5.3, 10.4);
    const GridCells cells = toGridCells(quadrants.cells, Transform4d::identity());
    labelCells(field, cells);
    const Grouping withSpeck =
        groupPieces(field, cells, quadrants.pieces, Transform4d::identity(), 10.0, 0.0, RunContext::silent());
    CHECK_FALSE(field.isInside(slot));
    REQUIRE(withSpeck.pieces.size() == 4);
    CHECK(withSpeck.isolatedSlivers == 0);
    const QuadrantPieces plain = quadrantPieces();
    CHECK(withSpeck.shellVolumeMm3 == doctest::Approx(plain.grouping.shellVolumeMm3));
    for (size_t p = 0; p < 4; ++p)
        CHECK(withSpeck.pieces[p].shellVolumeMm3 == doctest::Approx(plain.grouping.pieces[p].shellVolumeMm3));
}

TEST_CASE("pieces: an island of the wall too small for a piece that touches no other is left out") {
    // 27 inside voxels in the hollow, 60 mm from the wall: larger than a speck, smaller than the
    // smallest piece. Nothing could hold it (no tenon, no face to glue it onto): it is left out and
    // counted; with no smallest piece it stays a piece of its own.
    openvdb::FloatGrid::Ptr grid = sdf::levelSetGrid(shell())->deepCopy();
    const int cx = int(std::lround(30.0 / kVoxel));
    for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) {
                const openvdb::Coord c(cx + dx, dy, dz);
                REQUIRE(grid->tree().getValue(c) > 0);
                grid->tree().setValueOn(c, -0.3f);
            }
    const partition::PartitionResult quadrants = quadrantCells(-5.3, 10.4);
    const GridCells cells = toGridCells(quadrants.cells, Transform4d::identity());
    const double crumbMm3 = 27.0 * kVoxel * kVoxel * kVoxel;
    for (const double minVolumeMm3 : {crumbMm3 * 1.5, 0.0}) {
        VoxelField field = buildField(*grid);
        const size_t slot = field.slotAt({30.0, 0, 0});
        REQUIRE(slot != SIZE_MAX);
        REQUIRE(field.isInside(slot));
        labelCells(field, cells);
        const Grouping g = groupPieces(field, cells, quadrants.pieces, Transform4d::identity(), 10.0,
                                       minVolumeMm3, RunContext::silent());
        if (minVolumeMm3 > 0) {
            CHECK_FALSE(field.isInside(slot));
            CHECK(g.pieces.size() == 4);
            CHECK(g.isolatedSlivers == 1);
        } else {
            CHECK(field.isInside(slot));
            CHECK(g.pieces.size() == 5);
            CHECK(g.isolatedSlivers == 0);
        }
    }
}

TEST_CASE("pieces: a cell shared by two requests and a cell no request names") {
    // Cells: 0 = x ≥ 0 and 1 = x < 0. Both requests name cell 0 (its shell part is connected, so it
    // goes whole to the request whose surface box holds most of it); no request names cell 1,
    // whose shell part joins its neighbour, whatever its size.
    partition::PartitionResult cells = halfSpaceCells({1, 0, 0}, 0.0);
    cells.pieces.resize(2);
    cells.pieces[0].cells = {0};
    cells.pieces[0].boundsMm.expand({50, 50, 50});
    cells.pieces[0].boundsMm.expand({60, 60, 60});
    cells.pieces[1].cells = {0};
    cells.pieces[1].boundsMm.expand({0, -100, -100});
    cells.pieces[1].boundsMm.expand({100, 100, 100});
    RunContext context;
    PiecesOptions o = plainOptions();
    const Fabrication fab = printerOf({250, 250, 250});
    const Pieces result = makePieces(shell(), frame(), Transform4d::identity(), cells, fab, o, context);
    REQUIRE(result.pieces.size() == 1);
    CHECK(result.pieces[0].requests == std::vector<uint32_t>{1});
    CHECK(result.pieces[0].cells == std::vector<uint32_t>{0, 1});
    CHECK(result.sliversMerged == 0);
    CHECK(result.outsideCellsVolumeMm3 == doctest::Approx(0.5 * shellVolume()).epsilon(0.02));
    CHECK(result.pieces[0].volumeMm3 == doctest::Approx(shellVolume()).epsilon(0.01));
    REQUIRE(!context.warnings().empty());
    CHECK(context.warnings()[0].find("no partition piece names") != std::string::npos);
    checkClosedAndFits(result);
}

TEST_CASE("pieces: a piece larger than the printer is cut by planes until it fits") {
    // Two 200 × 200 × 100 mm half-shells for a 120 mm printer: the partition's cells could not make
    // them smaller (the cheese's case), so the pieces stage cuts each into parts that fit.
    const partition::PartitionResult cells = halfSpaceCells({0, 0, 1}, 0.0);
    const Fabrication fab = printerOf({120, 120, 120});
    std::vector<std::string> messages;
    RunContext context([&](LogLevel, const std::string& m) { messages.push_back(m); }, nullptr);
    const Pieces result = makePieces(shell(), frame(), Transform4d::identity(), cells, fab, plainOptions(), context);
    CHECK(result.pieces.size() >= 8);  // a half-shell needs two cuts at least (100 mm deep, 200 wide)
    CHECK(result.pieces.size() <= 12);
    checkClosedAndFits(result);
    double total = 0;
    for (const Piece& p : result.pieces) total += p.volumeMm3;
    CHECK(total == doctest::Approx(shellVolume()).epsilon(0.01));
    bool isSaid = false;
    for (const std::string& m : messages) isSaid |= m.find("cut(s) by planes") != std::string::npos;
    CHECK(isSaid);
}

TEST_CASE("pieces: a piece no cut can make fit the printer is an error of the partition") {
    // Halves of at least 10 litres may not be cut (the shell holds about 0.9 L): nothing fits.
    const partition::PartitionResult cells = halfSpaceCells({0, 0, 1}, 0.0);
    PiecesOptions o = plainOptions();
    o.minPieceVolumeMm3 = 1e7;
    const Fabrication fab = printerOf({120, 120, 120});
    try {
        makePieces(shell(), frame(), Transform4d::identity(), cells, fab, o, RunContext::silent());
        FAIL("no error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::ProcessingFailed);
        CHECK(std::string(e.what()).find("in no orientation") != std::string::npos);
        CHECK(std::string(e.what()).find("partition") != std::string::npos);
    }
}

TEST_CASE("pieces: the voxels' cells, searched among each leaf's candidates, are the argmax of all cells") {
    // 60 random cells (a partition after many repair rounds has hundreds) and one cell equal to
    // cell 5, so ties occur: they go to the lower cell either way.
    VoxelField field = buildField(*sdf::levelSetGrid(shell()));
    std::mt19937_64 rng(3);
    std::normal_distribution<double> g(0.0, 1.0);
    partition::LinearCells model;
    for (uint32_t k = 0; k < 60; ++k) {
        model.w.push_back({g(rng), g(rng), g(rng)});
        model.b.push_back(30.0 * g(rng));
        model.classes.push_back(k);
    }
    model.w.push_back(model.w[5]);
    model.b.push_back(model.b[5]);
    model.classes.push_back(60);
    const GridCells cells = toGridCells(model, Transform4d::identity());
    labelCells(field, cells);
    std::vector<double> scores(cells.count());
    size_t active = 0, mismatches = 0;
    std::set<uint32_t> used;
    for (size_t s = 0; s < field.phi.size(); ++s) {
        if (!field.isActive[s]) continue;
        ++active;
        mismatches += field.cell[s] != cells.owner(field.world(field.coordOf(s)), scores.data()) ? 1 : 0;
        used.insert(field.cell[s]);
    }
    CHECK(active > 100000);
    CHECK(mismatches == 0);
    CHECK(used.size() >= 10);
    CHECK(used.count(60) == 0);  // always tied with cell 5, which wins
}

TEST_CASE("pieces: the band outside the wall is told from the hollow's (the outer surface's mesh)") {
    // A hollow sphere of radius 100 mm with an 8 mm wall: the band voxels outside the wall beyond
    // r = 100 are the object's outside, those within r = 92 the hollow, which no 6-connected path
    // through the band reaches from outside.
    const VoxelField field = buildField(*sdf::levelSetGrid(shell()));
    const std::vector<uint8_t> exterior = exteriorBand(field);
    REQUIRE(exterior.size() == field.phi.size());
    size_t outside = 0, hollow = 0, wrong = 0;
    for (size_t s = 0; s < field.phi.size(); ++s) {
        if (!field.isActive[s] || field.phi[s] < 0) {
            wrong += exterior[s];  // inside the wall, or not in the field
            continue;
        }
        const double r = norm(field.world(field.coordOf(s)));
        if (r > kRadius - 0.5 * kShell) {
            ++outside;
            wrong += exterior[s] ? 0 : 1;
        } else {
            ++hollow;
            wrong += exterior[s];
        }
    }
    CHECK(outside > 10000);
    CHECK(hollow > 10000);
    CHECK(wrong == 0);
}

TEST_CASE("pieces: bad inputs and options") {
    const partition::PartitionResult cells = halfSpaceCells({0, 0, 1}, 0.0);
    auto codeOf = [&](const partition::PartitionResult& c, const PiecesOptions& o,
                      const Transform4d& t = Transform4d::identity()) {
        try {
            makePieces(shell(), frame(), t, c, printerOf({200, 200, 200}), o, RunContext::silent());
        } catch (const Error& e) {
            return int(e.code());
        }
        return -1;
    };
    partition::PartitionResult bad = cells;
    bad.pieces.resize(1);
    bad.pieces[0].cells = {5};
    CHECK(codeOf(bad, plainOptions()) == int(ErrorCode::InvalidInput));
    CHECK(codeOf(cells, plainOptions(), Transform4d::scaleTranslate(2.0, {0, 0, 0})) ==
          int(ErrorCode::InvalidInput));
    partition::PartitionResult empty;
    CHECK(codeOf(empty, plainOptions()) == int(ErrorCode::InvalidInput));
    PiecesOptions o = plainOptions();
    o.adaptivity = 1.5;
    CHECK(codeOf(cells, o) == int(ErrorCode::Usage));
    // Tenon prisms need a fine enough voxel: a 4 mm shell is too coarse for 7 mm.
    const sdf::LevelSet coarse = makeSphereShell({0, 0, 0}, 60.0, 8.0, 4.0);
    PiecesOptions withTenons;
    try {
        makePieces(coarse, frame(), Transform4d::identity(), cells, printerOf({200, 200, 200}), withTenons,
                   RunContext::silent());
        FAIL("no error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::Usage);
        CHECK(std::string(e.what()).find("voxel") != std::string::npos);
    }
}

TEST_CASE("pieces: the engraved number is cut into the inner surface") {
    const partition::PartitionResult cells = halfSpaceCells({0, 0, 1}, 10.0);
    PiecesOptions o;
    // The shell's wall: a number in a 2.4 mm wall must lie within 0.4 mm of flat, which no
    // 12 mm digit on this small sphere does (docs/pieces.md, "Engraved number").
    o.printWallMm = 0;
    o.tenons.maxTiltDeg = 35;
    // 12 mm digits (the default) and 30 mm ones, which bend over the sphere.
    for (const double heightMm : {12.0, 30.0}) {
        CAPTURE(heightMm);
        o.label.heightMm = heightMm;
        const Pieces result = makePieces(shell(), frame(), Transform4d::identity(), cells,
                                         printerOf({200, 200, 200}), o, RunContext::silent());
        checkClosedAndFits(result);
        size_t labelled = 0;
        for (const Piece& p : result.pieces) {
            if (!p.label) {
                CHECK(!p.labelNote.empty());
                continue;
            }
            ++labelled;
            const PieceLabel& l = *p.label;
            CHECK(l.text == std::to_string(p.id));
            // On the inner surface, facing the cavity (towards the centre).
            CHECK(norm(l.centerGridMm) == doctest::Approx(kRadius - kShell).epsilon(0.01));
            CHECK(dot(l.normalGrid, normalized(l.centerGridMm)) < -0.9);
            const TriMesh m = gridMesh(p);
            const auto strokes = labelStrokes(l.text, o.label);
            const Vec3d right = cross(l.upGrid, l.normalGrid);
            auto at = [&](double x, double y, double z) {
                return madd(madd(madd(l.centerGridMm, x, right), y, l.upGrid), z, l.normalGrid);
            };
            // The inner sphere below a point of the label's plane, along the normal (into the wall).
            auto below = [&](double x, double y, double depth) {
                const Vec3d q = at(x, y, 0);
                const Vec3d n = l.normalGrid;  // points to the centre
                // |q − s·n| = R − T for the s > 0 that reaches the sphere.
                const double b = dot(q, n), c = dot(q, q) - std::pow(kRadius - kShell, 2);
                const double s = b + std::sqrt(b * b - c);
                return madd(q, -(s + depth), n);
            };
            // Half the depth under the underline's surface: engraved (outside the piece); beside the
            // label at the same depth and below the engraving: wall.
            const Stroke& underline = strokes.back();
            CHECK(!isInsideMesh(m, below(underline.centerX, underline.centerY, 0.5 * o.label.depthMm)));
            CHECK(isInsideMesh(m, below(0.5 * l.widthMm + 1.5, 0, 0.5 * o.label.depthMm)));
            CHECK(isInsideMesh(m, below(underline.centerX, underline.centerY, o.label.depthMm + 1.0)));
            // Digits 30 mm high bend over the sphere: the stroke farthest from the centre lies more
            // than a millimetre below the label's plane, and is cut the depth into the sphere there
            // (a cut from the plane went that much deeper; with the old 0.6 mm flatness no number).
            if (o.label.heightMm < 20.0) continue;
            const Stroke* far = &strokes[0];
            for (const Stroke& st : strokes)
                if (std::hypot(st.centerX, st.centerY) > std::hypot(far->centerX, far->centerY)) far = &st;
            CHECK(std::hypot(far->centerX, far->centerY) > 15.0);
            CHECK(!isInsideMesh(m, below(far->centerX, far->centerY, 0.5 * o.label.depthMm)));
            CHECK(isInsideMesh(m, below(far->centerX, far->centerY, o.label.depthMm + 0.5)));
        }
        CHECK(labelled >= 1);
    }
    o.label = LabelOptions{};
    // Without tenons (--max-tenons 0) there is no plan to carry out, and the pieces are numbered all
    // the same.
    o.tenons.maxPerPiece = 0;
    o.tenons.minPerPiece = 0;
    const Pieces plain = makePieces(shell(), frame(), Transform4d::identity(), cells,
                                    printerOf({200, 200, 200}), o, RunContext::silent());
    CHECK(std::count_if(plain.pieces.begin(), plain.pieces.end(),
                        [](const Piece& p) { return bool(p.label); }) >= 1);
}

namespace {

/// A frame turned 0.3 rad about the vertical and shifted: where it lies in the grid.
Transform4d turnedFrameToGrid() {
    const double a = 0.3;
    Transform4d frameToGrid;
    frameToGrid.m = {
        std::cos(a), -std::sin(a), 0, 4.0, std::sin(a), std::cos(a), 0, -6.0, 0, 0, 1, 3.0, 0, 0, 0, 1};
    return frameToGrid;
}

}  // namespace

TEST_CASE("pieces: a frame rotated about the vertical and shifted") {
    const Transform4d frameToGrid = turnedFrameToGrid();
    // The shell stays centred at the origin of the grid; the frame (made around its own origin)
    // is placed by frameToGrid, so keep it well inside: a smaller lattice.
    const zome::Structure small = makeCubeLattice(60.0);
    const partition::PartitionResult cells = quadrantCells(-15.3, 20.4);  // in the frame's mm
    PiecesOptions o;
    o.printWallMm = 0;  // the point test below samples the whole wall
    o.label.isEnabled = false;
    o.tenons.maxTiltDeg = 35;
    const Pieces result =
        makePieces(shell(), small, frameToGrid, cells, printerOf({200, 200, 200}), o, RunContext::silent());
    // A quadrant too few pegs hold is printed as one with a neighbour (docs/mounting.md, "Merged
    // pieces"): the merged piece holds both quadrants' cells, which the point test below checks;
    // a pair cut anew leaves the count as it was.
    REQUIRE(result.pieces.size() + result.mergedPieces == 4);
    checkClosedAndFits(result);
    size_t total = 0;
    for (const Piece& p : result.pieces)
        for (const Tenon& t : p.tenons) {
            ++total;
            const Vec3d expected = applyLinear(frameToGrid, zome::holeDirection(t.hole));
            for (int k = 0; k < 3; ++k) CHECK(t.axisGrid[size_t(k)] == doctest::Approx(expected[size_t(k)]));
            const Vec3d c = frameToGrid.apply(small.ball(t.ball).positionMm);
            CHECK(norm(sub(t.ballCenterGridMm, c)) < 1e-9);
            const auto tip = firstHit(gridMesh(p), c, t.axisGrid);
            REQUIRE(tip);
            CHECK(std::abs(*tip - t.pegTipMm) < 0.01);
        }
    CHECK(total >= 3);
    CHECK(result.plan.isBuildable());
    // The cut planes are the frame's planes mapped into the grid: a sampled point test.
    std::vector<TriMesh> meshes;
    for (const Piece& p : result.pieces) meshes.push_back(gridMesh(p));
    const Transform4d gridToFrame = affineInverse(frameToGrid);
    std::mt19937_64 rng(3);
    std::uniform_real_distribution<double> u(-kRadius, kRadius);
    for (int i = 0; i < 200; ++i) {
        const Vec3d x{u(rng), u(rng), u(rng)};
        const double r = norm(x);
        if (!(r < kRadius - kVoxel && r > kRadius - kShell + kVoxel)) continue;
        const Vec3d xf = gridToFrame.apply(x);
        if (std::abs(xf[0] + 15.3) < 2 * kVoxel || std::abs(xf[2] - 20.4) < 2 * kVoxel) continue;
        const size_t expected = (xf[0] > -15.3 ? 0 : 2) + (xf[2] > 20.4 ? 0 : 1);
        bool isNearTenon = false;
        for (const Piece& p : result.pieces)
            for (const Tenon& t : p.tenons)
                if (tenonSignedDistanceMm(t, o.tenons, x) < 1.0) isNearTenon = true;
        if (isNearTenon) continue;
        // In exactly one piece, one that holds the cell (a pair cut anew by a plane, docs/mounting.md,
        // shares its cells between its halves).
        INFO("point " << x[0] << " " << x[1] << " " << x[2] << ", cell " << expected);
        size_t inside = 0;
        for (size_t k = 0; k < meshes.size(); ++k) {
            if (!isInsideMesh(meshes[k], x)) continue;
            ++inside;
            const std::vector<uint32_t>& has = result.pieces[k].cells;
            CHECK(std::count(has.begin(), has.end(), expected) == 1);
        }
        CHECK(inside == 1);
    }
}

TEST_CASE("pieces: the same result with 1 and 2 threads, and the written files") {
    const partition::PartitionResult cells = quadrantCells(-15.3, 20.4);
    PiecesOptions o;
    o.tenons.maxTiltDeg = 35;
    auto run = [&](int threads) {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));
        return makePieces(shell(), frame(), Transform4d::identity(), cells, printerOf({200, 200, 200}), o,
                          RunContext::silent());
    };
    const Pieces one = run(1), two = run(2);
    REQUIRE(one.pieces.size() == two.pieces.size());
    for (size_t i = 0; i < one.pieces.size(); ++i)
        CHECK(serializeMesh(one.pieces[i].mesh, MeshFormat::Stl) ==
              serializeMesh(two.pieces[i].mesh, MeshFormat::Stl));
    const PiecesJsonInfo info{"shell.vdb", "frame.json", "partition.json"};
    CHECK(piecesToJson(one, info).dump() == piecesToJson(two, info).dump());

    zomefab::test::ScratchDir dir("zomefab-pieces");
    const std::string out = dir.file("pieces");
    writePieces(one, out, info);
    const nlohmann::json j = nlohmann::json::parse(readInputBytes(out + "/pieces.json"));
    CHECK(j["format"] == "zomefab.pieces");
    CHECK(j["units"] == "mm");
    REQUIRE(j["pieces"].size() == one.pieces.size());
    for (size_t i = 0; i < one.pieces.size(); ++i) {
        const nlohmann::json& p = j["pieces"][i];
        CHECK(p["file"] == pieceFileName(one, i));
        const TriMesh back = readMesh(out + "/" + p["file"].get<std::string>());
        CHECK(back.triangles.size() == one.pieces[i].mesh.triangles.size());
        CHECK(p["volume_mm3"].get<double>() == doctest::Approx(one.pieces[i].volumeMm3));
        CHECK(p["tenons"].size() == one.pieces[i].tenons.size());
        CHECK(p["orientation"]["transform_mm"].size() == 4);
        for (const nlohmann::json& t : p["tenons"]) CHECK(t["length_mm"].get<double>() > 0);
    }
    CHECK(readInputBytes(out + "/plates/plate-01.3mf").substr(0, 4) == std::string("PK\x03\x04", 4));
    // Written again over the earlier output: replaced (it holds a pieces.json).
    writePieces(two, out, info);
    CHECK(readInputBytes(out + "/pieces.json") == piecesToJson(two, info).dump(2) + "\n");
    // A directory that is not ours is not replaced, and nothing is left behind.
    const std::string foreign = dir.file("foreign");
    std::filesystem::create_directory(foreign);
    zomefab::test::writeBytes(foreign + "/keep.txt", "x");
    CHECK_THROWS_AS(writePieces(one, foreign, info), Error);
    CHECK(std::filesystem::exists(foreign + "/keep.txt"));
    CHECK_THROWS_AS(writePieces(one, dir.file("no/such/parent"), info), Error);
    size_t entries = 0;
    for (const auto& e : std::filesystem::directory_iterator(dir.path()))
        entries += e.path().filename().string()[0] == '.';
    CHECK(entries == 0);  // no staging directory left
}

TEST_CASE("pieces.json: a stem cut through a thin wall reads back; a malformed cut is refused") {
    const partition::PartitionResult cells = quadrantCells(-15.3, 20.4);
    PiecesOptions o;
    o.printWallMm = 0;  // no stem is cut but the one below
    o.tenons.maxTiltDeg = 35;
    Pieces made = makePieces(shell(), frame(), Transform4d::identity(), cells, printerOf({200, 200, 200}), o,
                             RunContext::silent());
    Tenon* cut = nullptr;
    for (Piece& p : made.pieces)
        if (!p.tenons.empty()) cut = &p.tenons.front();
    REQUIRE(cut != nullptr);
    // A cut that slants across the section, as on a wall met obliquely.
    cut->isCut = true;
    for (int k = 0; k < kCutLines; ++k) cut->cutAlongMm[size_t(k)] = cut->baseMm + 1.0 + 0.05 * k;
    cut->endMm = cut->baseMm + 3.0;
    const PiecesJsonInfo info{"shell.vdb", "frame.json", "partition.json"};
    const nlohmann::json j = piecesToJson(made, info);
    const Pieces back = piecesFromJson(j, "");
    bool seen = false;
    for (const Piece& p : back.pieces)
        for (const Tenon& t : p.tenons)
            if (t.isClipped()) {
                seen = true;
                for (int k = 0; k < kCutLines; ++k)
                    CHECK(t.cutAlongMm[size_t(k)] ==
                          doctest::Approx(cut->cutAlongMm[size_t(k)]).epsilon(1e-9));
            }
    CHECK(seen);
    // The wrong number of points, and a point off the stem (past its end): one line naming the field.
    auto withCut = [&](auto edit) {
        nlohmann::json bad = j;
        for (nlohmann::json& p : bad["pieces"])
            for (nlohmann::json& t : p["tenons"])
                if (t.contains("cut_mm")) edit(t["cut_mm"]);
        return bad;
    };
    const nlohmann::json fewer = withCut([](nlohmann::json& c) { c.erase(c.size() - 1); });
    CHECK_THROWS_WITH_AS(piecesFromJson(fewer, ""), doctest::Contains("cut_mm must be an array of 25 points"),
                         Error);
    nlohmann::json older = j;  // a stem cut by a plane, before 2026-12-05
    for (nlohmann::json& p : older["pieces"])
        for (nlohmann::json& t : p["tenons"])
            if (t.contains("cut_mm")) t["cut_plane"] = {{"normal", {1, 0, 0}}, {"offset_mm", 90.0}};
    CHECK_THROWS_WITH_AS(piecesFromJson(older, ""), doctest::Contains("cut_plane is from an older zomefab"),
                         Error);
    const nlohmann::json far = withCut([](nlohmann::json& c) { c[3] = {1e6, 0, 0}; });
    CHECK_THROWS_WITH_AS(piecesFromJson(far, ""), doctest::Contains("cut_mm[3] must lie on the stem"), Error);
}

TEST_CASE("pieces.json: a step of two legs (a stave) reads back; a malformed slide is refused") {
    const partition::PartitionResult cells = quadrantCells(-15.3, 20.4);
    Pieces made = makePieces(shell(), frame(), Transform4d::identity(), cells, printerOf({200, 200, 200}), {},
                             RunContext::silent());
    REQUIRE(!made.plan.steps.empty());
    mount::MountStep& step = made.plan.steps.front();
    step.slide = {0, 0.6, 0.8};
    step.liftMm = 11.5;
    const nlohmann::json j = piecesToJson(made, {"shell.vdb", "frame.json", "partition.json"});
    const Pieces back = piecesFromJson(j, "");
    const mount::MountStep& read = back.plan.steps.front();
    CHECK(read.hasTwoLegs());
    CHECK(read.liftMm == doctest::Approx(11.5));
    CHECK(read.slide[1] == doctest::Approx(0.6));
    CHECK(read.slide[2] == doctest::Approx(0.8));
    for (size_t s = 1; s < back.plan.steps.size(); ++s) CHECK_FALSE(back.plan.steps[s].hasTwoLegs());
    auto withSlide = [&](auto edit) {
        nlohmann::json bad = j;
        edit(bad["installation"]["steps"][0]["slide"]);
        return bad;
    };
    CHECK_THROWS_WITH_AS(piecesFromJson(withSlide([](nlohmann::json& s) { s["lift_mm"] = -3; }), ""),
                         doctest::Contains("slide.lift_mm must be in (0, 100] mm"), Error);
    CHECK_THROWS_WITH_AS(piecesFromJson(withSlide([](nlohmann::json& s) {
                                            s["frame"] = {0, 2, 0};
                                        }),
                                        ""),
                         doctest::Contains("slide.frame must be a unit vector"), Error);
    CHECK_THROWS_WITH_AS(piecesFromJson(withSlide([](nlohmann::json& s) { s.erase("frame"); }), ""),
                         doctest::Contains("frame"), Error);
}

TEST_CASE("pieces: two pieces merged into one keep every voxel, and the others are numbered down") {
    QuadrantPieces q = quadrantPieces();
    VoxelField& field = q.field;
    const GridCells& cells = q.cells;
    Grouping& g = q.grouping;
    REQUIRE(g.pieces.size() == 4);
    auto owned = [&](uint32_t p) {
        size_t n = 0;
        for (size_t s = 0; s < field.phi.size(); ++s) n += field.isActive[s] && field.owner[s] == p ? 1 : 0;
        return n;
    };
    const size_t one = owned(1), two = owned(2), three = owned(3);
    const double volume = g.pieces[1].shellVolumeMm3 + g.pieces[3].shellVolumeMm3;
    std::vector<uint32_t> cellsOf13 = g.pieces[1].cells;
    cellsOf13.insert(cellsOf13.end(), g.pieces[3].cells.begin(), g.pieces[3].cells.end());
    std::sort(cellsOf13.begin(), cellsOf13.end());
    const std::vector<uint32_t> cellsOf2 = g.pieces[2].cells;
    REQUIRE(isMergeable(g.cellSets, 1, 3));

    CHECK(mergePieces(g.pieces, g.cellSets, field, 3, 1) == 2);  // 3 keeps, 1 goes: 3 becomes 2
    REQUIRE(g.pieces.size() == 3);
    for (uint32_t p = 0; p < 3; ++p) CHECK(g.pieces[p].id == p);
    CHECK(owned(2) == one + three);
    CHECK(owned(1) == two);  // the old piece 2, numbered down
    CHECK(owned(3) == 0);
    CHECK(g.pieces[2].cells == cellsOf13);
    CHECK(g.pieces[1].cells == cellsOf2);
    CHECK(g.pieces[2].shellVolumeMm3 == doctest::Approx(volume));
    // The union's cells bound it no more: only the other two cells cut it.
    CHECK(g.cellSets[2].members == cellsOf13);
    for (uint32_t c : g.cellSets[2].cutters) CHECK(!g.cellSets[2].isMember[c]);
    CHECK(g.cellSets[2].cutters.size() == 2);
    // Faces recomputed: the union touches both others, and they each other.
    g.faces = faceContacts(field, cells, g.cellSets, g.pieces);
    CHECK(g.pieces[2].neighbors.size() == 2);
    // A re-cut piece is a cell region cut by a plane: it is not merged.
    g.cellSets[0].halfSpaces.push_back({{1, 0, 0}, 0.0});
    CHECK_FALSE(isMergeable(g.cellSets, 0, 2));
    CHECK_FALSE(isMergeable(g.cellSets, 1, 1));
}

TEST_CASE("pieces: the two halves of a split are merged back into the piece before it") {
    QuadrantPieces q = quadrantPieces();
    VoxelField& field = q.field;
    Grouping& g = q.grouping;
    REQUIRE(g.pieces.size() == 4);
    const std::vector<uint32_t> owners = field.owner;
    const double volume = g.pieces[1].shellVolumeMm3;
    // Cut piece 1 at the middle of its voxels along x (and piece 2 by another plane, once).
    double lo = 1e9, hi = -1e9;
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isActive[s] && field.owner[s] == 1) {
            const double x = field.world(field.coordOf(s))[0];
            lo = std::min(lo, x), hi = std::max(hi, x);
        }
    const uint32_t half = splitPiece(g.pieces, g.cellSets, field, 1, {{1, 0, 0}, 0.5 * (lo + hi)});
    REQUIRE(half == 4);
    splitPiece(g.pieces, g.cellSets, field, 2, {{0, 1, 0}, 0.0});
    CHECK_FALSE(isMergeable(g.cellSets, 1, 4));
    REQUIRE(splitPlaneBetween(g.cellSets, 1, 4) == size_t(0));
    CHECK(splitPlaneBetween(g.cellSets, 4, 1) == size_t(0));
    CHECK_FALSE(splitPlaneBetween(g.cellSets, 1, 2));  // other cells
    CHECK_FALSE(splitPlaneBetween(g.cellSets, 1, 5));  // other cells, another plane
    CHECK_FALSE(splitPlaneBetween(g.cellSets, 0, 3));  // no planes: isMergeable's case
    CHECK_FALSE(splitPlaneBetween(g.cellSets, 1, 1));

    CHECK(mergePieces(g.pieces, g.cellSets, field, 1, 4) == 1);
    CHECK(g.cellSets[1].halfSpaces.empty());  // the region of its cells again
    CHECK(g.pieces[1].shellVolumeMm3 == doctest::Approx(volume));
    size_t moved = 0;  // voxels of the piece before the cut that another owns now
    for (size_t s = 0; s < field.phi.size(); ++s) moved += owners[s] == 1 && field.owner[s] != 1 ? 1 : 0;
    CHECK(moved == 0);
    // The halves of piece 2 (now 2 and 4) are not merged by isMergeable, but by their plane.
    CHECK(splitPlaneBetween(g.cellSets, 2, 4) == size_t(0));
}

TEST_CASE("pieces: a piece whose tenon reaches past the printer is cut; the others are left as they are") {
    // Four quadrants of the 200 mm shell, each about 100 × 200 × 100 mm: all fit a 210 mm printer.
    // A tenon on piece 0 reaching 205 mm below the sphere makes it 405 mm long: longer than the
    // printer's diagonal (364 mm).
    QuadrantPieces q = quadrantPieces();
    REQUIRE(q.grouping.pieces.size() == 4);
    const TenonOptions tenonOptions;
    const Vec3d printer{210, 210, 210};
    std::vector<size_t> before(4);
    for (size_t s = 0; s < q.field.phi.size(); ++s)
        if (q.field.isActive[s] && q.field.owner[s] < 4) ++before[q.field.owner[s]];
    std::vector<std::string> messages;
    RunContext context([&](LogLevel, const std::string& m) { messages.push_back(m); }, nullptr);
    CHECK(splitOverPrinter(q.grouping.pieces, q.grouping, q.field, q.cells, tenonOptions, printer, 2.0, 0.0,
                           context) == 0);
    CHECK(messages.empty());

    Tenon far;
    far.hole = 0;
    far.axisGrid = {0, 1, 0};
    far.longSideGrid = {1, 0, 0};
    far.ballCenterGridMm = {0, -300, 0};
    far.shoulderMm = 0, far.pegTipMm = -5, far.endMm = 100;
    for (const Vec3d& x : tenonHullMm(far, tenonOptions)) CHECK(x[1] >= -305.0 - 1e-9);
    q.grouping.pieces[0].tenons = {far};
    CHECK(splitOverPrinter(q.grouping.pieces, q.grouping, q.field, q.cells, tenonOptions, printer, 2.0, 0.0,
                           context) == 1);
    REQUIRE(q.grouping.pieces.size() == 5);
    std::vector<size_t> after(5);
    for (size_t s = 0; s < q.field.phi.size(); ++s)
        if (q.field.isActive[s] && q.field.owner[s] < 5) ++after[q.field.owner[s]];
    CHECK(after[0] + after[4] == before[0]);
    for (size_t p = 1; p < 4; ++p) CHECK(after[p] == before[p]);
    REQUIRE(messages.size() == 2);
    CHECK(messages[0].find("piece 0 with its tenons") != std::string::npos);
    CHECK(messages[1].find("cut in two (0 and 4)") != std::string::npos);
}

TEST_CASE("pieces: the fit of a solid is searched on its hull's extremes") {
    // A 196 × 150 × 20 mm slab of 200,000 random points, turned about two axes: it fits a 200 mm
    // cube only nearly along its own axes.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-0.5, 0.5);
    const double c1 = std::cos(0.5), s1 = std::sin(0.5), c2 = std::cos(0.9), s2 = std::sin(0.9);
    std::vector<Vec3d> points;
    for (int i = 0; i < 200000; ++i) {
        const Vec3d p{196 * u(rng), 150 * u(rng), 20 * u(rng)};
        const Vec3d q{c1 * p[0] - s1 * p[1], s1 * p[0] + c1 * p[1], p[2]};
        points.push_back({q[0], c2 * q[1] - s2 * q[2], s2 * q[1] + c2 * q[2]});
    }
    const std::vector<Vec3d> extremes = extremePoints(points);
    CHECK(extremes.size() <= 1000);
    CHECK(extremes.size() >= 8);
    const partition::PrinterFit fit = fitOfSolid(points, {200, 200, 200}, 1.0);
    CHECK(fit.fits);
    CHECK(fit.extentsMm[2] <= 196.0 + 2.0 + 1.0);  // the longest side, margin included
    // The box is measured on every point, not on the extremes alone.
    const partition::PrinterFit same = partition::evaluateFit(points, fit.axes, {200, 200, 200}, 1.0);
    CHECK(same.extentsMm[2] == doctest::Approx(fit.extentsMm[2]));
}

TEST_CASE("pieces: every piece fits the bed less its margins and lies centred on the bed") {
    // The quadrants (about 100 × 200 × 100 mm each) stand in a 182 × 182 × 200 mm box; with 60 mm
    // margins (an 80 × 80 mm bed area) each is cut until it fits.
    const partition::PartitionResult quadrants = quadrantCells(-5.3, 10.4);
    for (const double marginMm : {9.0, 60.0}) {
        INFO("margin " << marginMm);
        Fabrication fab = printerOf({200, 200, 200});
        fab.bedMarginMm = marginMm;
        const Pieces result = makePieces(shell(), frame(), Transform4d::identity(), quadrants, fab,
                                         plainOptions(), RunContext::silent());
        CHECK(result.pieces.size() >= (marginMm > 10 ? 8u : 4u));
        for (const Piece& p : result.pieces) {
            INFO("piece " << p.id);
            const Box3d box = boundingBox(p.mesh);
            for (int a = 0; a < 2; ++a) {
                CHECK(box.min[size_t(a)] >= marginMm - 1e-3);
                CHECK(box.max[size_t(a)] <= 200.0 - marginMm + 1e-3);
                CHECK(0.5 * (box.min[size_t(a)] + box.max[size_t(a)]) ==
                      doctest::Approx(100.0).epsilon(1e-6));
            }
            CHECK(box.max[2] <= 200.0 + 1e-3);
        }
    }
    Fabrication none = printerOf({200, 200, 200});
    none.bedMarginMm = 100;
    CHECK_THROWS_AS(makePieces(shell(), frame(), Transform4d::identity(), quadrants, none, plainOptions(),
                               RunContext::silent()),
                    Error);
}

namespace {

/// A 200 × 40 × 10 mm slab as the centres of 2 mm cells (on the cells' lattice), centred at the origin.
/// Tenon candidates along hole 0 from balls at (x, 0, 0) for each x, each a ball of its own.
std::vector<TenonCandidate> candidatesAlongX(const std::vector<double>& xs) {
    std::vector<TenonCandidate> list;
    for (const double x : xs) {
        TenonCandidate c;
        c.score = 1.0;
        c.tenon.ball = zome::BallId(list.size());
        c.tenon.axisGrid = zome::holeDirection(0);
        c.tenon.ballCenterGridMm = {x, 0.0, 0.0};
        list.push_back(c);
    }
    return list;
}

std::vector<const TenonCandidate*> pointersTo(const std::vector<TenonCandidate>& list) {
    std::vector<const TenonCandidate*> out;
    for (const TenonCandidate& c : list) out.push_back(&c);
    return out;
}

CoarseCells slabCells() {
    CoarseCells slab;
    slab.cellMm = 2.0;
    for (int i = -50; i < 50; ++i)
        for (int j = -10; j < 10; ++j)
            for (int k = -2; k < 3; ++k) slab.centresMm.push_back({2.0 * i, 2.0 * j, 2.0 * k});
    return slab;
}

}  // namespace

TEST_CASE("pieces: two under-held neighbours are cut anew along a plane that holds both and fits") {
    // The union of two pieces: a 200 × 40 × 10 mm slab of 2 mm cells (centres on the cells'
    // lattice), no frame in the way (every path free). Tenon candidates along one hole at x = −80,
    // −60, 60 and 80 mm: the plane x = −1 (or x = 19, ...) leaves two to each half, and each half fits a
    // 130 mm box where the whole slab does not (not even across a diagonal).
    const CoarseCells slab = slabCells();
    const zome::Structure none;
    const FrameSweeps sweeps(none, Transform4d::identity(), Box3d{}, 1.0, 1.0);
    const int hole = 0;
    auto candidatesAt = [&](const std::vector<double>& xs) {
        std::vector<TenonCandidate> out;
        for (size_t n = 0; n < xs.size(); ++n) {
            TenonCandidate c;
            c.piece = 0;
            c.score = 1.0;
            c.tenon.ball = zome::BallId(n);
            c.tenon.hole = hole;
            c.tenon.axisGrid = zome::holeDirection(hole);
            c.tenon.ballCenterGridMm = {xs[n], 0.0, 0.0};
            c.tenon.baseMm = 0.0;
            out.push_back(c);
        }
        return out;
    };
    auto pointers = [](const std::vector<TenonCandidate>& list) {
        std::vector<const TenonCandidate*> out;
        for (const TenonCandidate& c : list) out.push_back(&c);
        return out;
    };
    SplitSearch search;
    search.voxelMm = slab.cellMm;
    search.minVolumeMm3 = 1000.0;
    search.edgeMarginMm = 6.0;
    const Vec3d box{130, 130, 130};

    const std::vector<TenonCandidate> even = candidatesAt({-80, -60, 60, 80});
    REQUIRE_FALSE(fitOfSolid(slab.centresMm, box, 1.0).fits);
    const std::vector<SplitPlane> planes =
        findHoldingSplits(slab, pointers(even), sweeps, search, box, 1.0, 2, 3).bothFit;
    REQUIRE(!planes.empty());
    CHECK(planes.size() <= 3);
    const SplitPlane* plane = &planes[0];
    size_t beyond = 0;
    for (const TenonCandidate& c : even) {
        const double side = dot(plane->normal, c.tenon.pointAt(0.0)) - plane->offsetMm;
        CHECK(std::abs(side) > search.edgeMarginMm);
        beyond += side > 0 ? 1 : 0;
    }
    CHECK(beyond == 2);  // two on each side
    // A median plane first (each half has all its two tenons; ties in plane order, the medians
    // first): through the slab's centre, within a cell.
    CHECK(std::abs(plane->offsetMm) <= slab.cellMm);
    const std::vector<SplitPlane> one =
        findHoldingSplits(slab, pointers(even), sweeps, search, box, 1.0, 2, 1).bothFit;
    REQUIRE(one.size() == 1);
    CHECK(one[0].offsetMm == plane->offsetMm);
    // Three candidates on one side and one on the other: no plane gives both halves two, one does.
    const std::vector<TenonCandidate> uneven = candidatesAt({-80, -70, -60, 70});
    CHECK(findHoldingSplits(slab, pointers(uneven), sweeps, search, box, 1.0, 2, 3).bothFit.empty());
    CHECK(!findHoldingSplits(slab, pointers(uneven), sweeps, search, box, 1.0, 1, 3).bothFit.empty());
    // Halves that hold but do not fit a 50 mm box are no answer.
    CHECK(findHoldingSplits(slab, pointers(even), sweeps, search, {50, 50, 50}, 1.0, 2, 3).bothFit.empty());
}

/// A closed spherical shell, 140 mm across with a 6 mm wall, on 2 mm cells: however it lies, the
/// top of its inside hangs over the hollow (a closed cube would not do: lying on an edge, its
/// faces lean at 45°, which prints without support).
CoarseCells closedSphereCells() {
    CoarseCells out;
    out.cellMm = 2.0;
    for (int i = -35; i <= 35; ++i)
        for (int j = -35; j <= 35; ++j)
            for (int k = -35; k <= 35; ++k) {
                const double r = 2.0 * std::sqrt(double(i * i + j * j + k * k));
                if (r >= 64.0 && r <= 70.0) out.centresMm.push_back({2.0 * i, 2.0 * j, 2.0 * k});
            }
    return out;
}

TEST_CASE("pieces: a closed shell is cut into two bowls that need little support") {
    // The closed sphere above. Cut through the middle, each half is a bowl that lies on its
    // bottom, open side up: support only under the flat of its bottom. Candidates two on each
    // side of x = 0.
    const CoarseCells box = closedSphereCells();
    const zome::Structure none;
    const FrameSweeps sweeps(none, Transform4d::identity(), Box3d{}, 1.0, 1.0);
    const std::vector<TenonCandidate> list = candidatesAlongX({-40.0, -30.0, 30.0, 40.0});
    const std::vector<const TenonCandidate*> candidates = pointersTo(list);
    SplitSearch search;
    search.minVolumeMm3 = 1000.0;
    const Fabrication printer = printerOf({200, 200, 200});
    const std::optional<SupportCut> cut = supportCut(box, candidates, sweeps, search, printer, 2);
    REQUIRE(cut.has_value());
    CAPTURE(cut->beforeMm3);
    CAPTURE(cut->afterMm3);
    CHECK(cut->beforeMm3 > 100e3);                // columns under the top of the inside
    CHECK(cut->afterMm3 < 0.4 * cut->beforeMm3);  // the bowls: under their bottoms
    // Through the middle, two candidates on each side.
    CHECK(std::abs(cut->plane.offsetMm) < 12.0);
    auto side = [&](const TenonCandidate& c) {
        return dot(cut->plane.normal, c.tenon.ballCenterGridMm) > cut->plane.offsetMm;
    };
    for (const TenonCandidate& c : list)
        CHECK(side(c) == (side(list.back()) == (c.tenon.ballCenterGridMm[0] > 0)));
    // The lower half alone is a bowl already: no cut.
    CoarseCells cup;
    cup.cellMm = 2.0;
    for (const Vec3d& x : box.centresMm)
        if (x[2] < 0.0) cup.centresMm.push_back(x);
    CHECK_FALSE(supportCut(cup, candidates, sweeps, search, printer, 2).has_value());
    // A printer too small for the halves: no cut that fits.
    CHECK_FALSE(supportCut(box, candidates, sweeps, search, printerOf({60, 60, 60}), 2).has_value());
}

TEST_CASE("pieces: a closed shell no peg holds in halves is printed in two parts glued together") {
    // The closed sphere of the case above, with no tenon candidates at all: no cut keeps both
    // halves held (supportCut), but printed in two parts glued before mounting (printSplit) they
    // need not be: the same two bowls.
    const CoarseCells box = closedSphereCells();
    const zome::Structure none;
    const FrameSweeps sweeps(none, Transform4d::identity(), Box3d{}, 1.0, 1.0);
    SplitSearch search;
    search.minVolumeMm3 = 1000.0;
    const Fabrication printer = printerOf({200, 200, 200});
    CHECK_FALSE(supportCut(box, {}, sweeps, search, printer, 2).has_value());
    const std::optional<SupportCut> parts = printSplit(box, search, printer);
    REQUIRE(parts.has_value());
    CAPTURE(parts->beforeMm3);
    CAPTURE(parts->afterMm3);
    CHECK(parts->beforeMm3 > 100e3);
    CHECK(parts->afterMm3 < 0.2 * parts->beforeMm3);
    CHECK(std::abs(parts->plane.offsetMm) < 30.0);  // through the middle or a third: two bowls
    // A bowl already: nothing to gain.
    CoarseCells cup;
    cup.cellMm = 2.0;
    for (const Vec3d& x : box.centresMm)
        if (x[2] < 0.0) cup.centresMm.push_back(x);
    CHECK_FALSE(printSplit(cup, search, printer).has_value());
}

TEST_CASE("pieces: a thin wall leaning up to 45° needs no support on cells, one leaning further does") {
    // A wall one 2 mm cell thick and 40 mm wide, 40 layers high, each layer stepped sideways by
    // @p step cells: 0 stands upright, 1 leans at 45° (what a printer bridges), 2 at 63°, whose
    // every cell but the first layer's hangs over empty space down to the bed.
    const double cell = 2.0;
    auto wall = [&](int step) {
        std::vector<Vec3d> out;
        for (int k = 0; k < 40; ++k)
            for (int j = 0; j < 20; ++j) out.push_back({cell * k * step, cell * j, cell * (k + 0.5)});
        return out;
    };
    const Vec3d up{0, 0, 1};
    CHECK(restingSupportMm3(wall(0), up, 0.0, cell) == doctest::Approx(0.0));
    CHECK(restingSupportMm3(wall(1), up, 0.0, cell) == doctest::Approx(0.0));
    // Layer k (2..39; the first above the bed leans on it) hangs 2k mm over the bed, 20 cells of
    // 4 mm² each.
    double columns = 0.0;
    for (int k = 2; k < 40; ++k) columns += cell * k * 20 * cell * cell;
    CHECK(restingSupportMm3(wall(2), up, 0.0, cell) == doctest::Approx(columns));
}

TEST_CASE("pieces: a union no plane cuts into two held pieces that fit is cut into three") {
    // The slab of the case above (200 × 40 × 10 mm) and an 80 mm printer: no half of a plane through
    // the slab fits with the other (one of them is at least 100 mm long), but three parts of about
    // 67 mm do. Candidates in pairs at x = −90, −80 | −10, 10 | 80, 90: the first plane leaves one
    // pair on its fitting side, the second cuts the rest between the other two pairs.
    const CoarseCells slab = slabCells();
    const zome::Structure none;
    const FrameSweeps sweeps(none, Transform4d::identity(), Box3d{}, 1.0, 1.0);
    const std::vector<TenonCandidate> list = candidatesAlongX({-90.0, -80.0, -10.0, 10.0, 80.0, 90.0});
    const std::vector<const TenonCandidate*> candidates = pointersTo(list);
    SplitSearch search;
    search.voxelMm = slab.cellMm;
    search.minVolumeMm3 = 1000.0;
    const Fabrication printer = printerOf({80, 80, 80});
    REQUIRE(
        findHoldingSplits(slab, candidates, sweeps, search, printer.pieceBoxMm(), printer.fitMarginMm, 2, 3)
            .bothFit.empty());
    const std::vector<PairCut> cuts = pairCuts(slab, candidates, sweeps, search, printer, 2);
    REQUIRE(!cuts.empty());
    for (const PairCut& cut : cuts) {
        REQUIRE(cut.second.has_value());
        // The three parts (0: the first plane's fitting half, 1 and 2: the large half's sides of the
        // second plane): each fits the printer and keeps two candidates clear of both planes.
        std::array<std::vector<Vec3d>, 3> byPart;
        for (const Vec3d& x : slab.centresMm) {
            const uint8_t side = dot(cut.first.normal, x) > cut.first.offsetMm ? 1 : 0;
            const size_t part =
                side != cut.secondSide ? 0 : (dot(cut.second->normal, x) > cut.second->offsetMm ? 2 : 1);
            byPart[part].push_back(x);
        }
        for (const std::vector<Vec3d>& part : byPart) {
            REQUIRE(!part.empty());
            CHECK(fitOfSolid(part, printer.pieceBoxMm(), coarseMarginMm(slab, printer.fitMarginMm)).fits);
        }
        std::array<size_t, 3> kept{0, 0, 0};
        for (const TenonCandidate& c : list) {
            const Vec3d x = c.tenon.pointAt(c.tenon.baseMm);
            const double a = dot(cut.first.normal, x) - cut.first.offsetMm;
            const uint8_t side = a > 0 ? 1 : 0;
            if (std::abs(a) < search.edgeMarginMm) continue;
            if (side != cut.secondSide) {
                ++kept[0];
                continue;
            }
            const double b = dot(cut.second->normal, x) - cut.second->offsetMm;
            if (std::abs(b) >= search.edgeMarginMm) ++kept[b > 0 ? 2 : 1];
        }
        CHECK(kept[0] == 2);
        CHECK(kept[1] == 2);
        CHECK(kept[2] == 2);
    }
    // With a printer the halves fit, two pieces: no second plane.
    const Fabrication larger = printerOf({130, 130, 130});
    const std::vector<PairCut> two = pairCuts(slab, candidates, sweeps, search, larger, 2);
    REQUIRE(!two.empty());
    CHECK(!two[0].second.has_value());
}

TEST_CASE("pieces: the support a half needs lying on its cut face, counted on its cells") {
    // 2 mm cells. A 20 × 20 mm plate two cells thick standing on the bed needs none; the same
    // plate lifted so its underside is 10 mm above the bed needs 20 × 20 × 10 mm³; a roof over
    // a floor needs the space between them only.
    const double cell = 2.0;
    auto plate = [&](double z0, int layers) {
        std::vector<Vec3d> out;
        for (int i = 0; i < 10; ++i)
            for (int j = 0; j < 10; ++j)
                for (int k = 0; k < layers; ++k) out.push_back({cell * i, cell * j, z0 + cell * (k + 0.5)});
        return out;
    };
    const Vec3d up{0, 0, 1};
    CHECK(restingSupportMm3(plate(0.0, 2), up, 0.0, cell) == doctest::Approx(0.0));
    CHECK(restingSupportMm3(plate(10.0, 2), up, 0.0, cell) == doctest::Approx(20.0 * 20.0 * 10.0));
    std::vector<Vec3d> roof = plate(0.0, 1);
    for (const Vec3d& x : plate(16.0, 1)) roof.push_back(x);
    CHECK(restingSupportMm3(roof, up, 0.0, cell) == doctest::Approx(20.0 * 20.0 * 14.0));
    // The bed is the plane up·x = offset, whichever way up points.
    std::vector<Vec3d> flipped;
    for (const Vec3d& x : plate(10.0, 2)) flipped.push_back({x[0], x[1], -x[2]});
    CHECK(restingSupportMm3(flipped, {0, 0, -1}, 0.0, cell) == doctest::Approx(20.0 * 20.0 * 10.0));
    CHECK(restingSupportMm3(plate(10.0, 2), up, 10.0, cell) == doctest::Approx(0.0));
}

/// The rotated frame's quadrants (above) on a 60 mm lattice, made into pieces with @p o: one
/// quadrant gets fewer than two pegs, and its union with a neighbour does not fit the printer.
Pieces underHeldQuadrants(const PiecesOptions& o) {
    return makePieces(shell(), makeCubeLattice(60.0), turnedFrameToGrid(), quadrantCells(-15.3, 20.4),
                      printerOf({200, 200, 200}), o, RunContext::silent());
}

TEST_CASE("pieces: --recut-pairs cuts an under-held piece anew with a neighbour, so both are held") {
    // With the default, a quadrant stays under two pegs (no merge fits the printer); with
    // isRecuttingPairs it and a neighbour are cut anew.
    PiecesOptions o;
    o.label.isEnabled = false;
    auto underHeld = [&](const Pieces& r) {
        return std::count_if(r.pieces.begin(), r.pieces.end(),
                             [&](const Piece& p) { return p.tenons.size() < size_t(o.tenons.minPerPiece); });
    };
    const Pieces plain = underHeldQuadrants(o);
    o.isRecuttingPairs = true;
    const Pieces recut = underHeldQuadrants(o);
    MESSAGE("under two pegs: " << underHeld(plain) << " of " << plain.pieces.size() << " -> "
                               << underHeld(recut) << " of " << recut.pieces.size() << ", pairs cut anew "
                               << recut.recutPairs);
    CHECK(plain.recutPairs == 0);
    CHECK(recut.recutPairs > 0);
    CHECK(underHeld(recut) < underHeld(plain));
    CHECK(recut.pieces.size() == plain.pieces.size());  // two pieces became two others
    CHECK(recut.plan.isBuildable());
    checkClosedAndFits(recut);
}

TEST_CASE("pieces: a piece too few pegs hold is glued to a neighbour before mounting, and the two are held") {
    // The under-held quadrant glued to a neighbour: the two go on as one body that two pegs or
    // more hold.
    PiecesOptions o;
    o.label.isEnabled = false;
    auto underHeldSteps = [&](const Pieces& r) {
        size_t n = 0;
        for (const mount::MountStep& step : r.plan.steps) {
            size_t pegs = 0;
            for (uint32_t p : step.pieces) pegs += r.pieces[p].tenons.size();
            n += pegs < size_t(o.tenons.minPerPiece) ? 1 : 0;
        }
        return n;
    };
    o.isGluingUnderHeld = false;
    const Pieces apart = underHeldQuadrants(o);
    o.isGluingUnderHeld = true;
    const Pieces glued = underHeldQuadrants(o);
    MESSAGE("steps under two pegs: " << underHeldSteps(apart) << " of " << apart.plan.steps.size() << " -> "
                                     << underHeldSteps(glued) << " of " << glued.plan.steps.size()
                                     << ", pairs glued " << glued.gluedForPegs);
    REQUIRE(underHeldSteps(apart) > 0);
    CHECK(apart.gluedForPegs == 0);
    CHECK(apart.plan.glued.empty());
    CHECK(glued.gluedForPegs > 0);
    CHECK(underHeldSteps(glued) < underHeldSteps(apart));
    CHECK(glued.plan.steps.size() < apart.plan.steps.size());
    CHECK(glued.plan.isBuildable());
    // The glued pieces share a step and its direction, and their pins pair up across the face.
    REQUIRE(glued.plan.glued.size() == glued.gluedForPegs);
    for (const auto& [a, b] : glued.plan.glued) {
        CHECK(glued.plan.stepOf(a) == glued.plan.stepOf(b));
        CHECK(glued.pieces[a].hole == glued.pieces[b].hole);
        CHECK(glued.pieces[a].pins.size() + glued.pieces[b].pins.size() > 0);
    }
    // Nothing else changes: the same pieces, cut the same way.
    REQUIRE(glued.pieces.size() == apart.pieces.size());
    for (size_t p = 0; p < glued.pieces.size(); ++p)
        CHECK(glued.pieces[p].shellVolumeMm3 == apart.pieces[p].shellVolumeMm3);
    checkClosedAndFits(glued);
}

TEST_CASE("pieces: the frame grows toward a piece too few pegs hold, inside the clearance, and holds it") {
    // The quadrant fixture's under-held pieces; a strut may be added where its new ball stays
    // 3 mm clear of the inner wall (the sphere is convex: the strut then does too) and collides
    // with nothing: what the frame stage's test (frame::canGrowStrut) checks on the real object.
    PiecesOptions o;
    o.label.isEnabled = false;
    o.isGluingUnderHeld = false;
    const Vec3d centreFrameMm = affineInverse(turnedFrameToGrid()).apply({0, 0, 0});
    const double maxCentreMm = kRadius - kShell - 8.85 - 3.0;
    const StrutTest canGrow = [&](const zome::Structure& s, zome::BallId a, int hole, int size) {
        if (!s.isHoleFree(a, hole)) return false;
        const zome::GoldenVector3 end = s.ball(a).position + zome::strutVector(hole, size);
        return s.findBall(end) == zome::kNoId &&
               norm(sub(s.scale().toMm(end), centreFrameMm)) <= maxCentreMm && !s.ballCollides(end) &&
               !s.strutCollides(a, hole, size);
    };
    auto underHeld = [&](const Pieces& r) {
        return std::count_if(r.pieces.begin(), r.pieces.end(),
                             [&](const Piece& p) { return p.tenons.size() < size_t(o.tenons.minPerPiece); });
    };
    const zome::Structure frame = makeCubeLattice(60.0);
    auto run = [&](const PiecesOptions& options, const StrutTest& test) {
        return makePieces(shell(), frame, turnedFrameToGrid(), quadrantCells(-15.3, 20.4),
                          printerOf({200, 200, 200}), options, RunContext::silent(), test);
    };
    const Pieces plain = run(o, {});
    const Pieces grown = run(o, canGrow);
    MESSAGE("under two pegs: " << underHeld(plain) << " of " << plain.pieces.size() << " -> "
                               << underHeld(grown) << ", struts grown " << grown.frameStrutsGrown);
    REQUIRE(underHeld(plain) > 0);
    CHECK(plain.frameStrutsGrown == 0);
    CHECK_FALSE(plain.grownFrame.has_value());
    REQUIRE(grown.grownFrame.has_value());
    CHECK(grown.frameStrutsGrown > 0);
    CHECK(underHeld(grown) < underHeld(plain));
    CHECK(grown.plan.isBuildable());
    const zome::Structure& bigger = *grown.grownFrame;
    CHECK(bigger.strutCount() == frame.strutCount() + grown.frameStrutsGrown);
    CHECK(bigger.ballCount() == frame.ballCount() + grown.frameStrutsGrown);
    CHECK(zome::findCollisions(bigger).empty());
    for (zome::BallId id : bigger.ballIds())
        CHECK(norm(sub(bigger.ball(id).positionMm, centreFrameMm)) <= maxCentreMm + 1e-6);
    // Every peg goes into a free hole of a ball of the grown frame, along its piece's direction.
    for (const Piece& p : grown.pieces)
        for (const Tenon& t : p.tenons) {
            REQUIRE(bigger.hasBall(t.ball));
            CHECK(bigger.isHoleFree(t.ball, t.hole));
            CHECK(t.hole == p.hole);
        }
    checkClosedAndFits(grown);
    // Off, the frame stays as it is even with the test.
    o.isGrowingFrame = false;
    CHECK(run(o, canGrow).frameStrutsGrown == 0);
}
