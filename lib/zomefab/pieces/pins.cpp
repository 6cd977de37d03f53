// SPDX-License-Identifier: GPL-3.0-or-later
// Alignment pins between glued pieces (detail/pins.h, docs/mounting.md).
#include "zomefab/pieces/detail/pins.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <tuple>

#include "zomefab/mount/sweep.h"
#include "zomefab/pieces/detail/mounting.h"

namespace zomefab::pieces::detail {

namespace {

constexpr double kSocketExtraDepthMm = 0.3;  ///< the socket is deeper than the pin is long

/// A candidate spot on the face between a and b: the midpoint of two voxels across it.
struct Spot {
    Vec3d x;
    double wallMm;  ///< how deep both voxels lie in the wall (|φ|, the smaller)
};

/// The plane of one face contact (normal from a into b, offset: n·x + offset = 0).
struct FacePlane {
    Vec3d normal{0, 0, 1};
    double offsetMm = 0.0;
};

/// The cells' plane between two voxels of a and b, or the re-cut plane when they share a cell.
std::optional<FacePlane> planeBetween(const GridCells& cells, const std::vector<CellSet>& sets, uint32_t a,
                                      uint32_t b, uint32_t ca, uint32_t cb) {
    if (ca != cb && !sets[a].isLining && !sets[b].isLining) {
        const Vec3d w = sub(cells.w[cb], cells.w[ca]);
        const double len = norm(w);
        if (len == 0) return std::nullopt;
        return FacePlane{scale(w, 1.0 / len), (cells.b[cb] - cells.b[ca]) / len};
    }
    for (const CellSet::HalfSpace& h : sets[a].halfSpaces)
        for (const CellSet::HalfSpace& g : sets[b].halfSpaces)
            if (dot(h.normal, g.normal) < -0.999999 && std::abs(h.offsetMm + g.offsetMm) < 1e-6)
                return FacePlane{h.normal, -h.offsetMm};
    return std::nullopt;
}

/// Whether the slot at @p p is inside the wall and owned by @p piece.
bool isIn(const VoxelField& field, const Vec3d& p, uint32_t piece) {
    const size_t s = field.slotAt(p);
    return s != SIZE_MAX && field.isInside(s) && field.owner[s] == piece;
}

/// Whether the pin at @p c (axis n, radius r, standing out l) lies in b and its root in a: the
/// axis ends and eight points round each end.
bool fits(const VoxelField& field, uint32_t a, uint32_t b, const Vec3d& c, const Vec3d& n, double r,
          double l) {
    const mount::SweepAxes f(n);
    for (double t : {-l, -0.5 * l, 0.5 * l, l + kSocketExtraDepthMm}) {
        const uint32_t owner = t < 0 ? a : b;
        for (int k = -1; k < 8; ++k) {
            Vec3d p = madd(c, t, n);
            if (k >= 0) {
                const double angle = k * 3.14159265358979323846 / 4;
                p = madd(madd(p, (r + 0.5) * std::cos(angle), f.u), (r + 0.5) * std::sin(angle), f.v);
            }
            if (!isIn(field, p, owner)) return false;
        }
    }
    return true;
}

/// The spots on each plane between each glued pair, in slot order: (a, b) → plane index → spots.
struct PairFaces {
    std::vector<FacePlane> planes;
    std::vector<std::vector<Spot>> spots;
};

/// The planar faces of every pair of pieces glued together or glued on, by (lower, higher) piece;
/// normals from the lower into the higher.
std::map<std::pair<uint32_t, uint32_t>, PairFaces> gluedFaces(const Pieces& out, const VoxelField& field,
                                                              const GridCells& cells,
                                                              const std::vector<CellSet>& sets) {
    std::map<std::pair<uint32_t, uint32_t>, PairFaces> faces;
    for (const auto& [a, b] : out.plan.glued) faces[{std::min(a, b), std::max(a, b)}];
    for (const auto& [a, b] : out.plan.gluedOn) faces[{std::min(a, b), std::max(a, b)}];
    std::map<std::tuple<uint32_t, uint32_t, uint32_t, uint32_t>, size_t> planeOf;
    forEachForwardPair(field, [&](size_t s, size_t t) {
        if (!field.isInside(s) || !field.isInside(t) || field.owner[s] == field.owner[t]) return;
        if (field.owner[s] > field.owner[t]) std::swap(s, t);
        const auto it = faces.find({field.owner[s], field.owner[t]});
        if (it == faces.end()) return;
        const auto key = std::make_tuple(field.owner[s], field.owner[t], field.cell[s], field.cell[t]);
        auto plane = planeOf.find(key);
        if (plane == planeOf.end()) {
            const auto p =
                planeBetween(cells, sets, field.owner[s], field.owner[t], field.cell[s], field.cell[t]);
            if (!p) return;
            plane = planeOf.emplace(key, it->second.planes.size()).first;
            it->second.planes.push_back(*p);
            it->second.spots.emplace_back();
        }
        const Vec3d x = scale(add(field.world(field.coordOf(s)), field.world(field.coordOf(t))), 0.5);
        it->second.spots[plane->second].push_back({x, std::min(-field.phi[s], -field.phi[t])});
    });
    return faces;
}

/// Up to PinOptions::perPair pins from a into b (lower, higher piece of @p f) along @p axis, unit,
/// from a into b; null: each plane's normal. On the largest plane (with an axis: among those it
/// meets at most @p maxAngleCos off their normal): the spot farthest from the face's centre, then
/// each next the farthest from those chosen, where the wall is deep enough and the pin fits.
std::vector<AlignmentPin> pinsOnFace(const PairFaces& f, uint32_t a, uint32_t b, const VoxelField& field,
                                     const PinOptions& o, const Vec3d* axis = nullptr,
                                     double minCosine = 0.0) {
    size_t best = SIZE_MAX;
    for (size_t k = 0; k < f.spots.size(); ++k) {
        const double along = axis ? dot(*axis, scale(f.planes[k].normal, a < b ? 1.0 : -1.0)) : 1.0;
        if (along < minCosine) continue;
        if (best == SIZE_MAX || f.spots[k].size() > f.spots[best].size()) best = k;
    }
    if (best == SIZE_MAX) return {};
    const FacePlane& plane = f.planes[best];
    const Vec3d pinAxis = axis ? *axis : scale(plane.normal, a < b ? 1.0 : -1.0);
    const double r = 0.5 * o.diameterMm;
    std::vector<Vec3d> candidates;
    Vec3d centre{0, 0, 0};
    for (const Spot& spot : f.spots[best]) {
        if (spot.wallMm < std::min(r + 1.0, 0.99 * field.background)) continue;
        candidates.push_back(madd(spot.x, -(dot(plane.normal, spot.x) + plane.offsetMm), plane.normal));
        centre = add(centre, candidates.back());
    }
    if (candidates.empty()) return {};
    centre = scale(centre, 1.0 / double(candidates.size()));
    std::vector<Vec3d> chosen;
    std::vector<uint8_t> isTried(candidates.size(), 0);
    while (int(chosen.size()) < o.perPair) {
        size_t pick = SIZE_MAX;
        double far = -1;
        for (size_t i = 0; i < candidates.size(); ++i) {
            if (isTried[i]) continue;
            double d = chosen.empty() ? dist2(candidates[i], centre) : 1e300;
            for (const Vec3d& c : chosen) d = std::min(d, dist2(candidates[i], c));
            if (d > far) far = d, pick = i;
        }
        if (pick == SIZE_MAX || (!chosen.empty() && far < 16 * r * r)) break;  // nothing left 4r away
        isTried[pick] = 1;
        if (fits(field, a, b, candidates[pick], pinAxis, r, o.lengthMm)) chosen.push_back(candidates[pick]);
    }
    std::vector<AlignmentPin> pins;
    for (const Vec3d& c : chosen) pins.push_back({b, false, c, pinAxis, r, o.lengthMm});
    return pins;
}

/// The pins of one pair on both pieces: the pin on @p a, the socket in @p b. Returns how many.
size_t addPins(Pieces& out, uint32_t a, uint32_t b, const std::vector<AlignmentPin>& pins) {
    for (AlignmentPin pin : pins) {
        out.pieces[a].pins.push_back(pin);
        pin.partner = a;
        pin.isSocket = true;
        out.pieces[b].pins.push_back(pin);
    }
    return pins.size();
}

}  // namespace

size_t placePins(Pieces& out, const VoxelField& field, const GridCells& cells,
                 const std::vector<CellSet>& sets, const PiecesOptions& options, double minCosine) {
    size_t short_ = 0;
    const auto faces = gluedFaces(out, field, cells, sets);
    auto facesOf = [&](uint32_t a, uint32_t b) -> const PairFaces& {
        return faces.at({std::min(a, b), std::max(a, b)});
    };
    for (const auto& [a, b] : out.plan.glued) {
        const uint32_t lo = std::min(a, b), hi = std::max(a, b);
        if (int(addPins(out, lo, hi, pinsOnFace(facesOf(a, b), lo, hi, field, options.pins))) <
            options.pins.perPair)
            ++short_;
    }
    // Glued on: the pins stand on the host along the direction the piece goes on along, so its
    // sockets slide over them as it is pushed on.
    for (const auto& [host, piece] : out.plan.gluedOn) {
        const Vec3d d = gridDirection(out.plan.holeOfPiece[piece], out.frameToGridMm);
        if (int(addPins(out, host, piece,
                        pinsOnFace(facesOf(host, piece), host, piece, field, options.pins, &d, minCosine))) <
            options.pins.perPair)
            ++short_;
    }
    return short_;
}

double pinSignedDistanceMm(const AlignmentPin& pin, double clearanceMm, const Vec3d& p) {
    const Vec3d q = sub(p, pin.centerGridMm);
    const double along = dot(q, pin.axisGrid);
    const double radial = norm(sub(q, scale(pin.axisGrid, along)));
    // The pin: from inside its own piece (a pin length back) to its tip; the socket: from the face
    // (a little before, so the face is open) to past the tip.
    const double r = pin.isSocket ? pin.radiusMm + clearanceMm : pin.radiusMm;
    const double from = pin.isSocket ? -0.5 : -pin.lengthMm;
    const double to = pin.isSocket ? pin.lengthMm + kSocketExtraDepthMm : pin.lengthMm;
    const double dr = radial - r, da = std::abs(along - 0.5 * (from + to)) - 0.5 * (to - from);
    return std::hypot(std::max(dr, 0.0), std::max(da, 0.0)) + std::min(std::max(dr, da), 0.0);
}

Box3d pinBoundsMm(const AlignmentPin& pin, double clearanceMm) {
    const double r = pin.radiusMm + clearanceMm;
    Box3d b;
    for (double t : {-pin.lengthMm - 1.0, pin.lengthMm + kSocketExtraDepthMm + 1.0}) {
        const Vec3d p = madd(pin.centerGridMm, t, pin.axisGrid);
        b.expand(sub(p, {r, r, r}));
        b.expand(add(p, {r, r, r}));
    }
    return b;
}

}  // namespace zomefab::pieces::detail
