// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/mount/plan.h"

#include <algorithm>
#include <queue>

#include "zomefab/core/vec.h"

namespace zomefab::mount {

int InstallationPlan::stepOf(uint32_t piece) const {
    for (size_t s = 0; s < steps.size(); ++s)
        if (std::find(steps[s].pieces.begin(), steps[s].pieces.end(), piece) != steps[s].pieces.end())
            return int(s);
    return -1;
}

FaceOrder faceOrder(const Vec3d& n, const Vec3d& da, const Vec3d& db, double tolerance) {
    return {dot(db, n) >= -tolerance, dot(da, n) <= tolerance};
}

namespace {

/// One cycle of the relation among @p left (the bodies Kahn's algorithm could not place): walk
/// forward along predecessors until a body repeats.
std::vector<uint32_t> findCycle(const std::vector<std::vector<uint32_t>>& into,
                                const std::vector<uint8_t>& isLeft) {
    uint32_t start = 0;
    while (start < isLeft.size() && !isLeft[start]) ++start;
    std::vector<int> seenAt(isLeft.size(), -1);
    std::vector<uint32_t> path;
    uint32_t at = start;
    while (seenAt[at] < 0) {
        seenAt[at] = int(path.size());
        path.push_back(at);
        uint32_t next = at;
        for (uint32_t p : into[at])
            if (isLeft[p]) {
                next = p;
                break;
            }
        if (next == at) return path;  // not reached: a left body always has a left predecessor
        at = next;
    }
    std::vector<uint32_t> cycle(path.begin() + seenAt[at], path.end());
    std::reverse(cycle.begin(), cycle.end());
    return cycle;
}

}  // namespace

std::vector<uint32_t> mountingOrder(size_t count, const std::vector<std::pair<uint32_t, uint32_t>>& before,
                                    const std::vector<double>& priority, std::vector<uint32_t>* cycle) {
    std::vector<std::vector<uint32_t>> out(count), into(count);
    std::vector<size_t> indegree(count, 0);
    for (const auto& [a, b] : before) {
        out[a].push_back(b);
        into[b].push_back(a);
        ++indegree[b];
    }
    auto later = [&](uint32_t x, uint32_t y) {
        const double px = x < priority.size() ? priority[x] : 0.0,
                     py = y < priority.size() ? priority[y] : 0.0;
        return px != py ? px > py : x > y;
    };
    std::priority_queue<uint32_t, std::vector<uint32_t>, decltype(later)> ready(later);
    for (uint32_t i = 0; i < count; ++i)
        if (indegree[i] == 0) ready.push(i);
    std::vector<uint32_t> order;
    while (!ready.empty()) {
        const uint32_t x = ready.top();
        ready.pop();
        order.push_back(x);
        for (uint32_t y : out[x])
            if (--indegree[y] == 0) ready.push(y);
    }
    if (order.size() == count) return order;
    if (cycle) {
        std::vector<uint8_t> isLeft(count, 1);
        for (uint32_t x : order) isLeft[x] = 0;
        *cycle = findCycle(into, isLeft);
    }
    return {};
}

}  // namespace zomefab::mount
