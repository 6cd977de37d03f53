// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/mesh/scale.h"

#include <cmath>
#include <limits>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"

namespace zomefab::mesh {

void checkScaleOptions(const ScaleOptions& options) {
    if (options.heightMm && options.scale)
        throw Error(ErrorCode::Usage, "give either --height-mm or --scale, not both");
    if (options.heightMm && !(std::isfinite(*options.heightMm) && *options.heightMm > 0))
        throw Error(ErrorCode::Usage, "--height-mm must be a positive number of millimetres, got " +
                                          formatNumber(*options.heightMm));
    if (options.scale && !(std::isfinite(*options.scale) && *options.scale > 0))
        throw Error(ErrorCode::Usage,
                    "--scale must be a positive factor, got " + formatNumber(*options.scale));
}

ScaledMesh scaleToMillimetres(TriMesh mesh, const ScaleOptions& options) {
    checkScaleOptions(options);
    if (mesh.positions.empty()) throw Error(ErrorCode::InvalidInput, "cannot scale an empty mesh");
    const Transform4d rotate = options.up == UpAxis::Y ? Transform4d::yUpToZUp() : Transform4d::identity();

    // Bounding box after the rotation, in double, before any rounding to float.
    Box3d rotated;
    for (const Vec3f& p : mesh.positions) rotated.expand(rotate.apply({p[0], p[1], p[2]}));
    for (int i = 0; i < 3; ++i)
        if (!std::isfinite(rotated.min[i]) || !std::isfinite(rotated.max[i]))
            throw Error(ErrorCode::InvalidInput, "the mesh has non-finite coordinates");
    const double height = rotated.max[2] - rotated.min[2];

    double scale = 1.0;
    if (options.heightMm) {
        if (!(height > 0))
            throw Error(ErrorCode::InvalidInput, std::string("the mesh is flat along its up axis (") +
                                                     (options.up == UpAxis::Y ? "y" : "z") +
                                                     "), so it cannot be scaled to a height");
        scale = *options.heightMm / height;
    } else if (options.scale) {
        scale = *options.scale;
    }
    // Centre x/y on the origin and put the lowest point on z = 0 (the print bed).
    const Vec3d shift{-scale * (rotated.min[0] + rotated.max[0]) / 2,
                      -scale * (rotated.min[1] + rotated.max[1]) / 2, -scale * rotated.min[2]};
    const Transform4d transform = Transform4d::scaleTranslate(scale, shift) * rotate;

    ScaledMesh result;
    transformInPlace(mesh, transform);
    for (const Vec3f& p : mesh.positions)
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            throw Error(ErrorCode::InvalidInput,
                        "scaled coordinates overflow single precision (scale " + formatNumber(scale) + ")");
    result.sizeMm = boundingBox(mesh).size();
    result.mesh = std::move(mesh);
    result.transformMm = transform;
    return result;
}

}  // namespace zomefab::mesh
