// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/target_count.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <unordered_map>

#include "zomefab/core/error.h"
#include "zomefab/frame/random.h"

namespace zomefab::frame {

namespace {

constexpr uint64_t kTargetSalt = 0x7461750000000000ull;  // "tau"

/// Reachable surface samples bucketed in cells of the reach radius; marks the samples a ball
/// covers.
class CoverageGrid {
public:
    CoverageGrid(const std::vector<SurfaceSample>& samples, double reachMm)
        : mReachMm(reachMm), mInvCell(1.0 / reachMm) {
        for (size_t i = 0; i < samples.size(); ++i) {
            if (!samples[i].isReachable) continue;
            mPoints.push_back(samples[i].positionMm);
            mCells[key(samples[i].positionMm)].push_back(uint32_t(mPoints.size() - 1));
        }
        mIsCovered.assign(mPoints.size(), 0);
    }
    size_t reachable() const { return mPoints.size(); }
    size_t covered() const { return mCovered; }
    double fraction() const { return mPoints.empty() ? 1.0 : double(mCovered) / double(mPoints.size()); }

    void cover(const Vec3d& p) {
        const int64_t c[3] = {cell(p[0]), cell(p[1]), cell(p[2])};
        const double r2 = mReachMm * mReachMm;
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
                        if (d2 <= r2) {
                            mIsCovered[i] = 1;
                            ++mCovered;
                        }
                    }
                }
    }

private:
    int64_t cell(double x) const { return int64_t(std::floor(x * mInvCell)); }
    static int64_t pack(int64_t x, int64_t y, int64_t z) {
        return ((x & 0x1FFFFF) << 42) | ((y & 0x1FFFFF) << 21) | (z & 0x1FFFFF);
    }
    int64_t key(const Vec3d& p) const { return pack(cell(p[0]), cell(p[1]), cell(p[2])); }

    double mReachMm, mInvCell;
    std::vector<Vec3d> mPoints;
    std::unordered_map<int64_t, std::vector<uint32_t>> mCells;
    std::vector<uint8_t> mIsCovered;
    size_t mCovered = 0;
};

double reachOf(const FrameField& field) { return field.zone().dMaxMm + field.scale().ballRadiusMm(); }

struct RunOutcome {
    size_t items = 0;
    double coverage = 0;
};

/// One random assembling run: random ball, random free hole, random size; the strut is added
/// when it and its end ball (new, or an existing ball with the opposite hole free) keep the
/// clearance and collide with nothing.
RunOutcome assembleRandomly(const zome::Structure& initial, const FrameField& field,
                            const std::vector<SurfaceSample>& samples, const TargetCountOptions& o,
                            uint64_t seed, RunContext& context) {
    zome::Structure s = initial;
    CoverageGrid grid(samples, reachOf(field));
    std::vector<zome::BallId> live = s.ballIds();
    for (zome::BallId id : live) grid.cover(s.ball(id).positionMm);
    Rng rng(seed);
    const uint64_t budget = uint64_t(o.attemptsPerBall) * uint64_t(std::max<size_t>(1, live.size()));
    for (uint64_t attempt = 0; attempt < budget && grid.fraction() < o.coverage; ++attempt) {
        if ((attempt & 0xFFF) == 0) context.throwIfCancelled();
        const zome::BallId a = live[rng.below(uint32_t(live.size()))];
        const int hole = int(rng.below(zome::kHoleCount));
        const int size = int(rng.below(zome::kSizeCount));
        if (!s.isHoleFree(a, hole)) continue;
        const zome::Ball& ballA = s.ball(a);
        const zome::GoldenVector3 end = ballA.position + zome::strutVector(hole, size);
        const zome::BallId b = s.findBall(end);
        const Vec3d endMm = s.scale().toMm(end);
        const double depthA = field.depthMm(ballA.positionMm);
        const double depthB = field.depthMm(endMm);
        const zome::Color color = zome::holeColor(hole);
        if (b != zome::kNoId) {
            if (!s.isHoleFree(b, zome::oppositeHole(hole))) continue;
        } else if (!field.isBallAllowed(depthB) || s.ballCollides(end)) {
            continue;
        }
        if (!field.isSegmentAllowed(ballA.positionMm, depthA, endMm, depthB,
                                    field.strutDepthLimitMm(color)) ||
            s.strutCollides(ballA.position, hole, size))
            continue;
        if (b == zome::kNoId) {
            live.push_back(s.addBall(end));
            grid.cover(endMm);
        }
        s.addStrut(a, hole, size);
    }
    return {s.ballCount() + s.strutCount(), grid.fraction()};
}

}  // namespace

double coveredFraction(const zome::Structure& structure, const FrameField& field,
                       const std::vector<SurfaceSample>& samples) {
    CoverageGrid grid(samples, reachOf(field));
    for (zome::BallId id : structure.ballIds()) grid.cover(structure.ball(id).positionMm);
    return grid.fraction();
}

TargetCountResult estimateTargetCount(const zome::Structure& initial, const FrameField& field,
                                      const TargetCountOptions& o, uint64_t seed,
                                      RunContext& context) {
    if (o.runs < 1) throw Error(ErrorCode::Usage, "the target count needs at least one run");
    if (!(o.fraction > 0 && o.fraction <= 1) || !(o.coverage > 0 && o.coverage <= 1))
        throw Error(ErrorCode::Usage, "target-count fraction and coverage must be in (0, 1]");
    TargetCountResult result;
    const std::vector<SurfaceSample> samples = sampleSurface(field, o.sampleSpacingMm);
    result.surfaceSamples = samples.size();
    for (const SurfaceSample& s : samples) result.reachableSamples += s.isReachable ? 1 : 0;
    result.initialCoverage = coveredFraction(initial, field, samples);
    if (o.fixedTargetCount > 0) {
        result.targetItemCount = o.fixedTargetCount;
        return result;
    }
    context.progress("target count", 0.0);
    std::vector<RunOutcome> runs(size_t(o.runs));
    tbb::parallel_for(0, o.runs, [&](int r) {
        runs[size_t(r)] = assembleRandomly(initial, field, samples, o,
                                           deriveSeed(seed, kTargetSalt, uint64_t(r)), context);
    });
    context.throwIfCancelled();
    double sum = 0;
    for (const RunOutcome& r : runs) {
        result.runItems.push_back(r.items);
        result.runCoverage.push_back(r.coverage);
        sum += double(r.items);
    }
    result.targetItemCount = o.fraction * sum / double(o.runs);
    context.progress("target count", 1.0);
    return result;
}

}  // namespace zomefab::frame
