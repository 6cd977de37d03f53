// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Fixtures for the pieces tests: a spherical shell level set, a B0 cube-lattice frame inside
/// it, argmax cells from axis planes, and mesh queries (point inside, ray hits).
#pragma once

#include <optional>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces::test {

/// The shell {R − T ≤ |x − c| ≤ R} as a level set (a UV sphere mesh through meshToLevelSet and
/// makeShell), at @p voxelMm.
sdf::LevelSet makeSphereShell(const Vec3d& centerMm, double radiusMm, double shellMm, double voxelMm);

/// The shell most pieces tests cut: a 200 mm sphere (radius kSphereRadiusMm at the origin) with an
/// 8 mm wall (kSphereShellMm) at 1 mm voxels, built once (≈ 1 s); and the B0 lattice inside it whose
/// balls stay 3 mm clear of the inner wall.
inline constexpr double kSphereRadiusMm = 100.0, kSphereShellMm = 8.0;
const sdf::LevelSet& sphereShell();
const zome::Structure& sphereFrame();

/// Balls on the B0 cube lattice (exact (2+2φ)·(i, j, k) units, b0 = 47.3 mm) whose centre lies
/// within @p maxRadiusMm of the origin, joined by B0 struts to their lattice neighbours.
zome::Structure makeCubeLattice(double maxRadiusMm);

/// A partition whose argmax cells cut space along x = @p xMm and z = @p zMm (4 cells, frame mm):
/// for signs (sx, sz) ∈ {±1}², w = (sx, 0, sz), b = −sx·x − sz·z; one piece per cell, marked as
/// fitting the partition's printer (200 mm; makePieces tests pieces cut for another printer itself).
partition::PartitionResult quadrantCells(double xMm, double zMm);
/// Two cells cut by the plane n·x = d (n need not be unit): {n·x ≥ d} is cell 0; one piece each,
/// marked as fitting (as quadrantCells).
partition::PartitionResult halfSpaceCells(const Vec3d& n, double d);
/// A Fabrication with the printer @p printerMm and no bed margin: a piece may take the whole printer.
Fabrication printerOf(const Vec3d& printerMm);

/// Is @p p inside the closed mesh? (ray parity along a fixed skew direction)
bool isInsideMesh(const TriMesh& mesh, const Vec3d& p);
/// Distance along the ray @p origin + t·@p dir (t > 0) to the first triangle, if any.
std::optional<double> firstHit(const TriMesh& mesh, const Vec3d& origin, const Vec3d& dir);

/// @p piece's mesh in the shell grid's mm (undoes the print orientation).
TriMesh gridMesh(const Piece& piece);

/// Writes zf-pieces inputs into @p directory: shell.vdb (a 150 mm sphere, 8 mm wall, 1 mm voxel),
/// frame.json (the B0 lattice inside: 7 balls), partition.json (the quadrants x ≶ −5.3, z ≶ 10.4
/// as cells and pieces, printer 200 mm), and for the error tests bad-transform.json (the same
/// partition made with another frame transform) and not-partition.json.
void writeToolInputs(const std::string& directory);

}  // namespace zomefab::pieces::test
