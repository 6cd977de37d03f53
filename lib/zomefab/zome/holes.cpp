// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/holes.h"

#include <algorithm>
#include <cmath>

#include "zomefab/core/vec.h"

namespace zomefab::zome {

namespace {

/// A regular polygon with @p n corners on the circle of @p circumradius, corner 0 on +x.
std::vector<std::array<double, 2>> regularPolygon(int n, double circumradius) {
    std::vector<std::array<double, 2>> p;
    for (int k = 0; k < n; ++k) {
        const double a = 2.0 * kPi * k / n;
        p.push_back({circumradius * std::cos(a), circumradius * std::sin(a)});
    }
    return p;
}

}  // namespace

std::vector<std::array<double, 2>> holeSectionMm(Color color) {
    switch (color) {
        case Color::Blue:
            return {{-2.73, -1.69}, {2.73, -1.69}, {2.73, 1.69}, {-2.73, 1.69}};  // 1/φ × 1/φ² units
        case Color::Yellow:
            return regularPolygon(3, 5.46 / std::sqrt(3.0));  // edge = the blue long side
        case Color::Red:
            return regularPolygon(5, 2.87);  // lifelike model's radius
    }
    return {};
}

std::vector<std::array<double, 2>> insetPolygon(const std::vector<std::array<double, 2>>& p, double inset) {
    // Each edge moves inward by `inset`; the new corners are where consecutive moved edges meet.
    const size_t n = p.size();
    std::vector<std::array<double, 2>> out(n);
    for (size_t i = 0; i < n; ++i) {
        const auto& a = p[(i + n - 1) % n];
        const auto& b = p[i];
        const auto& c = p[(i + 1) % n];
        // Inward normals (left of each edge for a counter-clockwise polygon).
        auto normal = [](const std::array<double, 2>& u, const std::array<double, 2>& v) {
            const double dx = v[0] - u[0], dy = v[1] - u[1], l = std::hypot(dx, dy);
            return std::array<double, 2>{-dy / l, dx / l};
        };
        const auto n1 = normal(a, b), n2 = normal(b, c);
        const double cosHalf = std::sqrt(std::max(1e-12, 0.5 * (1.0 + n1[0] * n2[0] + n1[1] * n2[1])));
        const double bx = n1[0] + n2[0], by = n1[1] + n2[1], bl = std::hypot(bx, by);
        out[i] = {b[0] + bx / bl * inset / cosHalf, b[1] + by / bl * inset / cosHalf};
    }
    return out;
}

double inradiusMm(const std::vector<std::array<double, 2>>& p) {
    double r = 1e300;
    for (size_t i = 0; i < p.size(); ++i) {
        const auto& a = p[i];
        const auto& b = p[(i + 1) % p.size()];
        const double dx = b[0] - a[0], dy = b[1] - a[1];
        r = std::min(r, std::abs(a[0] * dy - a[1] * dx) / std::hypot(dx, dy));  // origin to the edge's line
    }
    return r;
}

double holeFaceRatio(Color color) {
    switch (color) {
        case Color::Blue:
            return 1.0;
        case Color::Yellow:
            return 1.0023;
        case Color::Red:
            return 1.0131;
    }
    return 1.0;
}

int nearestHole(const Vec3d& d) {
    int best = 0;
    double bestCos = -2.0;
    for (int h = 0; h < kHoleCount; ++h) {
        const Vec3d& e = holeDirection(h);
        const double c = e[0] * d[0] + e[1] * d[1] + e[2] * d[2];
        if (c > bestCos + 1e-12) bestCos = c, best = h;
    }
    return best;
}

std::string directionName(const Vec3d& d) {
    static const char* plus[3] = {"right", "back", "up"};
    static const char* minus[3] = {"left", "front", "down"};
    std::vector<std::pair<double, int>> parts;
    for (int a = 0; a < 3; ++a)
        if (std::abs(d[size_t(a)]) >= 0.3) parts.push_back({-std::abs(d[size_t(a)]), a});
    std::sort(parts.begin(), parts.end());
    auto word = [&](int a) { return std::string(d[size_t(a)] > 0 ? plus[a] : minus[a]); };
    if (parts.empty()) return "nowhere";
    if (parts.size() == 1 || -parts[0].first >= 0.94) return "straight " + word(parts[0].second);
    if (parts.size() == 2) return word(parts[0].second) + " and " + word(parts[1].second);
    return word(parts[0].second) + ", " + word(parts[1].second) + " and " + word(parts[2].second);
}

std::string holeName(int hole) {
    return std::string(colorName(holeColor(hole))) + " hole " + std::to_string(hole) + " (" +
           directionName(holeDirection(hole)) + ")";
}

}  // namespace zomefab::zome
