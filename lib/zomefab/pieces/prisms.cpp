// SPDX-License-Identifier: GPL-3.0-or-later
// The linings of two tunnels that cross, carved along their prisms (detail/prisms.h).
#include "zomefab/pieces/detail/prisms.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/merges.h"
#include "zomefab/pieces/detail/splits.h"
#include "zomefab/pieces/detail/staves.h"

namespace zomefab::pieces::detail {

namespace {

constexpr double kFarMm = 1e9;  // the core distance off a prism's raster

/// Per grid axis, which prism's lines each column lies on: the nearest core of that axis whose
/// prism's radius reaches the column (ties: the lowest index), over the field's columns.
struct PrismLookup {
    std::array<AxisShadow, 3> columns;           // the field's columns per axis (isHit unused)
    std::array<std::vector<uint32_t>, 3> prism;  // per column: a prism index or kNone

    uint32_t at(int axis, const Coord& ijk) const {
        const AxisShadow& s = columns[size_t(axis)];
        const auto [u, v] = s.columnOf(ijk);
        const size_t k = s.slotOf(u, v);
        return k == SIZE_MAX ? kNone : prism[size_t(axis)][k];
    }
};

PrismLookup prismLookup(const VoxelField& field, const std::vector<TunnelPrism>& prisms) {
    PrismLookup out;
    out.columns = emptyShadowsOf(field);
    std::array<std::vector<float>, 3> best;
    for (int a = 0; a < 3; ++a) {
        const size_t n = out.columns[size_t(a)].isHit.size();
        out.prism[size_t(a)].assign(n, kNone);
        best[size_t(a)].assign(n, std::numeric_limits<float>::infinity());
    }
    for (uint32_t k = 0; k < prisms.size(); ++k) {
        const TunnelPrism& p = prisms[k];
        const AxisShadow& s = out.columns[size_t(p.axis)];
        for (int a = 0; a < p.sizeU; ++a)
            for (int b = 0; b < p.sizeV; ++b) {
                const float d = p.coreDistanceMm[size_t(a) * size_t(p.sizeV) + size_t(b)];
                const size_t slot = s.slotOf(p.loU + a, p.loV + b);
                if (d > p.radiusMm || slot == SIZE_MAX || !(d < best[size_t(p.axis)][slot])) continue;
                best[size_t(p.axis)][slot] = d;
                out.prism[size_t(p.axis)][slot] = k;
            }
    }
    return out;
}

/// Whether three of @p cores, one per axis, cross each other (then all three meet at one point).
bool hasTripleCrossing(const std::vector<TunnelCore>& cores) {
    for (size_t i = 0; i < cores.size(); ++i)
        for (size_t j = i + 1; j < cores.size(); ++j) {
            if (!coresCross(cores[i], cores[j])) continue;
            for (size_t k = j + 1; k < cores.size(); ++k)
                if (coresCross(cores[i], cores[k]) && coresCross(cores[j], cores[k])) return true;
        }
    return false;
}

/// The band's owners after a carve: a band slot in a prism (or owned by a dropped piece, kNone)
/// takes the owner of a neighbour in the same prism (or, outside every prism, of a piece that is
/// no lining), layer by layer; what is left takes any neighbour's.
void ownBand(VoxelField& field, const std::vector<uint32_t>& prismOf, const std::vector<uint8_t>& isLining) {
    auto spread = [&](bool sameClass) {
        for (int layer = 0; layer < 8; ++layer) {
            std::vector<std::pair<size_t, uint32_t>> offers;
            auto offer = [&](size_t from, size_t to) {
                if (field.owner[from] == kNone || field.owner[to] != kNone || field.isInside(to)) return;
                if (sameClass &&
                    (prismOf[from] != prismOf[to] || (prismOf[to] == kNone && isLining[field.owner[from]])))
                    return;
                offers.push_back({to, field.owner[from]});
            };
            forEachForwardPair(field, [&](size_t a, size_t b) {
                offer(a, b);
                offer(b, a);
            });
            if (offers.empty()) return;
            // The lowest piece id on ties, whatever the visiting order.
            std::sort(offers.begin(), offers.end());
            for (size_t i = 0; i < offers.size(); ++i)
                if (i == 0 || offers[i].first != offers[i - 1].first)
                    field.owner[offers[i].first] = offers[i].second;
        }
    };
    spread(true);
    spread(false);
}

/// Drops the pieces no inside voxel belongs to and numbers the rest in order (ids, cell sets,
/// voxel owners; band voxels of a dropped piece become unowned); every piece's shell volume counted
/// anew. Returns how many were dropped.
size_t dropEmptyPieces(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field) {
    std::vector<size_t> inside(pieces.size(), 0);
    for (size_t s = 0; s < field.owner.size(); ++s)
        if (field.isInside(s) && field.owner[s] < pieces.size()) ++inside[field.owner[s]];
    const double voxelVolume = field.voxelMm * field.voxelMm * field.voxelMm;
    std::vector<uint32_t> newId(pieces.size(), kNone);
    std::vector<Piece> keptPieces;
    std::vector<CellSet> keptSets;
    for (size_t p = 0; p < pieces.size(); ++p) {
        if (inside[p] == 0) continue;
        newId[p] = uint32_t(keptPieces.size());
        keptPieces.push_back(std::move(pieces[p]));
        keptPieces.back().id = newId[p];
        keptPieces.back().shellVolumeMm3 = double(inside[p]) * voxelVolume;
        keptSets.push_back(std::move(sets[p]));
    }
    const size_t dropped = pieces.size() - keptPieces.size();
    pieces = std::move(keptPieces);
    sets = std::move(keptSets);
    for (uint32_t& o : field.owner)
        if (o != kNone) o = o < newId.size() ? newId[o] : kNone;
    return dropped;
}

}  // namespace

double TunnelPrism::columnDistanceMm(int u, int v) const {
    const int a = u - loU, b = v - loV;
    if (a < 0 || b < 0 || a >= sizeU || b >= sizeV) return kFarMm;
    return coreDistanceMm[size_t(a) * size_t(sizeV) + size_t(b)];
}

bool TunnelPrism::contains(const Coord& ijk) const {
    const double t = originMm[size_t(axis)] + voxelMm * ijk[axis];
    return t >= loMm && t <= hiMm && columnDistanceMm(ijk[(axis + 1) % 3], ijk[(axis + 2) % 3]) <= radiusMm;
}

double TunnelPrism::signedDistanceMm(const Vec3d& x) const {
    const size_t u = size_t(axis + 1) % 3, v = size_t(axis + 2) % 3;
    const double fu = (x[u] - originMm[u]) / voxelMm, fv = (x[v] - originMm[v]) / voxelMm;
    const int iu = int(std::floor(fu)), iv = int(std::floor(fv));
    const double su = fu - iu, sv = fv - iv;
    const double d =
        (1 - su) * (1 - sv) * columnDistanceMm(iu, iv) + su * (1 - sv) * columnDistanceMm(iu + 1, iv) +
        (1 - su) * sv * columnDistanceMm(iu, iv + 1) + su * sv * columnDistanceMm(iu + 1, iv + 1);
    const double t = x[size_t(axis)];
    return std::max({d - radiusMm, loMm - t, t - hiMm});
}

double TunnelPrism::splitMm() const {
    const double middle = 0.5 * (loMm + hiMm);
    double best = middle, far = std::numeric_limits<double>::infinity();
    for (const auto& [t, r] : crossingsMm)
        if (std::abs(t - middle) < far - 1e-9) far = std::abs(t - middle), best = t;
    return best;
}

Vec3d TunnelPrism::axisPointMm() const {
    Vec3d c{0, 0, 0};
    c[size_t(axis + 1) % 3] = centerUMm, c[size_t(axis + 2) % 3] = centerVMm;
    return c;
}

void markCrossings(std::vector<TunnelPrism>& prisms) {
    for (TunnelPrism& p : prisms) {
        std::vector<std::pair<double, double>> list;
        for (const TunnelPrism& q : prisms) {
            if (q.axis == p.axis || !q.isStaved) continue;
            const int c = 3 - p.axis - q.axis;  // the third axis
            const Vec3d pc = p.axisPointMm(), qc = q.axisPointMm();
            const double t = qc[size_t(p.axis)], b = pc[size_t(q.axis)];
            if (std::abs(pc[size_t(c)] - qc[size_t(c)]) <= p.coreRadiusMm && t >= p.loMm && t <= p.hiMm &&
                b >= q.loMm && b <= q.hiMm)
                list.push_back({t, q.coreRadiusMm});
        }
        std::sort(list.begin(), list.end());
        p.crossingsMm.clear();
        for (const auto& [t, r] : list)  // the tunnels of both other axes cross at one point
            if (!p.crossingsMm.empty() && t - p.crossingsMm.back().first <= p.voxelMm)
                p.crossingsMm.back().second = std::max(p.crossingsMm.back().second, r);
            else
                p.crossingsMm.push_back({t, r});
    }
}

const TunnelPrism* ownPrism(const CellSet& set) {
    for (const CellSet::PrismBound& b : set.prisms)
        if (b.isInside) return b.prism.get();
    return nullptr;
}

std::pair<double, double> extentAlong(const VoxelField& field, const std::vector<size_t>& slots, int a) {
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (size_t s : slots)
        if (field.isInside(s)) {
            const double t = field.world(field.coordOf(s))[size_t(a)];
            lo = std::min(lo, t), hi = std::max(hi, t);
        }
    return {lo, hi};
}

TunnelPrism tunnelPrism(const TunnelCore& core, const VoxelField& field, double radiusMm, double loMm,
                        double hiMm) {
    TunnelPrism p;
    p.axis = core.axis;
    p.priority = core.axis;
    p.radiusMm = radiusMm, p.loMm = loMm, p.hiMm = hiMm;
    p.voxelMm = field.voxelMm, p.originMm = field.originMm;
    int minU = std::numeric_limits<int>::max(), minV = minU, maxU = std::numeric_limits<int>::min(),
        maxV = maxU;
    for (const auto& [u, v] : core.columns)
        minU = std::min(minU, u), maxU = std::max(maxU, u), minV = std::min(minV, v),
        maxV = std::max(maxV, v);
    const size_t u = size_t(core.axis + 1) % 3, v = size_t(core.axis + 2) % 3;
    p.centerUMm = field.originMm[u] + field.voxelMm * 0.5 * (minU + maxU);
    p.centerVMm = field.originMm[v] + field.voxelMm * 0.5 * (minV + maxV);
    p.coreRadiusMm = field.voxelMm * 0.25 * (maxU - minU + maxV - minV + 2);
    const int margin = int(std::ceil(radiusMm / field.voxelMm)) + 2;
    p.loU = minU - margin, p.loV = minV - margin;
    p.sizeU = maxU - minU + 1 + 2 * margin, p.sizeV = maxV - minV + 1 + 2 * margin;
    std::vector<uint8_t> isCore(size_t(p.sizeU) * size_t(p.sizeV), 0);
    auto index = [&](int u, int v) { return size_t(u - p.loU) * size_t(p.sizeV) + size_t(v - p.loV); };
    for (const auto& [u, v] : core.columns) isCore[index(u, v)] = 1;
    // The core's edge: its columns with a 4-neighbour outside it (the nearest core column of any
    // other column is one of them).
    std::vector<std::array<int, 2>> edge;
    for (const auto& [u, v] : core.columns)
        if (!isCore[index(u + 1, v)] || !isCore[index(u - 1, v)] || !isCore[index(u, v + 1)] ||
            !isCore[index(u, v - 1)])
            edge.push_back({u, v});
    p.coreDistanceMm.assign(isCore.size(), 0.0f);
    for (int a = 0; a < p.sizeU; ++a)
        for (int b = 0; b < p.sizeV; ++b) {
            const size_t k = size_t(a) * size_t(p.sizeV) + size_t(b);
            if (isCore[k]) continue;
            double best = std::numeric_limits<double>::infinity();
            for (const auto& [u, v] : edge)
                best = std::min(
                    best, double((p.loU + a - u) * (p.loU + a - u) + (p.loV + b - v) * (p.loV + b - v)));
            p.coreDistanceMm[k] = float(std::sqrt(best) * field.voxelMm);
        }
    return p;
}

bool isSameTunnel(const TunnelKey& a, const TunnelKey& b, double toleranceMm) {
    return a.axis == b.axis && std::abs(a.centerUMm - b.centerUMm) <= toleranceMm &&
           std::abs(a.centerVMm - b.centerVMm) <= toleranceMm;
}

TunnelKey tunnelKeyOf(const TunnelPrism& prism) { return {prism.axis, prism.centerUMm, prism.centerVMm}; }

bool isTunnelOf(const TunnelKey& key, const TunnelPrism& prism, double toleranceMm) {
    return isSameTunnel(key, tunnelKeyOf(prism), toleranceMm);
}

std::vector<uint32_t> prismOwners(const VoxelField& field, const std::vector<TunnelPrism>& prisms,
                                  bool isLaterFirst) {
    std::vector<uint32_t> out(field.owner.size(), kNone);
    if (prisms.empty() || field.leafOrigin.empty()) return out;
    const PrismLookup lookup = prismLookup(field, prisms);
    for (size_t s = 0; s < out.size(); ++s) {
        if (!field.isActive[s]) continue;
        const Coord ijk = field.coordOf(s);
        for (int a = 0; a < 3; ++a) {  // one prism per axis at most: parallel prisms do not overlap
            const uint32_t k = lookup.at(a, ijk);
            if (k == kNone || !prisms[k].contains(ijk)) continue;
            if (out[s] == kNone) out[s] = k;
            if (!isLaterFirst) break;
            if (prisms[k].priority > prisms[out[s]].priority) out[s] = k;
        }
    }
    return out;
}

std::vector<TunnelPrism> crossingPrisms(const VoxelField& field, double minDiameterMm, double radiusMm,
                                        double endMm, bool* isTriple, bool isStaving) {
    if (isTriple) *isTriple = false;
    const std::array<AxisShadow, 3> shadows = shadowsOf(field);
    if (shadows[0].isHit.empty()) return {};
    const std::vector<TunnelCore> cores = coresAlongAxes(shadows, field.voxelMm, minDiameterMm);
    const std::vector<uint8_t> crosses = crossingFlags(cores, nullptr);
    std::vector<TunnelCore> crossing;
    for (size_t i = 0; i < cores.size(); ++i)
        if (crosses[i]) crossing.push_back(cores[i]);
    if (crossing.empty()) return {};
    const bool isStaved = hasTripleCrossing(crossing);
    if (isStaved) {
        if (isTriple) *isTriple = true;
        if (!isStaving) return {};
        endMm = 0.0;  // staves slide out through the mouths: the rims are theirs
    }
    const double inf = std::numeric_limits<double>::infinity();
    std::vector<TunnelPrism> prisms;
    for (const TunnelCore& core : crossing) {
        prisms.push_back(tunnelPrism(core, field, radiusMm, -inf, inf));
        prisms.back().isStaved = isStaved;
    }
    // Each prism's ends: where the object's voxels on its lines end, less the mouth's own shell.
    const PrismLookup lookup = prismLookup(field, prisms);
    std::vector<double> lo(prisms.size(), inf), hi(prisms.size(), -inf);
    for (size_t s = 0; s < field.isActive.size(); ++s) {
        if (!field.isInside(s)) continue;
        const Coord ijk = field.coordOf(s);
        for (int a = 0; a < 3; ++a)
            if (const uint32_t k = lookup.at(a, ijk); k != kNone) {
                const double t = field.originMm[size_t(a)] + field.voxelMm * ijk[a];
                lo[k] = std::min(lo[k], t), hi[k] = std::max(hi[k], t);
            }
    }
    std::vector<TunnelPrism> out;
    for (size_t k = 0; k < prisms.size(); ++k) {
        prisms[k].loMm = lo[k] + endMm, prisms[k].hiMm = hi[k] - endMm;
        if (prisms[k].loMm < prisms[k].hiMm) out.push_back(std::move(prisms[k]));
    }
    return out;
}

namespace {

/// One new piece per connected part of the inside voxels a prism owns (@p prismOf), each kept
/// to its prism and out of the earlier axes' prisms; parts under a cubic centimetre (specks where a
/// prism's edge grazes the shell) stay with their piece. Returns each new piece's prism.
std::vector<uint32_t> carveParts(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field,
                                 const std::vector<std::shared_ptr<const TunnelPrism>>& prisms,
                                 const std::vector<uint32_t>& prismOf, bool isLaterFirst) {
    const size_t minVoxels = size_t(std::ceil(1000.0 / (field.voxelMm * field.voxelMm * field.voxelMm)));
    const size_t oldCount = pieces.size();
    std::vector<uint8_t> marked(field.owner.size(), 0);
    std::vector<uint32_t> lining;
    for (size_t s = 0; s < field.owner.size(); ++s) {
        if (!field.isInside(s) || prismOf[s] == kNone || marked[s]) continue;
        marked[s] = 1;
        std::vector<size_t> part{s};
        floodFaces(field, {s}, marked, [&](size_t t) {
            if (!field.isInside(t) || prismOf[t] != prismOf[s]) return false;
            part.push_back(t);
            return true;
        });
        if (part.size() < minVoxels) continue;
        Piece piece;
        piece.id = uint32_t(pieces.size());
        std::set<uint32_t> cells, requests;
        for (size_t t : part) {
            cells.insert(field.cell[t]);
            if (field.owner[t] < oldCount)
                requests.insert(pieces[field.owner[t]].requests.begin(),
                                pieces[field.owner[t]].requests.end());
            field.owner[t] = piece.id;
        }
        piece.cells.assign(cells.begin(), cells.end());
        piece.requests.assign(requests.begin(), requests.end());
        CellSet set;
        set.isMember.assign(sets.empty() ? 0 : sets[0].isMember.size(), 0);
        for (uint32_t c : piece.cells) set.isMember[c] = 1;
        set.members = piece.cells;
        set.isLining = true;
        const uint32_t own = prismOf[s];
        set.prisms.push_back({prisms[own], true});
        for (const auto& prism : prisms)
            if (isLaterFirst ? prism->priority > prisms[own]->priority : prism->axis < prisms[own]->axis)
                set.prisms.push_back({prism, false});
        pieces.push_back(std::move(piece));
        sets.push_back(std::move(set));
        lining.push_back(own);
    }
    return lining;
}

/// What the carve left of a piece of the partition, under @p minPieceVolumeMm3, joins the neighbour
/// it shares most with (one that is no lining and mergeable; else it stays). Returns how many joined.
size_t joinRemnants(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field,
                    const GridCells& cells, double minPieceVolumeMm3) {
    size_t joined = 0;
    for (; joined < pieces.size(); ++joined) {
        faceContacts(field, cells, sets, pieces);
        std::pair<uint32_t, uint32_t> best{kNone, kNone};
        for (uint32_t p = 0; p < pieces.size() && best.first == kNone; ++p) {
            if (sets[p].isLining || pieces[p].shellVolumeMm3 >= minPieceVolumeMm3) continue;
            double area = 0.0;
            for (const auto& [q, a] : pieces[p].neighbors)
                if (!sets[q].isLining && isMergeable(sets, q, p) && a > area) area = a, best = {q, p};
        }
        if (best.first == kNone) break;
        mergePieces(pieces, sets, field, best.first, best.second);
    }
    return joined;
}

/// Every lining cut across its axis into equal rings no longer than kTunnelSlabMm. Returns how many
/// cuts.
size_t cutRings(std::vector<Piece>& pieces, std::vector<CellSet>& sets, VoxelField& field) {
    const std::vector<std::vector<size_t>> slots = slotsOfPieces(field, pieces.size());
    size_t cuts = 0;
    for (uint32_t p = 0; p < slots.size(); ++p) {
        const TunnelPrism* prism = sets[p].isLining ? ownPrism(sets[p]) : nullptr;
        if (!prism) continue;
        Vec3d axis{0, 0, 0};
        axis[size_t(prism->axis)] = 1.0;
        const auto [lo, hi] = extentAlong(field, slots[p], prism->axis);
        const int rings = int(std::ceil((hi - lo) / kTunnelSlabMm));
        uint32_t rest = p;
        for (int k = 1; k < rings; ++k)
            rest = splitPiece(pieces, sets, field, rest, {axis, lo + (hi - lo) * k / rings}), ++cuts;
    }
    return cuts;
}

}  // namespace

size_t carveCrossingLinings(std::vector<Piece>& pieces, Grouping& grouping, VoxelField& field,
                            const GridCells& cells, double wallMm, double frameDMinMm, double thinGapMm,
                            double minPieceVolumeMm3, const RunContext& context, bool isOnlyWhereThreeCross) {
    std::vector<CellSet>& sets = grouping.cellSets;
    // A wall and two voxels: the shell's voxels reach a voxel past the wall (φ < 0 at their
    // centres), and the core's columns lie up to a voxel off the surface.
    const double radiusMm = wallMm + 2.0 * field.voxelMm;
    if (!(wallMm < frameDMinMm)) return 0;  // the frame might reach into a prism
    bool isTriple = false;
    std::vector<TunnelPrism> found =
        crossingPrisms(field, 2.0 * wallMm, radiusMm, wallMm + field.voxelMm, &isTriple, true);
    if (found.empty() || (isOnlyWhereThreeCross && !isTriple)) return 0;
    for (TunnelPrism& p : found)
        for (const TunnelKey& key : grouping.lateTunnels)
            if (isTriple && isTunnelOf(key, p, 2.0 * field.voxelMm))
                p.priority = p.axis + kLatePriority * key.level;
    std::vector<TunnelPrism> marked = found;
    if (isTriple) markCrossings(marked);
    std::vector<std::shared_ptr<const TunnelPrism>> prisms;
    for (const TunnelPrism& p : marked) prisms.push_back(std::make_shared<const TunnelPrism>(p));
    const std::vector<uint32_t> prismOf = prismOwners(field, found, isTriple);
    const size_t oldCount = pieces.size();
    const size_t carved = carveParts(pieces, sets, field, prisms, prismOf, isTriple).size();
    if (carved == 0) return 0;
    for (size_t p = 0; p < oldCount; ++p)
        for (const auto& prism : prisms) sets[p].prisms.push_back({prism, false});
    // Band voxels in a prism belong to its lining; the pieces the carve emptied go.
    for (size_t s = 0; s < field.owner.size(); ++s)
        if (field.isActive[s] && !field.isInside(s) && prismOf[s] != kNone) field.owner[s] = kNone;
    const size_t dropped = dropEmptyPieces(pieces, sets, field);
    std::vector<uint8_t> isLining(pieces.size(), 0);
    for (size_t p = 0; p < pieces.size(); ++p) isLining[p] = sets[p].isLining ? 1 : 0;
    ownBand(field, prismOf, isLining);
    const size_t joined = joinRemnants(pieces, sets, field, cells, minPieceVolumeMm3);
    if (isTriple) {
        cutStaves(pieces, sets, field, wallMm, thinGapMm, minPieceVolumeMm3);
        dropEmptyPieces(pieces, sets, field);
        grouping.faces = faceContacts(field, cells, sets, pieces);
        const size_t staves = size_t(std::count_if(sets.begin(), sets.end(), isStaveSet));
        const size_t mouthRings =
            size_t(std::count_if(sets.begin(), sets.end(), [](const CellSet& c) { return c.isMouthRing; }));
        context.detail("mounting: " + std::to_string(found.size()) +
                       " tunnels cross three at a time; their linings carved into " + std::to_string(carved) +
                       " pieces along them and cut into " + std::to_string(staves) +
                       " staves that slide along them and are pushed onto pegs across them, and " +
                       std::to_string(mouthRings) + " rings at their mouths glued on (" +
                       std::to_string(dropped) + " pieces of the partition were all lining, " +
                       std::to_string(joined) + " small rests joined to neighbours)");
        return staves;
    }
    const size_t cuts = cutRings(pieces, sets, field);
    grouping.faces = faceContacts(field, cells, sets, pieces);
    context.detail("mounting: " + std::to_string(found.size()) +
                   " tunnels cross; their linings carved into " + std::to_string(carved) +
                   " pieces along them and cut into " + std::to_string(carved + cuts) +
                   " rings and segments across them (" + std::to_string(dropped) +
                   " pieces of the partition were all lining, " + std::to_string(joined) +
                   " small rests joined to neighbours)");
    return carved + cuts;
}

}  // namespace zomefab::pieces::detail
