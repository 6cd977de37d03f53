// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The assembly guide's pictures: a small orthographic software renderer (z-buffer, flat
/// shading) for meshes, balls and struts, with overlays (rings, arrows) drawn on top, written as PNG
/// (stb_image_write). Deterministic: the same calls give the same bytes.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::report {

using Rgb = std::array<double, 3>;  ///< sRGB, each in [0, 1]

class Picture {
public:
    /// A @p widthPx × @p heightPx picture seen along @p viewDirection (from the eye into the scene)
    /// with @p up roughly up on the picture, scaled so that @p fitMm (points, mm; grown by
    /// @p marginMm) fills it.
    Picture(int widthPx, int heightPx, const std::vector<Vec3d>& fitMm, double marginMm,
            const Vec3d& viewDirection, const Vec3d& up);

    /// Every triangle of @p mesh after @p toSceneMm, flat-shaded in @p color.
    void mesh(const TriMesh& mesh, const Transform4d& toSceneMm, const Rgb& color);
    void sphere(const Vec3d& centreMm, double radiusMm, const Rgb& color);
    /// A strut: a cylinder from @p a to @p b, drawn as a band of its width, shaded across.
    void cylinder(const Vec3d& a, const Vec3d& b, double radiusMm, const Rgb& color);
    /// On top of everything: a circle of @p radiusPx around @p centreMm, @p thicknessPx wide.
    void ring(const Vec3d& centreMm, double radiusPx, double thicknessPx, const Rgb& color);
    /// On top of everything: an arrow from @p fromMm to @p toMm with its head at @p toMm.
    void arrow(const Vec3d& fromMm, const Vec3d& toMm, double thicknessPx, const Rgb& color);

    /// The picture as PNG bytes.
    std::string png() const;
    int width() const { return mWidth; }
    int height() const { return mHeight; }

private:
    struct Screen {
        double x, y, depth;  ///< pixels; depth in mm along the view, larger is farther
    };
    Screen project(const Vec3d& p) const;
    void triangle(const Screen& a, const Screen& b, const Screen& c, const Rgb& color);
    void plot(int x, int y, double depth, const Rgb& color);
    void overlayDisk(double cx, double cy, double radius, const Rgb& color);

    int mWidth, mHeight;
    Vec3d mRight, mUp, mView;
    double mScale = 1, mCentreX = 0, mCentreY = 0;
    std::vector<double> mDepth;
    std::vector<uint8_t> mRgb;
};

}  // namespace zomefab::report
