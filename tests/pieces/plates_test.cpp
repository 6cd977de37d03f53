// SPDX-License-Identifier: GPL-3.0-or-later
// The pieces on printer beds: every piece on exactly one plate, inside the bed with its margin,
// none overlapping, big pieces alone, and one 3MF per plate.
#include "zomefab/pieces/plates.h"

#include <doctest/doctest.h>

#include <filesystem>

#include "test_util.h"
#include "zomefab/core/error.h"

using namespace zomefab;
using namespace zomefab::pieces;

namespace {

/// Pieces that are boxes of the given x, y, z sizes, centred on the bed as the pieces stage leaves them.
Pieces boxPieces(const std::vector<Vec3d>& sizesMm, const Vec3d& bedMm = {200, 200, 200},
                 double marginMm = 5.0) {
    Pieces all;
    all.printerMm = bedMm;
    all.bedMarginMm = marginMm;
    for (const Vec3d& s : sizesMm) {
        Piece p;
        p.mesh = test::makeBox({-s[0] / 2, -s[1] / 2, 0}, {s[0] / 2, s[1] / 2, s[2]});
        all.pieces.push_back(std::move(p));
    }
    return all;
}

/// The placed mesh's box: what the slicer sees.
Box3d placedBox(const Pieces& all, const PlacedPiece& item) {
    TriMesh mesh = all.pieces[item.piece].mesh;
    transformInPlace(mesh, item.placementMm);
    return boundingBox(mesh);
}

/// Every piece once, inside the bed (margin kept where the plate says so), no two closer than the
/// spacing, and the reported boxes are the placed meshes' boxes.
void checkPlates(const Pieces& all, const std::vector<Plate>& plates) {
    std::vector<int> seen(all.pieces.size(), 0);
    for (const Plate& plate : plates) {
        REQUIRE(!plate.items.empty());
        std::vector<Box3d> boxes;
        for (const PlacedPiece& item : plate.items) {
            ++seen[item.piece];
            const Box3d b = placedBox(all, item);
            for (int a = 0; a < 3; ++a) {
                CHECK(b.min[size_t(a)] == doctest::Approx(item.minMm[size_t(a)]).epsilon(1e-9));
                CHECK(b.max[size_t(a)] == doctest::Approx(item.maxMm[size_t(a)]).epsilon(1e-9));
            }
            CHECK(b.min[2] == doctest::Approx(0.0));
            for (int a = 0; a < 2; ++a) {
                CHECK(b.min[size_t(a)] >= plate.edgeMm - 1e-6);
                CHECK(b.max[size_t(a)] <= all.printerMm[size_t(a)] - plate.edgeMm + 1e-6);
            }
            for (const Box3d& o : boxes) {
                const bool apart = b.min[0] >= o.max[0] + kPlateSpacingMm - 0.11 ||
                                   o.min[0] >= b.max[0] + kPlateSpacingMm - 0.11 ||
                                   b.min[1] >= o.max[1] + kPlateSpacingMm - 0.11 ||
                                   o.min[1] >= b.max[1] + kPlateSpacingMm - 0.11;
                CHECK(apart);
            }
            boxes.push_back(b);
        }
        if (plate.items.size() > 1) CHECK(plate.edgeMm >= all.bedMarginMm - 1e-6);
    }
    for (const int n : seen) CHECK(n == 1);
}

}  // namespace

TEST_CASE("packPlates: small pieces share a bed, each inside the margin") {
    // Four 80 mm squares fit one 200 mm bed (80 + 5 + 80 ≤ 190); a fifth needs a second bed.
    const Pieces four = boxPieces({{80, 80, 50}, {80, 80, 60}, {80, 80, 70}, {80, 80, 80}});
    const std::vector<Plate> one = packPlates(four);
    REQUIRE(one.size() == 1);
    CHECK(one[0].items.size() == 4);
    checkPlates(four, one);
    const Pieces five = boxPieces({{80, 80, 50}, {80, 80, 60}, {80, 80, 70}, {80, 80, 80}, {80, 80, 90}});
    const std::vector<Plate> two = packPlates(five);
    CHECK(two.size() == 2);
    checkPlates(five, two);
    CHECK(two[0].items[0].piece == 0);  // plates in the order of their first piece
}

TEST_CASE("packPlates: a piece too large for the margin is alone and centred") {
    const Pieces all = boxPieces({{195, 120, 50}, {30, 30, 30}});
    const std::vector<Plate> plates = packPlates(all);
    REQUIRE(plates.size() == 2);
    checkPlates(all, plates);
    REQUIRE(plates[0].items.size() == 1);
    CHECK(plates[0].edgeMm == doctest::Approx(2.5));  // (200 − 195) / 2
    CHECK(plates[0].items[0].minMm[0] == doctest::Approx(2.5));
    CHECK(plates[0].items[0].minMm[1] == doctest::Approx(40.0));
    CHECK(plates[1].edgeMm >= 5.0);
}

TEST_CASE("packPlates: a long piece is turned to the bed's long side") {
    // A 100 × 250 mm bed: a 200 × 60 mm piece fits only turned; turning changes no height.
    const Pieces all = boxPieces({{200, 60, 40}}, {100, 250, 200});
    const std::vector<Plate> plates = packPlates(all);
    REQUIRE(plates.size() == 1);
    CHECK(plates[0].items[0].isTurned);
    checkPlates(all, plates);
    const Box3d b = placedBox(all, plates[0].items[0]);
    CHECK(b.size()[0] == doctest::Approx(60.0));
    CHECK(b.size()[1] == doctest::Approx(200.0));
    CHECK(b.size()[2] == doctest::Approx(40.0));
}

TEST_CASE("packPlates: many mixed pieces, deterministic") {
    std::vector<Vec3d> sizes;
    for (int i = 0; i < 23; ++i) sizes.push_back({20.0 + (i * 37) % 150, 15.0 + (i * 53) % 120, 10.0 + i});
    const Pieces all = boxPieces(sizes);
    const std::vector<Plate> plates = packPlates(all);
    checkPlates(all, plates);
    double area = 0;
    for (const Vec3d& s : sizes) area += (s[0] + kPlateSpacingMm) * (s[1] + kPlateSpacingMm);
    CHECK(plates.size() <= size_t(std::ceil(area / (195.0 * 195.0))) + 2);  // not far from the area bound
    CHECK(platesToJson(all, packPlates(all)) == platesToJson(all, plates));
}

TEST_CASE("packPlates refuses a piece larger than the bed; writePlates writes one 3MF per plate") {
    CHECK_THROWS_AS(packPlates(boxPieces({{210, 50, 50}})), Error);
    const Pieces all = boxPieces({{150, 150, 20}, {150, 150, 20}, {30, 30, 30}});
    const std::vector<Plate> plates = packPlates(all);
    REQUIRE(plates.size() == 2);
    test::ScratchDir dir("zomefab-plates");
    writePlates(all, plates, dir.path());
    for (size_t k = 0; k < plates.size(); ++k)
        CHECK(test::readFile(dir.file(plateFileName(k))).substr(0, 2) == "PK");
    CHECK(plateFileName(0) == "plates/plate-01.3mf");
    CHECK(!std::filesystem::exists(dir.file(plateFileName(2))));
    const nlohmann::json j = platesToJson(all, plates);
    CHECK(j[0]["file"] == "plates/plate-01.3mf");
    CHECK(j[0]["pieces"].size() + j[1]["pieces"].size() == 3);
}
