// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Does a body moved along a direction d hit something? A piece pushed off along +d (the
/// reverse of mounting it along −d) hits an obstacle exactly when, on some line parallel to d, an
/// obstacle point lies ahead of a point of the piece. So both are drawn into depth buffers over a
/// square pixel grid in the plane normal to d: the obstacles keep their largest depth x·d per
/// pixel, the piece its smallest; a pixel where the first exceeds the second is a collision.
/// Obstacles are drawn grown by a margin (never smaller than they are), the moving body either
/// grown (against the frame) or shrunk (against pieces it touches along a face parallel to d).
/// docs/mounting.md, "Free paths".
#pragma once

#include <array>
#include <cstdint>
#include <limits>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::mount {

/// An orthonormal frame (u, v, d) for a direction: u and v span the plane the rasters live in.
struct SweepAxes {
    Vec3d u{1, 0, 0}, v{0, 1, 0}, d{0, 0, 1};
    explicit SweepAxes(const Vec3d& direction);
};

/// A depth buffer along one direction over a fixed rectangle of the plane normal to it.
class DepthRaster {
public:
    /// Covers the projection of @p boundsMm (grown by @p padMm) with pixels of @p pixelMm.
    /// @p keepMax: obstacles (the largest depth per pixel), else a moving body (the smallest).
    DepthRaster(const SweepAxes& axes, const Box3d& boundsMm, double pixelMm, bool keepMax,
                double padMm = 0.0);
    /// A window of @p grid's pixel lattice (its axes and pixel, pixels aligned) that covers the
    /// projection of @p boundsMm grown by @p padMm: a small body tested against a large frame.
    DepthRaster(const DepthRaster& grid, const Box3d& boundsMm, bool keepMax, double padMm = 0.0);

    const SweepAxes& axes() const { return mAxes; }
    double pixelMm() const { return mPixel; }
    /// Plane coordinates of pixel (0, 0)'s corner.
    double u0() const { return mU0; }
    double v0() const { return mV0; }
    int width() const { return mWidth; }
    int height() const { return mHeight; }
    bool keepsMax() const { return mKeepMax; }
    /// The depth of pixel (i, j), ±infinity where nothing was drawn; the id of what set it.
    float depth(int i, int j) const { return mDepth[size_t(j) * size_t(mWidth) + size_t(i)]; }
    uint32_t owner(int i, int j) const { return mOwner[size_t(j) * size_t(mWidth) + size_t(i)]; }
    /// The point at @p depth on the line through pixel (i, j)'s centre.
    Vec3d pointAt(int i, int j, double depth) const;

    /// Obstacles drawn after this call count only as far as @p reachMm beyond @p bodyFar's depth
    /// on each line (a moving body drawn keeping its largest depth, a window of this raster's
    /// lattice): the body moved along the direction by reachMm, not without end (a stave lifted
    /// off its pegs before it slides along its tunnel). Nothing is drawn where bodyFar has nothing.
    void limitReach(const DepthRaster& bodyFar, double reachMm);

    /// A point drawn into every pixel within @p radiusMm of its projection (0: its own pixel).
    void addPoint(const Vec3d& pMm, double radiusMm, uint32_t id);
    /// The near (obstacles) or far side of a sphere, grown by @p growMm.
    void addSphere(const Vec3d& centerMm, double radiusMm, double growMm, uint32_t id);
    /// A ball (obstacles only) with the hole that points along the raster's direction: the sphere's
    /// far side, except over the hole's section @p holeUv (a convex polygon in the raster's (u, v)
    /// plane coordinates, mm), where the ball's material ends at the hole's floor, depth
    /// @p holeFloorDepthMm: a peg in that hole moves out along the direction freely.
    void addBallWithHole(const Vec3d& centerMm, double radiusMm,
                         const std::vector<std::array<double, 2>>& holeUv, double holeFloorDepthMm,
                         uint32_t id);
    /// A capsule (a segment with a radius), grown by @p growMm, sampled along its axis.
    void addCapsule(const Vec3d& aMm, const Vec3d& bMm, double radiusMm, double growMm, uint32_t id);
    /// A triangle: the pixels whose centre lies within @p growMm of its projection (0: inside it;
    /// < 0: that far inside; a face seen edge-on draws nothing unless grown), each with the depth
    /// of the triangle's point nearest to the centre's line.
    void addTriangle(const Vec3d& a, const Vec3d& b, const Vec3d& c, double growMm, uint32_t id);

private:
    /// Keeps @p depth at pixel (i, j); an obstacle that spans [nearDepth, depth] on the line is
    /// clipped to the reach (limitReach).
    void put(int i, int j, double depth, uint32_t id, double nearDepth);
    void put(int i, int j, double depth, uint32_t id) { put(i, j, depth, id, depth); }
    /// Pixel coordinates of a point's projection (continuous).
    double px(const Vec3d& p) const;
    double py(const Vec3d& p) const;

    SweepAxes mAxes;
    double mPixel = 1.0;
    double mU0 = 0.0, mV0 = 0.0;  ///< plane coordinates of pixel (0, 0)'s corner
    int mWidth = 0, mHeight = 0;
    bool mKeepMax = true;
    std::vector<float> mDepth;
    std::vector<uint32_t> mOwner;
    const DepthRaster* mReachOf = nullptr;  ///< limitReach's body, or none
    double mReachMm = 0.0;
    int mReachDi = 0, mReachDj = 0;  ///< this raster's pixel (i, j) is mReachOf's (i − di, j − dj)
};

/// Where a moving body first meets obstacles on its path.
struct SweepHit {
    bool isHit = false;
    uint32_t obstacle = 0xFFFFFFFFu;  ///< the owner id of the obstacle pixel
    uint32_t mover = 0xFFFFFFFFu;     ///< the owner id of the body's pixel
    double overlapMm = 0.0;           ///< how far the obstacle reaches ahead of the body there
    Vec3d atMm{0, 0, 0};              ///< the body's point on that line
};

/// The worst pixel (largest overlap beyond @p toleranceMm) of @p body against @p obstacles; the
/// rasters must share their axes, pixel size and pixel lattice (the same rectangle, or windows of
/// one, pixels outside either count as empty).
SweepHit worstHit(const DepthRaster& obstacles, const DepthRaster& body, double toleranceMm);

}  // namespace zomefab::mount
