// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Cutting a closed mesh by axis-aligned planes, with flat caps: what the print-cost baseline
/// needs to cut an object into octree cells that fit the printer (paper §7.2, docs/report.md).
#pragma once

#include "zomefab/core/tri_mesh.h"

namespace zomefab::report {

/// The part of the closed, outward mesh @p mesh on one side of the plane x[axis] = @p coordMm,
/// closed by planar caps (ear clipping, holes bridged), so the result is closed and outward too.
/// When a vertex lies within 1e-4 mm of the plane, the plane moves by up to 0.01 mm (deterministic)
/// so that no vertex lies on it. An empty mesh when nothing lies on the kept side.
/// @param axis 0, 1 or 2 (x, y, z)
/// @param keepBelow keep x[axis] < coordMm when true, x[axis] > coordMm otherwise
/// @throw Error(InvalidInput) when the cut edges do not close into loops (an open or non-manifold
///   input), Error(Usage) for an axis outside 0..2.
TriMesh clipByPlane(const TriMesh& mesh, int axis, double coordMm, bool keepBelow);

/// The part of the closed mesh inside @p box (six clipByPlane calls, skipped for faces of the box
/// that the mesh does not cross). @throw as clipByPlane().
TriMesh clipToBox(const TriMesh& mesh, const Box3d& box);

}  // namespace zomefab::report
