// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Shared fixtures of the frame tests: interior fields of simple solids (built once per test
/// binary), and a tiny hand-made cube lattice.
#pragma once

#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "test_util.h"
#include "zomefab/sdf/interior_field.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/zome/structure.h"

namespace zomefab::test {

/// The "interior" field of @p mesh (mm): exact distances over the whole inside, 10 mm outside.
inline sdf::InteriorField interiorFieldOf(const TriMesh& mesh, double voxelMm) {
    sdf::MeshToLevelSetOptions o;
    o.voxelMm = voxelMm;
    o.interiorBandMm = std::numeric_limits<double>::infinity();
    o.exteriorBandMm = 10.0;
    o.name = "interior";
    const sdf::LevelSet ls = sdf::meshToLevelSet(mesh, o, RunContext::silent());
    return sdf::makeInteriorField(ls, RunContext::silent());
}

/// A sphere of @p diameterMm centred at the origin, cached per diameter; 2 mm voxels as zf-sdf's
/// default interior field.
inline const sdf::InteriorField& sphereField(double diameterMm) {
    static std::map<double, sdf::InteriorField> cache;
    auto it = cache.find(diameterMm);
    if (it == cache.end())
        it = cache.emplace(diameterMm, interiorFieldOf(makeSphere({0, 0, 0}, 0.5 * diameterMm, 48, 96), 2.0))
                 .first;
    return it->second;
}

/// Balls of the n×n×n B0 grid (indices 0..n−1) joined by their B0 edges.
inline zome::Structure cubeGrid(int n, const zome::ZomeScale& scale = {}) {
    zome::Structure s(scale);
    const zome::Golden b0(2, 2);
    std::map<std::tuple<int, int, int>, zome::BallId> id;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j)
            for (int k = 0; k < n; ++k)
                id[{i, j, k}] = s.addBall({b0 * zome::Golden(i), b0 * zome::Golden(j), b0 * zome::Golden(k)});
    for (const auto& [ijk, ball] : id) {
        const auto [i, j, k] = ijk;
        if (i + 1 < n) s.addStrut(ball, id.at({i + 1, j, k}));
        if (j + 1 < n) s.addStrut(ball, id.at({i, j + 1, k}));
        if (k + 1 < n) s.addStrut(ball, id.at({i, j, k + 1}));
    }
    return s;
}

}  // namespace zomefab::test
