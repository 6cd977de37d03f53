// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Stage 1: bring the input to millimetres, z up (the printing convention).
#pragma once

#include <optional>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::mesh {

enum class UpAxis { Y, Z };

struct ScaleOptions {
    std::optional<double> heightMm;  ///< extent along the up axis after scaling; > 0
    std::optional<double> scale;     ///< alternative: uniform factor file units -> mm; > 0
    UpAxis up = UpAxis::Z;           ///< the input's up axis; y-up inputs are rotated to z-up
};

struct ScaledMesh {
    TriMesh mesh;               ///< millimetres, z up, centred in x/y, resting on z = 0
    Transform4d transformMm;    ///< input coordinates -> these millimetres
    Vec3d sizeMm{0, 0, 0};      ///< bounding-box extent after scaling
};

/// Without heightMm or scale, coordinates are taken as millimetres (only rotated and moved).
/// @throw Error(Usage) for a non-positive or non-finite height or scale, or both given;
///        Error(InvalidInput) for a mesh with zero extent along the up axis.
ScaledMesh scaleToMillimetres(TriMesh mesh, const ScaleOptions& options);

}  // namespace zomefab::mesh
