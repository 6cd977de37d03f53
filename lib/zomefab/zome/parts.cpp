// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/parts.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <string>

#include "zomefab/core/format.h"

namespace zomefab::zome {

size_t PartsList::strutTotal() const {
    size_t n = 0;
    for (const auto& row : struts)
        for (size_t k : row) n += k;
    return n;
}

PartsList partsList(const Structure& s) {
    PartsList p;
    p.balls = s.ballCount();
    for (StrutId id = 0; id < s.strutIdBound(); ++id)
        if (s.hasStrut(id)) ++p.struts[size_t(s.strut(id).color)][s.strut(id).size];
    return p;
}

double partsCostUsd(const PartsList& parts, const PriceOptions& prices) {
    return double(parts.strutTotal()) * prices.strutUsd + double(parts.balls) * prices.ballUsd;
}

nlohmann::json partsListToJson(const PartsList& parts, const PriceOptions& prices) {
    nlohmann::json struts = nlohmann::json::object();
    for (int c = 0; c < kColorCount; ++c)
        for (int size = 0; size < kSizeCount; ++size)
            struts[partName(Color(c), size)] = parts.count(Color(c), size);
    return {{"balls", parts.balls},
            {"struts", std::move(struts)},
            {"strut_total", parts.strutTotal()},
            {"cost_usd", partsCostUsd(parts, prices)},
            {"prices", {{"strut_usd", prices.strutUsd}, {"ball_usd", prices.ballUsd}}}};
}

std::string partsTable(const PartsList& parts, const PriceOptions& prices) {
    // The paper's column order: blue, red, yellow; columns widen for counts of 5 digits and more.
    const Color order[3] = {Color::Blue, Color::Red, Color::Yellow};
    size_t largest = std::max(parts.strutTotal(), parts.balls);
    const int width = std::max<int>(4, int(std::to_string(largest).size())) + 1;
    const int totalWidth = std::max(width, 8);
    auto pad = [](std::string text, int w) {
        if (int(text.size()) < w) text.append(size_t(w) - text.size(), ' ');
        return text;
    };
    std::string out;
    for (Color c : order) {
        const std::string name = colorName(c);
        out += pad(std::string(1, char(std::toupper(name[0]))) + name.substr(1), 3 * width + 1);
    }
    out += pad("Total", totalWidth) + "Total\n";
    for (Color c : order)
        for (int size = 0; size < kSizeCount; ++size)
            out += pad(partName(c, size), width + (size == kSizeCount - 1 ? 1 : 0));
    out += pad("struts", totalWidth) + "balls\n";
    for (Color c : order)
        for (int size = 0; size < kSizeCount; ++size)
            out += pad(std::to_string(parts.count(c, size)), width + (size == kSizeCount - 1 ? 1 : 0));
    out += pad(std::to_string(parts.strutTotal()), totalWidth) + std::to_string(parts.balls) + "\n";
    return out + "\nCost: " + std::to_string(parts.strutTotal()) +
           formatNumbers(" struts x %.2f USD + ", prices.strutUsd) + std::to_string(parts.balls) +
           formatNumbers(" balls x %.2f USD = %.2f USD\n", prices.ballUsd, partsCostUsd(parts, prices));
}

}  // namespace zomefab::zome
