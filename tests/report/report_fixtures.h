// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Closed test parts for the report tests and the estimator calibration: hollow boxes,
/// spherical shells and shell pieces (cut with report::clipToBox), and the bundled bunny in mm.
#pragma once

#include <algorithm>
#include <string>

#include "test_util.h"
#include "zomefab/core/transform.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/report/mesh_clip.h"

namespace zomefab::test {

/// @p m with every triangle reversed (an inward-facing cavity wall).
inline TriMesh reversed(TriMesh m) {
    for (Triangle& t : m.triangles) std::swap(t[1], t[2]);
    return m;
}

/// @p a and @p b in one mesh.
inline TriMesh merged(const TriMesh& a, const TriMesh& b) {
    TriMesh m = a;
    const uint32_t base = uint32_t(m.positions.size());
    m.positions.insert(m.positions.end(), b.positions.begin(), b.positions.end());
    for (const Triangle& t : b.triangles) m.triangles.push_back({t[0] + base, t[1] + base, t[2] + base});
    return m;
}

/// A closed box [0, size]³ with a closed cavity @p wallMm inside every face.
inline TriMesh hollowCube(double sizeMm, double wallMm) {
    return merged(
        makeBox({0, 0, 0}, {sizeMm, sizeMm, sizeMm}),
        reversed(makeBox({wallMm, wallMm, wallMm}, {sizeMm - wallMm, sizeMm - wallMm, sizeMm - wallMm})));
}

/// A closed spherical shell: outer radius @p radiusMm, wall @p wallMm, centred at @p c.
inline TriMesh sphereShell(const Vec3d& c, double radiusMm, double wallMm, int rings = 48,
                           int segments = 96) {
    return merged(makeSphere(c, radiusMm, rings, segments),
                  reversed(makeSphere(c, radiusMm - wallMm, rings, segments)));
}

/// A piece like the pipeline's: one octant of a spherical shell (outer radius @p radiusMm, wall
/// @p wallMm), resting on z = 0 with its cut faces.
inline TriMesh shellPiece(double radiusMm, double wallMm, int rings = 48, int segments = 96) {
    Box3d octant;
    octant.min = {0, 0, 0};
    octant.max = {radiusMm + 1, radiusMm + 1, radiusMm + 1};
    return report::clipToBox(sphereShell({0, 0, 0}, radiusMm, wallMm, rings, segments), octant);
}

/// A flat-lying dome like the pipeline's top pieces: the part of a spherical shell (outer radius
/// @p radiusMm, wall @p wallMm) above z = @p cutZMm, cut face down on z = 0.
inline TriMesh domePiece(double radiusMm, double wallMm, double cutZMm) {
    TriMesh m = report::clipByPlane(sphereShell({0, 0, 0}, radiusMm, wallMm), 2, cutZMm, false);
    for (Vec3f& p : m.positions) p[2] -= float(cutZMm);
    return m;
}

/// data/bunny_npm_3674.stl (y up) turned z up, scaled to @p heightMm, centred in x and y, on z = 0.
inline TriMesh bunnyMm(double heightMm) {
    TriMesh m = readMesh(dataPath("bunny_npm_3674.stl"));
    transformInPlace(m, Transform4d::yUpToZUp());
    const Box3d b = boundingBox(m);
    const double s = heightMm / (b.max[2] - b.min[2]);
    transformInPlace(m, Transform4d::scaleTranslate(s, {-s * 0.5 * (b.min[0] + b.max[0]),
                                                        -s * 0.5 * (b.min[1] + b.max[1]), -s * b.min[2]}));
    return m;
}

}  // namespace zomefab::test
