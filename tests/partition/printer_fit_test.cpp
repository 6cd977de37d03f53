// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "zomefab/partition/printer_fit.h"

using namespace zomefab;
using namespace zomefab::partition;

namespace {

/// The 8 corners of a box of @p size centred at the origin, rotated by @p r and moved by @p t.
std::vector<Vec3d> boxCorners(const Vec3d& size, const Eigen::Matrix3d& r, const Vec3d& t = {0, 0, 0}) {
    std::vector<Vec3d> pts;
    for (int i = 0; i < 8; ++i) {
        const Eigen::Vector3d p(((i & 1) ? 0.5 : -0.5) * size[0], ((i & 2) ? 0.5 : -0.5) * size[1],
                                ((i & 4) ? 0.5 : -0.5) * size[2]);
        const Eigen::Vector3d q = r * p;
        pts.push_back({q[0] + t[0], q[1] + t[1], q[2] + t[2]});
    }
    return pts;
}

/// Independent check of a reported fit: every point inside the reported box, and the box's
/// sorted extents within the sorted printer sizes.
void checkFitHolds(const std::vector<Vec3d>& pts, const PrinterFit& fit, const Vec3d& printer) {
    for (int a = 0; a < 3; ++a) {
        const Vec3d& ax = fit.axes[size_t(a)];
        CHECK(std::abs(ax[0] * ax[0] + ax[1] * ax[1] + ax[2] * ax[2] - 1.0) < 1e-9);
        const double c = ax[0] * fit.centerMm[0] + ax[1] * fit.centerMm[1] + ax[2] * fit.centerMm[2];
        for (const Vec3d& p : pts) {
            const double d = ax[0] * p[0] + ax[1] * p[1] + ax[2] * p[2] - c;
            CHECK(std::abs(d) <= 0.5 * fit.extentsMm[size_t(a)] + 1e-6);
        }
    }
    Vec3d e = fit.extentsMm, pr = printer;
    std::sort(e.begin(), e.end());
    std::sort(pr.begin(), pr.end());
    if (fit.fits)
        for (int a = 0; a < 3; ++a) CHECK(e[size_t(a)] <= pr[size_t(a)] + 1e-9);
}

}  // namespace

TEST_CASE("printer_fit: a rotated slab fits only when turned back") {
    // 260 × 30 × 10 mm turned 45° about z: its axis-aligned box is about 205 × 205 × 10 mm, which
    // does not fit a 300 × 50 × 50 printer; the slab itself does.
    const Eigen::Matrix3d r = Eigen::AngleAxisd(std::acos(-1.0) / 4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const std::vector<Vec3d> pts = boxCorners({260, 30, 10}, r, {5, -7, 11});
    const Vec3d printer{300, 50, 50};
    const PrinterFit aligned = evaluateFit(pts, {Vec3d{1, 0, 0}, Vec3d{0, 1, 0}, Vec3d{0, 0, 1}}, printer);
    CHECK_FALSE(aligned.fits);
    const PrinterFit fit = fitInPrinter(pts, printer);
    CHECK(fit.fits);
    // The search minimises the fit ratio (the largest side/printer ratio), here 260/300 or a little
    // less by tilting the slab; it need not return the slab's own axes.
    CHECK(fit.ratio <= 260.0 / 300.0 + 1e-6);
    CHECK(fit.extentsMm[2] <= 260.0 + 1e-6);
    checkFitHolds(pts, fit, printer);
}

TEST_CASE("printer_fit: a stick longer than every side fits along the diagonal") {
    // 300 × 6 × 6 mm: longer than the 200 mm sides, but along the cube's diagonal its box is about
    // 183 mm on each side.
    const std::vector<Vec3d> pts = boxCorners({300, 6, 6}, Eigen::Matrix3d::Identity());
    const Vec3d printer{200, 200, 200};
    const PrinterFit fit = fitInPrinter(pts, printer);
    CHECK(fit.fits);
    CHECK(fit.ratio < 1.0);
    checkFitHolds(pts, fit, printer);
}

TEST_CASE("printer_fit: too large in every orientation, and the margin counts") {
    const std::vector<Vec3d> cube = boxCorners({180, 180, 180}, Eigen::Matrix3d::Identity());
    const PrinterFit fit = fitInPrinter(cube, {200, 200, 200});
    CHECK(fit.fits);
    CHECK(fit.ratio == doctest::Approx(0.9));
    // A margin of 15 mm on each side makes 210 mm: no longer fits.
    const PrinterFit tight = fitInPrinter(cube, {200, 200, 200}, 15.0);
    CHECK_FALSE(tight.fits);
    CHECK(tight.ratio == doctest::Approx(1.05));
    // A 260 mm cube is larger than a 200 mm cube printer whichever way it is turned.
    const std::vector<Vec3d> big = boxCorners({260, 260, 260}, Eigen::Matrix3d::Identity());
    CHECK_FALSE(fitInPrinter(big, {200, 200, 200}).fits);
    CHECK(fitInPrinter({}, {200, 200, 200}).fits);
}
