// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The pieces stage's view of the shell (internal to lib/zomefab/pieces): every voxel of its
/// band and inside in leaf-sized slots with φ, its cell and its owner, and the partition's argmax
/// cells mapped into the shell grid's millimetres. docs/pieces.md, "Cutting the shell".
#pragma once

#include <openvdb/openvdb.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/linear_cells.h"

namespace zomefab::pieces::detail {

using openvdb::Coord;
using FloatGrid = openvdb::FloatGrid;
using FloatTree = openvdb::FloatTree;
using FloatLeaf = FloatTree::LeafNodeType;

constexpr uint32_t kNone = 0xFFFFFFFFu;
constexpr uint32_t kLeafSize = 512;  // 8³ voxels per leaf node

struct TunnelPrism;  // detail/prisms.h

/// The argmax cells mapped to grid mm, with 1/|w_i − w_j| for the plane distances.
struct GridCells {
    std::vector<Vec3d> w;
    std::vector<double> b;
    std::vector<double> invNorm;  ///< K × K; 0 for identical normals (no plane between them)
    size_t count() const { return w.size(); }
    double score(size_t k, const Vec3d& x) const { return dot(w[k], x) + b[k]; }
    /// argmax_k, ties to the lowest k; fills @p scores (size K).
    uint32_t owner(const Vec3d& x, double* scores) const {
        uint32_t best = 0;
        for (size_t k = 0; k < w.size(); ++k) {
            scores[k] = score(k, x);
            if (scores[k] > scores[best]) best = uint32_t(k);
        }
        return best;
    }
};

/// The partition's cells (frame mm) in the grid's mm: s(x_f) = w·x_f + b with x_f = Rᵀ(x_g − t).
GridCells toGridCells(const partition::LinearCells& model, const Transform4d& frameToGrid);

/// The cells a piece is cut from. A cell is "shared" when its part of the shell went to several
/// pieces (a merged sliver, or a cell the partition split): its planes then count as cuts too.
struct CellSet {
    std::vector<uint8_t> isMember;  ///< per cell
    std::vector<uint32_t> members;  ///< cells of the piece
    std::vector<uint32_t> cutters;  ///< cells whose planes may bound it: non-members and shared members
    /// Planes the piece was re-cut along (a piece no direction could mount, split in two; see
    /// detail/splits.h): the piece is its cells' region ∩ {x : normal·x ≤ offsetMm} for each.
    struct HalfSpace {
        Vec3d normal{0, 0, 1};  ///< unit, out of the piece
        double offsetMm = 0.0;
    };
    std::vector<HalfSpace> halfSpaces;
    /// Tunnel prisms that bound it (detail/prisms.h): a lining carved along its tunnel lies inside
    /// its own and outside those that keep the overlaps (of earlier axes; where three cross, of a
    /// higher TunnelPrism::priority); every other piece lies outside all of them.
    struct PrismBound {
        std::shared_ptr<const TunnelPrism> prism;
        bool isInside = false;
    };
    std::vector<PrismBound> prisms;
    /// A lining carved along a prism: its cells do not bound it, only its prisms and half-spaces.
    bool isLining = false;
    /// A stave's ring (a staved prism's lining): how far its far end lies from the mouth it slides
    /// out of (mm), which orders the rings along the tunnel (detail/staves.h, Stave).
    double ringDepthMm = 0.0;
    /// A staved prism's lining at a mouth too short to reach behind the face's wall (cutStaves):
    /// one ring, not cut into staves, that slides in along the tunnel and is glued on.
    bool isMouthRing = false;
    /// A staved prism's lining whose rings are cut into staves turned 45° about the axis (their
    /// lifts along the diagonals of the grid axes across it): fewer of them under a wall too thin
    /// for a ball (cutStaves; a tunnel just under a face of the cheese).
    bool isStaveTurned = false;
};

/// δ_P: a signed distance to the region of the piece's cells (negative inside), from the planes
/// between its member cells and the cutting cells: min over members k of max over cutters j of
/// (s_j − s_k)/|w_j − w_k|. Exact near a cut face; a bound with the right sign farther away, and
/// zero exactly on the region's boundary, where three cells meet too, so the mesh's cut faces are
/// planar up to the crease lines. Two pieces sharing a face see the same plane. @p scores: scratch
/// of size K.
double regionDistance(const GridCells& c, const CellSet& set, const Vec3d& x, double* scores);

/// A leaf's key in VoxelField::leafIndex.
inline uint64_t leafKey(const Coord& origin) {
    const uint64_t bias = uint64_t(1) << 20;
    return ((uint64_t(int64_t(origin.x() >> 3) + int64_t(bias)) & 0x1FFFFF) << 42) |
           ((uint64_t(int64_t(origin.y() >> 3) + int64_t(bias)) & 0x1FFFFF) << 21) |
           (uint64_t(int64_t(origin.z() >> 3) + int64_t(bias)) & 0x1FFFFF);
}

/// Every voxel of the shell's band and inside, in leaf-sized slots (leaf index × 512 + offset).
struct VoxelField {
    double voxelMm = 1.0;
    Vec3d originMm{0, 0, 0};  ///< world position of index (0, 0, 0)
    float background = 3.0f;
    std::vector<Coord> leafOrigin;
    std::unordered_map<uint64_t, uint32_t> leafIndex;
    std::vector<std::array<uint32_t, 3>> nextLeaf;  ///< the +x, +y, +z neighbour leaves
    std::vector<uint8_t> isActive;                  ///< per slot: in the band or inside
    std::vector<float> phi;                         ///< per slot: φ_shell, clamped to ± background
    std::vector<uint32_t> cell;                     ///< per slot: the cell it lies in (argmax)
    /// per slot: the component of an inside voxel; after the pieces are known, the piece that owns
    /// the voxel (inside: its piece; band: that of the nearest inside voxel of its cell); kNone
    std::vector<uint32_t> owner;
    /// per slot: φ of the thinner printed wall (PiecesOptions::printWallMm, thinWallPhi); empty
    /// when the pieces are printed with the shell's wall.
    std::vector<float> thinPhi;

    bool isInside(size_t slot) const { return isActive[slot] && phi[slot] < 0; }
    Coord coordOf(size_t slot) const {
        const Coord& o = leafOrigin[slot / kLeafSize];
        const uint32_t off = uint32_t(slot % kLeafSize);
        return Coord(o.x() + int(off >> 6), o.y() + int((off >> 3) & 7), o.z() + int(off & 7));
    }
    Vec3d world(const Coord& ijk) const {
        return {originMm[0] + voxelMm * ijk.x(), originMm[1] + voxelMm * ijk.y(),
                originMm[2] + voxelMm * ijk.z()};
    }
    uint32_t leafAt(const Coord& origin) const {
        const auto it = leafIndex.find(leafKey(origin));
        return it == leafIndex.end() ? kNone : it->second;
    }
    /// The slot of voxel @p ijk, or SIZE_MAX outside the field.
    size_t slotOf(const Coord& ijk) const {
        const uint32_t leaf = leafAt(ijk & ~7);
        if (leaf == kNone) return SIZE_MAX;
        const size_t slot = size_t(leaf) * kLeafSize + FloatLeaf::coordToOffset(ijk);
        return isActive[slot] ? slot : SIZE_MAX;
    }
    /// The slot of the voxel nearest to @p p, or SIZE_MAX outside the field.
    size_t slotAt(const Vec3d& p) const {
        Coord ijk;
        for (int a = 0; a < 3; ++a) ijk[a] = int(std::lround((p[size_t(a)] - originMm[size_t(a)]) / voxelMm));
        return slotOf(ijk);
    }
    /// The owner of the voxel nearest to @p p, band voxels included; −1 off the field or unowned.
    int64_t ownerNear(const Vec3d& p) const {
        const size_t s = slotAt(p);
        return s == SIZE_MAX || owner[s] == kNone ? -1 : int64_t(owner[s]);
    }
};

/// Every voxel of @p shell's band and of its whole inside (tiles voxelised), with φ clamped to
/// the background. @throw Error(InvalidInput) for a grid that is not a uniform scale and
/// translation; Error(Usage) for more leaves than 32-bit slot ids allow.
VoxelField buildField(const FloatGrid& shell);

/// Sets every active slot's cell (argmax of @p cells, ties to the lowest). Parallel, deterministic.
void labelCells(VoxelField& field, const GridCells& cells);

/// The six face neighbours' index offsets.
inline constexpr int kFaceOffsets[6][3] = {{1, 0, 0},  {-1, 0, 0}, {0, 1, 0},
                                           {0, -1, 0}, {0, 0, 1},  {0, 0, -1}};

/// Marks in @p marked (one byte per slot) every slot 6-connected to the slots of @p stack through
/// unmarked active slots that @p accept takes; the seeds themselves are marked only if the caller
/// did. The set marked does not depend on the order of the seeds.
template <class Accept>
void floodFaces(const VoxelField& f, std::vector<size_t> stack, std::vector<uint8_t>& marked,
                Accept&& accept) {
    while (!stack.empty()) {
        const Coord ijk = f.coordOf(stack.back());
        stack.pop_back();
        for (const auto& o : kFaceOffsets) {
            const size_t t = f.slotOf(ijk.offsetBy(o[0], o[1], o[2]));
            if (t == SIZE_MAX || marked[t] || !accept(t)) continue;
            marked[t] = 1;
            stack.push_back(t);
        }
    }
}

/// Calls @p visit(slot, neighbourSlot) for the +x, +y, +z neighbour of every active slot.
template <class Visit>
void forEachForwardPair(const VoxelField& f, Visit&& visit) {
    const size_t n = f.leafOrigin.size();
    for (size_t leaf = 0; leaf < n; ++leaf) {
        for (uint32_t off = 0; off < kLeafSize; ++off) {
            const size_t s = leaf * kLeafSize + off;
            if (!f.isActive[s]) continue;
            const uint32_t x = off >> 6, y = (off >> 3) & 7, z = off & 7;
            const uint32_t nx = f.nextLeaf[leaf][0], ny = f.nextLeaf[leaf][1], nz = f.nextLeaf[leaf][2];
            if (x < 7)
                visit(s, s + 64);
            else if (nx != kNone)
                visit(s, size_t(nx) * kLeafSize + off - 448);
            if (y < 7)
                visit(s, s + 8);
            else if (ny != kNone)
                visit(s, size_t(ny) * kLeafSize + off - 56);
            if (z < 7)
                visit(s, s + 1);
            else if (nz != kNone)
                visit(s, size_t(nz) * kLeafSize + off - 7);
        }
    }
}

}  // namespace zomefab::pieces::detail
