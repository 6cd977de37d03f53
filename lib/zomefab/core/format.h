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

/// @p value as printf's "%.<precision>g", which is also what an ostream prints at that precision:
/// "16", "0.15", "1e+06". The one single-number formatter of the library.
inline std::string formatNumber(double value, int precision = 6) {
    char text[64];
    std::snprintf(text, sizeof text, "%.*g", precision, value);
    return text;
}

}  // namespace zomefab
