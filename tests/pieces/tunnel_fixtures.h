// SPDX-License-Identifier: GPL-3.0-or-later
/// @file A cube with round tunnels through its middle, as the pieces stage's voxel field (the tunnel
/// and prism tests).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "zomefab/pieces/detail/voxels.h"

namespace zomefab::pieces::detail {

/// A solid cube [0, n)³ of 1 mm voxels as a shell field (every voxel inside), less round tunnels of
/// radius @p r through its middle along each axis in @p axes; voxels within @p liningMm of a tunnel's
/// wall are owned by piece 0, the rest by piece 1. With @p hollowWallMm the cube is hollow: only the
/// voxels within that of a tunnel's wall or of the cube's faces are inside.
inline VoxelField cubeWithTunnels(int n, double r, const std::vector<int>& axes, double liningMm,
                                  double hollowWallMm = 0.0) {
    FloatGrid::Ptr grid = FloatGrid::create(3.0f);
    FloatGrid::Accessor acc = grid->getAccessor();
    const double c = 0.5 * (n - 1);
    auto wallDistance = [&](const Coord& ijk) {  // to the nearest tunnel's wall, negative inside it
        double d = 1e9;
        for (int a : axes) {
            const double u = ijk[(a + 1) % 3] - c, v = ijk[(a + 2) % 3] - c;
            d = std::min(d, std::sqrt(u * u + v * v) - r);
        }
        return d;
    };
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k)
                if (const double d = wallDistance(Coord(i, j, k));
                    d > 0.0 && (hollowWallMm <= 0.0 || d <= hollowWallMm ||
                                std::min({i, j, k, n - 1 - i, n - 1 - j, n - 1 - k}) < hollowWallMm))
                    acc.setValue(Coord(i, j, k), -1.0f);
    VoxelField field = buildField(*grid);
    field.owner.assign(field.phi.size(), kNone);
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isInside(s)) field.owner[s] = wallDistance(field.coordOf(s)) <= liningMm ? 0 : 1;
    return field;
}

}  // namespace zomefab::pieces::detail
