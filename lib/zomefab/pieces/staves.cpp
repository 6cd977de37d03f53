// SPDX-License-Identifier: GPL-3.0-or-later
// Staves where three tunnels cross at one point (detail/staves.h): cut, told apart, held and lifted.
#include "zomefab/pieces/detail/staves.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/splits.h"
#include "zomefab/zome/zome_system.h"

namespace zomefab::pieces::detail {

std::array<Vec3d, 4> staveLifts(int axis, bool isTurned) {
    Vec3d u{0, 0, 0}, v{0, 0, 0};
    u[size_t(axis + 1) % 3] = 1.0, v[size_t(axis + 2) % 3] = 1.0;
    if (isTurned) {
        const double h = std::sqrt(0.5);
        const Vec3d du = scale(add(u, v), h), dv = scale(sub(v, u), h);
        u = du, v = dv;
    }
    return {u, scale(u, -1.0), v, scale(v, -1.0)};
}

namespace {

/// How many of the four staves of lining @p p (its slots @p slots, its prism @p prism), cut square
/// to the grid or turned (@p isTurned), would lie under a wall too thin for a ball: each inside
/// voxel counted with the stave whose lift it lies farthest along from the axis.
size_t thinStaveCount(const VoxelField& field, const std::vector<size_t>& slots, uint32_t p,
                      const TunnelPrism& prism, bool isTurned, double thinGapMm) {
    const std::array<Vec3d, 4> lifts = staveLifts(prism.axis, isTurned);
    const Vec3d c = prism.axisPointMm();
    std::array<std::vector<Vec3d>, 4> sectors;
    for (size_t s : slots) {
        if (!field.isInside(s)) continue;
        const Vec3d x = field.world(field.coordOf(s)), r = sub(x, c);
        size_t best = 0;
        for (size_t k = 1; k < 4; ++k)
            if (dot(r, lifts[k]) > dot(r, lifts[best])) best = k;
        sectors[best].push_back(x);
    }
    size_t thin = 0;
    for (size_t k = 0; k < 4; ++k) {
        Stave st;
        st.liftGrid = lifts[k];
        thin += staveUnderThinWall(st, p, sectors[k], field, thinGapMm) ? 1 : 0;
    }
    return thin;
}

}  // namespace

bool isMouthRingExtent(const TunnelPrism& prism, double loMm, double hiMm, double voxelMm, double wallMm,
                       double thinGapMm) {
    const bool isAtLo = loMm <= prism.loMm + 2.0 * voxelMm, isAtHi = hiMm >= prism.hiMm - 2.0 * voxelMm;
    if (!isAtLo && !isAtHi) return false;
    if (hiMm - loMm <= kMouthRingWalls * wallMm) return true;
    if (prism.crossingsMm.empty()) return false;
    const auto& [at, radius] = isAtLo ? prism.crossingsMm.front() : prism.crossingsMm.back();
    const bool isBefore = isAtLo ? hiMm < at : loMm > at;
    const double faceToAxisMm = isAtLo ? at - prism.loMm : prism.hiMm - at;
    return isBefore && faceToAxisMm - radius - 2.0 * wallMm < thinGapMm;
}

size_t cutStaves(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field, double wallMm,
                 double thinGapMm, double minVolumeMm3) {
    std::vector<std::vector<size_t>> slots = slotsOfPieces(field, pieces.size());
    size_t cuts = 0;
    const double voxelMm3 = field.voxelMm * field.voxelMm * field.voxelMm;
    // Where a cut would leave less than minVolumeMm3 on one side (a corner bit a crossing leaves of
    // a lining, cut off by a ring's seam: a sliver no peg reaches), that side stays with the rest.
    auto isWorthCutting = [&](uint32_t p, const Vec3d& normal, double offsetMm) {
        size_t above = 0, inside = 0;
        for (size_t s : slots[p]) {
            if (!field.isInside(s)) continue;
            ++inside;
            above += dot(normal, field.world(field.coordOf(s))) > offsetMm ? 1 : 0;
        }
        return double(std::min(above, inside - above)) * voxelMm3 >= minVolumeMm3;
    };
    // Returns the new piece, or p where the cut is not made. Equal rings of a segment are never slivers.
    auto split = [&](uint32_t p, const Vec3d& normal, double offsetMm, bool isEqualPart = false) {
        if (!isEqualPart && !isWorthCutting(p, normal, offsetMm)) return p;
        slots.emplace_back();
        std::vector<size_t> newSlots;
        const uint32_t q = splitPiece(pieces, sets, field, p, {normal, offsetMm}, &slots[p], &newSlots);
        slots[q] = std::move(newSlots);
        ++cuts;
        return q;
    };
    const size_t count = pieces.size();
    for (uint32_t p = 0; p < count; ++p) {
        const TunnelPrism* prism = sets[p].isLining ? ownPrism(sets[p]) : nullptr;
        if (!prism || !prism->isStaved) continue;
        const int a = prism->axis;
        Vec3d axis{0, 0, 0};
        axis[size_t(a)] = 1.0;
        const double splitAt = prism->splitMm();  // each side slides out of its own mouth
        // Cut where tunnels cross it (three round tunnels of one size leave corner bits there at
        // most) and where it is split: segments, each between crossings or a crossing and a mouth.
        std::vector<double> planes{splitAt};
        for (const auto& [t, r] : prism->crossingsMm) planes.push_back(t);
        if (const auto [lo, hi] = extentAlong(field, slots[p], a);
            isMouthRingExtent(*prism, lo, hi, field.voxelMm, wallMm, thinGapMm))
            planes.clear();  // a lining from mouth to mouth as short as a mouth ring stays whole
        std::sort(planes.begin(), planes.end());
        std::vector<uint32_t> segments{p};
        for (double t : planes)
            if (const auto [lo, hi] = extentAlong(field, slots[segments.back()], a); lo < t && hi > t)
                if (const uint32_t q = split(segments.back(), axis, t); q != segments.back())
                    segments.push_back(q);
        std::vector<uint32_t> rings;
        for (uint32_t g : segments) {
            const auto [lo, hi] = extentAlong(field, slots[g], a);
            if (!(lo <= hi)) continue;
            if (isMouthRingExtent(*prism, lo, hi, field.voxelMm, wallMm, thinGapMm)) {
                sets[g].isMouthRing = true;
                sets[g].ringDepthMm = hi - lo;
                continue;
            }
            sets[g].isStaveTurned = thinStaveCount(field, slots[g], g, *prism, true, thinGapMm) <
                                    thinStaveCount(field, slots[g], g, *prism, false, thinGapMm);
            const bool isHigh = lo + hi > 2.0 * splitAt;  // slides out of the mouth at the high end
            const int count = int(std::ceil((hi - lo) / kStaveRingMm));
            std::vector<uint32_t> along{g};
            for (int k = 1; k < count; ++k)
                along.push_back(split(along.back(), axis, lo + (hi - lo) * k / count, true));
            for (size_t k = 0; k < along.size(); ++k) {
                // along[k] holds [lo + k·len, lo + (k+1)·len]: its far end from its mouth.
                const double len = (hi - lo) / double(along.size());
                sets[along[k]].ringDepthMm =
                    isHigh ? prism->hiMm - (lo + len * double(k)) : lo + len * double(k + 1) - prism->loMm;
                rings.push_back(along[k]);
            }
        }
        // The side staves across su, then top and bottom across sv (square to the grid or turned).
        const double off = std::sqrt(0.5) * prism->coreRadiusMm;
        for (uint32_t r : rings) {
            const std::array<Vec3d, 4> lifts = staveLifts(a, sets[r].isStaveTurned);
            const Vec3d su = lifts[0], sv = lifts[2], c = prism->axisPointMm();
            const double cu = dot(su, c), cv = dot(sv, c);
            split(r, su, cu + off);
            split(r, scale(su, -1.0), off - cu);
            split(r, sv, cv);
        }
    }
    return cuts;
}

bool staveUnderThinWall(const Stave& stave, uint32_t p, const std::vector<Vec3d>& voxelsMm,
                        const VoxelField& field, double thinGapMm) {
    size_t samples = 0, thin = 0;
    for (const Vec3d& x : voxelsMm) {
        // Its wall's back, where the hollow begins (not a rim in the face's shell, beside other pieces).
        const size_t next = field.slotAt(madd(x, field.voxelMm, stave.liftGrid));
        if (next != SIZE_MAX && field.isInside(next)) continue;
        ++samples;
        // Across the hollow, voxel by voxel, to another piece's material.
        for (double t = 2.0 * field.voxelMm; t <= thinGapMm + 2.0 * field.voxelMm; t += field.voxelMm) {
            const size_t s = field.slotAt(madd(x, t, stave.liftGrid));
            if (s == SIZE_MAX || !field.isInside(s) || field.owner[s] == p) continue;
            thin += t - field.voxelMm <= thinGapMm ? 1 : 0;
            break;
        }
    }
    return samples > 0 && 2 * thin > samples;
}

size_t noteUnheldStaves(Pieces& out, const std::vector<CellSet>& sets, const VoxelField& field,
                        double thinGapMm) {
    const size_t unheld = unplacedStaves(out.plan.holeOfPiece, sets);
    if (unheld == 0) return 0;
    const size_t staves = size_t(std::count_if(sets.begin(), sets.end(), isStaveSet));
    std::vector<std::vector<Vec3d>> voxels(out.pieces.size());
    for (size_t s = 0; s < field.phi.size(); ++s) {
        const uint32_t p = field.owner[s];
        if (field.isInside(s) && p < out.pieces.size() && out.plan.holeOfPiece[p] < 0 && isStaveSet(sets[p]))
            voxels[p].push_back(field.world(field.coordOf(s)));
    }
    size_t thin = 0;
    for (uint32_t p = 0; p < out.pieces.size(); ++p)
        if (const std::optional<Stave> st = staveOf(sets[p], voxels[p]))
            thin += staveUnderThinWall(*st, p, voxels[p], field, thinGapMm) ? 1 : 0;
    std::string under;
    if (thin > 0)
        under = ", " + std::to_string(thin) +
                " of them under a wall too thin for a ball behind them (another " + "wall less than " +
                formatNumbers("%.1f", thinGapMm) + " mm of hollow away)";
    out.plan.problems.insert(
        out.plan.problems.begin(),
        "three tunnels cross at one point, and " + std::to_string(unheld) + " of the " +
            std::to_string(staves) + " staves lining them have no peg to hold them" + under +
            ": no ball's hole behind the wall points at the stave within a tenon's reach along a direction "
            "it can be lifted along (square to its seams, not back toward the staves deeper in), or another "
            "stave's tenon took it, and no stave of its ring that a peg holds shares a seam with it to glue "
            "it onto; partitioning again leaves the same tunnels and frame (docs/mounting.md, \"Three "
            "tunnels through one point\")");
    out.crossingTunnelPieces = unheld;
    return unheld;
}

bool isStavedLining(const CellSet& set) {
    const TunnelPrism* prism = set.isLining ? ownPrism(set) : nullptr;
    return prism && prism->isStaved;
}

bool isStaveSet(const CellSet& set) { return !set.isMouthRing && isStavedLining(set); }

bool isStaveDirection(const Stave& stave, const Vec3d& d) {
    // 2°: over a lift of 8 mm, a quarter of a millimetre; over 40 mm (a stem to a ball deep in),
    // 1.4 mm, within the prism's two voxels past the wall.
    const double sinSlack = std::sin(2.0 * kPi / 180.0);
    const Vec3d across = cross(stave.slideGrid, stave.liftGrid);  // round the axis
    return dot(d, stave.liftGrid) <= -std::cos(kStaveLeanDeg * kPi / 180.0) &&
           dot(d, stave.slideGrid) >= -sinSlack && std::abs(dot(d, across)) <= sinSlack;
}

namespace {

/// The way a lining of @p prism whose voxels' centres (grid mm) have the mean @p meanMm slides out
/// along its tunnel (grid, unit): toward the mouth on its side of the tunnel's split.
Vec3d slideOutOf(const TunnelPrism& prism, const Vec3d& meanMm) {
    Vec3d way{0, 0, 0};
    way[size_t(prism.axis)] = meanMm[size_t(prism.axis)] >= prism.splitMm() ? 1.0 : -1.0;
    return way;
}

Vec3d meanOf(const std::vector<Vec3d>& pointsMm) {
    Vec3d mean{0, 0, 0};
    for (const Vec3d& x : pointsMm) mean = add(mean, x);
    return scale(mean, 1.0 / double(pointsMm.size()));
}

}  // namespace

std::optional<Stave> staveOf(const CellSet& set, const std::vector<Vec3d>& voxelsMm) {
    if (!isStaveSet(set) || voxelsMm.empty()) return std::nullopt;
    const TunnelPrism* prism = ownPrism(set);
    const int a = prism->axis;
    const std::array<Vec3d, 4> lifts = staveLifts(a, set.isStaveTurned);
    const Vec3d mean = meanOf(voxelsMm);
    const Vec3d r = sub(mean, prism->axisPointMm());
    const double du = dot(r, lifts[0]), dv = dot(r, lifts[2]);
    const bool isSide = std::abs(du) >= std::abs(dv);
    const double lift = (isSide ? du : dv) >= 0 ? 1.0 : -1.0;
    Stave st;
    st.slideGrid = slideOutOf(*prism, mean);
    const double slide = st.slideGrid[size_t(a)];
    st.liftGrid = scale(lifts[isSide ? 0 : 2], lift);
    st.seamGrid = lifts[0];
    st.isSide = isSide;
    st.rank = {
        prism->priority, prism->centerUMm, prism->centerVMm, slide, -set.ringDepthMm, isSide ? 0 : 1, lift};
    return st;
}

std::optional<Vec3d> mouthRingSlide(const CellSet& set, const std::vector<Vec3d>& voxelsMm) {
    if (!set.isMouthRing || !isStavedLining(set) || voxelsMm.empty()) return std::nullopt;
    return slideOutOf(*ownPrism(set), meanOf(voxelsMm));
}

void setStaveLifts(Pieces& out, const std::vector<CellSet>& sets, const VoxelField& field,
                   const Transform4d& frameToGridMm, double frameDMinMm) {
    std::vector<int> stepOf(out.pieces.size(), -1);
    std::vector<Vec3d> wallOut(out.pieces.size(), Vec3d{0, 0, 0});  // across the wall, out of the tunnel
    for (size_t s = 0; s < out.plan.steps.size(); ++s) {
        const mount::MountStep& step = out.plan.steps[s];
        if (!step.hasTwoLegs()) continue;
        const uint32_t p = step.pieces[0];
        const Vec3d in = gridDirection(step.hole, frameToGridMm);
        const TunnelPrism* prism = p < sets.size() ? ownPrism(sets[p]) : nullptr;
        if (!prism) continue;  // every step of two legs is a stave's, which has its prism
        stepOf[p] = int(s);
        const std::array<Vec3d, 4> lifts = staveLifts(prism->axis, sets[p].isStaveTurned);
        wallOut[p] = *std::max_element(lifts.begin(), lifts.end(), [&](const Vec3d& x, const Vec3d& y) {
            return dot(x, in) > dot(y, in);  // the most against the direction
        });
    }
    std::vector<double> nearest(out.pieces.size(), std::numeric_limits<double>::infinity());
    for (size_t s = 0; s < field.phi.size(); ++s) {
        const uint32_t p = field.owner[s];
        if (!field.isInside(s) || p >= out.pieces.size() || stepOf[p] < 0) continue;
        nearest[p] = std::min(nearest[p], dot(wallOut[p], field.world(field.coordOf(s))));
    }
    for (uint32_t p = 0; p < out.pieces.size(); ++p) {
        if (stepOf[p] < 0) continue;
        mount::MountStep& step = out.plan.steps[size_t(stepOf[p])];
        // Lifted by L along the direction, a point rises L·cos(lean) across the wall.
        const double rise = -dot(gridDirection(step.hole, frameToGridMm), wallOut[p]);
        const double surface = nearest[p] - 0.5 * field.voxelMm;
        for (const Tenon& t : out.pieces[p].tenons) {
            const double depth = dot(wallOut[p], t.pointAt(t.pegTipMm)) - surface;
            step.liftMm = std::max(step.liftMm, (depth - frameDMinMm + 2.0) / rise);
        }
    }
}

MountBody staveBody(uint32_t p, const PlannerInput& input, const Transform4d& frameToGridMm, int maxPerPiece,
                    int* hole) {
    MountBody body;
    body.pieces = {p};
    body.addVoxelsOf(input.pieces[p]);
    body.options = rankedOptions(input.candidatesByHole[p], size_t(std::max(1, maxPerPiece)));
    *hole = -1;
    for (const DirectionOption& o : body.options)
        if (o.tenons > 0 && isStaveDirection(*input.staves[p], gridDirection(o.hole, frameToGridMm))) {
            *hole = o.hole;
            break;
        }
    return body;
}

void addStaveSteps(mount::InstallationPlan& plan, const PlannerInput& input, const StaveOrder& order,
                   const Transform4d& frameToGridMm, const std::vector<std::pair<size_t, size_t>>& slots) {
    std::vector<std::optional<mount::MountStep>> steps(order.pieces.size());  // per stave
    const Transform4d gridToFrame = affineInverse(frameToGridMm);
    for (size_t k = 0; k < order.pieces.size(); ++k) {
        const uint32_t p = order.pieces[k];
        if (order.holes[k] < 0) {
            plan.problems.push_back("piece " + std::to_string(p) +
                                    ", a stave lining a tunnel: no ball's hole behind its wall points at it "
                                    "within a tenon's reach, and it shares no seam with a stave of its ring "
                                    "that one holds to be glued onto");
            continue;
        }
        if (k < order.hosts.size() && !order.hosts[k].empty()) {
            // Glued in place: slid straight along its tunnel, along the seams of its hosts.
            steps[k] = mount::MountStep{{p}, order.holes[k]};
            for (uint32_t host : order.hosts[k]) plan.gluedOn.push_back({host, p});
            continue;
        }
        const Vec3d slide = normalized(applyLinear(gridToFrame, input.staves[p]->slideGrid));
        steps[k] = mount::MountStep{{p}, order.holes[k], slide, kStaveLiftMm};
    }
    std::sort(plan.gluedOn.begin(), plan.gluedOn.end());
    if (!plan.isBuildable()) return;
    std::vector<std::pair<size_t, size_t>> at = slots;  // (stave, steps of the rest before it)
    if (at.empty())
        for (size_t k = 0; k < order.pieces.size(); ++k) at.push_back({k, 0});
    std::vector<mount::MountStep> merged;
    size_t next = 0;  // the rest's next step
    for (const auto& [k, before] : at) {
        for (; next < before && next < plan.steps.size(); ++next)
            merged.push_back(std::move(plan.steps[next]));
        if (steps[k]) merged.push_back(std::move(*steps[k]));
    }
    for (; next < plan.steps.size(); ++next) merged.push_back(std::move(plan.steps[next]));
    plan.steps = std::move(merged);
}

mount::InstallationPlan unheldStavesPlan(const PlannerInput& input, const StaveOrder& order,
                                         const Transform4d& frameToGridMm) {
    mount::InstallationPlan plan;
    plan.holeOfPiece.assign(input.pieces.size(), -1);
    plan.groupOf.resize(input.pieces.size());
    for (uint32_t p = 0; p < input.pieces.size(); ++p) plan.groupOf[p] = p;
    for (size_t k = 0; k < order.pieces.size(); ++k) plan.holeOfPiece[order.pieces[k]] = order.holes[k];
    addStaveSteps(plan, input, order, frameToGridMm);
    return plan;
}

size_t unplacedStaves(const std::vector<int>& holeOfPiece, const std::vector<CellSet>& sets) {
    size_t unheld = 0;
    for (size_t p = 0; p < sets.size() && p < holeOfPiece.size(); ++p)
        unheld += holeOfPiece[p] < 0 && isStaveSet(sets[p]) ? 1 : 0;
    return unheld;
}

std::vector<TunnelKey> unheldTunnels(const std::vector<int>& holeOfPiece, const std::vector<CellSet>& sets) {
    std::vector<TunnelKey> out;
    for (size_t p = 0; p < sets.size() && p < holeOfPiece.size(); ++p) {
        if (holeOfPiece[p] >= 0 || !isStaveSet(sets[p])) continue;
        const TunnelPrism* prism = ownPrism(sets[p]);
        const bool isListed = std::any_of(out.begin(), out.end(), [&](const TunnelKey& k) {
            return isTunnelOf(k, *prism, 0.5 * prism->voxelMm);
        });
        if (!isListed) out.push_back(tunnelKeyOf(*prism));
    }
    return out;
}

bool isGluedOn(const mount::InstallationPlan& plan, uint32_t p) {
    return std::any_of(plan.gluedOn.begin(), plan.gluedOn.end(),
                       [&](const auto& e) { return e.second == p; });
}

size_t peglessStaves(const mount::InstallationPlan& plan, const std::vector<CellSet>& sets) {
    size_t count = 0;
    for (uint32_t p = 0; p < sets.size() && p < plan.holeOfPiece.size(); ++p)
        count += isStaveSet(sets[p]) && (plan.holeOfPiece[p] < 0 || isGluedOn(plan, p)) ? 1 : 0;
    return count;
}

}  // namespace zomefab::pieces::detail
