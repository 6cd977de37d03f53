// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Timings of the exact Zometool model: building, checking and writing a B0 cube lattice, and
/// the per-call cost of the operations a simulated-annealing move uses (docs/benchmarks.md).
///
/// Usage: bench_zome [N cubes per side, default 15] [queries, default 2000000] [output dir, default /tmp]
///                   [grid cell mm, default 0 = automatic]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <random>
#include <string>
#include <vector>

#include "zome_fixtures.h"
#include "zomefab/io/file_io.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;
using namespace zomefab::zome;

namespace {

/// The tests' n×n×n B0 lattice (tests/zome/zome_fixtures.h) with collision cells of @p cellMm.
Structure makeCubeLattice(int n, double cellMm) {
    CollisionOptions options;
    options.gridCellMm = cellMm;
    return test::makeCubeLattice(n, ZomeScale{}, options);
}

/// CPU time of this thread in seconds: less disturbed than wall time when other jobs share the
/// machine (the project's build machine has 2 cores and parallel builds).
double threadSeconds() {
    timespec ts;
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

/// Fastest of @p runs thread-CPU timings of @p f, in seconds.
template <class F>
double bestSeconds(int runs, F&& f) {
    double best = 1e300;
    for (int r = 0; r < runs; ++r) {
        const double start = threadSeconds();
        f();
        best = std::min(best, threadSeconds() - start);
    }
    return best;
}

struct Query {
    BallId ball;
    int hole;
    int size;
};

}  // namespace

int main(int argc, char** argv) {
    const int n = argc > 1 ? std::atoi(argv[1]) : 15;
    const int queries = argc > 2 ? std::atoi(argv[2]) : 2000000;
    const std::string dir = argc > 3 ? argv[3] : "/tmp";
    const double cellMm = argc > 4 ? std::atof(argv[4]) : 0.0;  // 0 = the library's automatic choice
    const int runs = 5;

    // --- a whole frame: build, check, write ------------------------------------------------------
    Structure frame;
    const double tBuild = bestSeconds(runs, [&] { frame = makeCubeLattice(n, cellMm); });
    size_t collisionCount = 0;
    const double tCheck = bestSeconds(runs, [&] { collisionCount = findCollisions(frame).size(); });
    const double tParts = bestSeconds(runs, [&] { (void)partsCostUsd(partsList(frame)); });
    std::string jsonText;
    const double tJson = bestSeconds(runs, [&] {
        jsonText = structureToJson(frame).dump(1);
        writeOutputAtomic(dir + "/bench_zome_frame.json", [&](std::ostream& o) { o << jsonText << '\n'; });
    });
    const double tVef = bestSeconds(runs, [&] {
        const std::string vef = structureToVef(frame);
        writeOutputAtomic(dir + "/bench_zome_frame.vef", [&](std::ostream& o) { o << vef; });
    });
    size_t readBalls = 0;
    const double tRead = bestSeconds(runs, [&] {
        readBalls = structureFromJsonText(readInputBytes(dir + "/bench_zome_frame.json")).ballCount();
    });
    std::printf(
        "frame: %dx%dx%d B0 cubes = %zu balls, %zu struts, %zu collisions (grid %.1f mm, %zu cells, %zu "
        "entries)\n",
        n, n, n, frame.ballCount(), frame.strutCount(), collisionCount, frame.gridCellMm(),
        frame.gridCellCount(), frame.gridEntryCount());
    std::printf("  build (addBall + addStrut)      %8.2f ms\n", tBuild * 1e3);
    std::printf("  check (findCollisions)          %8.2f ms\n", tCheck * 1e3);
    std::printf("  parts list + cost               %8.2f ms\n", tParts * 1e3);
    std::printf("  write JSON (%6.2f MB)           %8.2f ms\n", double(jsonText.size()) / 1e6, tJson * 1e3);
    std::printf("  write VEF                       %8.2f ms\n", tVef * 1e3);
    std::printf("  read + validate JSON            %8.2f ms (%zu balls)\n", tRead * 1e3, readBalls);
    std::printf("  build + check + write JSON      %8.2f ms\n", (tBuild + tCheck + tJson) * 1e3);

    // --- hot-loop operations on that frame -------------------------------------------------------
    std::mt19937_64 rng(12345);
    std::vector<Query> qs(size_t(std::max(1, queries)));
    for (Query& q : qs)
        q = {BallId(rng() % frame.ballIdBound()), int(rng() % kHoleCount), int(rng() % kSizeCount)};
    volatile size_t sink = 0;
    auto perCallNs = [&](auto&& f) {
        return bestSeconds(3,
                           [&] {
                               size_t hits = 0;
                               for (const Query& q : qs) hits += f(q) ? 1 : 0;
                               sink = sink + hits;
                           }) /
               double(qs.size()) * 1e9;
    };
    const double nsStrutQuery =
        perCallNs([&](const Query& q) { return frame.strutCollides(q.ball, q.hole, q.size); });
    std::vector<Query> all = qs;
    for (Query& q : qs) q.size = 0;  // size-0 struts only (B0, Y0, R0: what a B0 lattice mostly uses)
    const double nsStrutQuery0 =
        perCallNs([&](const Query& q) { return frame.strutCollides(q.ball, q.hole, q.size); });
    qs = all;
    // The same queries visited ball by ball (ids follow the lattice): neighbouring queries share
    // cache lines, as consecutive annealing moves around one region do.
    std::sort(qs.begin(), qs.end(), [](const Query& x, const Query& y) { return x.ball < y.ball; });
    const double nsStrutQuerySorted =
        perCallNs([&](const Query& q) { return frame.strutCollides(q.ball, q.hole, q.size); });
    const double nsBallQuerySorted = perCallNs([&](const Query& q) {
        return frame.ballCollides(frame.ball(q.ball).position + strutVector(q.hole, q.size));
    });
    qs = all;
    const double nsBallQuery = perCallNs([&](const Query& q) {
        return frame.ballCollides(frame.ball(q.ball).position + strutVector(q.hole, q.size));
    });
    const double nsFind = perCallNs([&](const Query& q) {
        return frame.findBall(frame.ball(q.ball).position + strutVector(q.hole, q.size)) != kNoId;
    });
    const double nsMatch =
        perCallNs([&](const Query& q) { return bool(matchStrut(strutVector(q.hole, q.size))); });

    // Remove and re-add existing struts (the structure is unchanged afterwards).
    std::vector<StrutId> struts = frame.strutIds();
    std::shuffle(struts.begin(), struts.end(), rng);
    const int cycles = std::max(1, queries / 4);
    const double nsAddRemove =
        bestSeconds(3,
                    [&] {
                        for (int i = 0; i < cycles; ++i) {
                            const Strut s = frame.strut(struts[size_t(i) % struts.size()]);
                            frame.removeStrut(struts[size_t(i) % struts.size()]);
                            struts[size_t(i) % struts.size()] = frame.addStrut(s.a, s.holeA, s.size);
                        }
                    }) /
        cycles * 1e9;

    // A whole "insert a ball and a strut" move, checked and undone: find, hole test, 2 queries,
    // addBall + addStrut, removeStrut + removeBall.
    size_t accepted = 0;
    const double nsMove = perCallNs([&](const Query& q) {
        const GoldenVector3& a = frame.ball(q.ball).position;
        const GoldenVector3 m = a + strutVector(q.hole, q.size);
        if (frame.findBall(m) != kNoId || !frame.isHoleFree(q.ball, q.hole) || frame.ballCollides(m) ||
            frame.strutCollides(q.ball, q.hole, q.size))
            return false;
        const BallId id = frame.addBall(m);
        const StrutId t = frame.addStrut(q.ball, q.hole, q.size);
        frame.removeStrut(t);
        frame.removeBall(id);
        ++accepted;
        return true;
    });
    std::printf(
        "hot loop on that frame (%zu random ball/hole/size triples, best of 3 passes, thread CPU time):\n",
        qs.size());
    std::printf("  strutCollides                   %8.1f ns\n", nsStrutQuery);
    std::printf("  strutCollides, size 0 only      %8.1f ns\n", nsStrutQuery0);
    std::printf("  ballCollides                    %8.1f ns\n", nsBallQuery);
    std::printf("  strutCollides, sorted by ball   %8.1f ns\n", nsStrutQuerySorted);
    std::printf("  ballCollides, sorted by ball    %8.1f ns\n", nsBallQuerySorted);
    std::printf("  findBall                        %8.1f ns\n", nsFind);
    std::printf("  matchStrut                      %8.1f ns\n", nsMatch);
    std::printf("  removeStrut + addStrut          %8.1f ns\n", nsAddRemove);
    std::printf("  insert-ball move, checked+undone %7.1f ns (%.1f%% passed the checks)\n", nsMove,
                100.0 * double(accepted) / double(3 * qs.size()));
    return sink == size_t(-1) ? 1 : 0;
}
