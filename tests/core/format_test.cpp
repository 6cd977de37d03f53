// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/format.h"

#include <doctest/doctest.h>

using namespace zomefab;

TEST_CASE("format: numbers into a printf pattern, as doubles, any length") {
    CHECK(formatNumbers("%.0f x %.0f x %.0f mm", 404.4, 313.0, 400.0) == "404 x 313 x 400 mm");
    CHECK(formatNumbers("%+.2f %g", 0.5, 1e-7) == "+0.50 1e-07");
    CHECK(formatNumbers("%.1f%%", 3) == "3.0%");  // an integer argument is passed as a double
    CHECK(formatNumbers("no numbers") == "no numbers");
    const std::string wide = formatNumbers("%400.1f", 1.0);  // past any fixed buffer
    CHECK(wide.size() == 400);
    CHECK(wide.substr(397) == "1.0");
}
