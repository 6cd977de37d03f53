// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/tri_mesh.h"

#include <algorithm>

namespace zomefab {

void Box3d::expand(const Vec3d& p) {
    for (int i = 0; i < 3; ++i) {
        min[i] = std::min(min[i], p[i]);
        max[i] = std::max(max[i], p[i]);
    }
}

Vec3d Box3d::size() const {
    if (isEmpty()) return {0, 0, 0};
    return {max[0] - min[0], max[1] - min[1], max[2] - min[2]};
}

Box3d boundingBox(const TriMesh& mesh) {
    Box3d box;
    for (const Vec3f& p : mesh.positions) box.expand({p[0], p[1], p[2]});
    return box;
}

}  // namespace zomefab
