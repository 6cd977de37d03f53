// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The longer end-to-end check (issue 8): `make demo`'s run, the bunny at 400 mm with the
/// default options, every output checked against the others and by real tools: the frame by
/// `zf-zome check`, the pieces closed and fitting (and by admesh), the preview by the Khronos
/// glTF-Validator and draco_decoder, the report's numbers against the files, and the estimator
/// against PrusaSlicer on the same pieces and baseline parts (within 15 %). The real checkers are
/// skipped with a message when they are not installed (`make test-deps` installs them).
#include <doctest/doctest.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "browser_test_util.h"
#include "glb_test_util.h"
#include "mesh_distance.h"
#include "test_util.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/pipeline/pipeline.h"
#include "zomefab/report/cost_report.h"
#include "zomefab/report/run_report.h"
#include "zomefab/report/slicer.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
namespace fs = std::filesystem;
using nlohmann::json;

namespace {

/// |estimate / reference − 1|.
double relativeError(double estimate, double reference) { return std::abs(estimate / reference - 1.0); }

/// `zomefab run data/bunny_cgal_75k.stl --up y --height-mm 400` in process, written once.
struct DemoRun {
    test::ScratchDir dir{"zomefab-long"};
    pipeline::RunOptions options;
    report::RunRecord result;
    json report;
    std::string out;
    bool isBuildable = false;  ///< the verifier passed (else the outputs are in out + ".failed")

    DemoRun() {
        options.scale.heightMm = 400;
        options.scale.up = mesh::UpAxis::Y;
        const TriMesh mesh = readMesh(test::dataPath("bunny_cgal_75k.stl"));
        result = pipeline::runPipeline(mesh, "bunny_cgal_75k.stl", options, RunContext::silent());
        report = report::runReportJson(result, RunContext::silent());
        out = dir.file("out");
        const pipeline::RunOutputs written =
            pipeline::writeRunOutputs(result, options, report, out, RunContext::silent());
        isBuildable = written.verification.passed();
    }
    std::string file(const std::string& name) const { return out + "/" + name; }
};

const DemoRun& demo() {
    static const DemoRun r;
    return r;
}

json partsJson(const zome::PartsList& parts) { return zome::partsListToJson(parts); }

/// How far the pieces' outer surface lies from the input (issue 17: "the outer surface still matches
/// the input", 95th percentile ≤ 0.5 mm), both ways, in mm.
struct SurfaceDeviation {
    double inputToPiecesMm = 0;  ///< 95th percentile, points spread over the scaled input
    double piecesToInputMm = 0;  ///< 95th percentile, points of the pieces' outer surface
    double outerShare = 0;       ///< of the points on the pieces, those found on the outer surface
};

/// The pieces taken back to the shell grid's mm (the scaled input's frame) by the inverse of each
/// print transform, one mesh.
TriMesh piecesInGridMm(const pieces::Pieces& all) {
    TriMesh out;
    for (const pieces::Piece& p : all.pieces) {
        TriMesh m = p.mesh;
        transformInPlace(m, affineInverse(p.gridToPrintMm));
        appendMesh(out, m);
    }
    return out;
}

/// Input → pieces: 20,000 points on the input, each one's distance to the nearest piece. Pieces →
/// input: 40,000 points on the pieces; a point is on the outer surface when it lies within half the
/// wall of the input and moving 3 mm against its triangle's normal (into the piece) takes it more
/// than 2 mm farther from the input (inner walls lie a wall away; cut faces, stems and pegs run
/// across the wall or inside it, so that move keeps their distance).
SurfaceDeviation surfaceDeviation(const TriMesh& input, const pieces::Pieces& all, double wallMm) {
    const TriMesh piecesMm = piecesInGridMm(all);
    const test::MeshDistance toInput(input), toPieces(piecesMm);
    SurfaceDeviation r;
    r.inputToPiecesMm =
        test::quantile(test::distancesTo(toPieces, test::sampleSurface(input, 20000, 7)), 0.95);
    std::vector<uint32_t> facets;
    const std::vector<Vec3d> points = test::sampleSurface(piecesMm, 40000, 8, &facets);
    std::vector<double> outer;
    for (size_t i = 0; i < points.size(); ++i) {
        const Triangle& t = piecesMm.triangles[facets[i]];
        const Vec3d a = toD(piecesMm.positions[t[0]]), b = toD(piecesMm.positions[t[1]]),
                    c = toD(piecesMm.positions[t[2]]);
        const Vec3d n = normalized(cross(sub(b, a), sub(c, a)));
        const double d = toInput.distance(points[i]);
        if (d < 0.5 * wallMm && toInput.distance(madd(points[i], -3.0, n)) - d > 2.0) outer.push_back(d);
    }
    if (!outer.empty())
        MESSAGE("outer surface -> input: median " << test::quantile(outer, 0.5) << ", 90 % "
                                                  << test::quantile(outer, 0.9) << ", 99 % "
                                                  << test::quantile(outer, 0.99) << " mm");
    r.outerShare = double(outer.size()) / double(points.size());
    r.piecesToInputMm = outer.empty() ? 1e9 : test::quantile(outer, 0.95);
    return r;
}

}  // namespace

TEST_CASE("long: every output of the 400 mm run is present") {
    const DemoRun& d = demo();
    for (const char* name :
         {"frame.json", "frame.vef", "partition.json", "pieces/pieces.json", "plates/plate-01.3mf",
          "preview.glb", "viewer.html", "assembly.md", "assembly.html", "cost.md", "report.json"}) {
        INFO(name);
        CHECK(fs::file_size(d.file(name)) > 0);
    }
    CHECK(readInputBytes(d.file("plates/plate-01.3mf")).substr(0, 2) == "PK");
    // report.json is the run's report plus the verifier's verdict on the files as written.
    json written = json::parse(readInputBytes(d.file("report.json")));
    CHECK(written["verify"]["passed"] == true);
    CHECK(d.isBuildable);
    written.erase("verify");
    CHECK(written == d.report);
}

TEST_CASE("long: 95 % of the demo's pieces have two tenons or more, every step is held by a peg") {
    // Issue 17's "≥ 95 % of pieces with ≥ 2 tenons" on the demo. With the pieces fitted to the bed
    // less its margins (docs/benchmarks.md, "Plates with supports and a skirt") 10 of its 12 pieces
    // had two pegs; the frame grown toward the other two (docs/mounting.md, "Frame grown toward a
    // piece": a strut to a new ball each) holds all 12, and nothing is glued.
    const DemoRun& d = demo();
    const json written = json::parse(readInputBytes(d.file("report.json")));
    const json& verify = written["verify"];
    MESSAGE(verify["bodies_with_two_pegs"].get<int>()
            << " of " << verify["bodies"].get<int>() << " steps held by two pegs or more, frame grown by "
            << d.result.pieces.frameStrutsGrown << " struts");
    size_t held = 0;
    for (const pieces::Piece& p : d.result.pieces.pieces) {
        CHECK(!p.tenons.empty());
        held += p.tenons.size() >= 2 ? 1 : 0;
    }
    CHECK(100 * held >= 95 * d.result.pieces.pieces.size());
    CHECK(verify["bodies"].get<int>() > 0);
    CHECK(100 * verify["bodies_with_two_pegs"].get<int>() >= 95 * verify["bodies"].get<int>());
    CHECK(verify["glued_on_pieces"] == 0);
    CHECK(d.result.pieces.frameStrutsGrown > 0);
    // The frame written is the grown one: every peg's ball is in it.
    const zome::Structure& frame = d.result.frame.structure;
    for (const pieces::Piece& p : d.result.pieces.pieces)
        for (const pieces::Tenon& t : p.tenons) CHECK(frame.hasBall(t.ball));
    // A glued group goes on as one body: its pieces share a step and a direction.
    for (const auto& [a, b] : d.result.pieces.plan.glued) {
        CHECK(d.result.pieces.plan.stepOf(a) == d.result.pieces.plan.stepOf(b));
        CHECK(d.result.pieces.pieces[a].hole == d.result.pieces.pieces[b].hole);
    }
}

TEST_CASE("long: the pieces' outer surface matches the input within 0.5 mm (95th percentile, both ways)") {
    const DemoRun& d = demo();
    const SurfaceDeviation dev =
        surfaceDeviation(d.result.scaled.mesh, d.result.pieces, d.result.fabrication.wallMm);
    MESSAGE("input -> pieces " << dev.inputToPiecesMm << " mm, pieces' outer surface -> input "
                               << dev.piecesToInputMm << " mm (" << 100 * dev.outerShare
                               << " % of the pieces' surface is outer surface)");
    CHECK(dev.inputToPiecesMm <= 0.5);
    CHECK(dev.piecesToInputMm <= 0.5);
    // The outer surface meshed with 3 % of the adaptivity: 0.27 / 0.28 mm (at the full 0.3, 0.46 /
    // 0.45 mm, at the limit above).
    CHECK(std::max(dev.inputToPiecesMm, dev.piecesToInputMm) <= 0.35);
    // The outer surface is a large share of what is printed (inner wall, cut faces and pegs the rest):
    // a classification that found none would pass the check above without measuring anything.
    CHECK(dev.outerShare > 0.25);
}

TEST_CASE("long: surface deviation of the runs in ZOMEFAB_DEVIATION_RUNS (by hand, for docs/benchmarks.md)") {
    // ZOMEFAB_DEVIATION_RUNS="armadillo_cgal_52k:y:500 dino_cgal_8k:z:400 ...": each data/ mesh run in
    // process with the default options and measured as the demo above; nothing when unset.
    const char* runs = std::getenv("ZOMEFAB_DEVIATION_RUNS");
    if (runs == nullptr) return;
    std::istringstream list(runs);
    for (std::string cell; list >> cell;) {
        const size_t a = cell.find(':'), b = cell.rfind(':');
        REQUIRE((a != std::string::npos && b > a));
        pipeline::RunOptions options;
        options.scale.heightMm = std::stod(cell.substr(b + 1));
        options.scale.up = cell.substr(a + 1, b - a - 1) == "z" ? mesh::UpAxis::Z : mesh::UpAxis::Y;
        const std::string name = cell.substr(0, a) + ".stl";
        const report::RunRecord run =
            pipeline::runPipeline(readMesh(test::dataPath(name)), name, options, RunContext::silent());
        const SurfaceDeviation dev = surfaceDeviation(run.scaled.mesh, run.pieces, run.fabrication.wallMm);
        MESSAGE(cell << ": input -> pieces " << dev.inputToPiecesMm << " mm, pieces -> input "
                     << dev.piecesToInputMm << " mm, outer share " << dev.outerShare);
        CHECK(std::max(dev.inputToPiecesMm, dev.piecesToInputMm) <= 0.5);
    }
}

TEST_CASE("long: the frame passes zf-zome check; every parts list equals the frame's struts") {
    const DemoRun& d = demo();
    CHECK(test::runShell(test::toolPath("zf-zome") + " check " + d.file("frame.json") + " -q") == 0);
    const zome::Structure frame = zome::structureFromJsonText(readInputBytes(d.file("frame.json")));
    const json parts = partsJson(zome::partsList(frame));
    CHECK(partsJson(d.result.cost.parts) == parts);
    CHECK(partsJson(d.result.assembly.parts) == parts);
    CHECK(d.report["frame"]["parts"] == parts);
    CHECK(d.report["frame"]["struts"] == frame.strutCount());
    CHECK(d.report["frame"]["balls"] == frame.ballCount());

    // The guide lists every ball exactly once, and every piece with its tenons.
    const std::string guide = readInputBytes(d.file("assembly.md"));
    std::map<std::string, int> seen;
    const std::regex ballHeading(R"(\*\*ball-(\d+)\*\* at)");
    for (auto it = std::sregex_iterator(guide.begin(), guide.end(), ballHeading);
         it != std::sregex_iterator(); ++it)
        ++seen[(*it)[1]];
    CHECK(seen.size() == frame.ballCount());
    for (const auto& [ball, count] : seen) CHECK(count == 1);
    size_t strutsInGuide = 0;
    for (const report::BallStep& step : d.result.assembly.steps) strutsInGuide += step.struts.size();
    CHECK(strutsInGuide == frame.strutCount());
    for (size_t i = 0; i < d.result.pieces.pieces.size(); ++i)
        CHECK(guide.find(pieces::pieceName(d.result.pieces, i)) != std::string::npos);
}

TEST_CASE("long: pieces are closed, fit the printer, and their parts sum to the shell's volume") {
    const DemoRun& d = demo();
    const json pj = json::parse(readInputBytes(d.file("pieces/pieces.json")));
    REQUIRE(pj["pieces"].size() == d.result.pieces.pieces.size());
    const bool hasAdmesh = test::hasCommand("admesh");
    if (!hasAdmesh) MESSAGE("admesh is not installed (apt-get install admesh): its check is skipped");
    double volumeMm3 = 0, shellShareMm3 = 0;
    size_t thin = 0;
    for (const json& p : pj["pieces"]) {
        const std::string file = d.file("pieces/" + p["file"].get<std::string>());
        INFO(file);
        const mesh::MeshReport m = mesh::checkMesh(readMesh(file));
        CHECK(m.boundaryEdges == 0);
        CHECK(m.nonManifoldEdges == 0);
        CHECK(m.inconsistentEdges == 0);
        CHECK(m.volume > 0);
        volumeMm3 += m.volume;
        shellShareMm3 += p["shell_volume_mm3"].get<double>();
        // Printed with the shell's wall, or (the default) 2.4 mm where its pegs reach through: about
        // that share of its part of the shell, the stems through the hollow on top.
        const double part = p["shell_volume_mm3"].get<double>();
        const double share = p["wall_mm"].get<double>() / d.result.fabrication.wallMm;
        thin += p["thin_wall"].get<bool>() ? 1 : 0;
        CHECK(m.volume >= 0.9 * share * part);
        CHECK(m.volume <= (p["thin_wall"].get<bool>() ? 0.5 : 1.05) * part);
        for (int a = 0; a < 3; ++a) {
            CHECK(m.bounds.min[size_t(a)] >= -1e-3);
            CHECK(m.bounds.max[size_t(a)] <= d.options.fabrication.printerMm[size_t(a)] + 1e-3);
        }
        CHECK(m.bounds.min[2] == doctest::Approx(0).epsilon(1e-6));  // on the bed
        if (hasAdmesh) {
            // The body is one part and each peg one more (a separate shell that overlaps the body,
            // united by the 3MF fill rule and the slicer); nothing admesh had to fix.
            const size_t parts = 1 + p["tenons"].size();
            std::string a;
            test::runCapture("admesh '" + file + "' 2>&1", &a);
            INFO(a);
            CHECK(std::regex_search(
                a, std::regex(R"(Number of parts\s*:\s*)" + std::to_string(parts) + R"(\s)")));
            CHECK(std::regex_search(a, std::regex(R"(Total disconnected facets\s*:\s*0\s+0\s)")));
            for (const char* field : {"Degenerate facets", "Edges fixed", "Facets removed", "Facets added",
                                      "Facets reversed", "Backwards edges", "Normals fixed"})
                CHECK(std::regex_search(a, std::regex(std::string(field) + R"(\s*:\s*0\s)")));
        }
    }
    // The pieces' parts are the shell, counted in voxels; most of the bunny's pieces are printed thin.
    CHECK(shellShareMm3 == doctest::Approx(d.result.pieces.shellVolumeMm3).epsilon(0.01));
    CHECK(thin == pj["summary"]["thin_pieces"].get<size_t>());
    CHECK(2 * thin > pj["pieces"].size());
    CHECK(volumeMm3 == doctest::Approx(d.report["pieces"]["volume_mm3"].get<double>()).epsilon(1e-4));
    CHECK(d.report["cost"]["pieces_volume_mm3"].get<double>() == doctest::Approx(volumeMm3).epsilon(1e-4));
    CHECK(d.report["cost"]["pieces"] == pj["pieces"].size());
}

TEST_CASE("long: preview.glb passes the Khronos validator and its Draco pieces decode") {
    const DemoRun& d = demo();
    const test::Glb g = test::parseGlb(readInputBytes(d.file("preview.glb")));
    std::set<std::string> names;
    for (const json& n : g.json["nodes"]) names.insert(n.value("name", ""));
    for (size_t i = 0; i < d.result.pieces.pieces.size(); ++i)
        CHECK(names.count(pieces::pieceName(d.result.pieces, i)) == 1);
    for (const zome::BallId id : d.result.frame.structure.ballIds())
        CHECK(names.count("ball-" + std::to_string(id)) == 1);
    CHECK(g.json["scenes"][0]["extras"]["parts"] == partsJson(d.result.cost.parts));

    if (!test::hasCommand("draco_decoder")) {
        MESSAGE("draco_decoder is not installed (Debian package draco): skipped");
    } else {
        test::ScratchDir scratch("zomefab-long-drc");
        size_t decoded = 0;
        for (const json& mesh : g.json["meshes"])
            for (const json& prim : mesh["primitives"]) {
                if (!prim.contains("extensions")) continue;
                const std::string drc = scratch.file("m.drc");
                test::writeBytes(
                    drc, test::viewBytes(g, prim["extensions"]["KHR_draco_mesh_compression"]["bufferView"]));
                const auto [vertices, faces] = test::dracoDecodeCounts(drc, scratch.file("m.obj"));
                CHECK(
                    vertices ==
                    g.json["accessors"][prim["attributes"]["POSITION"].get<size_t>()]["count"].get<size_t>());
                CHECK(3 * faces == g.json["accessors"][prim["indices"].get<size_t>()]["count"].get<size_t>());
                ++decoded;
            }
        CHECK(decoded == d.result.pieces.pieces.size());
    }

    if (!test::hasCommand("node")) {
        MESSAGE("node is not installed: the Khronos glTF-Validator check is skipped");
        return;
    }
    const json v = test::khronosValidate(d.file("preview.glb"));
    INFO(v.dump());
    CHECK(v["errors"] == 0);
}

/// Slices the plate @p file with PrusaSlicer on the demo's bed (@p bed), with @p settings (0.3 mm
/// layers, automatic supports, and what the caller adds), taking the plate's placement as it is;
/// the G-code's text.
static std::string slicePlate(const std::string& file, const Vec3d& bed, const std::string& settings) {
    test::ScratchDir dir("zomefab-plate");
    const std::string gcode = dir.file("plate.gcode");
    const std::string command =
        formatNumbers(
            "prusa-slicer --loglevel 1 --export-gcode --dont-arrange --layer-height 0.3 "
            "--first-layer-height 0.3 --gcode-flavor marlin2 --support-material "
            "--support-material-auto --bed-shape 0x0,%gx0,%gx%g,0x%g --max-print-height %g ",
            bed[0], bed[0], bed[1], bed[1], bed[2]) +
        settings;
    std::string log;
    const int code = test::runCapture(command + " -o " + gcode + " " + file + " 2>&1", &log);
    INFO(log);
    REQUIRE(code == 0);
    return readInputBytes(gcode);
}

/// The X and Y extents of every move of a G-code file: {minX, maxX, minY, maxY}.
static std::array<double, 4> gcodeExtents(const std::string& gcode) {
    std::array<double, 4> e{1e300, -1e300, 1e300, -1e300};
    std::istringstream lines(gcode);
    std::string line;
    const std::regex axis(R"(\b([XY])(-?[0-9.]+))");
    while (std::getline(lines, line)) {
        if (line.rfind("G1 ", 0) != 0 && line.rfind("G0 ", 0) != 0) continue;
        const std::string code = line.substr(0, line.find(';'));
        for (auto it = std::sregex_iterator(code.begin(), code.end(), axis); it != std::sregex_iterator();
             ++it) {
            const double v = std::stod((*it)[2]);
            const size_t k = (*it)[1] == "X" ? 0 : 2;
            e[k] = std::min(e[k], v);
            e[k + 1] = std::max(e[k + 1], v);
        }
    }
    return e;
}

TEST_CASE(
    "long: assembly.html has a picture per frame layer and per mounting step; both pages open offline") {
    const DemoRun& d = demo();
    const std::string html = readInputBytes(d.file("assembly.html"));
    size_t layers = 0, steps = 0;
    for (size_t at = html.find("<img class=\"step\""); at != std::string::npos;
         at = html.find("<img class=\"step\"", at + 1)) {
        const size_t alt = html.find("alt=\"", at) + 5;
        layers += html.compare(alt, 6, "Layer ") == 0;
        steps += html.compare(alt, 5, "Step ") == 0;
        CHECK(html.compare(html.find("src=\"", at) + 5, 22, "data:image/png;base64,") == 0);
    }
    size_t guideLayers = 0;  // (component, layer) pairs of the guide
    for (size_t i = 0; i < d.result.assembly.steps.size(); ++i)
        guideLayers += i == 0 || d.result.assembly.steps[i].layer != d.result.assembly.steps[i - 1].layer ||
                       d.result.assembly.steps[i].component != d.result.assembly.steps[i - 1].component;
    CHECK(layers == guideLayers);
    CHECK(steps == d.result.assembly.mounting.size());
    if (!test::hasChromium()) {
        MESSAGE("chromium is not installed: the browser checks are skipped");
        return;
    }
    // The guide's page is white, the viewer's background #f2f2f2.
    for (const auto& [page, background] :
         {std::pair<const char*, int>{"assembly.html", 255}, {"viewer.html", 0xf2}}) {
        INFO(page);
        test::ScratchDir dir("zomefab-page");
        const test::BrowserRun run = test::openInChromium(d.file(page), dir.file("shot.png"));
        INFO(run.log);
        CHECK(run.exitCode == 0);
        CHECK(run.consoleErrors.empty());
        const test::Image shot = test::readPng(dir.file("shot.png"));
        const uint8_t bg = uint8_t(background);
        CHECK(test::countPixelsUnlike(shot, bg, bg, bg, 4, 0, 150) > 20000);
    }
}

TEST_CASE(
    "long: every plate slices on the printer's bed as it is, with supports and a skirt, stays inside it, and "
    "needs at most half the support the cut-face orientation did") {
    if (!report::isSlicerAvailable()) {
        MESSAGE("prusa-slicer is not installed: skipped");
        return;
    }
    // One slice per plate serves both checks (slicing the 12 plates takes about 3 minutes on 2 cores).
    // Issue 15's measure (docs/benchmarks.md, "Supports today"): the support filament is the share of
    // the extrusion the G-code marks as support; the print orientation of before (a cut face down)
    // needed 1,915 cm³ of support filament on this demo. (A piece that stands on its supports cannot
    // be sliced without them: "no extrusions in the first layer".)
    constexpr double kBeforeMm3 = 1915e3;
    constexpr double kFilamentMm = 2.85;
    const double filamentAreaMm2 = 0.25 * std::acos(-1.0) * kFilamentMm * kFilamentMm;
    const DemoRun& d = demo();
    const Vec3d bed = d.options.fabrication.printerMm;
    std::map<std::string, int> placed;
    double supportMm3 = 0;
    for (const json& plate : d.report["plates"]) {
        const std::string name = plate["file"].get<std::string>();
        INFO(name);
        for (const json& item : plate["pieces"]) ++placed[item["piece"].get<std::string>()];
        // --dont-arrange: the slicer takes the plate's placement as it is (it would otherwise move
        // the objects itself), so the G-code shows where the file put them. With automatic
        // supports (the pieces rest on small bases and need them; their first layer reaches up to
        // 5.7 mm beyond a piece) and a skirt 2 mm away (Prusa's printer profiles): the bed's
        // margin must hold both (Fabrication::bedMarginMm).
        const std::string gcode =
            slicePlate(d.file(name), bed,
                       "--nozzle-diameter 0.4 --filament-diameter " + formatNumber(kFilamentMm, 4) +
                           " --fill-density 20% --perimeters 3 --skirts 1 --skirt-distance 2");
        const std::array<double, 4> e = gcodeExtents(gcode);
        std::istringstream lines(gcode);
        const double mm3 = report::supportFilamentMm(lines) * filamentAreaMm2;
        MESSAGE(name << ": X " << e[0] << " … " << e[1] << ", Y " << e[2] << " … " << e[3] << " mm; support "
                     << mm3 / 1000 << " cm³");
        CHECK(e[0] >= 0.0);
        CHECK(e[1] <= bed[0]);
        CHECK(e[2] >= 0.0);
        CHECK(e[3] <= bed[1]);
        CHECK(e[1] > e[0]);
        supportMm3 += mm3;
    }
    // Every piece on exactly one plate.
    CHECK(placed.size() == d.result.pieces.pieces.size());
    for (size_t i = 0; i < d.result.pieces.pieces.size(); ++i)
        CHECK(placed[pieces::pieceName(d.result.pieces, i)] == 1);
    MESSAGE("support filament on all plates: " << supportMm3 / 1000 << " cm³ (before: 1,915 cm³)");
    CHECK(supportMm3 > 0.0);
    CHECK(supportMm3 <= 0.5 * kBeforeMm3);
}

TEST_CASE("long: the estimator agrees with PrusaSlicer within 15 % on the pieces and the baseline") {
    if (!report::isSlicerAvailable()) {
        MESSAGE(
            "prusa-slicer is not installed (apt-get install --no-install-recommends prusa-slicer): skipped");
        return;
    }
    // Slicing all 2 × (pieces + baseline parts) takes about 20 minutes on 2 cores (`zomefab run
    // --slicer prusa-slicer` does it; docs/report.md has that run's table), so the test slices a fixed
    // sample: every other piece and every third baseline part at 20 %, every fourth piece and every
    // sixth part at 100 %, and compares the sample's sums.
    const DemoRun& d = demo();
    const report::CostOptions& cost = d.options.cost;
    const std::vector<TriMesh> baseline =
        report::octreeParts(d.result.scaled.mesh, d.options.fabrication.printerMm, 10, RunContext::silent());
    REQUIRE(baseline.size() == d.result.cost.baselinePartCount);
    struct Sample {
        std::string what;
        const std::vector<const TriMesh*> parts;
        double infillPercent;
        bool supports;
    };
    auto every = [](size_t step, auto&& meshes) {
        std::vector<const TriMesh*> out;
        for (size_t i = 0; i < meshes.size(); i += step) out.push_back(&meshes[i]);
        return out;
    };
    // The pieces as they are printed, with automatic supports where they overhang (some stand on
    // their supports and have no first layer without them); the baseline's parts lie on a cut face.
    // Without supports the estimator was 21 % slow on the pieces: they are turned so their thin walls
    // print steep, where its perimeter rate, fitted over thick parts, is too slow (docs/benchmarks.md,
    // "Pieces turned for print time"). With them, as printed, all 13 of the demo's pieces: 138.9 h
    // estimated against 140.8 h sliced.
    std::vector<TriMesh> printed;
    for (const pieces::Piece& p : d.result.pieces.pieces) printed.push_back(p.mesh);
    const Sample samples[] = {{"pieces", every(2, printed), cost.hollowInfillPercent, true},
                              {"baseline", every(3, baseline), cost.hollowInfillPercent, false},
                              {"pieces", every(4, printed), cost.solidInfillPercent, true},
                              {"baseline", every(6, baseline), cost.solidInfillPercent, false}};
    for (const Sample& sample : samples) {
        report::PrintSettings settings = cost.print;
        settings.infillPercent = sample.infillPercent;
        settings.supports = sample.supports;
        report::PrintEstimate estimated, sliced;
        for (size_t i = 0; i < sample.parts.size(); ++i) {
            estimated += report::estimatePrint(*sample.parts[i], settings, cost.rates);
            sliced += report::sliceWithPrusaSlicer(*sample.parts[i], settings,
                                                   std::string(sample.what) + " " + std::to_string(i));
        }
        MESSAGE(sample.what << " at " << sample.infillPercent << "% (" << sample.parts.size()
                            << " parts): " << estimated.hours() << " / " << sliced.hours() << " h, "
                            << estimated.filamentMm3 / 1000 << " / " << sliced.filamentMm3 / 1000
                            << " cm3 (estimator / PrusaSlicer)");
        CHECK(relativeError(estimated.seconds, sliced.seconds) <= 0.15);
        CHECK(relativeError(estimated.filamentMm3, sliced.filamentMm3) <= 0.15);
    }
}
