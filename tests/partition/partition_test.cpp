// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/partition.h"

#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>

#include "partition_fixtures.h"
#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/partition/alpha_expansion.h"
#include "zomefab/partition/face_graph.h"
#include "zomefab/partition/partition_json.h"

using namespace zomefab;
using namespace zomefab::partition;

namespace {

/// A frame of balls at i·B0 along x, y, z for the given lattice points (no struts needed here).
zome::Structure ballsAt(const std::vector<std::array<int, 3>>& points) {
    zome::Structure s;
    for (const auto& p : points)
        s.addBall({zome::Golden{2 * p[0], 2 * p[0]}, zome::Golden{2 * p[1], 2 * p[1]},
                   zome::Golden{2 * p[2], 2 * p[2]}});
    return s;
}

Vec3d toD(const Vec3f& p) { return {double(p[0]), double(p[1]), double(p[2])}; }

/// Invariants every result must satisfy.
void checkResult(const TriMesh& mesh, const PartitionResult& r) {
    const size_t n = mesh.triangles.size();
    REQUIRE(r.faceCells.size() == n);
    REQUIRE(r.facePieces.size() == n);
    REQUIRE(r.graphCutLabels.size() == n);
    // Energy: the graph cut never goes up and ends below the nearest-ball labelling.
    for (size_t i = 1; i < r.sweepEnergies.size(); ++i) CHECK(r.sweepEnergies[i] <= r.sweepEnergies[i - 1]);
    CHECK(r.energyGraphCut <= r.energyNearest);
    // Faces: each in the cell of its centroid, and that cell one of its piece's cells.
    const FaceGraph g = buildFaceGraph(mesh);
    size_t wrongCell = 0, foreignCell = 0;
    for (size_t f = 0; f < n; ++f) {
        wrongCell += r.faceCells[f] != r.cells.cellAt(g.centroidsMm[f]) ? 1 : 0;
        const auto& cells = r.pieces[r.facePieces[f]].cells;
        foreignCell += std::binary_search(cells.begin(), cells.end(), r.faceCells[f]) ? 0 : 1;
    }
    CHECK(wrongCell == 0);
    CHECK(foreignCell == 0);
    // Pieces: each one connected part of the surface, fitting the printer in its reported pose.
    std::vector<uint32_t> comp;
    CHECK(labelComponents(g, r.facePieces, comp) == r.pieces.size());
    std::vector<std::vector<Vec3d>> pts(r.pieces.size());
    for (size_t f = 0; f < n; ++f)
        for (uint32_t v : mesh.triangles[f]) pts[r.facePieces[f]].push_back(toD(mesh.positions[v]));
    Vec3d printer = r.printerMm;
    std::sort(printer.begin(), printer.end());
    for (size_t p = 0; p < r.pieces.size(); ++p) {
        const PrinterFit& fit = r.pieces[p].fit;
        CHECK(fit.fits);
        Vec3d e = fit.extentsMm;
        std::sort(e.begin(), e.end());
        for (int a = 0; a < 3; ++a) CHECK(e[size_t(a)] <= printer[size_t(a)] + 1e-9);
        // Every vertex inside the reported box (shrunk by the margin).
        for (int a = 0; a < 3; ++a) {
            const Vec3d& ax = fit.axes[size_t(a)];
            const double c = ax[0] * fit.centerMm[0] + ax[1] * fit.centerMm[1] + ax[2] * fit.centerMm[2];
            double worst = 0.0;
            for (const Vec3d& q : pts[p])
                worst = std::max(worst, std::abs(ax[0] * q[0] + ax[1] * q[1] + ax[2] * q[2] - c));
            CHECK(worst <= 0.5 * fit.extentsMm[size_t(a)] - r.fitMarginMm + 1e-6);
        }
    }
}

/// Do the faces flagged in @p salient lie in one piece, with every corner in that piece's cells?
bool isKeptWhole(const TriMesh& mesh, const PartitionResult& r, const std::vector<uint8_t>& salient) {
    std::set<uint32_t> pieces;
    for (size_t f = 0; f < salient.size(); ++f)
        if (salient[f]) pieces.insert(r.facePieces[f]);
    if (pieces.size() != 1) return false;
    const auto& cells = r.pieces[*pieces.begin()].cells;
    for (size_t f = 0; f < salient.size(); ++f)
        if (salient[f])
            for (uint32_t v : mesh.triangles[f])
                if (!std::binary_search(cells.begin(), cells.end(), r.cells.cellAt(toD(mesh.positions[v]))))
                    return false;
    return true;
}

}  // namespace

TEST_CASE("partition: a salient belt across the natural seam is never cut") {
    // A sphere of radius 100 mm with a ball 47.3 mm either side of x = 0: the nearest-ball and
    // graph-cut seam is the great circle x = 0. The printer (210 × 210 × 150) cannot take the
    // whole sphere, so there must be a seam. The salient belt |x| < 20 mm lies right on it.
    TriMesh sphere = zomefab::test::makeSphere({0, 0, 0}, 100.0, 48, 96);
    const zome::Structure frame = ballsAt({{-1, 0, 0}, {1, 0, 0}});
    PartitionOptions o;
    Fabrication fab;
    fab.printerMm = {210, 210, 150};
    fab.bedMarginMm = 0;  // the printer itself is the box a piece fits (Fabrication::pieceBoxMm)
    std::vector<uint8_t> belt(sphere.triangles.size(), 0);
    for (size_t f = 0; f < belt.size(); ++f) {
        double x = 0;
        for (uint32_t v : sphere.triangles[f]) x += sphere.positions[v][0] / 3.0;
        belt[f] = std::abs(x) < 20.0 ? 1 : 0;
    }

    // Without saliency the seam runs through the belt: the case tempts the cut.
    const PartitionResult plain = partitionSurface(sphere, frame, {0, 1}, fab, o, RunContext::silent());
    checkResult(sphere, plain);
    CHECK(plain.pieces.size() == 2);
    CHECK_FALSE(isKeptWhole(sphere, plain, belt));

    // Marked in the mesh (as a PLY `salient` property would), the belt stays in one piece.
    sphere.salientFaces = belt;
    const PartitionResult kept = partitionSurface(sphere, frame, {0, 1}, fab, o, RunContext::silent());
    checkResult(sphere, kept);
    CHECK(kept.salientRegions == 1);
    CHECK(kept.salientRegionsSplit == 0);
    CHECK(kept.pieces.size() == 2);
    CHECK(isKeptWhole(sphere, kept, belt));

    // Without the retraining rounds, a crossed belt is either merged into one piece or reported:
    // never crossed silently.
    {
        PartitionOptions noRetry = o;
        noRetry.salientRetries = 0;
        RunContext log;
        const PartitionResult r = partitionSurface(sphere, frame, {0, 1}, fab, noRetry, log);
        const bool isWarned = !log.warnings().empty();
        CHECK((isKeptWhole(sphere, r, belt) ? r.salientRegionsSplit == 0 && !isWarned
                                            : r.salientRegionsSplit == 1 && isWarned));
    }

    // The same belt given as a list of face indices.
    sphere.salientFaces.clear();
    {
        PartitionOptions byIndex = o;
        for (uint32_t f = 0; f < belt.size(); ++f)
            if (belt[f]) byIndex.salientFaceIndices.push_back(f);
        const PartitionResult r = partitionSurface(sphere, frame, {0, 1}, fab, byIndex, RunContext::silent());
        CHECK(r.salientFaces == belt);
        CHECK(isKeptWhole(sphere, r, belt));
    }

    // A sphere of saliency where the seam would cross the top.
    PartitionOptions bySphere = o;
    bySphere.salientSpheres.push_back({{0, 0, 100}, 30.0});
    const PartitionResult capped =
        partitionSurface(sphere, frame, {0, 1}, fab, bySphere, RunContext::silent());
    checkResult(sphere, capped);
    const std::vector<uint8_t> cap = salientFaceFlags(sphere, bySphere.salientSpheres, {});
    CHECK(std::count(cap.begin(), cap.end(), uint8_t(1)) > 20);
    CHECK(capped.salientFaces == cap);
    CHECK(isKeptWhole(sphere, capped, cap));
    CHECK_FALSE(isKeptWhole(sphere, plain, cap));
}

TEST_CASE("partition: small bunny, energies, pieces, determinism across thread counts") {
    const partition::test::MeshMm bunny =
        partition::test::loadMeshMm(zomefab::test::dataPath("bunny_npm_3674.stl"), 300.0, true);
    const partition::test::LatticeFrame frame = partition::test::makeLatticeFrame(bunny.mesh, 12.0);
    REQUIRE(frame.outermost.size() >= 8);
    PartitionOptions o;
    Fabrication fab;
    fab.printerMm = {120, 120, 120};  // forces several pieces on a 300 mm bunny
    fab.bedMarginMm = 0;              // the printer itself is the box a piece fits (Fabrication::pieceBoxMm)
    const PartitionResult r =
        partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, o, RunContext::silent());
    checkResult(bunny.mesh, r);
    CHECK(r.graphCutPartitions < r.nearestPartitions);
    CHECK(r.energyGraphCut < r.energyNearest);
    CHECK(r.pieces.size() >= 4);
    CHECK(r.cells.cellCount() >= 2);
    CHECK(r.svmAgreement > 0.8);
    for (const Piece& p : r.pieces) CHECK_FALSE(p.balls.empty());
    // The cells of a real result: sampled points of the mesh's bounding box each lie in exactly
    // one cell (argmax with a strict winner), and segments between points of one cell stay in it.
    {
        const Box3d box = boundingBox(bunny.mesh);
        std::mt19937 rng(5);
        std::vector<std::vector<Vec3d>> members(r.cells.cellCount());
        size_t ambiguous = 0;
        for (int i = 0; i < 20000; ++i) {
            Vec3d x;
            for (int a = 0; a < 3; ++a)
                x[size_t(a)] =
                    std::uniform_real_distribution<double>(box.min[size_t(a)], box.max[size_t(a)])(rng);
            int winners = 0;
            double best = -1e300;
            for (uint32_t k = 0; k < r.cells.cellCount(); ++k) best = std::max(best, r.cells.score(k, x));
            for (uint32_t k = 0; k < r.cells.cellCount(); ++k) winners += r.cells.score(k, x) == best ? 1 : 0;
            ambiguous += winners == 1 ? 0 : 1;
            members[r.cells.cellAt(x)].push_back(x);
        }
        CHECK(ambiguous == 0);
        size_t outside = 0;
        for (uint32_t k = 0; k < r.cells.cellCount(); ++k)
            for (size_t i = 0; i + 1 < members[k].size(); ++i) {
                const Vec3d& a = members[k][i];
                const Vec3d& b = members[k][i + 1];
                const Vec3d mid{0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1]), 0.5 * (a[2] + b[2])};
                outside += r.cells.cellAt(mid) == k ? 0 : 1;
            }
        CHECK(outside == 0);
    }
    // The schedule lowers w_smoothness by 10× per step and records each.
    for (size_t i = 1; i < r.schedule.size(); ++i)
        CHECK(r.schedule[i].smoothnessWeight == doctest::Approx(0.1 * r.schedule[i - 1].smoothnessWeight));
    CHECK(r.schedule.front().smoothnessWeight == 10.0);

    // Byte-identical JSON with one thread and with two.
    const PartitionJsonInfo info{"bunny.stl", "frame.json", bunny.transformMm, bunny.mesh.positions.size()};
    std::string one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = partitionToJson(partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, o,
                                               RunContext::silent()),
                              o, info)
                  .dump();
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = partitionToJson(partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, o,
                                               RunContext::silent()),
                              o, info)
                  .dump();
    }
    CHECK(one == two);
    CHECK(one == partitionToJson(r, o, info).dump());
}

TEST_CASE("partition: bunny at 400 mm, every piece fits 200 mm cubed") {
    const partition::test::MeshMm bunny =
        partition::test::loadMeshMm(zomefab::test::dataPath("bunny_cgal_75k.stl"), 400.0, true);
    const partition::test::LatticeFrame frame = partition::test::makeLatticeFrame(bunny.mesh, 12.0);
    const PartitionResult r = partitionSurface(bunny.mesh, frame.structure, frame.outermost, Fabrication{},
                                               {}, RunContext::silent());
    checkResult(bunny.mesh, r);
    CHECK(r.printerMm == Vec3d{200, 200, 200});
    CHECK(r.pieces.size() >= 3);  // a 400 mm bunny does not fit a 200 mm printer in fewer
    CHECK(r.graphCutPartitions < r.nearestPartitions);
}

TEST_CASE("partition: when the schedule bottoms out, oversized partitions are split") {
    // One ball in a 120 mm sphere and a 60 mm printer: no w_smoothness can help (one label), so the
    // schedule bottoms out and the partition is split until every piece fits.
    const TriMesh sphere = zomefab::test::makeSphere({0, 0, 0}, 60.0, 32, 64);
    const zome::Structure frame = ballsAt({{0, 0, 0}});
    PartitionOptions o;
    Fabrication fab;
    fab.printerMm = {70, 70, 70};
    fab.bedMarginMm = 0;  // the printer itself is the box a piece fits (Fabrication::pieceBoxMm)
    RunContext quiet;
    const PartitionResult r = partitionSurface(sphere, frame, {0}, fab, o, quiet);
    checkResult(sphere, r);
    CHECK(r.isScheduleBottomedOut);
    CHECK(r.splits >= 1);
    CHECK(r.pieces.size() >= 4);
    CHECK(r.schedule.back().smoothnessWeight == doctest::Approx(o.smoothnessMin));
    bool isSaid = false;
    for (const std::string& w : quiet.warnings())
        isSaid = isSaid || w.find("bottomed out") != std::string::npos;
    CHECK(isSaid);
    for (const Piece& p : r.pieces) CHECK(p.balls == std::vector<zome::BallId>{0});
}

TEST_CASE("partition: bad inputs fail with clear messages") {
    const TriMesh sphere = zomefab::test::makeSphere({0, 0, 0}, 100.0, 16, 32);
    const zome::Structure frame = ballsAt({{-1, 0, 0}, {1, 0, 0}});
    auto fails = [&](const zome::Structure& s, const std::vector<zome::BallId>& labels,
                     const PartitionOptions& o, ErrorCode code, const std::string& text,
                     const Fabrication& fab = {}) {
        try {
            partitionSurface(sphere, s, labels, fab, o, RunContext::silent());
            FAIL("no error for: " << text);
        } catch (const Error& e) {
            CHECK(e.code() == code);
            CHECK_MESSAGE(std::string(e.what()).find(text) != std::string::npos, e.what());
        }
    };
    fails(frame, {}, {}, ErrorCode::InvalidInput, "no outermost balls");
    fails(zome::Structure{}, {}, {}, ErrorCode::InvalidInput, "no balls at all");
    fails(frame, {0, 7}, {}, ErrorCode::InvalidInput, "label ball 7 is not a ball of the frame");
    Fabrication tiny;
    tiny.printerMm = {10, 200, 200};
    tiny.bedMarginMm = 0;
    fails(frame, {0, 1}, {}, ErrorCode::Usage, "smaller than a Zome ball", tiny);
    CHECK_THROWS_AS(checkPartitionOptions({}, tiny), Error);
    // A frame for another mesh: a ball 20 B0 away.
    const zome::Structure far = ballsAt({{-1, 0, 0}, {20, 0, 0}});
    fails(far, {0, 1}, {}, ErrorCode::InvalidInput, "frame and mesh do not match");
    PartitionOptions badIndex;
    badIndex.salientFaceIndices = {uint32_t(sphere.triangles.size())};
    fails(frame, {0, 1}, badIndex, ErrorCode::Usage, "out of range");
    PartitionOptions noK;
    noK.candidateCount = 0;
    fails(frame, {0, 1}, noK, ErrorCode::Usage, "k (candidate labels");
    // An empty mesh.
    CHECK_THROWS_AS(partitionSurface(TriMesh{}, frame, {0, 1}, Fabrication{}, {}, RunContext::silent()),
                    Error);
}

TEST_CASE("partition: partitions that fit at a high w_smoothness are kept while the others are cut again") {
    // The small bunny at 300 mm in a 120 mm printer: the first cut (w_smoothness 10) leaves some
    // partitions that fit and some that do not. Only the latter may be cut again at lower weights;
    // the paper's schedule (every step re-cuts the whole surface) would relabel all of them.
    const partition::test::MeshMm bunny =
        partition::test::loadMeshMm(zomefab::test::dataPath("bunny_npm_3674.stl"), 300.0, true);
    const partition::test::LatticeFrame frame = partition::test::makeLatticeFrame(bunny.mesh, 12.0);
    PartitionOptions o;
    o.mountBlockedShare = -1.0;  // the printer alone decides what fits (tests/partition/mount_fit_test.cpp)
    Fabrication fab;
    fab.printerMm = {120, 120, 120};
    fab.bedMarginMm = 0;  // the printer itself is the box a piece fits (Fabrication::pieceBoxMm)
    const PartitionResult r =
        partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, o, RunContext::silent());
    checkResult(bunny.mesh, r);

    // The first step alone: its labelling, and which of its regions fit the printer.
    PartitionOptions firstOnly = o;
    firstOnly.smoothnessMin = o.smoothnessStart;
    const PartitionResult r10 =
        partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, firstOnly, RunContext::silent());
    REQUIRE(r10.schedule.size() == 1);
    const FaceGraph g = buildFaceGraph(bunny.mesh);
    std::vector<uint32_t> compOf;
    const uint32_t compCount = labelComponents(g, r10.graphCutLabels, compOf);
    std::vector<std::vector<Vec3d>> pts(compCount);
    for (size_t f = 0; f < compOf.size(); ++f)
        for (uint32_t v : bunny.mesh.triangles[f]) pts[compOf[f]].push_back(toD(bunny.mesh.positions[v]));
    std::vector<char> fits(compCount);
    size_t fitCount = 0, fitFaces = 0;
    for (uint32_t c = 0; c < compCount; ++c) {
        fits[c] = fitInPrinter(pts[c], fab.printerMm, fab.fitMarginMm).fits ? 1 : 0;
        fitCount += size_t(fits[c]);
    }
    // The case exercises the refinement: some regions fit at w_smoothness 10, some do not.
    REQUIRE(fitCount >= 1);
    REQUIRE(fitCount < compCount);
    REQUIRE(r.schedule.size() >= 2);
    CHECK(r.schedule[0].kept == fitCount);
    CHECK(r.schedule[0].faces == bunny.mesh.triangles.size());
    for (size_t f = 0; f < compOf.size(); ++f) fitFaces += size_t(fits[compOf[f]]);
    CHECK(r.schedule[1].faces == bunny.mesh.triangles.size() - fitFaces);
    for (size_t i = 1; i < r.schedule.size(); ++i) CHECK(r.schedule[i].faces <= r.schedule[i - 1].faces);

    // Every face of a region that fit at w_smoothness 10 keeps its label from there.
    auto changedFaces = [&](const PartitionResult& result) {
        size_t changed = 0;
        for (size_t f = 0; f < compOf.size(); ++f)
            changed += (fits[compOf[f]] && result.graphCutLabels[f] != r10.graphCutLabels[f]) ? 1 : 0;
        return changed;
    };
    CHECK(changedFaces(r) == 0);

    // The paper's schedule re-cuts them (the check above tells the two apart) and ends with more
    // pieces.
    PartitionOptions whole = o;
    whole.refineOversizedOnly = false;
    const PartitionResult rw =
        partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, whole, RunContext::silent());
    checkResult(bunny.mesh, rw);
    CHECK(changedFaces(rw) > 0);
    CHECK(r.pieces.size() < rw.pieces.size());
}
