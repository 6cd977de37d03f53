// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/move_tables.h"

#include <cmath>

namespace zomefab::frame {

namespace {

constexpr double kHalfPi = 1.57079632679489661923;

MoveTables buildMoveTables() {
    using namespace zome;
    MoveTables t;
    for (int i = 0; i < kHoleCount; ++i) {
        for (int j = 0; j < kHoleCount; ++j) {
            const Golden d = dot(strutVector(i, 0), strutVector(j, 0));
            if (d.isZero()) {
                t.cosine[i][j] = 0.0;
                t.deviation[i][j] = 0.0;
            } else if (j == oppositeHole(i)) {
                t.cosine[i][j] = -1.0;
                t.deviation[i][j] = kHalfPi;
            } else if (i == j) {
                t.cosine[i][j] = 1.0;
                t.deviation[i][j] = kHalfPi;
            } else {
                const double c = holeCosine(i, j);
                t.cosine[i][j] = c;
                t.deviation[i][j] = std::abs(std::acos(std::max(-1.0, std::min(1.0, c))) - kHalfPi);
            }
        }
    }
    // Closing: v1 + v2 looked up exactly (a triangle a → c → b closed by a → b).
    for (int k1 = 0; k1 < kHoleCount * kSizeCount; ++k1) {
        for (int k2 = 0; k2 < kHoleCount * kSizeCount; ++k2) {
            const GoldenVector3 sum = strutVector(k1 / kSizeCount, k1 % kSizeCount) +
                                      strutVector(k2 / kSizeCount, k2 % kSizeCount);
            const std::optional<StrutMatch> m = sum.isZero() ? std::nullopt : matchStrut(sum);
            t.closing[size_t(k1)][size_t(k2)] = m ? int16_t(strutKey(m->hole, m->size)) : int16_t(-1);
        }
    }
    // Splits: v = v1 + v2 with v1, v2 catalogue struts; v2 = v − v1 looked up exactly.
    for (int h = 0; h < kHoleCount; ++h) {
        for (int s = 0; s < kSizeCount; ++s) {
            const GoldenVector3& v = strutVector(h, s);
            auto& list = t.splits[size_t(strutKey(h, s))];
            for (int h1 = 0; h1 < kHoleCount; ++h1) {
                for (int s1 = 0; s1 < kSizeCount; ++s1) {
                    const GoldenVector3 rest = v - strutVector(h1, s1);
                    if (rest.isZero()) continue;
                    const std::optional<StrutMatch> m = matchStrut(rest);
                    if (!m) continue;
                    // The new ball uses oppositeHole(h1) and m->hole; they differ unless the two
                    // struts fold back on one axis, which matchStrut cannot return here.
                    if (m->hole == oppositeHole(h1)) continue;
                    list.push_back({uint8_t(h1), uint8_t(s1), uint8_t(m->hole), uint8_t(m->size)});
                }
            }
        }
    }
    return t;
}

}  // namespace

const MoveTables& moveTables() {
    static const MoveTables tables = buildMoveTables();
    return tables;
}

double regularityOfMask(uint64_t mask) {
    if (__builtin_popcountll(mask) < 2) return 0.0;
    const MoveTables& t = moveTables();
    double sum = 0.0;
    for (uint64_t mi = mask; mi; mi &= mi - 1) {
        const int i = __builtin_ctzll(mi);
        // The nearest other strut has the largest cosine; its deviation is tabulated.
        double bestCos = -2.0;
        int best = -1;
        for (uint64_t mj = mask; mj; mj &= mj - 1) {
            const int j = __builtin_ctzll(mj);
            if (j == i) continue;
            if (t.cosine[size_t(i)][size_t(j)] > bestCos) {
                bestCos = t.cosine[size_t(i)][size_t(j)];
                best = j;
            }
        }
        sum += t.deviation[size_t(i)][size_t(best)];
    }
    return sum;
}

}  // namespace zomefab::frame
