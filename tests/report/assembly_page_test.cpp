// SPDX-License-Identifier: GPL-3.0-or-later
/// @file assembly.html: one picture per frame layer and per mounting step, each a real picture (not
/// blank), nothing fetched from anywhere; in headless Chromium with no network it opens with no
/// console error.
#include "zomefab/report/assembly_page.h"

#include <doctest/doctest.h>

#include <cstring>

#include "browser_test_util.h"
#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/report/picture.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
using namespace zomefab::report;

namespace {

zome::Structure cube() {
    return zome::structureFromJsonText(readInputBytes(std::string(ZOMEFAB_ZOME_TEST_DATA) + "/cube.json"));
}

std::string base64Decode(const std::string& text) {
    std::string out;
    uint32_t group = 0;
    int bits = 0;
    for (const char c : text) {
        const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        const char* at = std::strchr(alphabet, c);
        if (c == '=' || !at || !c) continue;
        group = (group << 6) | uint32_t(at - alphabet);
        bits += 6;
        if (bits >= 8) {
            bits -= 8;
            out += char((group >> bits) & 0xFF);
        }
    }
    return out;
}

/// The cube frame with a box piece on its top face, pegged into the top balls' straight-up holes.
struct CubeWithLid {
    zome::Structure frame = cube();
    TriMesh lid;
    AssemblyGuide guide;
    PreviewInput scene;

    CubeWithLid() {
        double top = -1e300;
        for (const zome::BallId b : frame.ballIds()) top = std::max(top, frame.ball(b).positionMm[2]);
        MountingStep step{{"piece-00"}, {}, 2, {}, {}};  // hole 2: blue, straight up
        Box3d box;
        for (const zome::BallId b : frame.ballIds()) {
            const Vec3d& p = frame.ball(b).positionMm;
            box.expand(p);
            if (p[2] > top - 1e-6) step.tenons.push_back({"piece-00", b, 2});
        }
        lid = test::makeBox({box.min[0] - 5, box.min[1] - 5, top + 15},
                            {box.max[0] + 5, box.max[1] + 5, top + 25});
        guide = assemblyGuide(frame, {step});
        scene.frame = &frame;
        scene.pieces = {&lid};
        scene.pieceNames = {"piece-00"};
    }
};

}  // namespace

TEST_CASE("assembly.html: a picture per layer and per mounting step, each with something drawn") {
    const CubeWithLid c;
    const std::string html = assemblyGuideHtml(c.guide, c.scene, "cube <test>");
    CHECK(html.find("<title>Assembly guide: cube &lt;test&gt;</title>") != std::string::npos);
    for (const char* tag : {"<script", "<link", "<iframe", "http://", "https://"})
        CHECK(html.find(tag) == std::string::npos);  // nothing to run or fetch
    // The pictures (found by hand: std::regex recurses per character and overflows on megabytes).
    std::vector<std::string> alts;
    for (size_t at = html.find("<img class=\"step\""); at != std::string::npos;
         at = html.find("<img class=\"step\"", at + 1)) {
        auto attribute = [&](const std::string& name) {
            const size_t from = html.find(name + "=\"", at) + name.size() + 2;
            return html.substr(from, html.find('"', from) - from);
        };
        alts.push_back(attribute("alt"));
        const std::string src = attribute("src");
        REQUIRE(src.rfind("data:image/png;base64,", 0) == 0);
        test::ScratchDir dir("zomefab-picture");
        test::writeBytes(dir.file("p.png"), base64Decode(src.substr(22)));
        const test::Image picture = test::readPng(dir.file("p.png"));
        INFO(alts.back());
        REQUIRE(picture.width == std::stoi(attribute("width")));
        REQUIRE(picture.height == std::stoi(attribute("height")));
        // The background is 0.97 grey (247): at least 1 % of the picture is something else.
        CHECK(test::countPixelsUnlike(picture, 247, 247, 247, 3) >
              size_t(picture.width * picture.height / 100));
    }
    std::vector<std::string> expected;
    for (size_t layer = 0; layer < c.guide.layers; ++layer)
        expected.push_back("Layer " + std::to_string(layer));
    expected.push_back("Step 1");
    CHECK(alts == expected);
    // The parts list names the parts; the holes are in words.
    CHECK(html.find("<td>B0</td><td>blue strut, short</td><td>12</td>") != std::string::npos);
    CHECK(html.find("the blue hole pointing straight up (2)") != std::string::npos);
    CHECK(assemblyGuideHtml(c.guide, c.scene, "x") == assemblyGuideHtml(c.guide, c.scene, "x"));
}

TEST_CASE("assembly.html: a step's piece in its preview colour, its pegs' balls ringed") {
    const CubeWithLid c;
    const std::string html = assemblyGuideHtml(c.guide, c.scene, "cube");
    const size_t at = html.rfind("data:image/png;base64,");
    const std::string png = base64Decode(html.substr(at + 22, html.find('"', at) - at - 22));
    test::ScratchDir dir("zomefab-picture");
    test::writeBytes(dir.file("step.png"), png);
    const test::Image picture = test::readPng(dir.file("step.png"));
    size_t magenta = 0, lid = 0;
    const Rgb colour = pieceColorSrgb(0);
    for (size_t i = 0; i + 2 < picture.rgb.size(); i += 3) {
        const int r = picture.rgb[i], g = picture.rgb[i + 1], b = picture.rgb[i + 2];
        magenta += r > 180 && g < 60 && b > 80 && b < 160;
        // Shaded, so only the hue: the channels in the colour's order.
        lid +=
            (r > g) == (colour[0] > colour[1]) && (g > b) == (colour[1] > colour[2]) && std::abs(r - g) > 20;
    }
    CHECK(magenta > 100);  // four rings
    CHECK(lid > 5000);
}

TEST_CASE("assembly.html: a step naming a piece the scene does not hold is refused") {
    CubeWithLid c;
    c.scene.pieceNames = {"piece-07"};
    CHECK_THROWS_AS(assemblyGuideHtml(c.guide, c.scene, "cube"), Error);
    PreviewInput noFrame;
    CHECK_THROWS_AS(assemblyGuideHtml(c.guide, noFrame, "cube"), Error);
}

TEST_CASE("assembly.html opens offline in headless Chromium with no console error and shows every picture") {
    if (!test::hasChromium()) {
        MESSAGE("chromium is not installed (apt-get install chromium): the browser check is skipped");
        return;
    }
    const CubeWithLid c;
    test::ScratchDir dir("zomefab-guide");
    test::writeBytes(dir.file("assembly.html"), assemblyGuideHtml(c.guide, c.scene, "cube"));
    const test::BrowserRun run =
        test::openInChromium(dir.file("assembly.html"), dir.file("shot.png"), 900, 2400);
    INFO(run.log);
    REQUIRE(run.exitCode == 0);
    CHECK(run.consoleErrors.empty());
    const test::Image shot = test::readPng(dir.file("shot.png"));
    REQUIRE(shot.width == 900);
    // The first picture (layer 0) is on screen: the page is not blank white below its heading.
    CHECK(test::countPixelsUnlike(shot, 255, 255, 255, 3, 0, 200) > 20000);
}
