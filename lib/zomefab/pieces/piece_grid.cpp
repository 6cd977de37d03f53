// SPDX-License-Identifier: GPL-3.0-or-later
// One piece's level set by CSG (detail/stages.h, docs/pieces.md §1 step 4, §2, §3).
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>

#include <algorithm>
#include <limits>
#include <memory>

#include "zomefab/pieces/detail/pins.h"
#include "zomefab/pieces/detail/prisms.h"
#include "zomefab/pieces/detail/stages.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::pieces::detail {

namespace {

/// δ of the cells' region of @p set and the half-spaces of its re-cuts (no seam gap).
double pieceRegionDistance(const GridCells& cells, const CellSet& set, const Vec3d& x, double* scores) {
    double d = regionDistance(cells, set, x, scores);
    for (const CellSet::HalfSpace& h : set.halfSpaces) d = std::max(d, dot(h.normal, x) - h.offsetMm);
    for (const CellSet::PrismBound& b : set.prisms) {
        const double e = b.prism->signedDistanceMm(x);
        d = std::max(d, b.isInside ? e : -e);
    }
    return d;
}

/// δ_R at a voxel, corrected where the voxel's owner O is another piece whose cells R shares (a
/// sliver merged into O): R's planes say nothing about that border, so there δ_R is −δ_O.
double ownerCorrected(const GridCells& cells, const std::vector<CellSet>& sets, uint32_t r, uint32_t owner,
                      bool isInside, const Vec3d& x, double* scores) {
    const double d = pieceRegionDistance(cells, sets[r], x, scores);
    if (d >= 0 || !isInside || owner == r || owner >= sets.size()) return d;
    return -pieceRegionDistance(cells, sets[owner], x, scores);
}

/// ψ_P = max(φ_shell, δ̃_P + gap) on the leaves near the piece: the CSG intersection of the shell and
/// the piece's region, its cut faces moved inward by the seam gap. δ̃_P = max over the neighbours Q
/// of (δ_P − δ_Q)/2: antisymmetric between two pieces, so where three cells meet (and each piece's
/// own distance follows another plane) the two faces still come out the same surface, a seam gap
/// apart, never overlapping. The sign at inside voxels follows the owners exactly.
void fillRegion(FloatGrid& grid, const VoxelField& field, const GridCells& cells,
                const std::vector<CellSet>& sets, const Piece& piece, const std::vector<uint32_t>& leaves,
                double seamGapMm) {
    const float bg = field.background;
    // A piece printed thin (thin_wall.h) is cut from the thin wall; who owns a voxel stays the shell's.
    const std::vector<float>& phi = piece.isThinWall ? field.thinPhi : field.phi;
    const double voxel = field.voxelMm;
    std::vector<double> scores(cells.count());
    std::vector<uint32_t> others;
    for (const auto& [q, area] : piece.neighbors) others.push_back(q);
    for (uint32_t leaf : leaves) {
        auto node = std::make_unique<FloatLeaf>(field.leafOrigin[leaf], bg, false);
        bool isUsed = false;
        for (uint32_t off = 0; off < kLeafSize; ++off) {
            const size_t s = size_t(leaf) * kLeafSize + off;
            if (!field.isActive[s] || phi[s] >= bg) continue;
            const Vec3d x = field.world(field.coordOf(s));
            const uint32_t owner = field.owner[s];
            const bool isInside = field.isInside(s), isMember = owner == piece.id;
            const double own = ownerCorrected(cells, sets, piece.id, owner, isInside, x, scores.data());
            double delta = others.empty() ? own : -std::numeric_limits<double>::infinity();
            for (uint32_t q : others)
                delta = std::max(
                    delta, 0.5 * (own - ownerCorrected(cells, sets, q, owner, isInside, x, scores.data())));
            if (!isMember && owner < sets.size() &&
                std::find(others.begin(), others.end(), owner) == others.end())
                delta = std::max(delta, 0.5 * (own - ownerCorrected(cells, sets, owner, owner, isInside, x,
                                                                    scores.data())));
            // The owner decides the side, then the seam gap moves the face inward.
            if (isInside) delta = isMember ? std::min(delta, -1e-6 * voxel) : std::max(delta, 1e-6 * voxel);
            const double psi = std::max(double(phi[s]), delta + seamGapMm);
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

/// Alignment pins: a pin unioned (ψ = min(ψ, pin)), a socket cut (ψ = max(ψ, −socket)).
void addPins(FloatGrid& grid, openvdb::BoolTree& mask, const VoxelField& field, const Piece& piece,
             const PinOptions& o) {
    const float bg = field.background;
    FloatGrid::Accessor acc = grid.getAccessor();
    for (const AlignmentPin& pin : piece.pins) {
        const openvdb::CoordBBox box = indexBox(field, pinBoundsMm(pin, o.clearanceMm));
        mask.fill(box, true, true);
        for (auto it = box.begin(); it; ++it) {
            const Coord ijk = *it;
            const double d = pinSignedDistanceMm(pin, o.clearanceMm, field.world(ijk));
            const float old = acc.getValue(ijk);
            const double value = pin.isSocket ? std::max(double(old), -d) : std::min(double(old), d);
            if (value == double(old)) continue;
            if (value >= bg)
                acc.setValueOff(ijk, bg);
            else if (value <= -bg)
                acc.setValueOff(ijk, -bg);
            else
                acc.setValueOn(ijk, float(value));
        }
    }
}

/// The engraved number: difference, ψ = max(ψ, −glyph), where the glyph is the strokes' solid
/// within depthMm of the surface (−glyph = min(−strokes, ψ + depthMm)): under the strokes the
/// inner surface moves depthMm into the wall wherever it lies within the label's flatness.
void engraveLabel(FloatGrid& grid, openvdb::BoolTree& mask, const VoxelField& field, const PieceLabel& label,
                  const LabelOptions& o) {
    const float bg = field.background;
    FloatGrid::Accessor acc = grid.getAccessor();
    const std::vector<Stroke> strokes = labelStrokes(label.text, o);
    const openvdb::CoordBBox box = indexBox(field, labelBoundsMm(label, o));
    mask.fill(box, true, true);
    for (auto it = box.begin(); it; ++it) {
        const Coord ijk = *it;
        const float old = acc.getValue(ijk);
        // Beyond the band ψ is only known to be below −bg: a cut deeper than the band (a depth
        // above 3 voxels: --voxel-mm under 0.4 mm) stops at the band instead of opening the wall.
        if (old <= -bg) continue;
        const double e =
            std::min(-labelSignedDistanceMm(label, strokes, o, field.world(ijk)), old + o.depthMm);
        if (e <= old) continue;  // also every e ≤ −bg, as old > −bg here
        if (e >= bg)
            acc.setValueOff(ijk, bg);
        else
            acc.setValueOn(ijk, float(e));
    }
}

/// Marks in @p mask the voxels of @p piece with a 6-neighbour slot @p isMarked accepts, and that
/// neighbour.
template <typename Accept>
void markFaces(openvdb::BoolTree& mask, const VoxelField& field, uint32_t piece,
               const std::vector<uint32_t>& leaves, const Accept& isMarked) {
    openvdb::tree::ValueAccessor<openvdb::BoolTree> acc(mask);
    for (uint32_t leaf : leaves)
        for (uint32_t off = 0; off < kLeafSize; ++off) {
            const size_t s = size_t(leaf) * kLeafSize + off;
            if (!field.isInside(s) || field.owner[s] != piece) continue;
            const Coord ijk = field.coordOf(s);
            for (const auto& o : kFaceOffsets) {
                const Coord n = ijk.offsetBy(o[0], o[1], o[2]);
                const size_t t = field.slotOf(n);
                if (t == SIZE_MAX || !isMarked(t)) continue;
                acc.setValueOn(ijk, true);
                acc.setValueOn(n, true);
            }
        }
}

/// The cut faces: voxels of the piece with a 6-neighbour of another piece, and that neighbour. The
/// mesher keeps them at full resolution: its adaptive simplification moves the two faces of a seam
/// differently where three cells meet (measured: up to 0.35 mm of overlap on the bunny at 400 mm).
void markSeams(openvdb::BoolTree& mask, const VoxelField& field, uint32_t piece,
               const std::vector<uint32_t>& leaves) {
    markFaces(mask, field, piece, leaves,
              [&](size_t t) { return field.isInside(t) && field.owner[t] != piece; });
}

/// The outer surface: voxels of the piece with a 6-neighbour in @p exterior, and that neighbour.
void markOuterSurface(openvdb::BoolTree& mask, const VoxelField& field, const std::vector<uint8_t>& exterior,
                      uint32_t piece, const std::vector<uint32_t>& leaves) {
    markFaces(mask, field, piece, leaves, [&](size_t t) { return exterior[t] != 0; });
}

/// The mesher's adaptivity on the outer surface, as a share of PiecesOptions::adaptivity. What the
/// maker sees must match the input: at the full 0.3 the mesher's flat regions cut chords up to half a
/// millimetre deep across curved skin (95th percentile 0.57 mm on the armadillo at 500 mm); at 3 %
/// 0.17 mm, with 43 MB of STL for the demo against 84 MB at full resolution (docs/pieces.md, "Meshing").
constexpr float kOuterAdaptivityWeight = 0.03f;

/// kOuterAdaptivityWeight on the piece's outer surface (markOuterSurface, grown by a voxel), 1 elsewhere.
FloatGrid::Ptr outerSurfaceWeight(const VoxelField& field, const std::vector<uint8_t>& exterior,
                                  uint32_t piece, const std::vector<uint32_t>& leaves,
                                  const openvdb::math::Transform& transform) {
    openvdb::BoolTree outer(false);
    markOuterSurface(outer, field, exterior, piece, leaves);
    openvdb::tools::dilateActiveValues(outer, 1);
    FloatGrid::Ptr weight = FloatGrid::create(1.0f);
    weight->setTransform(transform.copy());
    FloatGrid::Accessor acc = weight->getAccessor();
    for (auto it = outer.cbeginValueOn(); it; ++it) acc.setValue(it.getCoord(), kOuterAdaptivityWeight);
    return weight;
}

}  // namespace

std::vector<uint8_t> exteriorBand(const VoxelField& field) {
    std::vector<uint8_t> out(field.phi.size(), 0);
    // The topmost voxel outside the wall is outside the object: no cavity reaches above its top.
    size_t start = SIZE_MAX;
    int top = std::numeric_limits<int>::min();
    for (size_t s = 0; s < field.phi.size(); ++s) {
        if (!field.isActive[s] || field.phi[s] < 0) continue;
        const int z = field.coordOf(s).z();
        if (z > top) top = z, start = s;
    }
    if (start == SIZE_MAX) return out;
    out[start] = 1;
    floodFaces(field, {start}, out, [&](size_t t) { return field.phi[t] >= 0; });
    return out;
}

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

PieceGrid pieceGrid(const VoxelField& field, const GridCells& cells, const std::vector<CellSet>& sets,
                    const Piece& piece, const std::vector<uint32_t>& leaves,
                    const std::vector<uint8_t>& exterior, const openvdb::math::Transform& transform,
                    const PiecesOptions& options) {
    PieceGrid out;
    out.grid = FloatGrid::create(field.background);
    out.grid->setTransform(transform.copy());
    out.grid->setGridClass(openvdb::GRID_LEVEL_SET);
    fillRegion(*out.grid, field, cells, sets, piece, leaves, options.seamGapMm);
    // Where meshing keeps full resolution: the cut faces (seams must meet), around tenons (the
    // prisms keep their section) and engraved numbers (strokes of two voxels would blur); nearly so
    // on the outer surface (it must match the input).
    auto mask = std::make_shared<openvdb::BoolTree>(false);
    markSeams(*mask, field, piece.id, leaves);
    if (options.adaptivity > 0)
        out.adaptivityWeight = outerSurfaceWeight(field, exterior, piece.id, leaves, transform);
    openvdb::tools::dilateActiveValues(*mask, 1);
    addTenons(*out.grid, *mask, field, piece, options.tenons);
    addPins(*out.grid, *mask, field, piece, options.pins);
    if (piece.label)
        engraveLabel(*out.grid, *mask, field, *piece.label, labelOptionsForWall(options.label, piece.wallMm));
    openvdb::tools::pruneLevelSet(out.grid->tree());
    if (!mask->empty()) {
        mask->voxelizeActiveTiles();  // the mesher looks the mask up by leaf nodes only
        out.fullResolution = std::move(mask);
    }
    return out;
}

}  // namespace zomefab::pieces::detail
