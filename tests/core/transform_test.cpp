// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include "zomefab/core/transform.h"

using namespace zomefab;

TEST_CASE("transform: y-up to z-up is a proper rotation taking +y to +z") {
    const Transform4d r = Transform4d::yUpToZUp();
    const Vec3d y = r.apply({0, 1, 0});
    CHECK(y[0] == 0);
    CHECK(y[1] == 0);
    CHECK(y[2] == 1);
    const Vec3d x = r.apply({1, 0, 0});
    CHECK(x[0] == 1);
    const Vec3d z = r.apply({0, 0, 1});
    CHECK(z[1] == -1);
}

TEST_CASE("transform: composition applies the right factor first") {
    const Transform4d s = Transform4d::scaleTranslate(2.0, {1, 0, 0});
    const Transform4d t = Transform4d::scaleTranslate(1.0, {0, 5, 0});
    const Vec3d p = (t * s).apply({1, 1, 1});
    CHECK(p[0] == 3);
    CHECK(p[1] == 7);
    CHECK(p[2] == 2);
}
