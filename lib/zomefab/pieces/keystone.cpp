// SPDX-License-Identifier: GPL-3.0-or-later
// Keystones for rings of pieces around a hole (detail/keystone.h, docs/mounting.md, "Keystones").
#include "zomefab/pieces/detail/keystone.h"

#include <algorithm>
#include <cmath>

namespace zomefab::pieces::detail {

namespace {

/// A face whose normal lies within this of the direction (|m| = sin of the angle) cannot be
/// replaced by a plane parallel to it: the neighbour lies straight ahead.
constexpr double kMinSine = 0.26;  // 15°

/// The planes that replace the faces of @p piece forbidding removal along @p d; empty when no face
/// forbids it or one is nearly square to d.
std::vector<SplitPlane> keystonePlanes(uint32_t piece, const Vec3d& d,
                                       const std::map<uint32_t, std::vector<Vec3d>>& touching,
                                       const FaceContacts& faces, double voxelMm) {
    std::vector<SplitPlane> planes;
    for (const auto& [other, points] : touching) {
        const auto it = faces.find({std::min(piece, other), std::max(piece, other)});
        if (it == faces.end() || points.empty()) continue;
        for (const CutContact& c : it->second) {
            if (c.voxelFaces < kMinOrderFaceVoxels) continue;
            // The stored normal points from the lower piece into the higher: here, into piece.
            const Vec3d n = other < piece ? c.normal : scale(c.normal, -1.0);
            if (dot(d, n) >= 0.0) continue;  // the face lets the piece slide off along d
            const Vec3d m = madd(n, -dot(n, d), d);
            if (norm(m) < kMinSine) return {};
            const Vec3d unit = normalized(m);
            double offset = -1e300;
            for (const Vec3d& x : points) offset = std::max(offset, dot(unit, x));
            planes.push_back({unit, offset + 0.5 * voxelMm});
        }
    }
    return planes;
}

/// Whether every sliver and the keystone of @p planes hold at least @p minVoxels of @p voxels.
bool partsLargeEnough(const std::vector<Vec3d>& voxels, const std::vector<SplitPlane>& planes,
                      size_t minVoxels) {
    std::vector<size_t> count(planes.size() + 1, 0);
    for (const Vec3d& x : voxels) {
        size_t part = planes.size();  // the keystone, unless below a plane (the first it is below)
        for (size_t i = 0; i < planes.size(); ++i)
            if (dot(planes[i].normal, x) < planes[i].offsetMm) {
                part = i;
                break;
            }
        ++count[part];
    }
    return std::all_of(count.begin(), count.end(), [&](size_t c) { return c >= minVoxels; });
}

}  // namespace

std::optional<Keystone> findKeystone(uint32_t piece, const std::vector<Vec3d>& voxels,
                                     const std::map<uint32_t, std::vector<Vec3d>>& touching,
                                     const MountBody& body, const FaceContacts& faces,
                                     const std::vector<const TenonCandidate*>& candidates,
                                     const Transform4d& frameToGridMm, const SplitSearch& search) {
    const double voxelVolume = search.voxelMm * search.voxelMm * search.voxelMm;
    const size_t minVoxels = size_t(std::ceil(search.minVolumeMm3 / voxelVolume));
    for (const DirectionOption& o : body.options) {
        if (!o.isTested || !o.isFree || o.tenons == 0) continue;
        const Vec3d d = gridDirection(o.hole, frameToGridMm);
        const std::vector<SplitPlane> planes = keystonePlanes(piece, d, touching, faces, search.voxelMm);
        if (planes.empty() || !partsLargeEnough(voxels, planes, minVoxels)) continue;
        // A tenon along d whose wall point stays in the keystone, clear of the new faces.
        const bool isHeld = std::any_of(candidates.begin(), candidates.end(), [&](const TenonCandidate* c) {
            if (c->tenon.hole != o.hole) return false;
            const Vec3d w = c->tenon.pointAt(c->tenon.baseMm);
            return std::all_of(planes.begin(), planes.end(), [&](const SplitPlane& p) {
                return dot(p.normal, w) > p.offsetMm + search.edgeMarginMm;
            });
        });
        if (isHeld) return Keystone{piece, o.hole, planes};
    }
    return std::nullopt;
}

}  // namespace zomefab::pieces::detail
