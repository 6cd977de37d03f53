// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The holes of a ball as a builder and a printed peg see them: each colour's section (the
/// shape a strut end, or a tenon's peg, must fit), how far the ball's flat face around it is from
/// the centre, the hole that points closest to a direction, and a direction's name in words.
/// Sources and the rhombicosidodecahedron argument for the corners: docs/zome.md §3.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "zomefab/core/tri_mesh.h"
#include "zomefab/zome/zome_system.h"

namespace zomefab::zome {

/// The section of the holes of @p color as a convex polygon, counter-clockwise, in mm, in the
/// hole's own frame: x along holeSectionAxis(hole), y = holeDirection(hole) × x. Blue: the golden
/// rectangle 5.46 × 3.38 mm (its long side on x); yellow: the equilateral triangle of edge 5.46 mm
/// (a corner on +x, towards the nearest red axis); red: the regular pentagon of circumradius
/// 2.87 mm (a corner on +x, towards the nearest yellow axis). vZome's lifelike part models.
std::vector<std::array<double, 2>> holeSectionMm(Color color);

/// The polygon @p section moved inward by @p insetMm on every side (a peg that leaves that much
/// clearance in the hole). @pre convex, counter-clockwise; insetMm below its inradius.
std::vector<std::array<double, 2>> insetPolygon(const std::vector<std::array<double, 2>>& section,
                                                double insetMm);

/// Radius of the largest circle inside @p polygon around the origin (the thinnest half-width of a peg).
double inradiusMm(const std::vector<std::array<double, 2>>& polygon);

/// Distance from a ball's centre to the flat face around a hole of @p color, as a multiple of the
/// distance to a blue face (the ball's radius across the blue holes): blue 1, yellow 1.0023, red
/// 1.0131 (vZome's ball model, zome-geometry.md §3).
double holeFaceRatio(Color color);

/// The hole whose direction is closest to the unit vector @p direction (ties: the lowest number).
int nearestHole(const Vec3d& direction);

/// A direction as a builder says it, the frame's z up, +x right, +y back: "straight up", "down and
/// to the left", "back, right and up"; the components of at least 0.3, largest first.
std::string directionName(const Vec3d& direction);

/// "blue hole 2 (straight up)": a hole with its colour, number and direction in words.
std::string holeName(int hole);

}  // namespace zomefab::zome
