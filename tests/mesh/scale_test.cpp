// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/mesh/scale.h"

#include <doctest/doctest.h>

#include <cmath>
#include <limits>

#include "test_util.h"
#include "zomefab/core/error.h"

using namespace zomefab;
using namespace zomefab::test;
using namespace zomefab::mesh;

namespace {

ErrorCode errorCodeOf(const TriMesh& m, const ScaleOptions& o) {
    try {
        scaleToMillimetres(m, o);
    } catch (const Error& e) {
        return e.code();
    }
    FAIL("no error");
    return ErrorCode::Internal;
}

}  // namespace

TEST_CASE("scale: --height-mm on a y-up mesh gives z up, centred in x/y, resting on z = 0") {
    const TriMesh box = makeBox({1, 2, 3}, {3, 12, 7});  // 2 x 10 x 4, tallest along y
    ScaleOptions o;
    o.heightMm = 400;
    o.up = UpAxis::Y;
    const ScaledMesh s = scaleToMillimetres(box, o);
    CHECK(s.sizeMm[0] == doctest::Approx(80));   // x: 2 * 40
    CHECK(s.sizeMm[1] == doctest::Approx(160));  // old z: 4 * 40
    CHECK(s.sizeMm[2] == doctest::Approx(400));  // old y: 10 * 40
    const Box3d b = boundingBox(s.mesh);
    CHECK(b.min[2] == doctest::Approx(0).epsilon(1e-9));
    CHECK(b.min[0] == doctest::Approx(-b.max[0]));
    CHECK(b.min[1] == doctest::Approx(-b.max[1]));
    // transformMm takes every input vertex to its output position.
    for (size_t v = 0; v < box.positions.size(); ++v) {
        const Vec3f& p = box.positions[v];
        const Vec3d q = s.transformMm.apply({p[0], p[1], p[2]});
        for (int i = 0; i < 3; ++i) CHECK(q[i] == doctest::Approx(s.mesh.positions[v][i]));
    }
    // A proper rotation: the orientation (and so the sign of the volume) is kept.
    const double det = s.transformMm.at(0, 0) * (s.transformMm.at(1, 1) * s.transformMm.at(2, 2) -
                                                 s.transformMm.at(1, 2) * s.transformMm.at(2, 1)) -
                       s.transformMm.at(0, 1) * (s.transformMm.at(1, 0) * s.transformMm.at(2, 2) -
                                                 s.transformMm.at(1, 2) * s.transformMm.at(2, 0)) +
                       s.transformMm.at(0, 2) * (s.transformMm.at(1, 0) * s.transformMm.at(2, 1) -
                                                 s.transformMm.at(1, 1) * s.transformMm.at(2, 0));
    CHECK(det > 0);
}

TEST_CASE("scale: --scale multiplies; neither option keeps millimetres") {
    const TriMesh box = makeBox({0, 0, 0}, {2, 4, 6});
    ScaleOptions o;
    o.scale = 25.4;  // inches to mm
    ScaledMesh s = scaleToMillimetres(box, o);
    CHECK(s.sizeMm[0] == doctest::Approx(50.8));
    CHECK(s.sizeMm[2] == doctest::Approx(152.4));
    s = scaleToMillimetres(box, {});
    CHECK(s.sizeMm[0] == doctest::Approx(2));
    CHECK(s.sizeMm[1] == doctest::Approx(4));
    CHECK(s.sizeMm[2] == doctest::Approx(6));
    CHECK(boundingBox(s.mesh).min[0] == doctest::Approx(-1));
    CHECK(s.transformMm.at(0, 0) == 1);
}

TEST_CASE("scale: bad options are usage errors, a flat mesh is bad input") {
    const TriMesh box = makeBox({0, 0, 0}, {1, 1, 1});
    for (double bad :
         {0.0, -5.0, std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity()}) {
        ScaleOptions h;
        h.heightMm = bad;
        CHECK(errorCodeOf(box, h) == ErrorCode::Usage);
        CHECK_THROWS_AS(checkScaleOptions(h), Error);
        ScaleOptions s;
        s.scale = bad;
        CHECK(errorCodeOf(box, s) == ErrorCode::Usage);
    }
    ScaleOptions both;
    both.heightMm = 10;
    both.scale = 2;
    CHECK(errorCodeOf(box, both) == ErrorCode::Usage);
    try {
        ScaleOptions h;
        h.heightMm = 0;
        checkScaleOptions(h);
    } catch (const Error& e) {
        CHECK(std::string(e.what()) == "--height-mm must be a positive number of millimetres, got 0");
    }

    TriMesh flat;
    flat.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
    flat.triangles = {{0, 1, 2}};
    ScaleOptions h;
    h.heightMm = 100;
    CHECK(errorCodeOf(flat, h) == ErrorCode::InvalidInput);
    ScaleOptions huge;
    huge.scale = 1e300;
    CHECK(errorCodeOf(box, huge) == ErrorCode::InvalidInput);  // overflows float
    CHECK(errorCodeOf(TriMesh{}, {}) == ErrorCode::InvalidInput);
}
