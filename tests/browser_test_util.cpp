// SPDX-License-Identifier: GPL-3.0-or-later
#include "browser_test_util.h"

#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

#include "test_util.h"

namespace zomefab::test {

bool hasChromium() { return hasCommand("chromium"); }

namespace {

/// Chromium logs console.error like console.log, and failed loads not at all: the copy of the page
/// the browser opens starts with a script that reports both on the console with a marker.
constexpr const char* kErrorProbe =
    "<script>(function () { const mark = 'ZF-CONSOLE-ERROR: ';"
    "console.error = function () { console.log(mark + Array.from(arguments).join(' ')); };"
    "window.addEventListener('error', function (e) { console.log(mark + (e.message || (e.target && "
    "(e.target.src || e.target.href)) || 'error')); }, true);"
    "window.addEventListener('unhandledrejection', function (e) { console.log(mark + 'unhandled rejection ' "
    "+ "
    "e.reason); }); })();</script>";

/// @p htmlPath's copy with the probe first, next to it (so relative links still resolve).
std::string probedCopy(const std::string& htmlPath) {
    std::string page = readFile(htmlPath);
    const size_t head = page.find("<head>");
    page.insert(head == std::string::npos ? 0 : head + 6, kErrorProbe);
    const std::string copy = htmlPath + ".probe.html";
    writeBytes(copy, page);
    return copy;
}

}  // namespace

BrowserRun openInChromium(const std::string& htmlPath, const std::string& screenshotPng, int widthPx,
                          int heightPx) {
    const std::string probed = probedCopy(std::filesystem::absolute(htmlPath).string());
    // WebGL on the CPU (SwiftShader); nothing reaches the network: every URL goes to a proxy on a
    // closed port and every host name fails to resolve.
    const std::string command =
        "timeout 180 chromium --headless --no-sandbox --disable-gpu --use-angle=swiftshader "
        "--enable-unsafe-swiftshader --no-first-run --disable-extensions --proxy-server=http://127.0.0.1:9 "
        "--host-resolver-rules='MAP * ~NOTFOUND' --enable-logging=stderr --v=0 --window-size=" +
        std::to_string(widthPx) + "," + std::to_string(heightPx) +
        " --virtual-time-budget=30000 --screenshot='" + screenshotPng + "' 'file://" + probed + "' 2>&1";
    BrowserRun run;
    run.exitCode = runCapture(command, &run.log);
    std::istringstream lines(run.log);
    std::string line;
    while (std::getline(lines, line)) {
        if (line.find(":CONSOLE") == std::string::npos) continue;
        // GL driver performance notes (a screenshot reads the pixels back) are not the page's.
        if (line.find("GL Driver Message") != std::string::npos) continue;
        run.consoleLines.push_back(line);
        if (line.find("ZF-CONSOLE-ERROR") != std::string::npos || line.find("Uncaught") != std::string::npos)
            run.consoleErrors.push_back(line);
    }
    std::remove(probed.c_str());
    return run;
}

Image readPng(const std::string& path) {
    Image image;
    int channels = 0;
    unsigned char* data = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
    if (!data) return {};
    image.rgb.assign(data, data + size_t(image.width) * size_t(image.height) * 3);
    stbi_image_free(data);
    return image;
}

size_t countPixelsUnlike(const Image& image, uint8_t r, uint8_t g, uint8_t b, int tolerance, int x0, int y0,
                         int x1, int y1) {
    size_t count = 0;
    x1 = std::min(x1, image.width);
    y1 = std::min(y1, image.height);
    for (int y = std::max(y0, 0); y < y1; ++y)
        for (int x = std::max(x0, 0); x < x1; ++x) {
            const uint8_t* p = &image.rgb[(size_t(y) * size_t(image.width) + size_t(x)) * 3];
            if (std::abs(p[0] - r) > tolerance || std::abs(p[1] - g) > tolerance ||
                std::abs(p[2] - b) > tolerance)
                ++count;
        }
    return count;
}

}  // namespace zomefab::test
