// SPDX-License-Identifier: GPL-3.0-or-later
/// @file viewer.html: self-contained (three.js and the scene inlined, no URL to fetch), and, in headless
/// Chromium with no network, it draws the scene.
#include <doctest/doctest.h>

#include <filesystem>

#include "browser_test_util.h"
#include "test_util.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/glb_write.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/report/viewer_page.h"

using namespace zomefab;
using namespace zomefab::test;

TEST_CASE("base64Encode: RFC 4648 test vectors") {
    CHECK(base64Encode("") == "");
    CHECK(base64Encode("f") == "Zg==");
    CHECK(base64Encode("fo") == "Zm8=");
    CHECK(base64Encode("foo") == "Zm9v");
    CHECK(base64Encode("foob") == "Zm9vYg==");
    CHECK(base64Encode("fooba") == "Zm9vYmE=");
    CHECK(base64Encode("foobar") == "Zm9vYmFy");
    CHECK(base64Encode(std::string("\xff\x00\xfe", 3)) == "/wD+");
}

TEST_CASE("viewerPage: one file, nothing to fetch, the scene inlined") {
    const std::string glb("glTF\x02\x00\x00\x00 not a real scene", 29);
    const std::string page = report::viewerPage(glb, "a <bunny> & co");
    CHECK(page.rfind("<!DOCTYPE html>", 0) == 0);
    CHECK(page.find("<title>a &lt;bunny&gt; &amp; co</title>") != std::string::npos);
    CHECK(page.find(base64Encode(glb)) != std::string::npos);
    // No external script, style, image or module: everything the page runs is in it.
    for (const char* tag : {"<script", "<link", "<img", "<iframe"})
        for (size_t at = page.find(tag); at != std::string::npos; at = page.find(tag, at + 1)) {
            const std::string opening = page.substr(at, page.find('>', at) - at);
            CHECK(opening.find(" src=") == std::string::npos);
            CHECK(opening.find(" href=") == std::string::npos);
        }
    CHECK(page.find("import(") == std::string::npos);
    CHECK(page.find("three.js r111") != std::string::npos);  // the licence notice of the inlined library
    CHECK(report::viewerPage(glb, "x") == report::viewerPage(glb, "x"));
}

TEST_CASE("zf-preview --viewer: the page opens offline in headless Chromium and draws the frame and pieces") {
    if (!hasChromium()) {
        MESSAGE("chromium is not installed (apt-get install chromium): the browser check is skipped");
        return;
    }
    ScratchDir dir("zf-viewer");
    std::filesystem::create_directories(dir.path() / "pieces");
    writeMesh(makeBox({-20, -20, -20}, {0, 0, 0}), dir.file("pieces/piece-00.stl"));
    const std::string frame = std::string(ZOMEFAB_ZOME_TEST_DATA) + "/cube.json";
    REQUIRE(runShell(toolPath("zf-preview") + " " + frame + " --pieces " + dir.file("pieces") + " -q -o " +
                     dir.file("preview.glb") + " --viewer " + dir.file("viewer.html")) == 0);
    const BrowserRun run = openInChromium(dir.file("viewer.html"), dir.file("shot.png"));
    INFO(run.log);
    REQUIRE(run.exitCode == 0);
    CHECK(run.consoleErrors.empty());
    bool isReady = false;
    for (const std::string& line : run.consoleLines)
        isReady |= line.find("zomefab viewer: ready") != std::string::npos;
    CHECK(isReady);
    const Image shot = readPng(dir.file("shot.png"));
    REQUIRE(shot.width == 1000);
    REQUIRE(shot.height == 750);
    // Below the panel, the page's background is #f2f2f2: the scene covers a good part of the view.
    const size_t drawn = countPixelsUnlike(shot, 0xf2, 0xf2, 0xf2, 8, 0, 120);
    MESSAGE(drawn << " of " << 1000 * 630 << " pixels drawn");
    CHECK(drawn > 1000 * 630 / 50);
    // Blue struts (sRGB about 13, 84, 191) are among them.
    size_t blue = 0;
    for (size_t i = 0; i + 2 < shot.rgb.size(); i += 3)
        blue += shot.rgb[i + 2] > 120 && shot.rgb[i] < 90 && shot.rgb[i + 2] > shot.rgb[i + 1] + 40;
    CHECK(blue > 200);
}
