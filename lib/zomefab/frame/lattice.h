// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The initial frame (paper §4.2): cubes of B0 blue struts along the three blue axes x, y, z,
/// every ball and strut clear of the forbidden zone (dMin, ball and strut radii accounted for).
/// The lattice offset (and optionally its rotation about the up axis z) is searched to maximise
/// the number of whole cubes (ties: the lowest mean E_fid summand of the boundary balls, then the
/// first placement); the largest connected part is kept. docs/frame.md, "Initial lattice".
#pragma once

#include <cstddef>

#include "zomefab/core/run_context.h"
#include "zomefab/sdf/interior_field.h"
#include "zomefab/zome/structure.h"

namespace zomefab::frame {

struct LatticeOptions {
    /// Offsets tried per axis: the lattice origin moves by b0/offsetSteps steps over one cell, so
    /// offsetSteps³ placements (1 = the paper's single placement at the field's corner).
    int offsetSteps = 6;
    /// Also try rotations of the lattice about the up axis z (the paper does not rotate).
    bool searchRotation = false;
    double rotationStepDeg = 7.5;      ///< step of the rotation search over [0°, 90°)
    zome::ZomeScale scale;             ///< physical sizes (b0 47.3 mm, ball 17.7 mm, strut radii)
    sdf::ForbiddenZoneOptions zone;    ///< dMin: the clearance every ball and strut keeps
    zome::CollisionOptions collision;  ///< passed to the structure
};

struct LatticeResult {
    /// The kept cubes, balls numbered in lattice order; scale().originMm is the lattice offset.
    zome::Structure structure;
    double rotationDeg = 0;   ///< lattice rotation about z (frame = R(−rotation)·field)
    Vec3d offsetMm{0, 0, 0};  ///< position of lattice index (0,0,0) in the frame's mm
    size_t cubes = 0;         ///< whole cubes of the chosen placement
    size_t keptCubes = 0;     ///< whole cubes in the kept (largest connected) part
    size_t placementsTried = 0;
    size_t firstPlacementCubes = 0;  ///< whole cubes of the unsearched placement (corner, 0°)
};

/// The B0 cube lattice in @p field (the "interior" field in mm, z up). Where no whole cube fits
/// (an object thinner than a cube and its clearance), the placement with the most balls joined by
/// allowed B0 struts: a row, a square, one ball (LatticeResult::cubes is then 0).
/// @throw Error(ProcessingFailed) when not even one ball fits ("too thin"), naming the deepest inner
///        point found and the depth a ball needs; Error(Usage) for offsetSteps < 1 or a
///        non-positive rotation step; Error(Cancelled).
LatticeResult initialLattice(const sdf::InteriorField& field, const LatticeOptions& options,
                             RunContext& context);

/// How far inside the surface (mm) a point must lie for the offset search to find a whole B0 cube
/// there for sure: a ball's depth (ballDepthLimitMm, frame_field.h), half a cube's diagonal (its corners
/// round its centre) and half an offset step's diagonal (some placement puts a cube's centre that close to
/// any point). Depth falls by at most the distance moved, so every ball and strut of that cube
/// keeps dMin. A sufficient depth, not a necessary one: a luckier point may hold a cube less deep.
double cubeDepthMm(const LatticeOptions& options);

}  // namespace zomefab::frame
