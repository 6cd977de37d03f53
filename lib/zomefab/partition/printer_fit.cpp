// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/partition/printer_fit.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "zomefab/core/vec.h"

namespace zomefab::partition {

namespace {

using Mat3 = Eigen::Matrix3d;

std::array<Vec3d, 3> toAxes(const Mat3& r) {
    std::array<Vec3d, 3> a;
    for (int i = 0; i < 3; ++i) a[size_t(i)] = {r(i, 0), r(i, 1), r(i, 2)};
    return a;
}

Mat3 toMatrix(const std::array<Vec3d, 3>& a) {
    Mat3 r;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) r(i, j) = a[size_t(i)][size_t(j)];
    return r;
}

struct Score {
    double ratio = 0.0;
    double volume = 0.0;
    bool operator<(const Score& o) const {
        // 1e-12 relative slack so rounding noise does not steer the search.
        if (ratio < o.ratio * (1.0 - 1e-12)) return true;
        if (o.ratio < ratio * (1.0 - 1e-12)) return false;
        return volume < o.volume * (1.0 - 1e-12);
    }
};

Vec3d sorted3(Vec3d v) {
    std::sort(v.begin(), v.end());
    return v;
}

Score scoreOf(const std::vector<Vec3d>& pts, const Mat3& r, const Vec3d& printerSorted, double margin) {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
    for (const Vec3d& p : pts) {
        const Eigen::Vector3d q = r * Eigen::Vector3d(p[0], p[1], p[2]);
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
    }
    const Vec3d e =
        sorted3({hi[0] - lo[0] + 2 * margin, hi[1] - lo[1] + 2 * margin, hi[2] - lo[2] + 2 * margin});
    Score s;
    for (int i = 0; i < 3; ++i) s.ratio = std::max(s.ratio, e[size_t(i)] / printerSorted[size_t(i)]);
    s.volume = e[0] * e[1] * e[2];
    return s;
}

Mat3 rotationAbout(const Eigen::Vector3d& axis, double angleRad) {
    return Eigen::AngleAxisd(angleRad, axis.normalized()).toRotationMatrix();
}

}  // namespace

PrinterFit evaluateFit(const std::vector<Vec3d>& pts, const std::array<Vec3d, 3>& axes,
                       const Vec3d& printerMm, double marginMm) {
    PrinterFit fit;
    if (pts.empty()) {
        fit.fits = true;
        return fit;
    }
    const Mat3 r = toMatrix(axes);
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = Eigen::Vector3d::Constant(-1e300);
    for (const Vec3d& p : pts) {
        const Eigen::Vector3d q = r * Eigen::Vector3d(p[0], p[1], p[2]);
        lo = lo.cwiseMin(q);
        hi = hi.cwiseMax(q);
    }
    // Order the axes by extent, keeping a right-handed frame (flip the last axis if needed).
    std::array<int, 3> order{0, 1, 2};
    std::sort(order.begin(), order.end(), [&](int a, int b) { return hi[a] - lo[a] < hi[b] - lo[b]; });
    Mat3 sortedR;
    Eigen::Vector3d sLo, sHi;
    for (int i = 0; i < 3; ++i) {
        sortedR.row(i) = r.row(order[size_t(i)]);
        sLo[i] = lo[order[size_t(i)]];
        sHi[i] = hi[order[size_t(i)]];
    }
    if (sortedR.determinant() < 0) {
        sortedR.row(2) *= -1.0;
        std::swap(sLo[2], sHi[2]);
        sLo[2] = -sLo[2];
        sHi[2] = -sHi[2];
    }
    const Eigen::Vector3d centreLocal = 0.5 * (sLo + sHi);
    const Eigen::Vector3d centre = sortedR.transpose() * centreLocal;
    fit.axes = toAxes(sortedR);
    fit.centerMm = {centre[0], centre[1], centre[2]};
    for (int i = 0; i < 3; ++i) fit.extentsMm[size_t(i)] = sHi[i] - sLo[i] + 2 * marginMm;
    const Vec3d p = sorted3(printerMm);
    fit.ratio = 0.0;
    for (int i = 0; i < 3; ++i) fit.ratio = std::max(fit.ratio, fit.extentsMm[size_t(i)] / p[size_t(i)]);
    fit.fits = fit.ratio <= 1.0;
    return fit;
}

PrinterFit fitInPrinter(const std::vector<Vec3d>& pts, const Vec3d& printerMm, double marginMm) {
    if (pts.empty()) return evaluateFit(pts, toAxes(Mat3::Identity()), printerMm, marginMm);
    const Vec3d printerSorted = sorted3(printerMm);

    // The search runs on at most ~4096 points (every k-th); the final box uses all of them.
    std::vector<Vec3d> sample;
    const size_t stride = (pts.size() + 4095) / 4096;
    if (stride <= 1) {
        sample = pts;
    } else {
        for (size_t i = 0; i < pts.size(); i += stride) sample.push_back(pts[i]);
    }

    // Starting frames: axis-aligned, and the principal axes of the point cloud.
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const Vec3d& p : sample) mean += Eigen::Vector3d(p[0], p[1], p[2]);
    mean /= double(sample.size());
    Mat3 cov = Mat3::Zero();
    for (const Vec3d& p : sample) {
        const Eigen::Vector3d d = Eigen::Vector3d(p[0], p[1], p[2]) - mean;
        cov += d * d.transpose();
    }
    Eigen::SelfAdjointEigenSolver<Mat3> eig(cov);
    Mat3 pca = eig.eigenvectors().transpose();  // rows = principal axes
    if (pca.determinant() < 0) pca.row(0) *= -1.0;

    const double deg = kPi / 180.0;
    Mat3 best = Mat3::Identity();
    Score bestScore = scoreOf(sample, best, printerSorted, marginMm);
    // A long piece may only fit along the printer's diagonal: a third start turns the major
    // principal axis onto the box diagonal (1, 1, 1)/√3.
    const Mat3 diagonal =
        Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), Eigen::Vector3d(1, 1, 1).normalized())
            .toRotationMatrix() *
        pca;
    for (const Mat3& start : {Mat3(Mat3::Identity()), pca, diagonal}) {
        Mat3 r = start;
        Score s = scoreOf(sample, r, printerSorted, marginMm);
        // Scan: rotations about each axis of the start frame in 5° steps over a quarter turn (a
        // box repeats itself after 90°).
        for (int axis = 0; axis < 3; ++axis) {
            const Eigen::Vector3d a = start.row(axis).transpose();
            for (int k = 1; k < 18; ++k) {
                const Mat3 c = start * rotationAbout(a, k * 5.0 * deg).transpose();
                const Score cs = scoreOf(sample, c, printerSorted, marginMm);
                if (cs < s) s = cs, r = c;
            }
        }
        // Coordinate descent with shrinking steps about the current box axes.
        for (double step : {10.0, 3.0, 1.0, 0.3}) {
            for (int iter = 0; iter < 30; ++iter) {
                bool isImproved = false;
                for (int axis = 0; axis < 3; ++axis)
                    for (double sign : {1.0, -1.0}) {
                        const Eigen::Vector3d a = r.row(axis).transpose();
                        const Mat3 c = r * rotationAbout(a, sign * step * deg).transpose();
                        const Score cs = scoreOf(sample, c, printerSorted, marginMm);
                        if (cs < s) s = cs, r = c, isImproved = true;
                    }
                if (!isImproved) break;
            }
        }
        if (s < bestScore) bestScore = s, best = r;
    }
    // Re-orthonormalise (the products of small rotations drift by rounding).
    Eigen::JacobiSVD<Mat3> svd(best, Eigen::ComputeFullU | Eigen::ComputeFullV);
    best = svd.matrixU() * svd.matrixV().transpose();
    return evaluateFit(pts, toAxes(best), printerMm, marginMm);
}

}  // namespace zomefab::partition
