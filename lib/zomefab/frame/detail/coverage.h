// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Internal to lib/zomefab/frame: the reachable surface samples bucketed in cells of the
/// reach radius, which balls cover (target_count.cpp, reach.cpp), and the one test of whether a
/// catalogue strut may be added to a frame (the clearance and the collisions).
#pragma once

#include <cstdint>
#include <optional>
#include <unordered_map>
#include <vector>

#include "zomefab/frame/frame_field.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame::detail {

/// The coverage radius: a sample is covered when a ball centre lies within dMax + ball radius.
inline double coverageReachMm(const FrameField& field) {
    return field.zone().dMaxMm + field.scale().ballRadiusMm();
}

class CoverageGrid {
public:
    CoverageGrid(const std::vector<SurfaceSample>& samples, double reachMm);
    size_t reachable() const { return mPoints.size(); }
    size_t covered() const { return mCovered; }
    double fraction() const { return mPoints.empty() ? 1.0 : double(mCovered) / double(mPoints.size()); }
    /// Marks the samples a ball at @p p covers; returns how many were not covered before.
    size_t cover(const Vec3d& p) { return visit(p, true); }
    /// How many samples not yet covered a ball at @p p would cover.
    size_t gain(const Vec3d& p) const { return const_cast<CoverageGrid*>(this)->visit(p, false); }

private:
    size_t visit(const Vec3d& p, bool isMarking);
    int64_t cell(double x) const;
    static int64_t pack(int64_t x, int64_t y, int64_t z);

    double mReachMm, mInvCell;
    std::vector<Vec3d> mPoints;
    std::unordered_map<int64_t, std::vector<uint32_t>> mCells;
    std::vector<uint8_t> mIsCovered;
    size_t mCovered = 0;
};

/// A strut that may be added to a frame: from ball @p a through @p hole, of @p size, to the ball
/// already at its end (its opposite hole free) or to a new one.
struct StrutAddition {
    zome::BallId a = zome::kNoId;
    int hole = 0;
    int size = 0;
    zome::GoldenVector3 end;
    zome::BallId existing = zome::kNoId;  ///< the ball at the end, kNoId when it is new
    Vec3d endMm{0, 0, 0};
};

/// The strut from @p a (hole, size) when it may be added: the hole free, the end ball allowed by
/// the clearance and colliding with nothing (or an existing ball with the opposite hole free),
/// the strut clear of dMin and of every other part. Empty otherwise.
std::optional<StrutAddition> strutAddition(const zome::Structure& s, const FrameField& field, zome::BallId a,
                                           int hole, int size);

}  // namespace zomefab::frame::detail
