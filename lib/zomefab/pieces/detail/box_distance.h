// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The signed distance to a box, the primitive of the tenon and label solids.
#pragma once

#include <algorithm>
#include <cmath>

#include "zomefab/core/vec.h"

namespace zomefab::pieces::detail {

/// Signed distance to the box centred at the origin with half sizes @p half (Quílez's formula):
/// exact outside, the distance to the nearest face inside.
inline double boxDistance(const Vec3d& p, const Vec3d& half) {
    const double qx = std::abs(p[0]) - half[0], qy = std::abs(p[1]) - half[1], qz = std::abs(p[2]) - half[2];
    const double ox = std::max(qx, 0.0), oy = std::max(qy, 0.0), oz = std::max(qz, 0.0);
    return std::sqrt(ox * ox + oy * oy + oz * oz) + std::min(std::max(qx, std::max(qy, qz)), 0.0);
}

}  // namespace zomefab::pieces::detail
