// SPDX-License-Identifier: GPL-3.0-or-later
// The shell's voxels and the cells in grid mm (detail/voxels.h).
#include "zomefab/pieces/detail/voxels.h"

#include <openvdb/tools/LevelSetUtil.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <limits>

#include "zomefab/core/error.h"

namespace zomefab::pieces::detail {

GridCells toGridCells(const partition::LinearCells& model, const Transform4d& frameToGrid) {
    // w' = R·w, b' = b − w'·t.
    GridCells c;
    const Vec3d t{frameToGrid.at(0, 3), frameToGrid.at(1, 3), frameToGrid.at(2, 3)};
    for (size_t k = 0; k < model.cellCount(); ++k) {
        const Vec3d w = applyLinear(frameToGrid, model.w[k]);
        c.w.push_back(w);
        c.b.push_back(model.b[k] - dot(w, t));
    }
    const size_t n = c.count();
    c.invNorm.assign(n * n, 0.0);
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j) {
            const double d = norm(sub(c.w[i], c.w[j]));
            c.invNorm[i * n + j] = d > 1e-12 ? 1.0 / d : 0.0;
        }
    return c;
}

double regionDistance(const GridCells& c, const CellSet& set, const Vec3d& x, double* scores) {
    if (set.isLining) return -std::numeric_limits<double>::infinity();
    c.owner(x, scores);
    const size_t n = c.count();
    // min over member cells k of max over the cutting cells j of the signed distance to the plane
    // s_k = s_j: each max is zero exactly on cell k's boundary (a convex polytope), so the min is
    // zero exactly on the boundary of the union, also where three cells meet.
    double best = std::numeric_limits<double>::infinity();
    for (uint32_t k : set.members) {
        double m = -std::numeric_limits<double>::infinity();
        for (uint32_t j : set.cutters) {
            const double inv = j == k ? 0.0 : c.invNorm[k * n + j];
            if (inv > 0) m = std::max(m, (scores[j] - scores[k]) * inv);
        }
        best = std::min(best, m);
    }
    return best;
}

VoxelField buildField(const FloatGrid& shell) {
    VoxelField f;
    f.background = shell.background();
    f.voxelMm = shell.voxelSize()[0];
    const openvdb::Vec3d o = shell.transform().indexToWorld(Coord(0, 0, 0));
    const openvdb::Vec3d o1 = shell.transform().indexToWorld(Coord(1, 1, 1));
    f.originMm = {o[0], o[1], o[2]};
    for (int a = 0; a < 3; ++a)
        if (std::abs(o1[a] - o[a] - f.voxelMm) > 1e-9 * std::max(1.0, f.voxelMm))
            throw Error(ErrorCode::InvalidInput,
                        "the shell grid's transform is not a uniform scale and translation");

    // The band's voxels plus the whole inside (tiles included), as active voxels of one mask.
    openvdb::BoolGrid::Ptr interior = openvdb::tools::sdfInteriorMask(shell);
    openvdb::BoolTree region(shell.tree(), false, openvdb::TopologyCopy());
    region.topologyUnion(interior->tree());
    region.voxelizeActiveTiles();
    std::vector<const openvdb::BoolTree::LeafNodeType*> leaves;
    for (auto it = region.cbeginLeaf(); it; ++it) leaves.push_back(it.getLeaf());
    const size_t n = leaves.size();
    // Slots are numbered with 32-bit ids (union-find); 8 million leaves is a 4 m shell at 1 mm.
    if (n >= (size_t(1) << 32) / kLeafSize - 1)
        throw Error(ErrorCode::Usage, "the shell has too many voxels (" + std::to_string(n) +
                                          " leaf nodes) for the pieces stage: use a coarser voxel");
    f.leafOrigin.resize(n);
    f.leafIndex.reserve(n * 2);
    for (size_t i = 0; i < n; ++i) {
        f.leafOrigin[i] = leaves[i]->origin();
        f.leafIndex.emplace(leafKey(f.leafOrigin[i]), uint32_t(i));
    }
    f.nextLeaf.resize(n);
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < 3; ++a) {
            Coord c = f.leafOrigin[i];
            c[a] += 8;
            f.nextLeaf[i][size_t(a)] = f.leafAt(c);
        }
    f.isActive.assign(n * kLeafSize, 0);
    f.phi.assign(n * kLeafSize, f.background);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 64), [&](const tbb::blocked_range<size_t>& range) {
        FloatGrid::ConstAccessor acc = shell.getConstAccessor();
        for (size_t i = range.begin(); i < range.end(); ++i) {
            const FloatLeaf* source = shell.tree().probeConstLeaf(f.leafOrigin[i]);
            for (auto on = leaves[i]->cbeginValueOn(); on; ++on) {
                const uint32_t off = on.pos();
                const float v = source ? source->getValue(off) : acc.getValue(on.getCoord());
                const size_t slot = i * kLeafSize + off;
                f.isActive[slot] = 1;
                f.phi[slot] = std::clamp(v, -f.background, f.background);
            }
        }
    });
    return f;
}

void labelCells(VoxelField& field, const GridCells& cells) {
    const size_t cellCount = cells.count();
    field.cell.assign(field.phi.size(), kNone);
    // Per leaf, only the cells that can be the argmax somewhere in its box: over the box a score
    // varies by at most Σ|w_a|·h around its value at the centre, so a cell whose highest score there
    // is below another's lowest is never the argmax (strictly below: ties are unchanged). With the
    // hundreds of cells of a partition that needed many repair rounds this is what keeps the
    // labelling from taking minutes at 700 mm.
    const double halfMm = 3.5 * field.voxelMm;  // the leaf's 8 voxel centres span 7 voxels
    std::vector<double> reach(cellCount);       // Σ|w_a|·h, the same for every leaf
    for (size_t k = 0; k < cellCount; ++k)
        reach[k] = (std::abs(cells.w[k][0]) + std::abs(cells.w[k][1]) + std::abs(cells.w[k][2])) * halfMm;
    tbb::parallel_for(
        tbb::blocked_range<size_t>(0, field.leafOrigin.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
            std::vector<double> centre(cellCount);
            std::vector<uint32_t> candidates;
            for (size_t leaf = r.begin(); leaf < r.end(); ++leaf) {
                const Coord& o = field.leafOrigin[leaf];
                const Vec3d c = add(field.world(o), {halfMm, halfMm, halfMm});
                double floor = -std::numeric_limits<double>::infinity();
                for (size_t k = 0; k < cellCount; ++k) {
                    centre[k] = cells.score(k, c);
                    floor = std::max(floor, centre[k] - reach[k]);
                }
                candidates.clear();
                for (size_t k = 0; k < cellCount; ++k) {
                    const double slack = 1e-9 * (std::abs(centre[k]) + reach[k] + std::abs(floor) + 1.0);
                    if (centre[k] + reach[k] + slack >= floor) candidates.push_back(uint32_t(k));
                }
                for (uint32_t off = 0; off < kLeafSize; ++off) {
                    const size_t s = leaf * kLeafSize + off;
                    if (!field.isActive[s]) continue;
                    const Vec3d x = field.world(field.coordOf(s));
                    uint32_t best = candidates.front();
                    double bestScore = cells.score(best, x);
                    for (size_t i = 1; i < candidates.size(); ++i) {
                        const double score = cells.score(candidates[i], x);
                        if (score > bestScore) best = candidates[i], bestScore = score;
                    }
                    field.cell[s] = best;
                }
            }
        });
}

}  // namespace zomefab::pieces::detail
