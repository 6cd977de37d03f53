// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/frame_field.h"

#include <algorithm>
#include <cmath>

#include "zomefab/core/vec.h"

namespace zomefab::frame {

Transform4d rotationAboutZ(double degrees) {
    const double a = degrees * kPi / 180.0;
    const double c = std::cos(a), s = std::sin(a);
    Transform4d t;
    t.m = {c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
    return t;
}

FrameField::FrameField(const sdf::InteriorField& field, double rotationDeg, const zome::ZomeScale& scale,
                       const sdf::ForbiddenZoneOptions& zone)
    : mField(&field), mRotationDeg(rotationDeg), mScale(scale), mZone(zone) {
    const double a = rotationDeg * kPi / 180.0;
    mCos = std::cos(a);
    mSin = std::sin(a);
    if (rotationDeg == 0.0) {  // keep the identity exact
        mCos = 1.0;
        mSin = 0.0;
    }
}

bool FrameField::isSegmentAllowed(const Vec3d& p, double dp, const Vec3d& q, double dq,
                                  double limitMm) const {
    if (dp < limitMm || dq < limitMm) return false;
    const double len = norm({q[0] - p[0], q[1] - p[1], q[2] - p[2]});
    // Lipschitz: depth(x) ≥ max(dp − |x−p|, dq − |x−q|) ≥ (dp + dq − len)/2 on the segment.
    if (0.5 * (dp + dq - len) >= limitMm || len < 1.0) return true;
    const Vec3d m{0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1]), 0.5 * (p[2] + q[2])};
    const double dm = depthMm(m);
    if (dm < limitMm) return false;
    return isSegmentAllowed(p, dp, m, dm, limitMm) && isSegmentAllowed(m, dm, q, dq, limitMm);
}

std::vector<SurfaceSample> sampleSurface(const FrameField& frameField, double spacingMm) {
    const sdf::InteriorField& field = frameField.field();
    std::vector<SurfaceSample> samples;
    if (field.empty() || !(spacingMm > 0)) return samples;
    const Box3d box = field.boundsMm();
    int n[3];
    for (int a = 0; a < 3; ++a) n[a] = int(std::floor((box.max[a] - box.min[a]) / spacingMm)) + 1;
    const double reachMm = frameField.ballDepthLimitMm() + 1.0;
    for (int i = 0; i < n[0]; ++i) {
        for (int j = 0; j < n[1]; ++j) {
            for (int k = 0; k < n[2]; ++k) {
                const Vec3d p{box.min[0] + i * spacingMm, box.min[1] + j * spacingMm,
                              box.min[2] + k * spacingMm};
                const sdf::FieldSample s = field.sample(p);
                if (!(std::abs(s.signedDistanceMm) < 0.5 * spacingMm)) continue;
                const double g = norm(s.gradient);
                if (!(g > 1e-9)) continue;
                const Vec3d nrm{s.gradient[0] / g, s.gradient[1] / g, s.gradient[2] / g};
                const Vec3d onSurface{p[0] - s.signedDistanceMm * nrm[0], p[1] - s.signedDistanceMm * nrm[1],
                                      p[2] - s.signedDistanceMm * nrm[2]};
                const Vec3d inward{onSurface[0] - reachMm * nrm[0], onSurface[1] - reachMm * nrm[1],
                                   onSurface[2] - reachMm * nrm[2]};
                SurfaceSample sample;
                sample.positionMm = frameField.toFrameMm(onSurface);
                sample.isReachable = field.depthMm(inward) >= frameField.ballDepthLimitMm();
                samples.push_back(sample);
            }
        }
    }
    return samples;
}

double deepestDepthMm(const sdf::InteriorField& field) {
    if (field.empty()) return 0.0;
    const Box3d box = field.boundsMm();
    const double h = field.voxelMm();
    double best = -1e300;
    for (double x = box.min[0]; x <= box.max[0]; x += h)
        for (double y = box.min[1]; y <= box.max[1]; y += h)
            for (double z = box.min[2]; z <= box.max[2]; z += h)
                best = std::max(best, field.depthMm({x, y, z}));
    return best;
}

}  // namespace zomefab::frame
