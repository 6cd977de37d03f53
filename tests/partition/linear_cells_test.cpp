// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include <cmath>
#include <random>

#include "zomefab/partition/linear_cells.h"

using namespace zomefab;
using namespace zomefab::partition;

namespace {

/// Points around @p centres with the index of their centre as class (a Voronoi-like labelling).
void makeClusters(const std::vector<Vec3d>& centres, int perCentre, std::vector<Vec3d>& pts,
                  std::vector<uint32_t>& classes, uint32_t seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    for (size_t c = 0; c < centres.size(); ++c)
        for (int i = 0; i < perCentre; ++i) {
            pts.push_back({centres[c][0] + 30 * u(rng), centres[c][1] + 30 * u(rng), centres[c][2] + 30 * u(rng)});
            classes.push_back(uint32_t(10 * c + 3));  // arbitrary class ids
        }
}

/// The cells containing @p x: every k with score_k ≥ score_j for all j (ties count twice).
int cellsContaining(const LinearCells& cells, const Vec3d& x) {
    int count = 0;
    for (uint32_t k = 0; k < cells.cellCount(); ++k) {
        bool isMax = true;
        for (uint32_t j = 0; j < cells.cellCount(); ++j)
            if (j != k && cells.score(j, x) > cells.score(k, x)) isMax = false;
        count += isMax ? 1 : 0;
    }
    return count;
}

}  // namespace

TEST_CASE("linear_cells: multi-class argmax cells are convex, cover the box and do not overlap") {
    for (bool crammerSinger : {true, false}) {
        CAPTURE(crammerSinger);
        const std::vector<Vec3d> centres{{0, 0, 0}, {100, 0, 0}, {0, 100, 0}, {0, 0, 100}, {100, 100, 100}};
        std::vector<Vec3d> pts;
        std::vector<uint32_t> classes;
        makeClusters(centres, 200, pts, classes, 3);
        CellTrainingOptions o;
        o.useCrammerSinger = crammerSinger;
        const LinearCells cells = trainLinearCells(pts, classes, o);
        REQUIRE(cells.cellCount() == centres.size());
        // Well separated clusters are learnt exactly.
        size_t wrong = 0;
        for (size_t i = 0; i < pts.size(); ++i) wrong += cells.classes[cells.cellAt(pts[i])] != classes[i] ? 1 : 0;
        CHECK(wrong == 0);

        // Sampled points of the bounding box (grown by 50 mm) lie in exactly one cell, and every
        // cell met contains the segment between two of its points (convexity).
        std::mt19937 rng(11);
        std::uniform_real_distribution<double> u(-80.0, 180.0), t(0.0, 1.0);
        std::vector<std::vector<Vec3d>> members(cells.cellCount());
        for (int i = 0; i < 20000; ++i) {
            const Vec3d x{u(rng), u(rng), u(rng)};
            CHECK(cellsContaining(cells, x) == 1);
            members[cells.cellAt(x)].push_back(x);
        }
        size_t checked = 0;
        for (uint32_t k = 0; k < cells.cellCount(); ++k) {
            const auto& m = members[k];
            for (size_t i = 0; i + 1 < m.size() && i < 400; ++i) {
                const Vec3d& a = m[i];
                const Vec3d& b = m[m.size() - 1 - i];
                const double s = t(rng);
                const Vec3d x{a[0] + s * (b[0] - a[0]), a[1] + s * (b[1] - a[1]), a[2] + s * (b[2] - a[2])};
                CHECK(cells.cellAt(x) == k);
                ++checked;
            }
        }
        CHECK(checked > 1000);
    }
}

TEST_CASE("linear_cells: the planes are in millimetres whatever the feature scaling") {
    // Two classes split at x = 500 mm, far from the origin: the boundary must come back there.
    std::vector<Vec3d> pts;
    std::vector<uint32_t> classes;
    for (int i = 0; i < 400; ++i) {
        const double x = 400 + 200.0 * i / 399.0;
        if (std::abs(x - 500) < 5) continue;
        pts.push_back({x, 1000.0 + (i % 7), -300.0 + (i % 5)});
        classes.push_back(x < 500 ? 1 : 2);
    }
    CellTrainingOptions o;
    o.cost = 1000;
    o.tolerance = 0.001;
    const LinearCells cells = trainLinearCells(pts, classes, o);
    REQUIRE(cells.cellCount() == 2);
    // Boundary: (w_0 − w_1)·x + (b_0 − b_1) = 0 along the x axis through the data.
    const Vec3d dw{cells.w[0][0] - cells.w[1][0], cells.w[0][1] - cells.w[1][1], cells.w[0][2] - cells.w[1][2]};
    const double db = cells.b[0] - cells.b[1];
    const double xCut = -(db + dw[1] * 1003.0 + dw[2] * -298.0) / dw[0];
    CHECK(xCut == doctest::Approx(500.0).epsilon(0.01));
    CHECK(cells.cellAt({300, 1000, -300}) == 0);  // class 1 → first cell (classes sorted)
    CHECK(cells.cellAt({700, 1000, -300}) == 1);
    // One class: one cell covering space.
    const LinearCells one = trainLinearCells({{0, 0, 0}, {1, 1, 1}}, {4, 4});
    CHECK(one.cellCount() == 1);
    CHECK(one.cellAt({1e6, -1e6, 3}) == 0);
}
