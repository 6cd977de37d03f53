// SPDX-License-Identifier: GPL-3.0-or-later
/// @file What the report's HTML pages (viewer.html, assembly.html) share.
#pragma once

#include <string>

namespace zomefab::report::detail {

/// @p text with & < > " escaped, for HTML text and attribute values.
inline std::string escapeHtml(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        switch (c) {
            case '&':
                out += "&amp;";
                break;
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

}  // namespace zomefab::report::detail
