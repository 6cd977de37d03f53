// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Pages in a real browser for the tests: Debian's Chromium, headless, with no network (a proxy
/// that refuses every connection and a resolver that finds no host), and the screenshots it takes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace zomefab::test {

/// chromium is on PATH (Debian package chromium).
bool hasChromium();

/// What one headless Chromium run of a page gave.
struct BrowserRun {
    int exitCode = -1;
    std::string log;                         ///< Chromium's stderr, console messages included
    std::vector<std::string> consoleLines;   ///< the page's console messages (INFO:CONSOLE / ERROR:CONSOLE)
    std::vector<std::string> consoleErrors;  ///< console.error, uncaught exceptions, failed loads
};

/// Opens @p htmlPath (a local file) offline, lets its scripts run (virtual time), and writes a
/// @p widthPx × @p heightPx screenshot to @p screenshotPng.
BrowserRun openInChromium(const std::string& htmlPath, const std::string& screenshotPng, int widthPx = 1000,
                          int heightPx = 750);

/// An RGB image read with stb_image.
struct Image {
    int width = 0, height = 0;
    std::vector<uint8_t> rgb;  ///< row-major, 3 bytes per pixel
};
/// @p path's PNG (an empty image when it cannot be read).
Image readPng(const std::string& path);
/// Pixels of @p image inside the box [x0, x1) × [y0, y1) (clamped) farther than @p tolerance (per
/// channel) from the colour (r, g, b).
size_t countPixelsUnlike(const Image& image, uint8_t r, uint8_t g, uint8_t b, int tolerance = 8, int x0 = 0,
                         int y0 = 0, int x1 = 1 << 30, int y1 = 1 << 30);

}  // namespace zomefab::test
