// SPDX-License-Identifier: GPL-3.0-or-later
// The greedy region merge after the fit schedule (PartitionOptions::mergeSmallRegions,
// docs/partition.md §4).
#include <doctest/doctest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <set>

#include "partition_fixtures.h"
#include "test_util.h"
#include "zomefab/partition/face_graph.h"
#include "zomefab/partition/partition.h"
#include "zomefab/partition/partition_json.h"

using namespace zomefab;
using namespace zomefab::partition;

namespace {

Vec3d toD(const Vec3f& p) { return {double(p[0]), double(p[1]), double(p[2])}; }

/// A sphere of radius 50 mm cut into four slabs by centroid z: a small cap below −40 mm (0), a
/// large band below 0 (1), a large band above 0 (2), a small cap above 40 mm (3).
struct Slabs {
    TriMesh mesh = zomefab::test::makeSphere({0, 0, 0}, 50.0, 32, 64);
    FaceGraph graph = buildFaceGraph(mesh);
    std::vector<uint32_t> regionOf;
    Slabs() {
        for (const Vec3d& c : graph.centroidsMm)
            regionOf.push_back(c[2] < -40 ? 0 : c[2] < 0 ? 1 : c[2] < 40 ? 2 : 3);
    }
    /// Do the faces of each group fit @p printerMm with @p marginMm?
    bool groupsFit(const RegionMerge& m, const Vec3d& printerMm, double marginMm) const {
        std::vector<std::vector<Vec3d>> pts(m.groupCount);
        for (size_t f = 0; f < regionOf.size(); ++f)
            for (uint32_t v : mesh.triangles[f])
                pts[m.groupOf[regionOf[f]]].push_back(toD(mesh.positions[v]));
        return std::all_of(pts.begin(), pts.end(), [&](const std::vector<Vec3d>& p) {
            return fitInPrinter(p, printerMm, marginMm).fits;
        });
    }
};

}  // namespace

TEST_CASE("region merge: small caps go into the band next to them while the union fits") {
    const Slabs s;
    // A hemisphere (100 × 100 × 50 mm, + 2 × 2 mm margin) fits 110 × 110 × 60 mm; the sphere does not.
    const Vec3d printer{110, 110, 60};
    const RegionMerge m = mergeRegionsThatFit(s.mesh, s.graph, s.regionOf, 4, printer, 2.0);
    CHECK(m.merges == 2);
    REQUIRE(m.groupCount == 2);
    CHECK(m.groupOf == std::vector<uint32_t>{0, 0, 1, 1});  // each cap with its own half
    CHECK(s.groupsFit(m, printer, 2.0));

    // A printer the whole sphere fits: everything ends as one region.
    const RegionMerge all = mergeRegionsThatFit(s.mesh, s.graph, s.regionOf, 4, {120, 120, 120}, 2.0);
    CHECK(all.merges == 3);
    CHECK(all.groupCount == 1);

    // Same result with one thread.
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    const RegionMerge m1 = mergeRegionsThatFit(s.mesh, s.graph, s.regionOf, 4, printer, 2.0);
    CHECK(m1.groupOf == m.groupOf);
}

TEST_CASE("region merge: no merge when the union would not fit the printer") {
    const Slabs s;
    // Two hemispheres: each fits 110 × 110 × 60 mm, their union (the sphere) does not.
    std::vector<uint32_t> halves(s.regionOf);
    for (uint32_t& r : halves) r = r < 2 ? 0 : 1;
    const RegionMerge m = mergeRegionsThatFit(s.mesh, s.graph, halves, 2, {110, 110, 60}, 2.0);
    CHECK(m.merges == 0);
    CHECK(m.groupCount == 2);
    CHECK(m.groupOf == std::vector<uint32_t>{0, 1});
    // The margin is part of the test: a hemisphere is 50 mm high, 54 mm with the margin.
    CHECK(mergeRegionsThatFit(s.mesh, s.graph, s.regionOf, 4, {110, 110, 52}, 2.0).merges == 0);
    CHECK(mergeRegionsThatFit(s.mesh, s.graph, s.regionOf, 4, {110, 110, 52}, 0.0).merges == 2);
    // Regions that do not touch are never merged: the two caps alone.
    std::vector<uint32_t> caps(s.regionOf.size());
    for (size_t f = 0; f < caps.size(); ++f) caps[f] = s.regionOf[f] == 0 ? 0 : s.regionOf[f] == 3 ? 1 : 2;
    const RegionMerge apart = mergeRegionsThatFit(s.mesh, s.graph, caps, 3, {110, 110, 60}, 2.0);
    CHECK(apart.groupOf[0] != apart.groupOf[1]);
}

TEST_CASE("region merge: the small bunny in a small printer ends with fewer pieces, all fitting") {
    const partition::test::MeshMm bunny =
        partition::test::loadMeshMm(zomefab::test::dataPath("bunny_npm_3674.stl"), 300.0, true);
    const partition::test::LatticeFrame frame = partition::test::makeLatticeFrame(bunny.mesh, 12.0);
    PartitionOptions o;
    Fabrication fab;
    fab.printerMm = {120, 120, 120};
    fab.bedMarginMm = 0;
    const PartitionResult merged =
        partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, o, RunContext::silent());
    PartitionOptions off = o;
    off.mergeSmallRegions = false;
    const PartitionResult plain =
        partitionSurface(bunny.mesh, frame.structure, frame.outermost, fab, off, RunContext::silent());
    CHECK(plain.regionMerges == 0);
    CHECK(merged.regionMerges > 0);
    CHECK(merged.pieces.size() < plain.pieces.size());
    for (const Piece& p : merged.pieces) CHECK(p.fit.fits);
    // Faces: each in one of its piece's cells; each piece one connected part of the surface.
    const FaceGraph g = buildFaceGraph(bunny.mesh);
    size_t foreignCell = 0, multiCell = 0;
    for (size_t f = 0; f < merged.faceCells.size(); ++f) {
        const auto& cells = merged.pieces[merged.facePieces[f]].cells;
        foreignCell += std::binary_search(cells.begin(), cells.end(), merged.faceCells[f]) ? 0 : 1;
    }
    for (const Piece& p : merged.pieces) multiCell += p.cells.size() > 1 ? 1 : 0;
    CHECK(foreignCell == 0);
    CHECK(multiCell > 0);  // merged regions keep their cells
    std::vector<uint32_t> comp;
    CHECK(labelComponents(g, merged.facePieces, comp) == merged.pieces.size());
    // Recorded in the JSON.
    const PartitionJsonInfo info{"bunny.stl", "frame.json", bunny.transformMm, bunny.mesh.positions.size()};
    CHECK(partitionToJson(merged, o, info)["counts"]["region_merges"] == merged.regionMerges);
}
