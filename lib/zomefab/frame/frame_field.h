// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The object as the frame sees it: the interior distance field in the frame's millimetres
/// (the lattice may be rotated about the up axis z), the clearance rules of the forbidden zone
/// (paper §4.3.1: nothing of the frame closer than dMin to the surface, ball and strut radii
/// accounted for) and surface samples for the coverage and gap measures. docs/frame.md.
#pragma once

#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/sdf/interior_field.h"
#include "zomefab/zome/zome_system.h"

namespace zomefab::frame {

/// Rotation about +z by @p degrees as a transform (x ↦ R·x).
Transform4d rotationAboutZ(double degrees);

/// Smallest depth inside the surface a ball's centre may have: the clearance dMin and the ball's
/// radius (mm). The one rule, for a FrameField and for the lattice's depth bounds (cubeDepthMm).
inline double ballDepthLimitMm(const sdf::ForbiddenZoneOptions& zone, const zome::ZomeScale& scale) {
    return zone.dMinMm + scale.ballRadiusMm();
}

/// The interior field seen from the frame's coordinates, plus the clearance rules. The frame's
/// millimetres are the field's millimetres rotated by −rotationDeg about z: a point p of the frame
/// lies at R(rotationDeg)·p in the field. Read-only after construction: safe for any number of
/// concurrent readers (parallel chains). Keeps a reference to @p field.
class FrameField {
public:
    FrameField(const sdf::InteriorField& field, double rotationDeg, const zome::ZomeScale& scale,
               const sdf::ForbiddenZoneOptions& zone);

    const sdf::InteriorField& field() const { return *mField; }
    double rotationDeg() const { return mRotationDeg; }
    const zome::ZomeScale& scale() const { return mScale; }
    const sdf::ForbiddenZoneOptions& zone() const { return mZone; }

    Vec3d toFieldMm(const Vec3d& frameMm) const {
        return {mCos * frameMm[0] - mSin * frameMm[1], mSin * frameMm[0] + mCos * frameMm[1],
                frameMm[2]};
    }
    Vec3d toFrameMm(const Vec3d& fieldMm) const {
        return {mCos * fieldMm[0] + mSin * fieldMm[1], -mSin * fieldMm[0] + mCos * fieldMm[1],
                fieldMm[2]};
    }
    /// Distance of @p frameMm inside the surface (negative outside), mm.
    double depthMm(const Vec3d& frameMm) const { return mField->depthMm(toFieldMm(frameMm)); }

    /// Smallest centre depth a ball may have: dMin + ball radius (frame::ballDepthLimitMm).
    double ballDepthLimitMm() const { return frame::ballDepthLimitMm(mZone, mScale); }
    /// Smallest depth the axis of a strut of @p color may have: dMin + strut radius.
    double strutDepthLimitMm(zome::Color color) const {
        return mZone.dMinMm + mScale.strutRadiusMm(color);
    }
    bool isBallAllowed(double centreDepthMm) const { return centreDepthMm >= ballDepthLimitMm(); }
    /// True when the segment p–q (centre depths dp, dq, already computed) stays at least
    /// @p limitMm deep. Recursive bisection with the 1-Lipschitz bound of a distance field: a
    /// piece whose end depths d0, d1 and length L give (d0 + d1 − L)/2 ≥ limit is clear without
    /// sampling; a sample below the limit rejects; pieces shorter than 1 mm are accepted (at most
    /// 0.5 mm of tolerance).
    bool isSegmentAllowed(const Vec3d& p, double dp, const Vec3d& q, double dq, double limitMm) const;

private:
    const sdf::InteriorField* mField;
    double mRotationDeg;
    double mCos, mSin;
    zome::ZomeScale mScale;
    sdf::ForbiddenZoneOptions mZone;
};

/// A point on the object's surface, in the frame's millimetres.
struct SurfaceSample {
    Vec3d positionMm{};
    /// True when the object is thick enough under the point to hold a ball at the clearance dMin
    /// (the point dMin + ball radius + 1 mm inward along the normal is at least dMin + ball
    /// radius deep): only such points can ever have a frame ball within reach.
    bool isReachable = false;
};

/// Surface points about @p spacingMm apart: the field's grid points at this spacing closer than
/// spacing/2 to the surface, projected onto it with δ(p). Deterministic order.
std::vector<SurfaceSample> sampleSurface(const FrameField& field, double spacingMm);

/// The deepest point of the field found on a grid at the field's voxel (for the "too thin"
/// message): its depth in mm.
double deepestDepthMm(const sdf::InteriorField& field);

}  // namespace zomefab::frame
