// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The print estimator's volume model, filament conversions and the octree baseline.
#include "zomefab/report/print_estimate.h"

#include <doctest/doctest.h>

#include <cmath>

#include "report_fixtures.h"
#include "report_test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/core/fabrication.h"
#include "zomefab/report/mesh_clip.h"

using namespace zomefab;
using namespace zomefab::report;
using namespace zomefab::test;

namespace {

PrintSettings withInfill(double percent) {
    PrintSettings s;
    s.infillPercent = percent;
    return s;
}

}  // namespace

TEST_CASE("print_estimate: filament length, mass and cost") {
    // 1 m of 2.85 mm filament = π·1.425²·1000 mm³ = 6379.4 mm³ (print-estimates.md: ≈ 6.38 cm³, 7.9 g).
    const double pi = std::acos(-1.0);
    const FilamentUse one = filamentUse(pi * 1.425 * 1.425 * 1000.0, FilamentOptions{});
    CHECK(one.lengthM == doctest::Approx(1.0));
    CHECK(one.massG == doctest::Approx(7.9106).epsilon(1e-4));
    CHECK(one.costUsd == doctest::Approx(0.56));
    FilamentOptions thin;
    thin.diameterMm = 1.75;
    thin.usdPerM = 0.1;
    CHECK(filamentUse(pi * 0.875 * 0.875 * 2000.0, thin).lengthM == doctest::Approx(2.0));
    FilamentOptions bad;
    bad.diameterMm = 0.0;
    CHECK_THROWS_AS(bad.validate(), Error);
}

TEST_CASE("print_estimate: the breakdown of a 20 mm cube follows the documented model exactly") {
    const PrintEstimate e = estimatePrint(makeBox({0, 0, 0}, {20, 20, 20}), withInfill(20));
    const double pi = std::acos(-1.0);
    const double spacing = 0.45 - 0.2 * (1.0 - pi / 4.0);
    const double wall = 0.45 + 2.0 * spacing;  // 3 perimeters, horizontal thickness
    CHECK(e.perimeterMm3 == doctest::Approx(4 * 400.0 * wall));
    CHECK(e.solidMm3 == doctest::Approx(400.0 * 1.0 + 400.0 * (0.27 + 4 * 0.2)));  // top 5 layers, bottom 5
    const double interior = 8000.0 - 4 * 400.0 * wall - 400.0 * 2.07;
    CHECK(e.infillMm3 == doctest::Approx(interior * 0.2 * PrintRates{}.sparseInfillFactor));
    CHECK(e.filamentMm3 == doctest::Approx(e.perimeterMm3 + e.solidMm3 + e.infillMm3));
    CHECK(e.layers == 100);  // 0.27 + 99 × 0.2 ≥ 20
    CHECK(e.partVolumeMm3 == doctest::Approx(8000.0));
    const PrintRates r;
    CHECK(e.seconds == doctest::Approx(e.perimeterMm3 * r.perimeterSPerMm3 + e.solidMm3 * r.solidSPerMm3 +
                                       e.infillMm3 * r.sparseInfillSPerMm3));
}

TEST_CASE("print_estimate: the pieces' orientation weighs time with the estimator's defaults") {
    // pieces::PrintTimeModel{} is what orientForPrinter uses; it must be the estimator's model at
    // the default settings (20 % infill), or the pieces would be turned for another printer.
    const pieces::PrintTimeModel mine = printTimeModel(PrintSettings{});
    const pieces::PrintTimeModel theirs;
    CHECK(theirs.skin.perimeterMm == doctest::Approx(mine.skin.perimeterMm).epsilon(1e-4));
    CHECK(theirs.skin.topMm == doctest::Approx(mine.skin.topMm));
    CHECK(theirs.skin.bottomMm == doctest::Approx(mine.skin.bottomMm));
    CHECK(theirs.skin.marginMm == doctest::Approx(mine.skin.marginMm));
    CHECK(theirs.skin.maxSlopeTan == doctest::Approx(mine.skin.maxSlopeTan).epsilon(1e-4));
    // Perimeters: PrusaSlicer's rate in a thin wall, below the estimator's fit over thick parts.
    CHECK(theirs.perimeterSPerMm3 < mine.perimeterSPerMm3);
    CHECK(theirs.solidSPerMm3 == doctest::Approx(mine.solidSPerMm3));
    CHECK(theirs.interiorSPerMm3 == doctest::Approx(mine.interiorSPerMm3));
    // The same model: skinSeconds is estimatePrint's time without supports.
    const TriMesh sphere = makeSphere({0, 0, 30}, 30);
    CHECK(pieces::skinSeconds(sphere, {0, 0, 1}, mine) ==
          doctest::Approx(estimatePrint(sphere, PrintSettings{}).seconds));
    // A 2.4 mm plate prints faster standing than lying (PrusaSlicer: 1.9 h against 3.2 h for
    // 100 × 100 mm): perimeters rather than slow solid layers.
    const TriMesh plate = makeBox({0, 0, 0}, {100, 100, 2.4});
    const double lying = pieces::skinSeconds(plate, {0, 0, 1}),
                 standing = pieces::skinSeconds(plate, {1, 0, 0});
    CHECK(lying > 1.15 * standing);
    CHECK(lying / 3600.0 == doctest::Approx(3.2).epsilon(0.15));
    CHECK(standing / 3600.0 == doctest::Approx(1.9).epsilon(0.15));
}

TEST_CASE("print_estimate: solid parts use all their volume; thin walls are all shell") {
    const TriMesh cube = makeBox({0, 0, 0}, {50, 50, 50});
    const PrintEstimate solid = estimatePrint(cube, withInfill(100));
    CHECK(solid.filamentMm3 == doctest::Approx(125000.0));
    // A 1 mm plate and a hollow cube with 1 mm walls: perimeters and solid layers fill them.
    for (const TriMesh& thin : {makeBox({0, 0, 0}, {100, 100, 1}), hollowCube(60, 1)}) {
        const PrintEstimate e = estimatePrint(thin, withInfill(20));
        CHECK(e.infillMm3 == doctest::Approx(0.0));
        CHECK(e.filamentMm3 == doctest::Approx(signedVolume(thin)));
    }
}

TEST_CASE("print_estimate: more infill costs more, and moving a part changes nothing") {
    const TriMesh sphere = makeSphere({0, 0, 30}, 30);
    double lastSeconds = 0.0, lastMm3 = 0.0;
    for (double infill : {10.0, 20.0, 50.0, 100.0}) {
        const PrintEstimate e = estimatePrint(sphere, withInfill(infill));
        CHECK(e.seconds > lastSeconds);
        CHECK(e.filamentMm3 > lastMm3);
        lastSeconds = e.seconds, lastMm3 = e.filamentMm3;
    }
    TriMesh moved = sphere;
    for (Vec3f& p : moved.positions) p[0] += 100.0f, p[1] -= 40.0f, p[2] += 250.0f;
    const PrintEstimate a = estimatePrint(sphere, withInfill(20)), b = estimatePrint(moved, withInfill(20));
    CHECK(b.seconds == doctest::Approx(a.seconds).epsilon(1e-5));
    CHECK(b.filamentMm3 == doctest::Approx(a.filamentMm3).epsilon(1e-5));
}

TEST_CASE("print_estimate: invalid settings are usage errors") {
    CHECK_THROWS_AS(estimatePrint(makeBox({0, 0, 0}, {1, 1, 1}), withInfill(0)), Error);
    CHECK_THROWS_AS(estimatePrint(makeBox({0, 0, 0}, {1, 1, 1}), withInfill(120)), Error);
    PrintSettings s;
    s.layerHeightMm = -0.2;
    CHECK_THROWS_AS(s.validate(), Error);
}

TEST_CASE("print_estimate: fitsPrinter tries the axis permutations") {
    CHECK(boxFitsPrinter({250, 100, 100}, {100, 100, 250}));
    CHECK(boxFitsPrinter({200, 200, 200}, {200, 200, 200}));
    CHECK_FALSE(boxFitsPrinter({201, 10, 10}, {200, 200, 200}));
    CHECK(boxFitsPrinter({150, 150, 10}, {100, 200, 200}));  // 10 mm along the 100 mm side
    CHECK_FALSE(boxFitsPrinter({150, 150, 150}, {100, 200, 200}));
}

TEST_CASE("print_estimate: parts are turned onto their largest flat face") {
    // The lower half of a sphere has its cap on top and a pole at the bottom: turned over.
    const TriMesh lower = clipByPlane(makeSphere({0, 0, 0}, 30, 31, 64), 2, 0.0, true);
    const TriMesh turned = orientOnBed(lower, {200, 200, 200});
    CHECK(isClosedOriented(turned));
    CHECK(signedVolume(turned) == doctest::Approx(signedVolume(lower)).epsilon(1e-6));
    const Box3d b = boundingBox(turned);
    CHECK(b.min[2] == 0.0);
    double bedArea = 0.0;
    for (const Triangle& t : turned.triangles)
        if (turned.positions[t[0]][2] == 0.0f && turned.positions[t[1]][2] == 0.0f &&
            turned.positions[t[2]][2] == 0.0f)
            bedArea += surfaceArea(TriMesh{
                {turned.positions[t[0]], turned.positions[t[1]], turned.positions[t[2]]}, {{0, 1, 2}}, {}});
    CHECK(bedArea == doctest::Approx(std::acos(-1.0) * 900.0).epsilon(0.01));  // the cap, r = 30 mm
    // The upper half already has its cap down: only moved to z = 0.
    const TriMesh upper = clipByPlane(makeSphere({0, 0, 0}, 30, 31, 64), 2, 0.0, false);
    CHECK(orientOnBed(upper, {200, 200, 200}).triangles == upper.triangles);
    CHECK(boundingBox(orientOnBed(upper, {200, 200, 200})).size()[2] ==
          doctest::Approx(boundingBox(upper).size()[2]));
    // A box lies on its largest face, unless only standing fits the printer.
    CHECK(boundingBox(orientOnBed(makeBox({0, 0, 0}, {150, 50, 190}), {200, 200, 200})).size()[2] == 50.0);
    CHECK(boundingBox(orientOnBed(makeBox({0, 0, 0}, {150, 50, 190}), {200, 200, 60})).size()[2] == 50.0);
    CHECK(boundingBox(orientOnBed(makeBox({0, 0, 0}, {150, 50, 190}), {160, 160, 200})).size()[2] == 190.0);
    CHECK(boundingBox(orientOnBed(makeBox({0, 0, 0}, {150, 190, 50}), {160, 160, 200})).size()[2] == 190.0);
}

TEST_CASE("print_estimate: the octree baseline cuts until every part fits, and keeps the volume") {
    SUBCASE("a long box becomes eight octants") {
        const TriMesh box = makeBox({0, 0, 0}, {300, 100, 100});
        const std::vector<TriMesh> parts = octreeParts(box, {200, 200, 200});
        REQUIRE(parts.size() == 8);
        double volume = 0.0;
        for (const TriMesh& p : parts) {
            CHECK(isClosedOriented(p));
            CHECK(boxFitsPrinter(boundingBox(p).size(), {200, 200, 200}));
            volume += signedVolume(p);
        }
        CHECK(volume == doctest::Approx(3e6).epsilon(1e-6));
    }
    SUBCASE("a part that fits stays whole") {
        CHECK(octreeParts(makeBox({0, 0, 0}, {150, 50, 190}), {200, 200, 200}).size() == 1);
    }
    SUBCASE("the bunny at 400 mm") {
        const TriMesh bunny = bunnyMm(400);
        const std::vector<TriMesh> parts = octreeParts(bunny, {200, 200, 200});
        CHECK(parts.size() >= 2);
        double volume = 0.0;
        for (const TriMesh& p : parts) {
            CHECK(isClosedOriented(p));
            CHECK(boxFitsPrinter(boundingBox(p).size(), {200, 200, 200}));
            volume += signedVolume(p);
        }
        CHECK(volume == doctest::Approx(signedVolume(bunny)).epsilon(1e-4));
    }
    CHECK_THROWS_AS(octreeParts(makeBox({0, 0, 0}, {10, 10, 10}), {0, 200, 200}), Error);
}

TEST_CASE("print_estimate: supports under an overhang, none under a cube on the bed") {
    // A table: a 10 mm stem carrying a 40 × 40 × 5 mm top 30 mm up. Its top's underside overhangs.
    TriMesh table = makeBox({15, 15, 0}, {25, 25, 30});
    appendMesh(table, makeBox({0, 0, 30}, {40, 40, 35}));
    PrintSettings s;
    s.supports = true;
    const PrintRates rates;
    const PrintEstimate withSupport = estimatePrint(table, s);
    // The columns under the top, 30 mm tall on the 40 × 40 mm footprint outlined by 160 mm (the
    // stem's top meets the top's underside: its cells count as overhang too), sampled on a 2 mm
    // grid; the support filament is SupportModel's of those three.
    const pieces::SupportEstimate columns =
        pieces::estimateSupport(table, {0, 0, -1}, s.overhangDeg, rates.support);
    CHECK(columns.footprintMm2 == doctest::Approx(1600).epsilon(0.1));
    CHECK(columns.edgeMm == doctest::Approx(160).epsilon(0.1));
    CHECK(columns.volumeMm3 == doctest::Approx(1600 * 30).epsilon(0.1));
    CHECK(withSupport.supportMm3 ==
          doctest::Approx(pieces::supportFilamentMm3(columns.footprintMm2, columns.edgeMm, columns.volumeMm3,
                                                     rates.support)));
    // 2.6 mm of interface over the footprint, 11.5 % of the columns, a 0.63 mm sheath round them.
    CHECK(withSupport.supportMm3 ==
          doctest::Approx(2.6 * 1600 + 0.115 * 48000 + 0.63 * 160 * 30).epsilon(0.1));
    s.supports = false;
    const PrintEstimate without = estimatePrint(table, s);
    CHECK(without.supportMm3 == 0.0);
    CHECK(withSupport.filamentMm3 == doctest::Approx(without.filamentMm3 + withSupport.supportMm3));
    CHECK(withSupport.seconds ==
          doctest::Approx(without.seconds + withSupport.supportMm3 * rates.supportSPerMm3));
    s.supports = true;
    CHECK(estimatePrint(makeBox({0, 0, 0}, {40, 40, 40}), s).supportMm3 == 0.0);
}
