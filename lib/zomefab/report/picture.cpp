// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/picture.h"

#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>

#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"

namespace zomefab::report {

namespace {

constexpr double kBackground = 0.97;  // a light grey page
/// Light from over the viewer's left shoulder: flat shading = ambient + diffuse on |n · light|.
double shade(const Vec3d& normal, const Vec3d& light) { return 0.45 + 0.55 * std::fabs(dot(normal, light)); }

uint8_t byteOf(double c) { return uint8_t(std::lround(std::clamp(c, 0.0, 1.0) * 255.0)); }

}  // namespace

Picture::Picture(int widthPx, int heightPx, const std::vector<Vec3d>& fitMm, double marginMm,
                 const Vec3d& viewDirection, const Vec3d& up)
    : mWidth(widthPx), mHeight(heightPx) {
    if (widthPx <= 0 || heightPx <= 0 || widthPx > 4096 || heightPx > 4096 || fitMm.empty())
        throw Error(ErrorCode::Usage, "picture: size out of range or empty scene");
    mView = normalized(viewDirection);
    mRight = normalized(cross(mView, up));
    if (!std::isfinite(mRight[0])) mRight = normalized(cross(mView, Vec3d{1, 0, 0}));
    mUp = cross(mRight, mView);
    // Fit the points' projection, grown by the margin, with 6 % of the picture free on every side.
    double loX = 1e300, hiX = -1e300, loY = 1e300, hiY = -1e300;
    for (const Vec3d& p : fitMm) {
        loX = std::min(loX, dot(p, mRight) - marginMm), hiX = std::max(hiX, dot(p, mRight) + marginMm);
        loY = std::min(loY, dot(p, mUp) - marginMm), hiY = std::max(hiY, dot(p, mUp) + marginMm);
    }
    mScale = 0.88 * std::min(widthPx / std::max(hiX - loX, 1e-6), heightPx / std::max(hiY - loY, 1e-6));
    mCentreX = 0.5 * (loX + hiX);
    mCentreY = 0.5 * (loY + hiY);
    mDepth.assign(size_t(widthPx) * size_t(heightPx), 1e300);
    mRgb.assign(size_t(widthPx) * size_t(heightPx) * 3, byteOf(kBackground));
}

Picture::Screen Picture::project(const Vec3d& p) const {
    return {0.5 * mWidth + (dot(p, mRight) - mCentreX) * mScale,
            0.5 * mHeight - (dot(p, mUp) - mCentreY) * mScale, dot(p, mView)};
}

void Picture::plot(int x, int y, double depth, const Rgb& color) {
    if (x < 0 || y < 0 || x >= mWidth || y >= mHeight) return;
    const size_t i = size_t(y) * size_t(mWidth) + size_t(x);
    if (depth >= mDepth[i]) return;
    mDepth[i] = depth;
    for (size_t k = 0; k < 3; ++k) mRgb[i * 3 + k] = byteOf(color[k]);
}

void Picture::triangle(const Screen& a, const Screen& b, const Screen& c, const Rgb& color) {
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (std::fabs(area) < 1e-12) return;
    const int x0 = std::max(0, int(std::floor(std::min({a.x, b.x, c.x})))),
              x1 = std::min(mWidth - 1, int(std::ceil(std::max({a.x, b.x, c.x}))));
    const int y0 = std::max(0, int(std::floor(std::min({a.y, b.y, c.y})))),
              y1 = std::min(mHeight - 1, int(std::ceil(std::max({a.y, b.y, c.y}))));
    for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) {
            const double px = x + 0.5, py = y + 0.5;  // pixel centres, barycentric weights
            const double wa = ((b.x - px) * (c.y - py) - (b.y - py) * (c.x - px)) / area;
            const double wb = ((c.x - px) * (a.y - py) - (c.y - py) * (a.x - px)) / area;
            const double wc = 1.0 - wa - wb;
            if (wa < 0 || wb < 0 || wc < 0) continue;
            plot(x, y, wa * a.depth + wb * b.depth + wc * c.depth, color);
        }
}

void Picture::mesh(const TriMesh& m, const Transform4d& toSceneMm, const Rgb& color) {
    const Vec3d light = normalized(add(scale(mView, -1.0), add(scale(mUp, 0.6), scale(mRight, -0.4))));
    std::vector<Vec3d> p(m.positions.size());
    std::vector<Screen> s(m.positions.size());
    for (size_t i = 0; i < p.size(); ++i) {
        // Rounded to float, as a GLB stores them: a transform read back from JSON (last bits apart) then
        // draws the same pixels as the one computed in memory.
        const Vec3d q = toSceneMm.apply(
            {double(m.positions[i][0]), double(m.positions[i][1]), double(m.positions[i][2])});
        p[i] = {double(float(q[0])), double(float(q[1])), double(float(q[2]))};
        s[i] = project(p[i]);
    }
    for (const Triangle& t : m.triangles) {
        const Vec3d n = normalized(cross(sub(p[t[1]], p[t[0]]), sub(p[t[2]], p[t[0]])));
        if (!std::isfinite(n[0])) continue;
        const double k = shade(n, light);
        triangle(s[t[0]], s[t[1]], s[t[2]], {color[0] * k, color[1] * k, color[2] * k});
    }
}

void Picture::sphere(const Vec3d& centreMm, double radiusMm, const Rgb& color) {
    const Screen c = project(centreMm);
    const double r = radiusMm * mScale;
    for (int y = int(std::floor(c.y - r)); y <= int(std::ceil(c.y + r)); ++y)
        for (int x = int(std::floor(c.x - r)); x <= int(std::ceil(c.x + r)); ++x) {
            const double dx = (x + 0.5 - c.x) / r, dy = (y + 0.5 - c.y) / r, rr = dx * dx + dy * dy;
            if (rr > 1.0) continue;
            const double dz = std::sqrt(1.0 - rr);  // toward the eye
            const double k = 0.45 + 0.55 * std::max(0.0, -0.4 * dx - 0.6 * dy + 0.7 * dz);
            plot(x, y, c.depth - dz * radiusMm, {color[0] * k, color[1] * k, color[2] * k});
        }
}

void Picture::cylinder(const Vec3d& a, const Vec3d& b, double radiusMm, const Rgb& color) {
    const Screen sa = project(a), sb = project(b);
    const double dx = sb.x - sa.x, dy = sb.y - sa.y, length = std::hypot(dx, dy);
    if (length < 1e-9) return;
    const double nx = -dy / length, ny = dx / length, w = std::max(radiusMm * mScale, 0.8);
    // The band as strips across its width, each a little darker toward the edges (a round strut).
    constexpr int kStrips = 5;
    for (int i = 0; i < kStrips; ++i) {
        const double u0 = -1.0 + 2.0 * i / kStrips, u1 = -1.0 + 2.0 * (i + 1) / kStrips, um = 0.5 * (u0 + u1);
        const double k = 0.55 + 0.45 * std::sqrt(std::max(0.0, 1.0 - um * um));
        const Rgb c{color[0] * k, color[1] * k, color[2] * k};
        const double lift = radiusMm * std::sqrt(std::max(0.0, 1.0 - um * um));
        const Screen p0{sa.x + nx * w * u0, sa.y + ny * w * u0, sa.depth - lift};
        const Screen p1{sa.x + nx * w * u1, sa.y + ny * w * u1, sa.depth - lift};
        const Screen q0{sb.x + nx * w * u0, sb.y + ny * w * u0, sb.depth - lift};
        const Screen q1{sb.x + nx * w * u1, sb.y + ny * w * u1, sb.depth - lift};
        triangle(p0, p1, q1, c);
        triangle(p0, q1, q0, c);
    }
}

void Picture::overlayDisk(double cx, double cy, double radius, const Rgb& color) {
    for (int y = int(std::floor(cy - radius)); y <= int(std::ceil(cy + radius)); ++y)
        for (int x = int(std::floor(cx - radius)); x <= int(std::ceil(cx + radius)); ++x)
            if (std::hypot(x + 0.5 - cx, y + 0.5 - cy) <= radius) plot(x, y, -1e300, color);
}

void Picture::ring(const Vec3d& centreMm, double radiusPx, double thicknessPx, const Rgb& color) {
    const Screen c = project(centreMm);
    const double outer = radiusPx + 0.5 * thicknessPx, inner = radiusPx - 0.5 * thicknessPx;
    for (int y = int(std::floor(c.y - outer)); y <= int(std::ceil(c.y + outer)); ++y)
        for (int x = int(std::floor(c.x - outer)); x <= int(std::ceil(c.x + outer)); ++x) {
            const double d = std::hypot(x + 0.5 - c.x, y + 0.5 - c.y);
            if (d <= outer && d >= inner) plot(x, y, -1e300, color);
        }
}

void Picture::arrow(const Vec3d& fromMm, const Vec3d& toMm, double thicknessPx, const Rgb& color) {
    const Screen a = project(fromMm), b = project(toMm);
    const double length = std::hypot(b.x - a.x, b.y - a.y);
    if (length < 1e-6) {  // straight into the picture: a target mark
        ring(toMm, 3.0 * thicknessPx, thicknessPx, color);
        overlayDisk(b.x, b.y, thicknessPx, color);
        return;
    }
    const double ux = (b.x - a.x) / length, uy = (b.y - a.y) / length;
    const double head = std::min(5.0 * thicknessPx, 0.5 * length);
    for (double t = 0; t <= length - head; t += 0.5)
        overlayDisk(a.x + ux * t, a.y + uy * t, 0.5 * thicknessPx, color);
    const Screen tip{b.x, b.y, -1e300}, base{b.x - ux * head, b.y - uy * head, -1e300};
    const double hw = 0.6 * head;
    triangle(tip, {base.x - uy * hw, base.y + ux * hw, -1e300}, {base.x + uy * hw, base.y - ux * hw, -1e300},
             color);
}

std::string Picture::png() const {
    std::string out;
    auto append = [](void* context, void* data, int size) {
        static_cast<std::string*>(context)->append(static_cast<const char*>(data), size_t(size));
    };
    if (!stbi_write_png_to_func(append, &out, mWidth, mHeight, 3, mRgb.data(), mWidth * 3))
        throw Error(ErrorCode::ProcessingFailed, "picture: PNG encoding failed");
    return out;
}

}  // namespace zomefab::report
