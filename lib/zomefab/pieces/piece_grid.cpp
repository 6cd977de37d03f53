// SPDX-License-Identifier: GPL-3.0-or-later
// One piece's level set by CSG (detail/stages.h, docs/pieces.md §1 step 4, §2, §3).
#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <memory>

#include "zomefab/pieces/detail/stages.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::pieces::detail {

namespace {

/// ψ_P = max(φ_shell, δ_P) on the leaves near the piece: the CSG intersection of the shell and the
/// piece's region. The sign at inside voxels follows the owners exactly (ties on a plane included).
void fillRegion(FloatGrid& grid, const VoxelField& field, const GridCells& cells, const CellSet& set,
                uint32_t piece, const std::vector<uint32_t>& leaves) {
    const float bg = field.background;
    const double voxel = field.voxelMm;
    std::vector<double> scores(cells.count());
    for (uint32_t leaf : leaves) {
        auto node = std::make_unique<FloatLeaf>(field.leafOrigin[leaf], bg, false);
        bool isUsed = false;
        for (uint32_t off = 0; off < kLeafSize; ++off) {
            const size_t s = size_t(leaf) * kLeafSize + off;
            if (!field.isActive[s] || field.phi[s] >= bg) continue;
            const Vec3d x = field.world(field.coordOf(s));
            const bool isMember = field.owner[s] == piece;
            double psi =
                std::max(double(field.phi[s]), regionDistance(cells, set, x, isMember, scores.data()));
            if (field.isInside(s))
                psi = isMember ? std::min(psi, -1e-6 * voxel) : std::max(psi, 1e-6 * voxel);
            if (psi >= bg) continue;
            isUsed = true;
            if (psi <= -bg)
                node->setValueOnly(off, -bg);
            else
                node->setValueOn(off, float(psi));
        }
        if (isUsed) grid.tree().addLeaf(node.release());
    }
}

/// The index box around @p box (grid mm) with the band and a voxel to spare.
openvdb::CoordBBox indexBox(const VoxelField& field, const Box3d& box) {
    const double pad = (sdf::kHalfWidthVoxels + 1) * field.voxelMm;
    Coord lo, hi;
    for (int a = 0; a < 3; ++a) {
        lo[a] = int(std::floor((box.min[size_t(a)] - pad - field.originMm[size_t(a)]) / field.voxelMm));
        hi[a] = int(std::ceil((box.max[size_t(a)] + pad - field.originMm[size_t(a)]) / field.voxelMm));
    }
    return openvdb::CoordBBox(lo, hi);
}

/// Tenons: union, ψ = min(ψ, τ).
void addTenons(FloatGrid& grid, openvdb::BoolTree& mask, const VoxelField& field, const Piece& piece,
               const TenonOptions& o) {
    const float bg = field.background;
    FloatGrid::Accessor acc = grid.getAccessor();
    for (const Tenon& t : piece.tenons) {
        const openvdb::CoordBBox box = indexBox(field, tenonBoundsMm(t, o));
        mask.fill(box, true, true);
        for (auto it = box.begin(); it; ++it) {
            const Coord ijk = *it;
            const double tau = tenonSignedDistanceMm(t, o, field.world(ijk));
            if (tau >= bg) continue;
            const float old = acc.getValue(ijk);
            if (tau >= old) continue;
            if (tau <= -bg)
                acc.setValueOff(ijk, -bg);
            else
                acc.setValueOn(ijk, float(tau));
        }
    }
}

/// The engraved number: difference, ψ = max(ψ, −glyph).
void engraveLabel(FloatGrid& grid, openvdb::BoolTree& mask, const VoxelField& field, const PieceLabel& label,
                  const LabelOptions& o) {
    const float bg = field.background;
    FloatGrid::Accessor acc = grid.getAccessor();
    const std::vector<Stroke> strokes = labelStrokes(label.text, o);
    const openvdb::CoordBBox box = indexBox(field, labelBoundsMm(label, o));
    mask.fill(box, true, true);
    for (auto it = box.begin(); it; ++it) {
        const Coord ijk = *it;
        const double e = -labelSignedDistanceMm(label, strokes, o, field.world(ijk));
        if (e <= -bg) continue;
        const float old = acc.getValue(ijk);
        if (e <= old) continue;
        if (e >= bg)
            acc.setValueOff(ijk, bg);
        else
            acc.setValueOn(ijk, float(e));
    }
}

}  // namespace

std::vector<std::vector<uint32_t>> leavesOfPieces(const VoxelField& field, size_t pieceCount) {
    std::vector<std::vector<uint32_t>> leafPieces(field.leafOrigin.size());
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isInside(s)) {
            auto& list = leafPieces[s / kLeafSize];
            const uint32_t p = field.owner[s];
            if (std::find(list.begin(), list.end(), p) == list.end()) list.push_back(p);
        }
    std::vector<std::vector<uint32_t>> pieceLeaves(pieceCount);
    for (size_t leaf = 0; leaf < field.leafOrigin.size(); ++leaf) {
        std::vector<uint32_t> near;
        for (int dx = -8; dx <= 8; dx += 8)
            for (int dy = -8; dy <= 8; dy += 8)
                for (int dz = -8; dz <= 8; dz += 8) {
                    const uint32_t other = field.leafAt(field.leafOrigin[leaf].offsetBy(dx, dy, dz));
                    if (other == kNone) continue;
                    for (uint32_t p : leafPieces[other])
                        if (std::find(near.begin(), near.end(), p) == near.end()) near.push_back(p);
                }
        for (uint32_t p : near) pieceLeaves[p].push_back(uint32_t(leaf));
    }
    return pieceLeaves;
}

PieceGrid pieceGrid(const VoxelField& field, const GridCells& cells, const CellSet& set, const Piece& piece,
                    const std::vector<uint32_t>& leaves, const openvdb::math::Transform& transform,
                    const PiecesOptions& options) {
    PieceGrid out;
    out.grid = FloatGrid::create(field.background);
    out.grid->setTransform(transform.copy());
    out.grid->setGridClass(openvdb::GRID_LEVEL_SET);
    fillRegion(*out.grid, field, cells, set, piece.id, leaves);
    // Where meshing keeps full resolution: around tenons (the pegs must keep their section) and
    // engraved numbers (strokes of two voxels would blur into the surface).
    auto mask = std::make_shared<openvdb::BoolTree>(false);
    addTenons(*out.grid, *mask, field, piece, options.tenons);
    if (piece.label) engraveLabel(*out.grid, *mask, field, *piece.label, options.label);
    openvdb::tools::pruneLevelSet(out.grid->tree());
    if (!mask->empty()) {
        mask->voxelizeActiveTiles();  // the mesher looks the mask up by leaf nodes only
        out.fullResolution = std::move(mask);
    }
    return out;
}

}  // namespace zomefab::pieces::detail
