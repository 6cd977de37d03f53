// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/mount/sweep.h"

#include <algorithm>
#include <cmath>

#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"

namespace zomefab::mount {

namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

SweepAxes::SweepAxes(const Vec3d& direction) {
    d = normalized(direction);
    // u: perpendicular to d, built from the world axis least aligned with it (deterministic).
    int least = 0;
    for (int a = 1; a < 3; ++a)
        if (std::abs(d[size_t(a)]) < std::abs(d[size_t(least)])) least = a;
    Vec3d e{0, 0, 0};
    e[size_t(least)] = 1.0;
    u = normalized(cross(d, e));
    v = cross(d, u);
}

DepthRaster::DepthRaster(const SweepAxes& axes, const Box3d& bounds, double pixelMm, bool keepMax,
                         double padMm)
    : mAxes(axes), mPixel(pixelMm), mKeepMax(keepMax) {
    if (!(pixelMm > 0) || bounds.isEmpty())
        throw Error(ErrorCode::Internal, "depth raster: empty bounds or pixel");
    double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
    for (int k = 0; k < 8; ++k) {
        const Vec3d p{(k & 1) ? bounds.max[0] : bounds.min[0], (k & 2) ? bounds.max[1] : bounds.min[1],
                      (k & 4) ? bounds.max[2] : bounds.min[2]};
        u0 = std::min(u0, dot(p, axes.u)), u1 = std::max(u1, dot(p, axes.u));
        v0 = std::min(v0, dot(p, axes.v)), v1 = std::max(v1, dot(p, axes.v));
    }
    mU0 = u0 - padMm - pixelMm;
    mV0 = v0 - padMm - pixelMm;
    mWidth = int(std::ceil((u1 - u0 + 2 * padMm) / pixelMm)) + 3;
    mHeight = int(std::ceil((v1 - v0 + 2 * padMm) / pixelMm)) + 3;
    if (double(mWidth) * double(mHeight) > 2.0e8)
        throw Error(ErrorCode::Internal, "depth raster: too many pixels for the bounds");
    mDepth.assign(size_t(mWidth) * size_t(mHeight), keepMax ? -kInf : kInf);
    mOwner.assign(mDepth.size(), 0xFFFFFFFFu);
}

DepthRaster::DepthRaster(const DepthRaster& grid, const Box3d& bounds, bool keepMax, double padMm)
    : mAxes(grid.mAxes), mPixel(grid.mPixel), mKeepMax(keepMax) {
    if (bounds.isEmpty()) throw Error(ErrorCode::Internal, "depth raster: empty window");
    double u0 = 1e300, u1 = -1e300, v0 = 1e300, v1 = -1e300;
    for (int k = 0; k < 8; ++k) {
        const Vec3d p{(k & 1) ? bounds.max[0] : bounds.min[0], (k & 2) ? bounds.max[1] : bounds.min[1],
                      (k & 4) ? bounds.max[2] : bounds.min[2]};
        u0 = std::min(u0, dot(p, mAxes.u)), u1 = std::max(u1, dot(p, mAxes.u));
        v0 = std::min(v0, dot(p, mAxes.v)), v1 = std::max(v1, dot(p, mAxes.v));
    }
    // Whole pixels of the grid's lattice, one to spare on each side.
    const double i0 = std::floor((u0 - padMm - grid.mU0) / mPixel) - 1,
                 i1 = std::ceil((u1 + padMm - grid.mU0) / mPixel) + 1;
    const double j0 = std::floor((v0 - padMm - grid.mV0) / mPixel) - 1,
                 j1 = std::ceil((v1 + padMm - grid.mV0) / mPixel) + 1;
    mU0 = grid.mU0 + i0 * mPixel;
    mV0 = grid.mV0 + j0 * mPixel;
    mWidth = int(i1 - i0) + 1;
    mHeight = int(j1 - j0) + 1;
    if (double(mWidth) * double(mHeight) > 2.0e8)
        throw Error(ErrorCode::Internal, "depth raster: too many pixels for the bounds");
    mDepth.assign(size_t(mWidth) * size_t(mHeight), keepMax ? -kInf : kInf);
    mOwner.assign(mDepth.size(), 0xFFFFFFFFu);
}

Vec3d DepthRaster::pointAt(int i, int j, double depth) const {
    const double u = mU0 + mPixel * (i + 0.5), v = mV0 + mPixel * (j + 0.5);
    return add(add(scale(mAxes.u, u), scale(mAxes.v, v)), scale(mAxes.d, depth));
}

double DepthRaster::px(const Vec3d& p) const { return (dot(p, mAxes.u) - mU0) / mPixel; }
double DepthRaster::py(const Vec3d& p) const { return (dot(p, mAxes.v) - mV0) / mPixel; }

void DepthRaster::limitReach(const DepthRaster& bodyFar, double reachMm) {
    if (!mKeepMax || !bodyFar.mKeepMax || bodyFar.mPixel != mPixel)
        throw Error(ErrorCode::Internal, "depth raster: a reach is kept by obstacles of a body's far side");
    mReachOf = &bodyFar;
    mReachMm = reachMm;
    mReachDi = int(std::lround((bodyFar.mU0 - mU0) / mPixel));
    mReachDj = int(std::lround((bodyFar.mV0 - mV0) / mPixel));
}

void DepthRaster::put(int i, int j, double depth, uint32_t id, double nearDepth) {
    if (i < 0 || j < 0 || i >= mWidth || j >= mHeight) return;
    if (mReachOf) {
        const int bi = i - mReachDi, bj = j - mReachDj;
        if (bi < 0 || bj < 0 || bi >= mReachOf->mWidth || bj >= mReachOf->mHeight) return;
        const double ceiling = double(mReachOf->depth(bi, bj)) + mReachMm;
        if (!std::isfinite(ceiling) || nearDepth > ceiling) return;
        depth = std::min(depth, ceiling);
    }
    const size_t k = size_t(j) * size_t(mWidth) + size_t(i);
    if (mKeepMax ? depth > mDepth[k] : depth < mDepth[k]) {
        mDepth[k] = float(depth);
        mOwner[k] = id;
    }
}

void DepthRaster::addPoint(const Vec3d& p, double radiusMm, uint32_t id) {
    const double x = px(p), y = py(p), depth = dot(p, mAxes.d), r = radiusMm / mPixel;
    if (r <= 0) {
        put(int(std::floor(x)), int(std::floor(y)), depth, id);
        return;
    }
    for (int j = std::max(0, int(std::floor(y - r))); j <= std::min(mHeight - 1, int(std::floor(y + r))); ++j)
        for (int i = std::max(0, int(std::floor(x - r))); i <= std::min(mWidth - 1, int(std::floor(x + r)));
             ++i) {
            const double dx = std::max(0.0, std::abs(i + 0.5 - x) - 0.5),
                         dy = std::max(0.0, std::abs(j + 0.5 - y) - 0.5);
            if (dx * dx + dy * dy <= r * r) put(i, j, depth, id);
        }
}

namespace {

/// Calls @p f(i, j, halfMm) for every pixel of a width × height raster that a sphere of radius
/// @p R pixels, centred over pixel coordinates (x, y), covers: halfMm is half the sphere's
/// thickness at the pixel's point nearest to the centre's projection (where it is thickest).
template <class F>
void forEachSpherePixel(int width, int height, double x, double y, double R, double pixelMm, F&& f) {
    const double halfDiagonal = std::sqrt(0.5);
    for (int j = std::max(0, int(std::floor(y - R - 1)));
         j <= std::min(height - 1, int(std::floor(y + R + 1))); ++j)
        for (int i = std::max(0, int(std::floor(x - R - 1)));
             i <= std::min(width - 1, int(std::floor(x + R + 1))); ++i) {
            const double rho = std::max(0.0, std::hypot(i + 0.5 - x, j + 0.5 - y) - halfDiagonal);
            if (rho <= R) f(i, j, std::sqrt(R * R - rho * rho) * pixelMm);
        }
}

}  // namespace

void DepthRaster::addSphere(const Vec3d& c, double radiusMm, double growMm, uint32_t id) {
    const double depth = dot(c, mAxes.d);
    forEachSpherePixel(mWidth, mHeight, px(c), py(c), (radiusMm + growMm) / mPixel, mPixel,
                       [&](int i, int j, double half) {
                           if (mKeepMax)
                               put(i, j, depth + half, id, depth - half);
                           else
                               put(i, j, depth - half, id);
                       });
}

void DepthRaster::addBallWithHole(const Vec3d& c, double radiusMm,
                                  const std::vector<std::array<double, 2>>& hole, double floorDepth,
                                  uint32_t id) {
    const double depth = dot(c, mAxes.d);
    auto isInHole = [&](double u, double v) {
        const size_t n = hole.size();
        if (n < 3) return false;
        double sign = 0;
        for (size_t k = 0; k < n; ++k) {
            const auto& a = hole[k];
            const auto& b = hole[(k + 1) % n];
            const double side = (b[0] - a[0]) * (v - a[1]) - (b[1] - a[1]) * (u - a[0]);
            if (side == 0) continue;
            if (sign == 0)
                sign = side;
            else if ((side > 0) != (sign > 0))
                return false;
        }
        return true;
    };
    forEachSpherePixel(mWidth, mHeight, px(c), py(c), radiusMm / mPixel, mPixel,
                       [&](int i, int j, double half) {
                           double far = depth + half;
                           if (isInHole(mU0 + mPixel * (i + 0.5), mV0 + mPixel * (j + 0.5)))
                               far = std::min(far, floorDepth);
                           put(i, j, far, id, depth - half);
                       });
}

void DepthRaster::addCapsule(const Vec3d& a, const Vec3d& b, double radiusMm, double growMm, uint32_t id) {
    const double r = (radiusMm + growMm) / mPixel + 2;
    if (std::max(px(a), px(b)) < -r || std::min(px(a), px(b)) > mWidth + r || std::max(py(a), py(b)) < -r ||
        std::min(py(a), py(b)) > mHeight + r)
        return;  // its shadow misses the raster
    const double length = norm(sub(b, a));
    const int steps = std::max(1, int(std::ceil(length / (0.5 * mPixel))));
    for (int s = 0; s <= steps; ++s) addSphere(madd(a, double(s) / steps, sub(b, a)), radiusMm, growMm, id);
}

void DepthRaster::addTriangle(const Vec3d& a, const Vec3d& b, const Vec3d& c, double growMm, uint32_t id) {
    const double x[3] = {px(a), px(b), px(c)}, y[3] = {py(a), py(b), py(c)};
    const double z[3] = {dot(a, mAxes.d), dot(b, mAxes.d), dot(c, mAxes.d)};
    const double area2 = (x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]);
    const double grow = growMm / mPixel;
    if (std::abs(area2) < 1e-9) {  // edge-on: only a grown triangle draws its edges
        if (growMm <= 0) return;
        for (int e = 0; e < 3; ++e) {
            const Vec3d& p = e == 0 ? a : e == 1 ? b : c;
            const Vec3d& q = e == 0 ? b : e == 1 ? c : a;
            const int steps = std::max(1, int(std::ceil(norm(sub(q, p)) / (0.5 * mPixel))));
            for (int s = 0; s <= steps; ++s) addPoint(madd(p, double(s) / steps, sub(q, p)), growMm, id);
        }
        return;
    }
    const double sign = area2 > 0 ? 1.0 : -1.0;
    const double reach = std::max(grow, 0.0) + 1.0;
    const int i0 = std::max(0, int(std::floor(std::min({x[0], x[1], x[2]}) - reach)));
    const int i1 = std::min(mWidth - 1, int(std::floor(std::max({x[0], x[1], x[2]}) + reach)));
    const int j0 = std::max(0, int(std::floor(std::min({y[0], y[1], y[2]}) - reach)));
    const int j1 = std::min(mHeight - 1, int(std::floor(std::max({y[0], y[1], y[2]}) + reach)));
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            const double qx = i + 0.5, qy = j + 0.5;
            // Signed distance of the pixel centre to the triangle (outside > 0), by its edge lines.
            double outside = -1e300;
            double w[3];
            for (int e = 0; e < 3; ++e) {
                const int p = (e + 1) % 3, q = (e + 2) % 3;
                const double ex = x[q] - x[p], ey = y[q] - y[p];
                // cross(q − p, centre − p) / |q − p|: the distance inside edge p→q (a CCW triangle).
                w[e] = sign * (ex * (qy - y[p]) - ey * (qx - x[p])) / std::hypot(ex, ey);
                outside = std::max(outside, -w[e]);
            }
            if (outside > grow) continue;  // the pixel's centre is farther than grow outside
            // Depth at the nearest point of the triangle: barycentric weights, clamped.
            double l[3], sum = 0;
            for (int e = 0; e < 3; ++e) {
                const int p = (e + 1) % 3, q = (e + 2) % 3;
                l[e] = std::max(0.0, ((x[q] - x[p]) * (qy - y[p]) - (y[q] - y[p]) * (qx - x[p])) / area2);
                sum += l[e];
            }
            double depth = 0;
            for (int e = 0; e < 3; ++e) depth += (sum > 0 ? l[e] / sum : 1.0 / 3) * z[e];
            put(i, j, depth, id);
        }
}

SweepHit worstHit(const DepthRaster& obstacles, const DepthRaster& body, double toleranceMm) {
    SweepHit hit;
    // The body's pixel (i, j) is the obstacles' (i + di, j + dj): windows of one lattice.
    const int di = int(std::lround((body.u0() - obstacles.u0()) / body.pixelMm()));
    const int dj = int(std::lround((body.v0() - obstacles.v0()) / body.pixelMm()));
    const int iFrom = std::max(0, -di), iTo = std::min(body.width(), obstacles.width() - di);
    const int jFrom = std::max(0, -dj), jTo = std::min(body.height(), obstacles.height() - dj);
    for (int j = jFrom; j < jTo; ++j)
        for (int i = iFrom; i < iTo; ++i) {
            const float b = body.depth(i, j), o = obstacles.depth(i + di, j + dj);
            if (!std::isfinite(b) || !std::isfinite(o)) continue;
            const double overlap = double(o) - double(b);
            if (overlap > toleranceMm && overlap > hit.overlapMm) {
                hit.isHit = true;
                hit.overlapMm = overlap;
                hit.obstacle = obstacles.owner(i + di, j + dj);
                hit.mover = body.owner(i, j);
                hit.atMm = body.pointAt(i, j, b);
            }
        }
    return hit;
}

}  // namespace zomefab::mount
