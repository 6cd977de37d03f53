// SPDX-License-Identifier: GPL-3.0-or-later
// Growing the frame toward the surface it does not reach (reach.h): a lazy greedy over strut
// additions. Coverage is submodular, so a candidate's gain only falls as balls are added: popping
// the best stored gain and recomputing it finds the true best without re-evaluating every
// candidate after every addition.
#include "zomefab/frame/reach.h"

#include <queue>
#include <tuple>

#include "zomefab/core/error.h"
#include "zomefab/frame/detail/coverage.h"

namespace zomefab::frame {

namespace {

struct Candidate {
    size_t gain = 0;
    zome::BallId a = zome::kNoId;
    int hole = 0;
    int size = 0;
    /// Larger gain first, then the lower (ball, hole, size): a strict, deterministic order.
    bool operator<(const Candidate& o) const {
        if (gain != o.gain) return gain < o.gain;
        return std::tie(a, hole, size) > std::tie(o.a, o.hole, o.size);
    }
};

void pushCandidates(std::priority_queue<Candidate>& queue, const zome::Structure& s, const FrameField& field,
                    const detail::CoverageGrid& grid, zome::BallId a, size_t minGain) {
    for (int hole = 0; hole < zome::kHoleCount; ++hole)
        for (int size = 0; size < zome::kSizeCount; ++size) {
            const auto add = detail::strutAddition(s, field, a, hole, size);
            if (!add || add->existing != zome::kNoId) continue;
            const size_t gain = grid.gain(add->endMm);
            if (gain >= minGain) queue.push({gain, a, hole, size});
        }
}

}  // namespace

bool canGrowStrut(const zome::Structure& s, const FrameField& field, zome::BallId a, int hole, int size) {
    const auto add = detail::strutAddition(s, field, a, hole, size);
    return add && add->existing == zome::kNoId;
}

ReachResult growForReach(zome::Structure& s, const FrameField& field, const ReachOptions& o,
                         const RunContext& context) {
    if (o.minGainSamples < 1 || !(o.sampleSpacingMm > 0) || !(o.coverage > 0 && o.coverage <= 1) ||
        o.maxStruts < 0)
        throw Error(ErrorCode::Usage,
                    "reach growth: gain >= 1, spacing > 0, coverage in (0, 1], struts >= 0");
    detail::CoverageGrid grid(sampleSurface(field, o.sampleSpacingMm), detail::coverageReachMm(field));
    for (zome::BallId id : s.ballIds()) grid.cover(s.ball(id).positionMm);
    ReachResult r;
    r.coverageBefore = r.coverageAfter = grid.fraction();
    if (!o.isEnabled) return r;
    const size_t minGain = size_t(o.minGainSamples);
    std::priority_queue<Candidate> queue;
    for (zome::BallId id : s.ballIds()) pushCandidates(queue, s, field, grid, id, minGain);
    while (!queue.empty() && grid.fraction() < o.coverage &&
           (o.maxStruts == 0 || r.strutsAdded < size_t(o.maxStruts))) {
        context.throwIfCancelled();
        Candidate c = queue.top();
        queue.pop();
        const auto add = detail::strutAddition(s, field, c.a, c.hole, c.size);
        if (!add || add->existing != zome::kNoId) continue;  // a part added since is in the way
        c.gain = grid.gain(add->endMm);
        if (c.gain < minGain) continue;
        if (!queue.empty() && queue.top().gain > c.gain) {
            queue.push(c);  // no longer the best: back in line with its true gain
            continue;
        }
        const zome::BallId b = s.addBall(add->end);
        s.addStrut(c.a, c.hole, c.size);
        grid.cover(add->endMm);
        ++r.strutsAdded;
        pushCandidates(queue, s, field, grid, b, minGain);
    }
    r.coverageAfter = grid.fraction();
    return r;
}

}  // namespace zomefab::frame
