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
    TriMesh mesh;             ///< millimetres, z up, centred in x/y, resting on z = 0
    Transform4d transformMm;  ///< input coordinates -> these millimetres
    Vec3d sizeMm{0, 0, 0};    ///< bounding-box extent after scaling
};

/// @throw Error(Usage) for a non-positive or non-finite height or scale, or both given. Tools call
///        it before reading any input, so a bad option fails fast with exit code 1.
void checkScaleOptions(const ScaleOptions& options);

/// Rotates a y-up input to z up, scales it uniformly (to heightMm along z, or by scale), then
/// centres it in x/y and rests it on z = 0. Without heightMm or scale, coordinates are taken as
/// millimetres (only rotated and moved).
/// @throw Error(Usage) as checkScaleOptions; Error(InvalidInput) for an empty mesh, one with zero
///        extent along the up axis (with heightMm), or coordinates that overflow float when scaled.
ScaledMesh scaleToMillimetres(TriMesh mesh, const ScaleOptions& options);

}  // namespace zomefab::mesh
