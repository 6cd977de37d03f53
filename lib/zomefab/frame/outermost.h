// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The outermost balls N_out of a frame (paper §4.3.1, E_fid), decided from the structure
/// alone so that zf-frame (energy) and zf-partition (which only has the mesh and the frame file)
/// agree on them. docs/frame.md, "Outermost and internal balls".
///
/// Definition: a ball is *outermost* when its struts leave a closed half-space free, i.e. there
/// is a direction d ≠ 0 with d·u ≤ 0 for the direction u of every strut at the ball (the strut
/// directions do not positively span R³). Balls with fewer than four struts are always outermost.
/// Every other ball is *internal* (the paper's N_in, E_val). In the B0 cube lattice the outermost
/// balls are exactly those of the boundary layer (a ball missing any of its six cube struts).
/// The test is exact: the signs come from exact golden-integer cross and dot products of the hole
/// vectors, tabulated once; a query is a few 64-bit mask operations per pair of struts.
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/zome/structure.h"

namespace zomefab::frame {

/// Bit h set for every used hole h (0..61) of @p ball.
uint64_t holeMask(const zome::Ball& ball);

/// True when a ball whose used holes are @p mask is outermost (see the file comment).
/// Deterministic and exact; thread-safe.
bool isOutermostMask(uint64_t mask);

/// N_out: the ids of the live outermost balls of @p structure, sorted increasingly.
std::vector<zome::BallId> outermostBalls(const zome::Structure& structure);

}  // namespace zomefab::frame
