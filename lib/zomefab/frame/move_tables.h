// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Tables the annealing moves and the regularity term look up instead of computing
/// (paper §4.3.2, §4.4): the triangles every catalogue strut can be split into (InsNode), and the
/// deviation from 90° of the angle between any two holes. Built once, exactly, thread-safe.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "zomefab/zome/zome_system.h"

namespace zomefab::frame {

/// One way to split the strut (hole, size) leaving ball a: the new ball sits at
/// a + strutVector(hole1, size1) and the second strut leaves it through hole2 with size2, so that
/// strutVector(hole1, size1) + strutVector(hole2, size2) = strutVector(hole, size) exactly.
struct SplitEntry {
    uint8_t hole1 = 0, size1 = 0, hole2 = 0, size2 = 0;
};

/// Index of a (hole, size) pair in the tables: hole·3 + size.
inline int strutKey(int hole, int size) { return hole * zome::kSizeCount + size; }

struct MoveTables {
    /// Every split of each (hole, size), ordered by (hole1, size1); 186 lists.
    std::array<std::vector<SplitEntry>, zome::kHoleCount * zome::kSizeCount> splits;
    /// Triangle closing (the merge table of InsStrut): closing[k1][k2] = strutKey of the strut
    /// v(k1) + v(k2) when that sum is a catalogue strut, else −1. k = strutKey(hole, size).
    std::array<std::array<int16_t, zome::kHoleCount * zome::kSizeCount>, zome::kHoleCount * zome::kSizeCount>
        closing{};
    /// cos of the angle between holes i and j.
    std::array<std::array<double, zome::kHoleCount>, zome::kHoleCount> cosine{};
    /// |θ_ij − π/2| in radians, exactly 0 for perpendicular holes (exact dot product zero) and
    /// exactly π/2 for opposite holes.
    std::array<std::array<double, zome::kHoleCount>, zome::kHoleCount> deviation{};
};

const MoveTables& moveTables();

/// The regularity sum of one ball whose used holes are @p mask (paper Eq. 3 as chosen in
/// docs/frame.md): Σ over its struts i of |min_{j≠i} θ_ij − π/2|, where j runs over the other
/// struts of the same ball; 0 for fewer than two struts. Radians.
double regularityOfMask(uint64_t mask);

}  // namespace zomefab::frame
