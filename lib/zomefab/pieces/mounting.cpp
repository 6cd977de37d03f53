// SPDX-License-Identifier: GPL-3.0-or-later
// The installation plan on the shell's voxels: bodies, their directions and the frame sweeps
// (detail/mounting.h, docs/mounting.md).
#include "zomefab/pieces/detail/mounting.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <tuple>

#include "zomefab/core/format.h"
#include "zomefab/mount/sweep.h"
#include "zomefab/zome/holes.h"

namespace zomefab::pieces::detail {

namespace {

constexpr uint32_t kStrutBit = 0x80000000u;

/// The rearmost point of a voxel's cube along @p d, relative to its centre.
double halfDepth(const Vec3d& d, double voxelMm) {
    return 0.5 * voxelMm * (std::abs(d[0]) + std::abs(d[1]) + std::abs(d[2]));
}

/// The frame's balls and struts along @p d, grown by @p marginMm: what a body must not meet.
std::unique_ptr<mount::DepthRaster> frameRaster(const zome::Structure& frame,
                                                const Transform4d& frameToGridMm, const Vec3d& d,
                                                const Box3d& bounds, double pixelMm, double marginMm) {
    auto r = std::make_unique<mount::DepthRaster>(mount::SweepAxes(d), bounds, pixelMm, true);
    const zome::ZomeScale& scale = frame.scale();
    for (zome::BallId id : frame.ballIds())
        r->addSphere(frameToGridMm.apply(frame.ball(id).positionMm), scale.ballRadiusMm(), marginMm, id);
    for (zome::StrutId id : frame.strutIds()) {
        const zome::Strut& s = frame.strut(id);
        r->addCapsule(frameToGridMm.apply(s.startMm), frameToGridMm.apply(s.endMm),
                      scale.strutRadiusMm(s.color), marginMm, kStrutBit | id);
    }
    return r;
}

std::string obstacleName(uint32_t id) {
    return (id & kStrutBit) ? "strut " + std::to_string(id & ~kStrutBit) : "ball " + std::to_string(id);
}

}  // namespace

const DirectionOption* MountBody::bestFree() const {
    for (const DirectionOption& o : options)
        if (o.isFree && o.tenons > 0) return &o;
    return nullptr;
}

FrameSweeps::FrameSweeps(const zome::Structure& frame, const Transform4d& frameToGridMm, const Box3d& bounds,
                         double pixelMm, double marginMm)
    : mFrame(&frame),
      mFrameToGrid(frameToGridMm),
      mBounds(bounds),
      mPixelMm(pixelMm),
      mMarginMm(marginMm),
      mRasters(zome::kHoleCount),
      mOnce(new std::once_flag[zome::kHoleCount]) {}

const mount::DepthRaster& FrameSweeps::raster(int hole) const {
    std::call_once(mOnce[size_t(hole)], [&] {
        mRasters[size_t(hole)] = frameRaster(*mFrame, mFrameToGrid, gridDirection(hole, mFrameToGrid),
                                             mBounds, mPixelMm, mMarginMm);
    });
    return *mRasters[size_t(hole)];
}

bool FrameSweeps::isFree(const MountBody& body, int hole, double voxelMm, std::string* blockedBy) const {
    if (mBounds.isEmpty() || mFrame->ballCount() == 0) return true;
    const mount::DepthRaster& obstacles = raster(hole);
    // The body as a moving one: its voxels' rearmost points (a voxel's cube as seen along d).
    mount::DepthRaster moving(obstacles, body.bounds, false, voxelMm);
    const Vec3d& d = obstacles.axes().d;
    const double half = halfDepth(d, voxelMm);
    for (size_t i = 0; i < body.voxels.size(); ++i)
        moving.addPoint(madd(body.voxels[i], -half, d), 0.0, uint32_t(i));
    const mount::SweepHit hit = mount::worstHit(obstacles, moving, 0.0);
    if (hit.isHit && blockedBy)
        *blockedBy = obstacleName(hit.obstacle) + " by " + formatNumber(hit.overlapMm, 3) + " mm";
    return !hit.isHit;
}

uint8_t MountBody::cutLayerWith(size_t i, const MountBody& other) const {
    uint8_t nearest = 0;
    for (size_t k = 0; k < 2; ++k)
        if (nearCutOf[i][k] != kNone && (nearest == 0 || cutLayer[i][k] < nearest) &&
            std::find(other.pieces.begin(), other.pieces.end(), nearCutOf[i][k]) != other.pieces.end())
            nearest = cutLayer[i][k];
    return nearest;
}

void MountBody::addVoxelsOf(const MountBody& part) {
    voxels.insert(voxels.end(), part.voxels.begin(), part.voxels.end());
    nearCutOf.insert(nearCutOf.end(), part.nearCutOf.begin(), part.nearCutOf.end());
    cutLayer.insert(cutLayer.end(), part.cutLayer.begin(), part.cutLayer.end());
    bounds.expand(part.bounds.min), bounds.expand(part.bounds.max);
}

PlannerInput plannerInput(const Pieces& out, const VoxelField& field,
                          const std::vector<TenonCandidate>& candidates) {
    const size_t n = out.pieces.size();
    PlannerInput in;
    in.pieces.resize(n);
    in.candidatesByHole.resize(n);
    for (uint32_t p = 0; p < n; ++p) in.pieces[p].pieces = {p};
    // A body pushed along d first meets things with its rearmost points, which lie on its surface:
    // the inside voxels with a 6-neighbour outside the wall or in another piece are enough.
    std::vector<uint8_t> isSurface(field.phi.size(), 0);
    // The pieces across the cut faces each near-cut voxel is near (up to two), and its layer from
    // each face (1: on it, up to kWideCutLayers).
    std::vector<std::array<uint32_t, 2>> nearOf(field.phi.size(), {kNone, kNone});
    std::vector<std::array<uint8_t, 2>> layerOf(field.phi.size(), {0, 0});
    auto addNear = [&](size_t s, uint32_t piece, uint8_t layer) {
        auto& list = nearOf[s];
        for (size_t k = 0; k < 2; ++k)
            if (list[k] == piece) return;  // reached before, in an earlier (nearer) layer
        for (size_t k = 0; k < 2; ++k)
            if (list[k] == kNone) {
                list[k] = piece, layerOf[s][k] = layer;
                return;
            }
        // Near a third piece's face too (a corner): swept against that one, the safe side.
    };
    // Voxel faces per cut face (as faceContacts counts them): only faces large enough to order
    // their pieces by their plane leave their voxels out of the sweeps between neighbours.
    auto faceKey = [&](size_t a, size_t b) {
        if (field.owner[a] > field.owner[b]) std::swap(a, b);
        return std::make_tuple(field.owner[a], field.owner[b], field.cell[a], field.cell[b]);
    };
    std::map<std::tuple<uint32_t, uint32_t, uint32_t, uint32_t>, size_t> faceSize;
    forEachForwardPair(field, [&](size_t a, size_t b) {
        if (field.isInside(a) && field.isInside(b) && field.owner[a] != field.owner[b])
            ++faceSize[faceKey(a, b)];
    });
    forEachForwardPair(field, [&](size_t a, size_t b) {
        const bool ia = field.isInside(a), ib = field.isInside(b);
        const bool isCut = ia && ib && field.owner[a] != field.owner[b];
        if (ia && (!ib || isCut)) isSurface[a] = 1;
        if (ib && (!ia || isCut)) isSurface[b] = 1;
        if (isCut && faceSize[faceKey(a, b)] >= kMinOrderFaceVoxels) {
            addNear(a, field.owner[b], 1);
            addNear(b, field.owner[a], 1);
        }
    });
    // Layer by layer inward from the cut faces (6-neighbours in the same piece): a pass spreads
    // layer k to k + 1 only, so one pass never spreads twice.
    for (uint8_t layer = 1; layer < kWideCutLayers; ++layer)
        forEachForwardPair(field, [&](size_t a, size_t b) {
            if (!field.isInside(a) || !field.isInside(b) || field.owner[a] != field.owner[b]) return;
            auto spread = [&](size_t from, size_t to) {
                for (size_t k = 0; k < 2; ++k)
                    if (nearOf[from][k] != kNone && layerOf[from][k] == layer)
                        addNear(to, nearOf[from][k], uint8_t(layer + 1));
            };
            spread(a, b);
            spread(b, a);
        });
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (isSurface[s] && field.owner[s] < n) {
            const Vec3d x = field.world(field.coordOf(s));
            MountBody& body = in.pieces[field.owner[s]];
            body.voxels.push_back(x);
            body.nearCutOf.push_back(nearOf[s]);
            body.cutLayer.push_back(layerOf[s]);
            body.bounds.expand(x);
        }
    for (const TenonCandidate& c : candidates) {
        if (c.piece < 0 || size_t(c.piece) >= n || !c.rejection.empty()) continue;
        auto& entry = in.candidatesByHole[size_t(c.piece)][c.tenon.hole];
        ++entry.first;
        entry.second += c.score;
    }
    return in;
}

std::vector<DirectionOption> rankedOptions(const std::map<int, std::pair<size_t, double>>& byHole,
                                           size_t cap) {
    std::vector<DirectionOption> options;
    for (const auto& [hole, entry] : byHole) {
        DirectionOption o;
        o.hole = hole;
        o.tenons = entry.first;
        o.score = entry.second;
        options.push_back(o);
    }
    std::stable_sort(options.begin(), options.end(), [&](const DirectionOption& a, const DirectionOption& b) {
        const size_t ta = std::min(a.tenons, cap), tb = std::min(b.tenons, cap);
        return ta != tb ? ta > tb : a.score > b.score;
    });
    return options;
}

Vec3d gridDirection(int hole, const Transform4d& frameToGridMm) {
    return normalized(applyLinear(frameToGridMm, zome::holeDirection(hole)));
}

void testPaths(MountBody& body, const FrameSweeps& sweeps, double voxelMm, size_t freeWanted) {
    auto test = [&](DirectionOption& o) {
        if (o.isTested) return;
        o.isFree = sweeps.isFree(body, o.hole, voxelMm, &o.blockedBy);
        o.isTested = true;
    };
    if (freeWanted > 0) {
        size_t free = 0;
        for (DirectionOption& o : body.options) {
            test(o);
            if (o.isFree && ++free == freeWanted) return;
        }
        return;
    }
    // In parallel: the rasters are read-only.
    tbb::parallel_for(size_t(0), body.options.size(), [&](size_t i) { test(body.options[i]); });
}

void addGlueOptions(MountBody& body, const std::vector<int>& holes, const FrameSweeps& sweeps,
                    double voxelMm) {
    body.glueOptions.clear();
    for (int hole : holes) body.glueOptions.push_back({hole, 0, 0.0, false, false, {}});
    tbb::parallel_for(size_t(0), body.glueOptions.size(), [&](size_t i) {
        DirectionOption& o = body.glueOptions[i];
        o.isFree = sweeps.isFree(body, o.hole, voxelMm, &o.blockedBy);
        o.isTested = true;
    });
}

MountBody makeBody(const std::vector<uint32_t>& members, const PlannerInput& input, const FrameSweeps& sweeps,
                   double voxelMm, int maxPerPiece, size_t freeWanted) {
    MountBody body;
    body.pieces = members;
    std::sort(body.pieces.begin(), body.pieces.end());
    std::map<int, std::pair<size_t, double>> byHole;
    for (uint32_t p : body.pieces) {
        body.addVoxelsOf(input.pieces[p]);
        for (const auto& [hole, entry] : input.candidatesByHole[p]) {
            byHole[hole].first += entry.first;
            byHole[hole].second += entry.second;
        }
    }
    body.options = rankedOptions(byHole, size_t(std::max(1, maxPerPiece)) * body.pieces.size());
    if (body.pieces.size() == 1 && body.pieces[0] < input.sleeves.size())
        body.sleeveGrid = input.sleeves[body.pieces[0]];
    testPaths(body, sweeps, voxelMm, freeWanted);
    return body;
}

std::vector<uint32_t> unplaceablePieces(const mount::InstallationPlan& plan, const PlannerInput& input,
                                        const FaceContacts& faces, double voxelMm) {
    const size_t n = plan.holeOfPiece.size();
    std::vector<uint8_t> hasHost(n, 0);
    for (const auto& [pair, contacts] : faces)
        for (const CutContact& c : contacts)
            if (GlueOnRule{}.isLargeEnough(c.voxelFaces, voxelMm) && pair.first < n && pair.second < n)
                hasHost[pair.first] = hasHost[pair.second] = 1;
    std::vector<uint32_t> out;
    for (uint32_t p = 0; p < n && p < input.candidatesByHole.size(); ++p)
        if (plan.holeOfPiece[p] < 0 && !hasHost[p] && input.candidatesByHole[p].empty()) out.push_back(p);
    return out;
}

bool shadowsMeet(const Box3d& moving, const Box3d& still, const Vec3d& d) {
    const mount::SweepAxes axes(d);
    auto range = [](const Box3d& b, const Vec3d& e) {
        double lo = 1e300, hi = -1e300;
        for (int k = 0; k < 8; ++k) {
            const Vec3d p{(k & 1) ? b.max[0] : b.min[0], (k & 2) ? b.max[1] : b.min[1],
                          (k & 4) ? b.max[2] : b.min[2]};
            lo = std::min(lo, dot(p, e)), hi = std::max(hi, dot(p, e));
        }
        return std::make_pair(lo, hi);
    };
    for (const Vec3d& e : {axes.u, axes.v}) {
        const auto [a0, a1] = range(moving, e);
        const auto [b0, b1] = range(still, e);
        if (a1 < b0 || b1 < a0) return false;
    }
    return range(still, d).second > range(moving, d).first;
}

}  // namespace zomefab::pieces::detail
