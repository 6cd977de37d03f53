// SPDX-License-Identifier: GPL-3.0-or-later
// The pieces stage (paper §6), the one OpenVDB translation unit of the module:
//  1. the shell's voxels (its narrow band and its whole inside) are labelled with their cell,
//     argmax_k w_k·x + b_k (§5.2), and split into connected components per cell;
//  2. components become pieces (grouped by the partition's requests, slivers merged);
//  3. each piece's level set is the CSG intersection max(φ_shell, δ_P) of the shell and the
//     level set δ_P of its cells' half-spaces, then tenons are unioned (min) and the number is
//     engraved (max with −glyph);
//  4. each is meshed (volumeToMesh with adaptivity), checked and oriented for the printer.
// docs/pieces.md describes each step and why.
#include <openvdb/openvdb.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/LevelSetUtil.h>
#include <openvdb/tools/Prune.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>

#include "zomefab/pieces/pieces.h"

#include "zomefab/core/disjoint_sets.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/pieces/orientation.h"
#include "zomefab/sdf/level_set_grid.h"

namespace zomefab::pieces {

using namespace detail;
using openvdb::Coord;
using FloatGrid = openvdb::FloatGrid;
using FloatTree = openvdb::FloatTree;
using FloatLeaf = FloatTree::LeafNodeType;

namespace {

constexpr uint32_t kNone = 0xFFFFFFFFu;
constexpr uint32_t kLeafSize = 512;  // 8³ voxels per leaf node

// --- cells in the grid's millimetres --------------------------------------------------------------

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

GridCells toGridCells(const partition::LinearCells& model, const Transform4d& frameToGrid) {
    // s(x_f) = w·x_f + b with x_f = Rᵀ(x_g − t): w' = R·w, b' = b − w'·t.
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

/// The cells a piece is cut from. A cell is "shared" when its part of the shell went to several
/// pieces (a merged sliver, or a cell the partition split): its planes then count as cuts too.
struct CellSet {
    std::vector<uint8_t> isMember;  ///< per cell
    std::vector<uint32_t> members;  ///< cells of the piece
    std::vector<uint32_t> cutters;  ///< cells whose planes may bound it: non-members and shared members
};

/// δ_P: a signed distance to the piece's region (negative inside). @p isMember says whether the
/// voxel belongs to the piece (its owner). Near a cut face it is the exact distance to the face's
/// plane (s_own − s_j)/|w_own − w_j|; farther away a lower bound with the right sign, which is all
/// the mesher needs. Two pieces sharing a face see the same plane, so their faces coincide.
/// @p scores: scratch of size K.
double regionDistance(const GridCells& c, const CellSet& set, const Vec3d& x, bool isMember, double* scores) {
    const uint32_t own = c.owner(x, scores);
    const size_t n = c.count();
    double m = std::numeric_limits<double>::infinity();
    for (uint32_t j : isMember ? set.cutters : set.members) {
        const double inv = j == own ? 0.0 : c.invNorm[own * n + j];
        if (inv > 0) m = std::min(m, (scores[own] - scores[j]) * inv);
    }
    return isMember ? -m : m;
}

// --- the shell's voxels ------------------------------------------------------------------------------

uint64_t leafKey(const Coord& origin) {
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
    std::vector<uint8_t> isActive;   ///< per slot: in the band or inside
    std::vector<float> phi;          ///< per slot: φ_shell, clamped to ± background
    std::vector<uint32_t> cell;      ///< per slot: the cell it lies in (argmax)
    /// per slot: the component of an inside voxel; after the pieces are known, the piece that owns
    /// the voxel (inside: its piece; band: that of the nearest inside voxel of its cell); kNone
    std::vector<uint32_t> owner;

    bool isInside(size_t slot) const { return isActive[slot] && phi[slot] < 0; }
    Coord coordOf(size_t slot) const {
        const Coord& o = leafOrigin[slot / kLeafSize];
        const uint32_t off = uint32_t(slot % kLeafSize);
        return Coord(o.x() + int(off >> 6), o.y() + int((off >> 3) & 7), o.z() + int(off & 7));
    }
    Vec3d world(const Coord& ijk) const {
        return {originMm[0] + voxelMm * ijk.x(), originMm[1] + voxelMm * ijk.y(), originMm[2] + voxelMm * ijk.z()};
    }
    uint32_t leafAt(const Coord& origin) const {
        const auto it = leafIndex.find(leafKey(origin));
        return it == leafIndex.end() ? kNone : it->second;
    }
    /// The slot of the voxel nearest to @p p, or SIZE_MAX outside the field.
    size_t slotAt(const Vec3d& p) const {
        Coord ijk;
        for (int a = 0; a < 3; ++a) ijk[a] = int(std::lround((p[size_t(a)] - originMm[size_t(a)]) / voxelMm));
        const uint32_t leaf = leafAt(ijk & ~7);
        if (leaf == kNone) return SIZE_MAX;
        const size_t slot = size_t(leaf) * kLeafSize + FloatLeaf::coordToOffset(ijk);
        return isActive[slot] ? slot : SIZE_MAX;
    }
};

VoxelField buildField(const FloatGrid& shell) {
    VoxelField f;
    f.background = shell.background();
    f.voxelMm = shell.voxelSize()[0];
    const openvdb::Vec3d o = shell.transform().indexToWorld(Coord(0, 0, 0));
    const openvdb::Vec3d o1 = shell.transform().indexToWorld(Coord(1, 1, 1));
    f.originMm = {o[0], o[1], o[2]};
    for (int a = 0; a < 3; ++a)
        if (std::abs(o1[a] - o[a] - f.voxelMm) > 1e-9 * std::max(1.0, f.voxelMm))
            throw Error(ErrorCode::InvalidInput, "the shell grid's transform is not a uniform scale and translation");

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
            if (x < 7) visit(s, s + 64);
            else if (nx != kNone) visit(s, size_t(nx) * kLeafSize + off - 448);
            if (y < 7) visit(s, s + 8);
            else if (ny != kNone) visit(s, size_t(ny) * kLeafSize + off - 56);
            if (z < 7) visit(s, s + 1);
            else if (nz != kNone) visit(s, size_t(nz) * kLeafSize + off - 7);
        }
    }
}

/// One connected component of shell ∩ cell.
struct Component {
    uint32_t cell = 0;
    size_t voxels = 0;
    uint32_t group = 0;  ///< request index, or requests.size() + component index for an orphan
};

/// Drops the vertex-connected components of @p mesh enclosing less than @p minVolumeMm3: specks
/// the mesher leaves where the iso-surface grazes a voxel. Returns how many were dropped.
size_t dropSpecks(TriMesh& mesh, double minVolumeMm3) {
    const VertexComponents components = vertexComponents(mesh);
    return keepComponents(mesh, components, [&](uint32_t root) { return std::abs(components.volume[root]) >= minVolumeMm3; });
}

/// A piece's grid → closed, outward triangles (quads split along the shorter diagonal), specks
/// under @p minVolumeMm3 dropped. Deterministic: OpenVDB's output order for a given grid.
TriMesh meshGrid(openvdb::tools::VolumeToMesh& mesher, const FloatGrid& grid, double minVolumeMm3) {
    mesher(grid);
    TriMesh mesh;
    const size_t pointCount = mesher.pointListSize();
    const openvdb::tools::PointList& points = mesher.pointList();
    mesh.positions.resize(pointCount);
    for (size_t i = 0; i < pointCount; ++i) mesh.positions[i] = {points[i][0], points[i][1], points[i][2]};
    const openvdb::tools::PolygonPoolList& pools = mesher.polygonPoolList();
    auto d2 = [&](uint32_t a, uint32_t b) { return (points[a] - points[b]).lengthSqr(); };
    for (size_t n = 0; n < mesher.polygonPoolListSize(); ++n) {
        const openvdb::tools::PolygonPool& pool = pools[n];
        // OpenVDB winds clockwise seen from outside; zomefab's meshes are counter-clockwise.
        for (size_t i = 0; i < pool.numQuads(); ++i) {
            const openvdb::Vec4I& q = pool.quad(i);
            if (d2(q[0], q[2]) <= d2(q[1], q[3])) {
                mesh.triangles.push_back({q[0], q[2], q[1]});
                mesh.triangles.push_back({q[0], q[3], q[2]});
            } else {
                mesh.triangles.push_back({q[0], q[3], q[1]});
                mesh.triangles.push_back({q[1], q[3], q[2]});
            }
        }
        for (size_t i = 0; i < pool.numTriangles(); ++i) {
            const openvdb::Vec3I& t = pool.triangle(i);
            mesh.triangles.push_back({t[0], t[2], t[1]});
        }
    }
    dropSpecks(mesh, minVolumeMm3);
    return mesh;
}

void checkRigid(const Transform4d& t) {
    // Columns orthonormal and a proper rotation: frame and shell were scaled alike and not mirrored.
    double det = 0;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            double d = 0;
            for (int k = 0; k < 3; ++k) d += t.at(k, i) * t.at(k, j);
            if (std::abs(d - (i == j ? 1.0 : 0.0)) > 1e-6)
                throw Error(ErrorCode::InvalidInput,
                            "the frame and the shell are not in the same millimetres (frame→grid transform scales or "
                            "shears: make both from the same scaled mesh)");
        }
    det = t.at(0, 0) * (t.at(1, 1) * t.at(2, 2) - t.at(1, 2) * t.at(2, 1)) -
          t.at(0, 1) * (t.at(1, 0) * t.at(2, 2) - t.at(1, 2) * t.at(2, 0)) +
          t.at(0, 2) * (t.at(1, 0) * t.at(2, 1) - t.at(1, 1) * t.at(2, 0));
    if (det < 0) throw Error(ErrorCode::InvalidInput, "the frame→grid transform mirrors: the frame and the shell disagree");
}

}  // namespace

void checkPiecesOptions(const PiecesOptions& o) {
    if (!(o.minPieceVolumeMm3 >= 0 && std::isfinite(o.minPieceVolumeMm3)))
        throw Error(ErrorCode::Usage, "the smallest piece volume must be a finite number ≥ 0 mm³");
    if (!(o.adaptivity >= 0 && o.adaptivity <= 1))
        throw Error(ErrorCode::Usage, "adaptivity must be in [0, 1], got " + formatNumber(o.adaptivity, 4));
    checkTenonOptions(o.tenons);
    checkLabelOptions(o.label);
}

Pieces makePieces(const sdf::LevelSet& shellSet, const zome::Structure& frame, const Transform4d& frameToGridMm,
                  const partition::PartitionResult& partition, const Fabrication& fabrication,
                  const PiecesOptions& options, RunContext& context) {
    Stopwatch clock;
    checkFabrication(fabrication);
    checkPiecesOptions(options);
    const partition::LinearCells& model = partition.cells;
    const std::vector<partition::Piece>& requests = partition.pieces;
    checkRigid(frameToGridMm);
    if (model.w.empty() || model.w.size() != model.b.size())
        throw Error(ErrorCode::InvalidInput, "the cell model needs as many offsets b as normals w, and at least one cell");
    for (size_t k = 0; k < model.cellCount(); ++k)
        if (!std::isfinite(model.b[k]) || !std::isfinite(model.w[k][0]) || !std::isfinite(model.w[k][1]) ||
            !std::isfinite(model.w[k][2]))
            throw Error(ErrorCode::InvalidInput, "cell " + std::to_string(k) + " has a non-finite coefficient");
    for (size_t r = 0; r < requests.size(); ++r)
        for (uint32_t c : requests[r].cells)
            if (c >= model.cellCount())
                throw Error(ErrorCode::InvalidInput, "piece " + std::to_string(r) + " names cell " + std::to_string(c) +
                                                         ", but there are " + std::to_string(model.cellCount()) + " cells");
    if (shellSet.empty()) throw Error(ErrorCode::InvalidInput, "the shell level set is empty");
    const FloatGrid::ConstPtr shell = sdf::levelSetGrid(shellSet);
    const double voxel = shell->voxelSize()[0];
    PiecesOptions opt = options;
    if (opt.tenons.maxPerPiece > 0 && voxel > maxVoxelForPegsMm(opt.tenons))
        throw Error(ErrorCode::Usage, "tenon pegs " + formatNumber(pegShortMm(opt.tenons), 4) + " mm thick need a voxel of at most " +
                                          formatNumber(maxVoxelForPegsMm(opt.tenons), 4) + " mm, but the shell's voxel is " +
                                          formatNumber(voxel, 4) + " mm: rebuild it finer (zf-sdf --voxel-mm) or turn tenons off");
    if (opt.label.isEnabled && opt.label.strokeMm < 2.0 * voxel) {
        context.warn("piece numbers are not engraved: a " + formatNumber(opt.label.strokeMm, 4) + " mm stroke needs a voxel of at most " +
                     formatNumber(opt.label.strokeMm / 2.0, 4) + " mm (the shell's is " + formatNumber(voxel, 4) + " mm)");
        opt.label.isEnabled = false;
    }

    Pieces out;
    out.options = opt;
    out.printerMm = fabrication.printerMm;
    out.voxelMm = voxel;
    out.frameToGridMm = frameToGridMm;
    out.gridTransformMm = shellSet.info().transformMm;
    const double voxelVolume = voxel * voxel * voxel;

    // --- 1. voxels, owner cells, components -----------------------------------------------------
    context.progress("pieces", 0.0);
    VoxelField field = buildField(*shell);
    context.throwIfCancelled();
    const GridCells cells = toGridCells(model, frameToGridMm);
    const size_t cellCount = cells.count();
    const size_t slotCount = field.phi.size();
    field.cell.assign(slotCount, kNone);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, field.leafOrigin.size(), 64), [&](const tbb::blocked_range<size_t>& r) {
        std::vector<double> scores(cellCount);
        for (size_t leaf = r.begin(); leaf < r.end(); ++leaf)
            for (uint32_t off = 0; off < kLeafSize; ++off) {
                const size_t s = leaf * kLeafSize + off;
                if (field.isActive[s]) field.cell[s] = cells.owner(field.world(field.coordOf(s)), scores.data());
            }
    });
    context.throwIfCancelled();
    DisjointSets voxelSets(slotCount);
    forEachForwardPair(field, [&](size_t a, size_t b) {
        if (field.isInside(a) && field.isInside(b) && field.cell[a] == field.cell[b])
            voxelSets.unite(uint32_t(a), uint32_t(b));
    });
    std::vector<Component> comps;
    field.owner.assign(slotCount, kNone);
    {
        std::vector<uint32_t> compOfRoot(slotCount, kNone);
        for (size_t s = 0; s < slotCount; ++s) {
            if (!field.isInside(s)) continue;
            const uint32_t root = voxelSets.find(uint32_t(s));
            if (compOfRoot[root] == kNone) {
                compOfRoot[root] = uint32_t(comps.size());
                comps.push_back({field.cell[s], 0, 0});
            }
            field.owner[s] = compOfRoot[root];
            ++comps[compOfRoot[root]].voxels;
        }
    }
    voxelSets = DisjointSets();
    if (comps.empty()) throw Error(ErrorCode::InvalidInput, "the shell has no inside");
    // Cut-face contacts between components (voxel faces).
    std::map<std::pair<uint32_t, uint32_t>, size_t> contacts;
    forEachForwardPair(field, [&](size_t a, size_t b) {
        if (!field.isInside(a) || !field.isInside(b)) return;
        const uint32_t ca = field.owner[a], cb = field.owner[b];
        if (ca != cb) ++contacts[{std::min(ca, cb), std::max(ca, cb)}];
    });
    context.progress("pieces", 0.15);
    context.debug(std::string("voxels, cells and components: ") + formatNumber(clock.seconds(), 3) + " s");
    context.throwIfCancelled();

    // --- 2. components → pieces -------------------------------------------------------------
    const Transform4d gridToFrame = affineInverse(frameToGridMm);
    std::vector<std::vector<uint32_t>> cellRequests(cellCount);
    for (size_t r = 0; r < requests.size(); ++r)
        for (uint32_t c : requests[r].cells) cellRequests[c].push_back(uint32_t(r));
    for (auto& list : cellRequests) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
    }
    std::vector<std::vector<size_t>> votes(comps.size());
    bool needsVotes = false;
    for (size_t c = 0; c < comps.size(); ++c) {
        const auto& reqs = cellRequests[comps[c].cell];
        if (reqs.empty()) {
            comps[c].group = uint32_t(requests.size() + c);
            out.outsideCellsVolumeMm3 += double(comps[c].voxels) * voxelVolume;
        } else if (reqs.size() == 1) {
            comps[c].group = reqs[0];
        } else {
            votes[c].assign(reqs.size(), 0);
            needsVotes = true;
        }
    }
    if (needsVotes) {
        // A cell shared by several requests: each component goes to the request whose surface box
        // (grown by the wall's thickness) holds most of its voxels.
        const double grow = std::max(shellSet.info().shellMm, 4 * voxel) + 2 * voxel;
        for (size_t s = 0; s < slotCount; ++s) {
            if (!field.isInside(s) || votes[field.owner[s]].empty()) continue;
            const uint32_t c = field.owner[s];
            const Vec3d x = gridToFrame.apply(field.world(field.coordOf(s)));
            const auto& reqs = cellRequests[comps[c].cell];
            for (size_t i = 0; i < reqs.size(); ++i) {
                const Box3d& box = requests[reqs[i]].boundsMm;
                if (box.isEmpty()) continue;
                bool isIn = true;
                for (int a = 0; a < 3; ++a)
                    if (x[size_t(a)] < box.min[size_t(a)] - grow || x[size_t(a)] > box.max[size_t(a)] + grow) isIn = false;
                if (isIn) ++votes[c][i];
            }
        }
        for (size_t c = 0; c < comps.size(); ++c) {
            if (votes[c].empty()) continue;
            const size_t best = size_t(std::max_element(votes[c].begin(), votes[c].end()) - votes[c].begin());
            comps[c].group = cellRequests[comps[c].cell][best];
        }
    }
    // Components of one request that touch form one piece. Then two kinds of pieces join the
    // neighbour they share the largest cut face with: the parts of the shell in cells that no
    // request names (cells with no outer surface: the partition meant no piece there), whatever
    // their size, and slivers below minPieceVolumeMm3. Never dropped: with no neighbour they stay.
    DisjointSets pieceSets(comps.size());
    for (const auto& [pair, count] : contacts)
        if (comps[pair.first].group == comps[pair.second].group) pieceSets.unite(pair.first, pair.second);
    std::vector<double> rootVolume(comps.size(), 0.0);
    std::vector<uint32_t> rootSlivers(comps.size(), 0);
    std::vector<uint8_t> isOrphan(comps.size(), 0);  // per root: only components of unnamed cells
    for (size_t c = 0; c < comps.size(); ++c) {
        rootVolume[pieceSets.find(uint32_t(c))] += double(comps[c].voxels) * voxelVolume;
        isOrphan[c] = comps[c].group >= requests.size();
    }
    auto mergeIntoNeighbour = [&](uint32_t root, bool isOrphanPass) {
        std::map<uint32_t, size_t> shared;  // neighbour root → contact voxel faces
        for (const auto& [pair, count] : contacts) {
            const uint32_t ra = pieceSets.find(pair.first), rb = pieceSets.find(pair.second);
            if (ra == rb) continue;
            if (ra == root) shared[rb] += count;
            else if (rb == root) shared[ra] += count;
        }
        if (shared.empty()) return false;
        // Largest contact, named pieces before unnamed ones; ties to the lowest root.
        uint32_t target = kNone;
        for (const auto& [r, count] : shared) {
            if (target == kNone) {
                target = r;
                continue;
            }
            const bool isBetterKind = isOrphan[target] && !isOrphan[r];
            const bool isSameKind = isOrphan[target] == isOrphan[r];
            if (isBetterKind || (isSameKind && count > shared[target])) target = r;
        }
        const double volume = rootVolume[root] + rootVolume[target];
        const uint32_t slivers = rootSlivers[root] + rootSlivers[target] + (isOrphanPass ? 0 : 1);
        const bool isStillOrphan = isOrphan[root] && isOrphan[target];
        pieceSets.unite(root, target);
        const uint32_t merged = pieceSets.find(root);
        rootVolume[merged] = volume;
        rootSlivers[merged] = slivers;
        isOrphan[merged] = isStillOrphan;
        return true;
    };
    auto rootsByVolume = [&] {
        std::vector<uint32_t> roots;
        for (size_t c = 0; c < comps.size(); ++c)
            if (pieceSets.find(uint32_t(c)) == c) roots.push_back(uint32_t(c));
        std::stable_sort(roots.begin(), roots.end(), [&](uint32_t a, uint32_t b) { return rootVolume[a] < rootVolume[b]; });
        return roots;
    };
    size_t orphansKept = 0;
    for (bool isChanged = true; isChanged;) {
        isChanged = false;
        orphansKept = 0;
        for (uint32_t r0 : rootsByVolume()) {
            const uint32_t root = pieceSets.find(r0);
            if (root != r0 || !isOrphan[root]) continue;
            if (mergeIntoNeighbour(root, true)) isChanged = true;
            else ++orphansKept;
        }
    }
    if (out.outsideCellsVolumeMm3 > 0)
        context.warn(formatNumber(out.outsideCellsVolumeMm3, 4) +
                     " mm³ of the shell lie in cells that no partition piece names; merged into their neighbours" +
                     (orphansKept ? " (" + std::to_string(orphansKept) + " with no neighbour kept as pieces)" : ""));
    for (uint32_t r0 : rootsByVolume()) {
        const uint32_t root = pieceSets.find(r0);
        if (rootVolume[root] >= opt.minPieceVolumeMm3) continue;
        if (mergeIntoNeighbour(root, false)) {
            ++out.sliversMerged;
        } else {
            ++out.isolatedSlivers;
            context.warn("a " + formatNumber(rootVolume[root], 4) +
                         " mm³ piece touches no other piece and cannot be merged: it is kept as it is");
        }
    }
    // Piece order: by the lowest request they come from, then by their first voxel.
    std::vector<uint32_t> pieceOfComp(comps.size(), kNone);
    std::vector<uint32_t> pieceRoots;
    {
        std::map<uint32_t, uint32_t> lowestGroup;
        for (size_t c = 0; c < comps.size(); ++c) {
            const uint32_t r = pieceSets.find(uint32_t(c));
            auto it = lowestGroup.find(r);
            if (it == lowestGroup.end()) lowestGroup[r] = comps[c].group;
            else it->second = std::min(it->second, comps[c].group);
        }
        for (const auto& [r, g] : lowestGroup) pieceRoots.push_back(r);
        std::stable_sort(pieceRoots.begin(), pieceRoots.end(),
                         [&](uint32_t a, uint32_t b) { return lowestGroup[a] < lowestGroup[b]; });
        std::vector<uint32_t> idOfRoot(comps.size(), kNone);
        for (size_t i = 0; i < pieceRoots.size(); ++i) idOfRoot[pieceRoots[i]] = uint32_t(i);
        for (size_t c = 0; c < comps.size(); ++c) pieceOfComp[c] = idOfRoot[pieceSets.find(uint32_t(c))];
    }
    const size_t pieceCount = pieceRoots.size();
    out.pieces.resize(pieceCount);
    std::vector<CellSet> cellSets(pieceCount);
    for (size_t p = 0; p < pieceCount; ++p) {
        out.pieces[p].id = uint32_t(p);
        out.pieces[p].sliversMerged = rootSlivers[pieceRoots[p]];
        cellSets[p].isMember.assign(cellCount, 0);
    }
    for (size_t c = 0; c < comps.size(); ++c) {
        Piece& piece = out.pieces[pieceOfComp[c]];
        piece.cells.push_back(comps[c].cell);
        if (comps[c].group < requests.size()) piece.requests.push_back(comps[c].group);
        piece.shellVolumeMm3 += double(comps[c].voxels) * voxelVolume;
        out.shellVolumeMm3 += double(comps[c].voxels) * voxelVolume;
    }
    for (size_t p = 0; p < pieceCount; ++p) {
        Piece& piece = out.pieces[p];
        for (auto* list : {&piece.cells, &piece.requests}) {
            std::sort(list->begin(), list->end());
            list->erase(std::unique(list->begin(), list->end()), list->end());
        }
        for (uint32_t c : piece.cells) cellSets[p].isMember[c] = 1;
    }
    // Voxel owners: inside voxels belong to their component's piece; band voxels outside the shell
    // to the piece of the nearest inside voxel of the same cell (up to the band's width, by
    // layers, the lowest piece id on ties), else to the piece holding most of their cell.
    std::vector<uint32_t> cellPieceCount(cellCount, 0), cellDefault(cellCount, kNone);
    {
        std::vector<size_t> best(cellCount, 0);
        std::vector<std::vector<uint32_t>> piecesOfCell(cellCount);
        for (size_t c = 0; c < comps.size(); ++c) {
            const uint32_t k = comps[c].cell, p = pieceOfComp[c];
            if (std::find(piecesOfCell[k].begin(), piecesOfCell[k].end(), p) == piecesOfCell[k].end())
                piecesOfCell[k].push_back(p);
            if (cellDefault[k] == kNone || comps[c].voxels > best[k]) cellDefault[k] = p, best[k] = comps[c].voxels;
        }
        for (size_t k = 0; k < cellCount; ++k) cellPieceCount[k] = uint32_t(piecesOfCell[k].size());
    }
    for (size_t s = 0; s < slotCount; ++s)
        if (field.isInside(s)) field.owner[s] = pieceOfComp[field.owner[s]];
    {
        std::vector<uint32_t> proposal(slotCount, kNone);
        std::vector<size_t> touched;
        for (int layer = 0; layer < sdf::kHalfWidthVoxels; ++layer) {
            auto offer = [&](size_t from, size_t to) {
                if (!field.isActive[to] || field.owner[from] == kNone || field.owner[to] != kNone ||
                    field.cell[from] != field.cell[to])
                    return;
                if (proposal[to] == kNone) touched.push_back(to);
                proposal[to] = std::min(proposal[to], field.owner[from]);
            };
            forEachForwardPair(field, [&](size_t a, size_t b) {
                offer(a, b);
                offer(b, a);
            });
            for (size_t slot : touched) field.owner[slot] = proposal[slot], proposal[slot] = kNone;
            touched.clear();
        }
    }
    for (size_t s = 0; s < slotCount; ++s)
        if (field.isActive[s] && field.owner[s] == kNone) field.owner[s] = cellDefault[field.cell[s]];
    for (size_t p = 0; p < pieceCount; ++p)
        for (uint32_t k = 0; k < cellCount; ++k) {
            if (cellSets[p].isMember[k]) cellSets[p].members.push_back(k);
            if (!cellSets[p].isMember[k] || cellPieceCount[k] > 1) cellSets[p].cutters.push_back(k);
        }
    {
        std::map<std::pair<uint32_t, uint32_t>, size_t> pieceContacts;
        for (const auto& [pair, count] : contacts) {
            const uint32_t a = pieceOfComp[pair.first], b = pieceOfComp[pair.second];
            if (a != b) pieceContacts[{std::min(a, b), std::max(a, b)}] += count;
        }
        for (const auto& [pair, count] : pieceContacts) {
            const double area = double(count) * voxel * voxel;
            out.pieces[pair.first].neighbors.push_back({pair.second, area});
            out.pieces[pair.second].neighbors.push_back({pair.first, area});
        }
        for (Piece& piece : out.pieces) std::sort(piece.neighbors.begin(), piece.neighbors.end());
    }
    context.info(std::to_string(pieceCount) + " pieces from " + std::to_string(comps.size()) + " components of " +
                 std::to_string(cellCount) + " cells (" + std::to_string(out.sliversMerged) + " slivers merged)");
    context.progress("pieces", 0.25);
    context.debug(std::string("pieces: ") + formatNumber(clock.seconds(), 3) + " s");
    context.throwIfCancelled();

    // --- 3. tenons and labels, planned against the shell and the piece labels ------------------------
    const FloatGrid::ConstAccessor probeAccessor = shell->getConstAccessor();
    const openvdb::tools::GridSampler<FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
        probeAccessor, shell->transform());
    ShellProbe probe;
    probe.voxelMm = voxel;
    probe.signedDistanceMm = [&](const Vec3d& p) { return double(sampler.wsSample(openvdb::Vec3d(p[0], p[1], p[2]))); };
    // The owner of the nearest voxel, band voxels included: a point the trilinear φ puts just
    // inside the wall may have its nearest voxel centre just outside.
    probe.pieceAt = [&](const Vec3d& p) -> int64_t {
        const size_t s = field.slotAt(p);
        if (s == SIZE_MAX || field.owner[s] == kNone) return -1;
        return int64_t(field.owner[s]);
    };
    if (opt.tenons.maxPerPiece > 0) {
        const std::vector<TenonCandidate> candidates = findTenonCandidates(frame, frameToGridMm, probe, opt.tenons);
        TenonPlan plan = chooseTenons(candidates, pieceCount, opt.tenons);
        for (size_t p = 0; p < pieceCount; ++p) {
            out.pieces[p].tenons = std::move(plan.perPiece[p]);
            out.pieces[p].tenonShortfall = std::move(plan.shortfall[p]);
        }
        // The reasons summed over the pieces that fall short, most frequent first. (Naming the
        // first such piece's top reason misled: its reasons were often one each, and the tie went
        // to the alphabetically first, "crosses another piece", though on the bunny at 400 mm that
        // rejected 7 of 136 rays against 52 "too far from the wall".)
        size_t few = 0;
        std::map<std::string, int> reasons;
        for (const Piece& piece : out.pieces)
            if (piece.tenons.size() < size_t(opt.tenons.minPerPiece)) {
                ++few;
                for (const auto& [why, count] : piece.tenonShortfall) reasons[why] += count;
            }
        if (few > 0) {
            std::vector<std::pair<int, std::string>> ranked;
            for (const auto& [why, count] : reasons) ranked.push_back({-count, why});
            std::sort(ranked.begin(), ranked.end());
            std::string list;
            for (const auto& [negCount, why] : ranked) list += (list.empty() ? "" : ", ") + why + " " + std::to_string(-negCount);
            context.warn(std::to_string(few) + " of " + std::to_string(pieceCount) + " pieces have fewer than " +
                         std::to_string(opt.tenons.minPerPiece) + " tenons (rejected rays: " + list +
                         "); pieces.json lists why per piece");
        }
    }
    context.throwIfCancelled();
    if (opt.label.isEnabled) {
        const double reach = frame.scale().ballRadiusMm() + 3.0 * frame.scale().b0Mm;
        const auto spots = innerSurfaceSpots(frame, frameToGridMm, probe, pieceCount, reach);
        size_t unlabelled = 0;
        for (size_t p = 0; p < pieceCount; ++p) {
            Piece& piece = out.pieces[p];
            piece.label = placeLabel(std::to_string(p), uint32_t(p), spots[p], piece.tenons, opt.tenons, probe,
                                     opt.label, &piece.labelNote);
            if (!piece.label) ++unlabelled;
        }
        if (unlabelled > 0)
            context.warn(std::to_string(unlabelled) + " of " + std::to_string(pieceCount) +
                         " pieces have no engraved number (no flat inner spot clear of cuts and tenons)");
    }
    context.progress("pieces", 0.35);
    context.debug(std::string("tenons and labels planned: ") + formatNumber(clock.seconds(), 3) + " s");
    context.throwIfCancelled();

    // --- 4. per piece: level set by CSG, mesh, checks, orientation --------------------------------
    // Leaves holding each piece's inside voxels, and their 26 neighbours (the band is 3 voxels).
    std::vector<std::vector<uint32_t>> leafPieces(field.leafOrigin.size());
    for (size_t s = 0; s < slotCount; ++s)
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
    leafPieces.clear();

    const float bg = field.background;
    std::vector<FloatGrid::Ptr> grids(pieceCount);
    // Where meshing keeps full resolution: around tenons (the pegs must keep their section) and
    // engraved numbers (strokes of two voxels would blur into the surface).
    std::vector<openvdb::BoolTree::Ptr> fullResolution(pieceCount);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pieceCount, 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t p = range.begin(); p < range.end(); ++p) {
            context.throwIfCancelled();
            Piece& piece = out.pieces[p];
            const CellSet& set = cellSets[p];
            FloatGrid::Ptr grid = FloatGrid::create(bg);
            grid->setTransform(shell->transform().copy());
            grid->setGridClass(openvdb::GRID_LEVEL_SET);
            std::vector<double> scores(cellCount);
            // ψ_P = max(φ_shell, δ_P): the CSG intersection of the shell and the piece's region.
            for (uint32_t leaf : pieceLeaves[p]) {
                auto node = std::make_unique<FloatLeaf>(field.leafOrigin[leaf], bg, false);
                bool isUsed = false;
                for (uint32_t off = 0; off < kLeafSize; ++off) {
                    const size_t s = size_t(leaf) * kLeafSize + off;
                    if (!field.isActive[s] || field.phi[s] >= bg) continue;
                    const Vec3d x = field.world(field.coordOf(s));
                    const bool isMember = field.owner[s] == p;
                    double psi = std::max(double(field.phi[s]), regionDistance(cells, set, x, isMember, scores.data()));
                    // The sign follows the voxel labels exactly (ties on a plane included).
                    if (field.isInside(s)) psi = isMember ? std::min(psi, -1e-6 * voxel) : std::max(psi, 1e-6 * voxel);
                    if (psi >= bg) continue;
                    isUsed = true;
                    if (psi <= -bg) node->setValueOnly(off, -bg);
                    else node->setValueOn(off, float(psi));
                }
                if (isUsed) grid->tree().addLeaf(node.release());
            }
            FloatGrid::Accessor acc = grid->getAccessor();
            auto indexBox = [&](const Box3d& box) {
                const double pad = (sdf::kHalfWidthVoxels + 1) * voxel;
                Coord lo, hi;
                for (int a = 0; a < 3; ++a) {
                    lo[a] = int(std::floor((box.min[size_t(a)] - pad - field.originMm[size_t(a)]) / voxel));
                    hi[a] = int(std::ceil((box.max[size_t(a)] + pad - field.originMm[size_t(a)]) / voxel));
                }
                return openvdb::CoordBBox(lo, hi);
            };
            auto mask = std::make_shared<openvdb::BoolTree>(false);
            // Tenons: union, ψ = min(ψ, τ).
            for (const Tenon& t : piece.tenons) {
                const openvdb::CoordBBox box = indexBox(tenonBoundsMm(t, opt.tenons));
                mask->fill(box, true, true);
                for (auto it = box.begin(); it; ++it) {
                    const Coord ijk = *it;
                    const double tau = tenonSignedDistanceMm(t, opt.tenons, field.world(ijk));
                    if (tau >= bg) continue;
                    const float old = acc.getValue(ijk);
                    if (tau >= old) continue;
                    if (tau <= -bg) acc.setValueOff(ijk, -bg);
                    else acc.setValueOn(ijk, float(tau));
                }
            }
            // The engraved number: difference, ψ = max(ψ, −glyph).
            if (piece.label) {
                const std::vector<Stroke> strokes = labelStrokes(piece.label->text, opt.label);
                const openvdb::CoordBBox box = indexBox(labelBoundsMm(*piece.label, opt.label));
                mask->fill(box, true, true);
                for (auto it = box.begin(); it; ++it) {
                    const Coord ijk = *it;
                    const double e = -labelSignedDistanceMm(*piece.label, strokes, opt.label, field.world(ijk));
                    if (e <= -bg) continue;
                    const float old = acc.getValue(ijk);
                    if (e <= old) continue;
                    if (e >= bg) acc.setValueOff(ijk, bg);
                    else acc.setValueOn(ijk, float(e));
                }
            }
            openvdb::tools::pruneLevelSet(grid->tree());
            grids[p] = std::move(grid);
            if (!mask->empty()) {
                mask->voxelizeActiveTiles();  // the mesher looks the mask up by leaf nodes only
                fullResolution[p] = std::move(mask);
            }
        }
    });
    context.throwIfCancelled();
    context.progress("pieces", 0.5);
    context.debug(std::string("level sets: ") + formatNumber(clock.seconds(), 3) + " s");
    field = VoxelField();

    // Meshing. Not OpenVDB's fracture scheme (VolumeToMesh::setRefGrid): it snaps the seam
    // vertices to the uncut shell's surface, up to a voxel beyond the cut planes, so cut faces
    // would not be flat and neighbours would overlap at their rims (measured, docs/pieces.md).
    std::vector<TriMesh> meshes(pieceCount);
    std::atomic<size_t> meshed{0};
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pieceCount, 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t p = range.begin(); p < range.end(); ++p) {
            context.throwIfCancelled();
            openvdb::tools::VolumeToMesh mesher(0.0, opt.adaptivity, /*relaxDisorientedTriangles=*/true);
            if (fullResolution[p]) mesher.setAdaptivityMask(fullResolution[p]);
            tbb::this_task_arena::isolate([&] { meshes[p] = meshGrid(mesher, *grids[p], voxelVolume); });
            grids[p].reset();
            fullResolution[p].reset();
            context.progress("pieces", 0.5 + 0.4 * double(++meshed) / double(pieceCount));
        }
    });
    context.throwIfCancelled();
    context.debug("meshed: " + formatNumber(clock.seconds(), 3) + " s");

    std::vector<std::string> orientationNotes(pieceCount);  // reported in piece order below
    tbb::parallel_for(tbb::blocked_range<size_t>(0, pieceCount, 1), [&](const tbb::blocked_range<size_t>& range) {
        for (size_t p = range.begin(); p < range.end(); ++p) {
            Piece& piece = out.pieces[p];
            const CellSet& set = cellSets[p];
            TriMesh mesh = std::move(meshes[p]);
            // Sealed pockets of a few voxels (seen up to 28 voxels, where a tenon prism meets a
            // tilted wall) would be printed as empty pockets and make admesh count extra parts: fill
            // them. An uncut closed shell keeps its hollow, which is far larger.
            const mesh::CavityRemoval cavities = mesh::removeCavities(mesh, 1000.0 * voxel * voxel * voxel);
            if (cavities.cavities > 0)
                context.debug("piece " + std::to_string(p) + ": filled " + std::to_string(cavities.cavities) +
                              " sealed cavities of " + formatNumber(cavities.volumeMm3, 4) + " mm³");
            const mesh::MeshReport report = mesh::checkMesh(mesh);
            if (report.boundaryEdges > 0 || report.nonManifoldEdges > 0 || !(report.volume > 0))
                throw Error(ErrorCode::ProcessingFailed,
                            "piece " + std::to_string(p) + ": the mesh is not a closed, outward surface (" +
                                std::to_string(report.boundaryEdges) + " boundary and " +
                                std::to_string(report.nonManifoldEdges) + " non-manifold edges, volume " +
                                formatNumber(report.volume, 4) + " mm³)");
            piece.volumeMm3 = report.volume;
            piece.gridBoundsMm = boundingBox(mesh);

            // Cut faces: the planes between its cells and the others, outward into the other cell.
            std::vector<CutFace> planes;
            for (uint32_t k : set.members)
                for (uint32_t j = 0; j < cellCount; ++j) {
                    if (set.isMember[j]) continue;
                    const double inv = cells.invNorm[k * cellCount + j];
                    if (inv <= 0) continue;
                    planes.push_back({scale(sub(cells.w[j], cells.w[k]), inv), (cells.b[j] - cells.b[k]) * inv, 0.0});
                }
            const std::vector<CutFace> faces = measureCutFaces(mesh, planes, 0.05 * voxel);
            const PrintOrientation orientation = orientForPrinter(mesh, faces, fabrication.printerMm);
            orientationNotes[p] = orientation.note;
            if (!orientation.fits) {
                const Vec3d e = orientation.extentsMm;
                throw Error(ErrorCode::ProcessingFailed,
                            "piece " + std::to_string(p) + " (" + formatNumber(e[0], 4) + " × " + formatNumber(e[1], 4) + " × " +
                                formatNumber(e[2], 4) + " mm at best) fits the " + formatNumber(fabrication.printerMm[0], 4) + " × " +
                                formatNumber(fabrication.printerMm[1], 4) + " × " + formatNumber(fabrication.printerMm[2], 4) +
                                " mm printer in no orientation: the partition must cut it smaller (zf-partition "
                                "--printer-mm, --fit-margin-mm)");
            }
            piece.gridToPrintMm = orientation.transformMm;
            piece.isCutFaceDown = orientation.isCutFaceDown;
            piece.downNormalGridMm = orientation.downNormal;
            piece.baseAreaMm2 = orientation.baseAreaMm2;
            piece.extentsMm = orientation.extentsMm;
            transformInPlace(mesh, orientation.transformMm);
            // The adaptive mesher can emit two points a float's rounding apart (seen where a tenon
            // off the lattice axes meets a curved wall); turned onto the bed they can round to the
            // same point. Welded, the zero-area triangles between them repeat a vertex and go, so
            // the STL has no degenerate facet.
            weldIdenticalVertices(mesh);
            mesh.triangles.erase(std::remove_if(mesh.triangles.begin(), mesh.triangles.end(), hasRepeatedIndex),
                                 mesh.triangles.end());
            piece.mesh = std::move(mesh);
        }
    });
    context.throwIfCancelled();
    size_t offCutFace = 0;
    for (size_t p = 0; p < pieceCount; ++p) {
        if (orientationNotes[p].empty()) continue;
        ++offCutFace;
        context.debug("piece " + std::to_string(p) + ": " + orientationNotes[p]);
    }
    if (offCutFace > 0)
        context.info(std::to_string(offCutFace) + " of " + std::to_string(pieceCount) +
                     " pieces have no cut face they can lie on; they rest on their largest base that fits");
    out.seconds = clock.seconds();
    context.debug("meshed, checked and oriented: " + formatNumber(out.seconds, 3) + " s");
    return out;
}

}  // namespace zomefab::pieces
