// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/tri_mesh.h"

#include <algorithm>
#include <cstring>
#include <unordered_map>

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

void weldIdenticalVertices(TriMesh& mesh) {
    struct KeyHash {
        size_t operator()(const std::array<uint32_t, 3>& k) const {
            uint64_t h = 1469598103934665603ull;
            for (uint32_t v : k) h = (h ^ v) * 1099511628211ull;
            return size_t(h ^ (h >> 29));
        }
    };
    std::unordered_map<std::array<uint32_t, 3>, uint32_t, KeyHash> index;
    index.reserve(mesh.positions.size());
    std::vector<Vec3f> welded;
    welded.reserve(mesh.positions.size() / 4 + 16);
    std::vector<uint32_t> remap(mesh.positions.size());
    for (size_t i = 0; i < mesh.positions.size(); ++i) {
        Vec3f p = mesh.positions[i];
        std::array<uint32_t, 3> key;
        for (int c = 0; c < 3; ++c) {
            if (p[c] == 0.0f) p[c] = 0.0f;  // -0 and +0 are the same point
            std::memcpy(&key[c], &p[c], sizeof(float));
        }
        auto [it, inserted] = index.emplace(key, uint32_t(welded.size()));
        if (inserted) welded.push_back(p);
        remap[i] = it->second;
    }
    for (Triangle& t : mesh.triangles)
        for (uint32_t& v : t) v = remap[v];
    mesh.positions = std::move(welded);
}

}  // namespace zomefab
