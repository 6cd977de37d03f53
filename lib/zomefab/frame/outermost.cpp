// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/outermost.h"

#include <array>

namespace zomefab::frame {

namespace {

using zome::kHoleCount;

/// For every pair of non-parallel holes (i, j) with n = v_i × v_j: the holes k with n·v_k > 0
/// (positive) and n·v_k < 0 (negative). Exact golden arithmetic on the size-0 strut vectors
/// (directions only matter). Parallel pairs (same axis) have isPlane = false.
struct HalfSpaceTables {
    std::array<std::array<uint64_t, kHoleCount>, kHoleCount> positive{};
    std::array<std::array<uint64_t, kHoleCount>, kHoleCount> negative{};
    std::array<std::array<bool, kHoleCount>, kHoleCount> isPlane{};

    HalfSpaceTables() {
        for (int i = 0; i < kHoleCount; ++i) {
            for (int j = 0; j < kHoleCount; ++j) {
                const zome::GoldenVector3 n =
                    zome::cross(zome::strutVector(i, 0), zome::strutVector(j, 0));
                isPlane[i][j] = !n.isZero();
                if (!isPlane[i][j]) continue;
                for (int k = 0; k < kHoleCount; ++k) {
                    const int s = zome::dot(n, zome::strutVector(k, 0)).sign();
                    if (s > 0) positive[i][j] |= uint64_t(1) << k;
                    if (s < 0) negative[i][j] |= uint64_t(1) << k;
                }
            }
        }
    }
};

const HalfSpaceTables& halfSpaceTables() {
    static const HalfSpaceTables tables;  // thread-safe initialisation (C++11 magic statics)
    return tables;
}

}  // namespace

uint64_t holeMask(const zome::Ball& ball) {
    uint64_t mask = 0;
    for (int h = 0; h < kHoleCount; ++h)
        if (ball.holes[size_t(h)] != zome::kNoId) mask |= uint64_t(1) << h;
    return mask;
}

bool isOutermostMask(uint64_t mask) {
    // Fewer than four directions can never positively span R³.
    if (__builtin_popcountll(mask) < 4) return true;
    const HalfSpaceTables& t = halfSpaceTables();
    // Farkas: if some d ≠ 0 has d·u ≤ 0 for all strut directions u and the u span R³, the cone
    // of such d is pointed and has an extreme ray on which two independent constraints are tight,
    // so d ∥ u_i × u_j for some pair. Hence: outermost iff some pair's plane has every strut on
    // one closed side (or the struts do not span R³, when every plane test finds one side empty).
    bool hasPlane = false;
    for (uint64_t mi = mask; mi; mi &= mi - 1) {
        const int i = __builtin_ctzll(mi);
        for (uint64_t mj = mi & (mi - 1); mj; mj &= mj - 1) {
            const int j = __builtin_ctzll(mj);
            if (!t.isPlane[size_t(i)][size_t(j)]) continue;
            hasPlane = true;
            if ((mask & t.positive[size_t(i)][size_t(j)]) == 0 ||
                (mask & t.negative[size_t(i)][size_t(j)]) == 0)
                return true;
        }
    }
    return !hasPlane;
}

std::vector<zome::BallId> outermostBalls(const zome::Structure& structure) {
    std::vector<zome::BallId> result;
    for (zome::BallId id = 0; id < structure.ballIdBound(); ++id)
        if (structure.hasBall(id) && isOutermostMask(holeMask(structure.ball(id))))
            result.push_back(id);
    return result;
}

}  // namespace zomefab::frame
