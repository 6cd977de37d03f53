// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The Table 1 report: assembly time model, savings arithmetic, JSON and Markdown.
#include "zomefab/report/cost_report.h"

#include <doctest/doctest.h>

#include <cmath>

#include "report_fixtures.h"
#include "zomefab/core/error.h"
#include "zomefab/report/mesh_clip.h"

using namespace zomefab;
using namespace zomefab::report;
using namespace zomefab::test;

namespace {

zome::PartsList bunnyParts() {
    // The paper's Table 2, bunny row: 215 B0, 266 Y0, 126 balls.
    zome::PartsList p;
    p.balls = 126;
    p.struts[size_t(zome::Color::Blue)][0] = 215;
    p.struts[size_t(zome::Color::Yellow)][0] = 266;
    return p;
}

/// A 300 mm sphere and its 16 mm shell cut into eight octant pieces.
struct SphereCase {
    TriMesh object = makeSphere({0, 0, 150}, 150, 48, 96);
    std::vector<TriMesh> pieces;
    SphereCase() {
        const TriMesh shell = sphereShell({0, 0, 150}, 150, 16, 48, 96);
        for (int i = 0; i < 8; ++i) {
            Box3d b;
            b.min = {i & 1 ? 0.0 : -200.0, i & 2 ? 0.0 : -200.0, i & 4 ? 150.0 : -50.0};
            b.max = {i & 1 ? 200.0 : 0.0, i & 2 ? 200.0 : 0.0, i & 4 ? 350.0 : 150.0};
            pieces.push_back(clipToBox(shell, b));
        }
    }
};

}  // namespace

TEST_CASE("cost_report: assembly time is 32 s per part, fitted to the paper's Table 1") {
    // Bunny (Table 2): 481 struts + 126 balls = 607 parts → 5.40 h.
    CHECK(assemblyHours(bunnyParts()) == doctest::Approx(607 * 32.0 / 3600.0));
    // The paper's Moai (252 struts, 73 balls) took 2.5 h; the model gives 2.89 h.
    zome::PartsList moai;
    moai.balls = 73;
    moai.struts[0][0] = 112;
    moai.struts[1][0] = 140;
    CHECK(assemblyHours(moai) == doctest::Approx(2.89).epsilon(0.01));
    AssemblyTimeOptions slow;
    slow.secondsPerStrut = 60;
    slow.secondsPerBall = 0;
    CHECK(assemblyHours(moai, slow) == doctest::Approx(252 * 60 / 3600.0));
}

TEST_CASE("cost_report: hollow and solid cases against the octree baseline") {
    const SphereCase sphere;
    const zome::PartsList parts = bunnyParts();
    const CostReport r = costReport(sphere.object, test::pointersTo(sphere.pieces), parts, Fabrication{});
    REQUIRE(r.cases.size() == 2);
    CHECK(r.pieceCount == 8);
    CHECK(r.baselinePartCount == 8);  // 300 mm on a 200 mm printer: one octree level
    CHECK(r.piecesVolumeMm3 < r.objectVolumeMm3);

    const CostCase& hollow = r.cases[0];
    const CostCase& solid = r.cases[1];
    CHECK(hollow.name == "hollow");
    CHECK(hollow.infillPercent == 20.0);
    CHECK(solid.name == "solid");
    for (const CostCase* c : {&hollow, &solid}) {
        // One estimate per piece, summing to the case's total; grams from each piece's filament.
        REQUIRE(c->pieces.size() == sphere.pieces.size());
        double seconds = 0, mm3 = 0, grams = 0;
        for (const PieceCost& p : c->pieces) {
            CHECK(p.print.seconds > 0);
            CHECK(p.filament.massG > 0);
            seconds += p.print.seconds, mm3 += p.print.filamentMm3, grams += p.filament.massG;
        }
        CHECK(seconds == doctest::Approx(c->zomefab.print.seconds));
        CHECK(mm3 == doctest::Approx(c->zomefab.print.filamentMm3));
        CHECK(grams == doctest::Approx(c->zomefab.filament.massG));
        // Savings are 1 − zomefab/baseline, on overall hours and overall USD (paper Table 1).
        CHECK(c->savedTimePercent ==
              doctest::Approx(100 * (1 - c->zomefab.totalHours() / c->baseline.totalHours())));
        CHECK(c->savedMaterialPercent ==
              doctest::Approx(100 * (1 - c->zomefab.totalUsd() / c->baseline.totalUsd())));
        CHECK(c->zomefab.zomeUsd == doctest::Approx(481 * 0.19 + 126 * 0.29));
        CHECK(c->zomefab.assemblyHours == doctest::Approx(assemblyHours(parts)));
        CHECK(c->baseline.zomeUsd == 0.0);
        CHECK(c->baseline.print.parts == 8);
        CHECK(c->zomefab.filament.costUsd ==
              doctest::Approx(filamentUse(c->zomefab.print.filamentMm3, FilamentOptions{}).costUsd));
        CHECK(c->savedFilamentPercent > 0.0);
        // Printed whole: one part, fewer perimeters than the octree's 8 parts, so less plastic in
        // the part than the baseline, but a sphere printed whole stands on supports under its lower
        // half, each octree part on a cut face; the savings against it are 1 − ZomeFab / whole.
        CHECK(c->whole.print.parts == 1);
        CHECK(c->whole.print.filamentMm3 - c->whole.print.supportMm3 <=
              c->baseline.print.filamentMm3 - c->baseline.print.supportMm3);
        CHECK(c->whole.print.supportMm3 > c->baseline.print.supportMm3);
        CHECK(c->whole.print.supportMm3 > 0.0);
        CHECK(c->whole.print.hours() <= c->baseline.print.hours());
        CHECK(c->savedTimeVsWholePercent ==
              doctest::Approx(100 * (1 - c->zomefab.totalHours() / c->whole.totalHours())));
        CHECK(c->savedFilamentVsWholePercent ==
              doctest::Approx(100 * (1 - c->zomefab.print.filamentMm3 / c->whole.print.filamentMm3)));
    }
    CHECK(solid.whole.print.filamentMm3 - solid.whole.print.supportMm3 ==
          doctest::Approx(r.objectVolumeMm3).epsilon(1e-6));
    // The paper's observation (§7.2): the benefit grows with the infill rate.
    CHECK(solid.savedMaterialPercent > hollow.savedMaterialPercent);
    CHECK(solid.savedTimePercent > hollow.savedTimePercent);
    // At 100 % the baseline uses the object's volume in plastic.
    CHECK(solid.baseline.print.filamentMm3 - solid.baseline.print.supportMm3 ==
          doctest::Approx(r.objectVolumeMm3).epsilon(1e-6));

    const nlohmann::json j = costReportToJson(r);
    CHECK(j["source"] == "estimator");
    CHECK(j["cases"].size() == 2);
    CHECK(j["cases"][0]["baseline"]["print"]["parts"] == 8);
    CHECK(j["zometool"]["balls"] == 126);
    CHECK(j["options"]["filament_usd_per_m"] == 0.56);
    const std::string md = costReportMarkdown(r);
    CHECK(md.find("| hollow (20%) | ZomeFab |") != std::string::npos);
    CHECK(md.find("| | baseline (8 octree parts) |") != std::string::npos);
    CHECK(md.find("| | whole object (1 part, large bed) |") != std::string::npos);
    CHECK(j["cases"][1]["whole"]["print"]["parts"] == 1);
    CHECK(j["cases"][0]["saved_filament_vs_whole_percent"].is_number());
    CHECK(md.find("| solid (100%) | ZomeFab |") != std::string::npos);
    CHECK(j["supports_counted"] == true);
    CHECK(j["cases"][0]["whole"]["print"]["support_mm3"].get<double>() > 0);
    CHECK(md.find("Automatic supports are counted on every side") != std::string::npos);
    // Without supports counted, no part carries any.
    CostOptions none;
    none.countSupports = false;
    const CostReport bare =
        costReport(sphere.object, test::pointersTo(sphere.pieces), parts, Fabrication{}, none);
    CHECK(bare.cases[0].whole.print.supportMm3 == 0.0);
    CHECK(bare.cases[0].whole.print.filamentMm3 < hollow.whole.print.filamentMm3);
}

TEST_CASE("cost_report: a part the slicer fails on is estimated instead, with a warning") {
    // /bin/false stands for a slicer that fails on everything.
    const TriMesh object = makeBox({0, 0, 0}, {40, 40, 40});
    const std::vector<TriMesh> pieces = {hollowCube(40, 6)};
    CostOptions o;
    o.source = EstimateSource::PrusaSlicer;
    o.slicer.executable = "false";
    std::vector<std::string> warnings;
    RunContext context(
        [&](LogLevel level, const std::string& m) {
            if (level == LogLevel::Warning) warnings.push_back(m);
        },
        nullptr);
    const CostReport r =
        costReport(object, test::pointersTo(pieces), bunnyParts(), Fabrication{}, o, context);
    CHECK(r.slicerFallbacks ==
          std::vector<std::string>{"hollow piece 0 at 20%", "hollow baseline part 0 at 20%",
                                   "hollow whole object 0 at 20%", "solid piece 0 at 100%",
                                   "solid baseline part 0 at 100%", "solid whole object 0 at 100%"});
    REQUIRE(warnings.size() == 6);
    CHECK(warnings[0].find("false failed on hollow piece 0 at 20%") != std::string::npos);
    const CostReport model = costReport(object, test::pointersTo(pieces), bunnyParts(), Fabrication{});
    CHECK(r.cases[0].zomefab.print.seconds == model.cases[0].zomefab.print.seconds);
    CHECK(costReportToJson(r)["slicer_fallbacks"].size() == 6);
    // A slicer that is not there at all is a usage error, before any work.
    o.slicer.executable = "/nonexistent/prusa-slicer";
    CHECK_THROWS_WITH_AS(
        costReport(object, test::pointersTo(pieces), bunnyParts(), Fabrication{}, o),
        "--slicer /nonexistent/prusa-slicer: not installed or not executable (Debian package prusa-slicer)",
        Error);
}

TEST_CASE("cost_report: filament options change cost and length, not time") {
    const SphereCase sphere;
    CostOptions cheap;
    cheap.filament.usdPerM = 0.28;
    cheap.filament.diameterMm = 1.75;
    const CostReport a =
        costReport(sphere.object, test::pointersTo(sphere.pieces), bunnyParts(), Fabrication{});
    const CostReport b =
        costReport(sphere.object, test::pointersTo(sphere.pieces), bunnyParts(), Fabrication{}, cheap);
    const double area = (2.85 * 2.85) / (1.75 * 1.75);
    CHECK(b.cases[0].zomefab.filament.lengthM == doctest::Approx(a.cases[0].zomefab.filament.lengthM * area));
    CHECK(b.cases[0].zomefab.filament.costUsd ==
          doctest::Approx(a.cases[0].zomefab.filament.costUsd * area * 0.5));
    CHECK(b.cases[0].zomefab.print.seconds == a.cases[0].zomefab.print.seconds);
    CostOptions bad;
    Fabrication badPrinter;
    badPrinter.printerMm = {200, -1, 200};
    CHECK_THROWS_AS(costReport(sphere.object, test::pointersTo(sphere.pieces), bunnyParts(), badPrinter, bad),
                    Error);
}
