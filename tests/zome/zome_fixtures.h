// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Small structures shared by the zome tests.
#pragma once

#include "zomefab/zome/structure.h"

namespace zomefab::zome::test {

/// The exact point i·B0 x̂ + j·B0 ŷ + k·B0 ẑ (B0 = 2 + 2φ units).
inline GoldenVector3 latticePoint(int i, int j, int k) {
    return {Golden{2 * i, 2 * i}, Golden{2 * j, 2 * j}, Golden{2 * k, 2 * k}};
}

/// An n×n×n-cube lattice of B0 struts: (n+1)³ balls with ids i + (n+1)(j + (n+1)k), struts along
/// +x, +y, +z (holes 0, 1, 2) in that order per ball.
inline Structure makeCubeLattice(int n, const ZomeScale& scale = {}, const CollisionOptions& options = {}) {
    Structure s(scale, options);
    const int m = n + 1;
    for (int k = 0; k < m; ++k)
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < m; ++i) s.addBall(latticePoint(i, j, k));
    for (int k = 0; k < m; ++k)
        for (int j = 0; j < m; ++j)
            for (int i = 0; i < m; ++i) {
                const BallId id = BallId(i + m * (j + m * k));
                if (i < n) s.addStrut(id, 0, 0);
                if (j < n) s.addStrut(id, 1, 0);
                if (k < n) s.addStrut(id, 2, 0);
            }
    return s;
}

}  // namespace zomefab::zome::test
