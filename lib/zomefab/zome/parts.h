// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The parts list (bill of materials) of a structure in Zometool naming, and its cost.
#pragma once

#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>

#include "zomefab/zome/structure.h"

namespace zomefab::zome {

/// Counts of every part: balls and struts by [colour][size] (B0..B2, Y0..Y2, R0..R2).
struct PartsList {
    size_t balls = 0;
    std::array<std::array<size_t, kSizeCount>, kColorCount> struts{};

    size_t strutTotal() const;
    size_t count(Color color, int size) const { return struts[size_t(color)][size_t(size)]; }
};

/// Kit prices; defaults are the paper's (§7.2: 0.19 USD a strut, 0.29 USD a ball).
struct PriceOptions {
    double strutUsd = 0.19;  ///< any strut, USD
    double ballUsd = 0.29;   ///< one ball, USD
};

PartsList partsList(const Structure& structure);
/// strutTotal × strutUsd + balls × ballUsd.
double partsCostUsd(const PartsList& parts, const PriceOptions& prices = {});

/// {"balls": n, "struts": {"B0": n, ..., "R2": n}, "strut_total": n, "cost_usd": x,
///  "prices": {"strut_usd": x, "ball_usd": y}}
nlohmann::json partsListToJson(const PartsList& parts, const PriceOptions& prices = {});

/// A text table laid out like the paper's Table 2 (blue, red, yellow; sizes 0/1/2 = its S/M/L;
/// total struts; total balls) followed by a cost line.
std::string partsTable(const PartsList& parts, const PriceOptions& prices = {});

}  // namespace zomefab::zome
