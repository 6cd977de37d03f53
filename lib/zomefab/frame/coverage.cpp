// SPDX-License-Identifier: GPL-3.0-or-later
// Surface coverage by balls and the strut-addition test (detail/coverage.h).
#include "zomefab/frame/detail/coverage.h"

#include <cmath>

namespace zomefab::frame::detail {

CoverageGrid::CoverageGrid(const std::vector<SurfaceSample>& samples, double reachMm)
    : mReachMm(reachMm), mInvCell(1.0 / reachMm) {
    for (const SurfaceSample& s : samples) {
        if (!s.isReachable) continue;
        mPoints.push_back(s.positionMm);
        mCells[pack(cell(s.positionMm[0]), cell(s.positionMm[1]), cell(s.positionMm[2]))].push_back(
            uint32_t(mPoints.size() - 1));
    }
    mIsCovered.assign(mPoints.size(), 0);
}

int64_t CoverageGrid::cell(double x) const { return int64_t(std::floor(x * mInvCell)); }

int64_t CoverageGrid::pack(int64_t x, int64_t y, int64_t z) {
    return ((x & 0x1FFFFF) << 42) | ((y & 0x1FFFFF) << 21) | (z & 0x1FFFFF);
}

size_t CoverageGrid::visit(const Vec3d& p, bool isMarking) {
    const int64_t c[3] = {cell(p[0]), cell(p[1]), cell(p[2])};
    const double r2 = mReachMm * mReachMm;
    size_t count = 0;
    for (int dx = -1; dx <= 1; ++dx)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dz = -1; dz <= 1; ++dz) {
                const auto it = mCells.find(pack(c[0] + dx, c[1] + dy, c[2] + dz));
                if (it == mCells.end()) continue;
                for (uint32_t i : it->second) {
                    if (mIsCovered[i]) continue;
                    const Vec3d& q = mPoints[i];
                    const double d2 = (q[0] - p[0]) * (q[0] - p[0]) + (q[1] - p[1]) * (q[1] - p[1]) +
                                      (q[2] - p[2]) * (q[2] - p[2]);
                    if (d2 > r2) continue;
                    ++count;
                    if (isMarking) mIsCovered[i] = 1;
                }
            }
    if (isMarking) mCovered += count;
    return count;
}

std::optional<StrutAddition> strutAddition(const zome::Structure& s, const FrameField& field, zome::BallId a,
                                           int hole, int size) {
    if (!s.isHoleFree(a, hole)) return std::nullopt;
    const zome::Ball& ballA = s.ball(a);
    StrutAddition out;
    out.a = a;
    out.hole = hole;
    out.size = size;
    out.end = ballA.position + zome::strutVector(hole, size);
    out.existing = s.findBall(out.end);
    out.endMm = s.scale().toMm(out.end);
    const double depthEnd = field.depthMm(out.endMm);
    if (out.existing != zome::kNoId) {
        if (!s.isHoleFree(out.existing, zome::oppositeHole(hole))) return std::nullopt;
    } else if (!field.isBallAllowed(depthEnd) || s.ballCollides(out.end)) {
        return std::nullopt;
    }
    if (!field.isSegmentAllowed(ballA.positionMm, field.depthMm(ballA.positionMm), out.endMm, depthEnd,
                                field.strutDepthLimitMm(zome::holeColor(hole))) ||
        s.strutCollides(ballA.position, hole, size))
        return std::nullopt;
    return out;
}

}  // namespace zomefab::frame::detail
