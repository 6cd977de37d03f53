// SPDX-License-Identifier: GPL-3.0-or-later
/// @file printf-style text from numbers, for messages and reports.
#pragma once

#include <cstdio>
#include <string>

namespace zomefab {

/// @p pattern with its conversions filled from @p numbers, each passed as a double, so every
/// conversion must be a floating one (%f, %g, %e with any flags, width and precision). Any length.
template <class... Numbers>
std::string formatNumbers(const char* pattern, Numbers... numbers) {
    const int length = std::snprintf(nullptr, 0, pattern, double(numbers)...);
    if (length <= 0) return {};
    std::string text(size_t(length), '\0');
    std::snprintf(&text[0], text.size() + 1, pattern, double(numbers)...);
    return text;
}

}  // namespace zomefab
