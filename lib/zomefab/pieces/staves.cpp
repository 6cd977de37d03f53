// SPDX-License-Identifier: GPL-3.0-or-later
// Staves where three tunnels cross at one point (detail/staves.h): cut, told apart, held and lifted.
#include "zomefab/pieces/detail/staves.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/splits.h"

namespace zomefab::pieces::detail {

size_t cutStaves(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field,
                 double maxMouthRingMm) {
    std::vector<std::vector<size_t>> slots = slotsOfPieces(field, pieces.size());
    size_t cuts = 0;
    auto split = [&](uint32_t p, const Vec3d& normal, double offsetMm) {
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
        Vec3d axis{0, 0, 0}, u{0, 0, 0}, v{0, 0, 0};
        axis[size_t(a)] = 1.0, u[size_t(a + 1) % 3] = 1.0, v[size_t(a + 2) % 3] = 1.0;
        const double middle = 0.5 * (prism->loMm + prism->hiMm);
        if (const auto [lo, hi] = extentAlong(field, slots[p], a);
            hi - lo <= maxMouthRingMm &&
            (lo <= prism->loMm + 2.0 * field.voxelMm || hi >= prism->hiMm - 2.0 * field.voxelMm)) {
            sets[p].isMouthRing = true;
            sets[p].ringDepthMm = hi - lo;
            continue;
        }
        std::vector<uint32_t> halves{p};
        if (const auto [lo, hi] = extentAlong(field, slots[p], a); lo < middle && hi > middle)
            halves.push_back(split(p, axis, middle));
        std::vector<uint32_t> rings;
        for (uint32_t h : halves) {
            const auto [lo, hi] = extentAlong(field, slots[h], a);
            if (!(lo <= hi)) continue;
            const bool isHigh = lo + hi > 2.0 * middle;  // slides out of the mouth at the high end
            const int count = int(std::ceil((hi - lo) / kStaveRingMm));
            std::vector<uint32_t> along{h};
            for (int k = 1; k < count; ++k)
                along.push_back(split(along.back(), axis, lo + (hi - lo) * k / count));
            for (size_t k = 0; k < along.size(); ++k) {
                // along[k] holds [lo + k·len, lo + (k+1)·len]: its far end from its mouth.
                const double len = (hi - lo) / double(along.size());
                sets[along[k]].ringDepthMm =
                    isHigh ? prism->hiMm - (lo + len * double(k)) : lo + len * double(k + 1) - prism->loMm;
                rings.push_back(along[k]);
            }
        }
        const double off = std::sqrt(0.5) * prism->coreRadiusMm;
        for (uint32_t r : rings) {
            split(r, u, prism->centerUMm + off);
            split(r, scale(u, -1.0), off - prism->centerUMm);
            split(r, v, prism->centerVMm);
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
    const size_t unheld = unheldStaves(out.plan.holeOfPiece, sets);
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
            "stave's tenon took it; partitioning again leaves the same tunnels and frame (docs/mounting.md, "
            "\"Three tunnels through one point\")");
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
    return dot(d, stave.liftGrid) <= -std::cos(35.0 * kPi / 180.0) && dot(d, stave.slideGrid) >= -sinSlack &&
           std::abs(dot(d, across)) <= sinSlack;
}

std::optional<Stave> staveOf(const CellSet& set, const std::vector<Vec3d>& voxelsMm) {
    if (!isStaveSet(set) || voxelsMm.empty()) return std::nullopt;
    const TunnelPrism* prism = ownPrism(set);
    const int a = prism->axis;
    const size_t u = size_t(a + 1) % 3, v = size_t(a + 2) % 3;
    Vec3d mean{0, 0, 0};
    for (const Vec3d& x : voxelsMm) mean = add(mean, x);
    mean = scale(mean, 1.0 / double(voxelsMm.size()));
    const double du = mean[u] - prism->centerUMm, dv = mean[v] - prism->centerVMm;
    const double slide = 2.0 * mean[size_t(a)] >= prism->loMm + prism->hiMm ? 1.0 : -1.0;
    const bool isSide = std::abs(du) >= std::abs(dv);
    const double lift = (isSide ? du : dv) >= 0 ? 1.0 : -1.0;
    Stave st;
    st.slideGrid[size_t(a)] = slide;
    st.liftGrid[isSide ? u : v] = lift;
    st.seamGrid[u] = 1.0;
    st.isSide = isSide;
    st.rank = {a, prism->centerUMm, prism->centerVMm, slide, -set.ringDepthMm, isSide ? 0 : 1, lift};
    return st;
}

void setStaveLifts(Pieces& out, const VoxelField& field, const Transform4d& frameToGridMm,
                   double frameDMinMm) {
    std::vector<int> stepOf(out.pieces.size(), -1);
    std::vector<Vec3d> wallOut(out.pieces.size(), Vec3d{0, 0, 0});  // across the wall, out of the tunnel
    for (size_t s = 0; s < out.plan.steps.size(); ++s) {
        const mount::MountStep& step = out.plan.steps[s];
        if (!step.hasTwoLegs()) continue;
        const uint32_t p = step.pieces[0];
        stepOf[p] = int(s);
        const Vec3d in = gridDirection(step.hole, frameToGridMm);
        const Vec3d slide = normalized(applyLinear(frameToGridMm, step.slide));
        size_t best = 0;
        for (size_t k = 1; k < 3; ++k)
            if (std::abs(in[k]) * (1.0 - std::abs(slide[k])) >
                std::abs(in[best]) * (1.0 - std::abs(slide[best])))
                best = k;
        wallOut[p][best] = in[best] > 0 ? -1.0 : 1.0;
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

void addStaveSteps(mount::InstallationPlan& plan, const PlannerInput& input,
                   const std::vector<uint32_t>& staves, const std::vector<int>& holes,
                   const Transform4d& frameToGridMm) {
    std::vector<mount::MountStep> steps;
    const Transform4d gridToFrame = affineInverse(frameToGridMm);
    for (size_t k = 0; k < staves.size(); ++k) {
        const uint32_t p = staves[k];
        if (holes[k] < 0) {
            plan.problems.push_back("piece " + std::to_string(p) +
                                    ", a stave lining a tunnel: no ball's hole behind its wall points at it "
                                    "within a tenon's reach");
            continue;
        }
        const Vec3d slide = normalized(applyLinear(gridToFrame, input.staves[p]->slideGrid));
        steps.push_back({{p}, holes[k], slide, kStaveLiftMm});
    }
    if (plan.isBuildable()) plan.steps.insert(plan.steps.begin(), steps.begin(), steps.end());
}

mount::InstallationPlan unheldStavesPlan(const PlannerInput& input, const std::vector<uint32_t>& staves,
                                         const std::vector<int>& holes, const Transform4d& frameToGridMm) {
    mount::InstallationPlan plan;
    plan.holeOfPiece.assign(input.pieces.size(), -1);
    plan.groupOf.resize(input.pieces.size());
    for (uint32_t p = 0; p < input.pieces.size(); ++p) plan.groupOf[p] = p;
    for (size_t k = 0; k < staves.size(); ++k) plan.holeOfPiece[staves[k]] = holes[k];
    addStaveSteps(plan, input, staves, holes, frameToGridMm);
    return plan;
}

size_t unheldStaves(const std::vector<int>& holeOfPiece, const std::vector<CellSet>& sets) {
    size_t unheld = 0;
    for (size_t p = 0; p < sets.size() && p < holeOfPiece.size(); ++p)
        unheld += holeOfPiece[p] < 0 && isStaveSet(sets[p]) ? 1 : 0;
    return unheld;
}

}  // namespace zomefab::pieces::detail
