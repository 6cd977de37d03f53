// SPDX-License-Identifier: GPL-3.0-or-later
// From the shell's voxels to pieces (detail/grouping.h, docs/pieces.md §1).
#include "zomefab/pieces/detail/grouping.h"

#include <algorithm>
#include <cmath>
#include <tuple>

#include "zomefab/core/disjoint_sets.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/staves.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::pieces::detail {

namespace {

using Contacts = std::map<std::pair<uint32_t, uint32_t>, size_t>;

/// An island of the shell (inside voxels joined across cells, touching nothing else) of at most
/// this many voxels is a speck (dropSpecks).
constexpr size_t kSpeckVoxels = 2;

/// Components of one group that touch form one piece. Then two kinds of pieces join the
/// neighbour they share the largest cut face with: the parts of the shell in cells that no
/// request names (cells with no outer surface: the partition meant no piece there), whatever
/// their size, and slivers below minPieceVolumeMm3. Never dropped: with no neighbour they stay
/// (specks were dropped before, dropSpecks).
struct Merger {
    const std::vector<Component>& comps;
    const Contacts& contacts;
    DisjointSets sets;
    std::vector<double> rootVolume;
    std::vector<uint32_t> rootSlivers;
    std::vector<uint8_t> isOrphan;  ///< per root: only components of unnamed cells
    double voxelVolume;

    Merger(const std::vector<Component>& comps, const Contacts& c, size_t requestCount, double voxelVolume)
        : comps(comps),
          contacts(c),
          sets(comps.size()),
          rootVolume(comps.size(), 0.0),
          rootSlivers(comps.size(), 0),
          isOrphan(comps.size(), 0),
          voxelVolume(voxelVolume) {
        for (const auto& [pair, count] : contacts)
            if (comps[pair.first].group == comps[pair.second].group) sets.unite(pair.first, pair.second);
        for (size_t k = 0; k < comps.size(); ++k) {
            rootVolume[sets.find(uint32_t(k))] += double(comps[k].voxels) * voxelVolume;
            isOrphan[k] = comps[k].group >= requestCount;
        }
    }

    /// Merges @p root into the neighbour with the largest contact (named pieces before unnamed
    /// ones, ties to the lowest root). False when it touches no other piece.
    bool mergeIntoNeighbour(uint32_t root, bool isOrphanPass) {
        std::map<uint32_t, size_t> shared;  // neighbour root → contact voxel faces
        for (const auto& [pair, count] : contacts) {
            const uint32_t ra = sets.find(pair.first), rb = sets.find(pair.second);
            if (ra == rb) continue;
            if (ra == root)
                shared[rb] += count;
            else if (rb == root)
                shared[ra] += count;
        }
        if (shared.empty()) return false;
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
        join(root, target, rootSlivers[root] + rootSlivers[target] + (isOrphanPass ? 0 : 1),
             isOrphan[root] && isOrphan[target]);
        return true;
    }

    /// Unites the roots @p root and @p target; the merged root gets both volumes, @p slivers and
    /// @p isStillOrphan.
    void join(uint32_t root, uint32_t target, uint32_t slivers, bool isStillOrphan) {
        const double volume = rootVolume[root] + rootVolume[target];
        sets.unite(root, target);
        const uint32_t merged = sets.find(root);
        rootVolume[merged] = volume;
        rootSlivers[merged] = slivers;
        isOrphan[merged] = isStillOrphan;
    }

    std::vector<uint32_t> rootsByVolume() {
        std::vector<uint32_t> roots;
        for (size_t k = 0; k < rootVolume.size(); ++k)
            if (sets.find(uint32_t(k)) == k) roots.push_back(uint32_t(k));
        std::stable_sort(roots.begin(), roots.end(),
                         [&](uint32_t a, uint32_t b) { return rootVolume[a] < rootVolume[b]; });
        return roots;
    }

    /// Orphans first (until none can move), then slivers. Returns the orphans kept.
    size_t mergeAll(double minPieceVolumeMm3, Grouping& out, const RunContext& context) {
        size_t orphansKept = 0;
        for (bool isChanged = true; isChanged;) {
            isChanged = false;
            orphansKept = 0;
            for (uint32_t r0 : rootsByVolume()) {
                const uint32_t root = sets.find(r0);
                if (root != r0 || !isOrphan[root]) continue;
                if (mergeIntoNeighbour(root, true))
                    isChanged = true;
                else
                    ++orphansKept;
            }
        }
        if (out.outsideCellsVolumeMm3 > 0)
            context.warn(
                formatNumber(out.outsideCellsVolumeMm3, 4) +
                " mm³ of the shell lie in cells that no partition piece names; merged into their neighbours" +
                (orphansKept ? " (" + std::to_string(orphansKept) + " with no neighbour kept as pieces)"
                             : ""));
        for (uint32_t r0 : rootsByVolume()) {
            const uint32_t root = sets.find(r0);
            if (rootVolume[root] >= minPieceVolumeMm3) continue;
            if (mergeIntoNeighbour(root, false)) {
                ++out.sliversMerged;
            } else {
                ++out.isolatedSlivers;
                context.warn("a " + formatNumber(rootVolume[root], 4) +
                             " mm³ piece touches no other piece and cannot be merged: it is kept as it is");
            }
        }
        return orphansKept;
    }
};

/// What dropSpecks left out: voxels in specks, and crumbs (islands larger than a speck).
struct Dropped {
    size_t speckVoxels = 0, crumbs = 0, crumbVoxels = 0;
};

/// Drops the specks: islands of the shell (components joined by their contacts, across cells) of
/// at most kSpeckVoxels voxels, a corner of a cell the cut grazed or a thread of wall thinner than
/// a voxel. Their voxels become outside voxels (φ mirrored), so no piece holds them: the mesher
/// would drop them anyway (components under a voxel's volume), and joined to a piece they made it
/// two islands that no plane cuts into connected halves and whose far crumb meets the frame along
/// every direction (the dino at 450 mm: "piece 1: no direction to push it on along"). So are the
/// crumbs, islands of fewer than @p maxCrumbVoxels: too small for a tenon, and touching no other
/// piece to be glued onto, nothing could hold one (the cheese at 700 mm: a 52 mm³ piece the plan
/// could place nowhere); never the largest island. The caller finds the components again.
Dropped dropSpecks(VoxelField& field, const std::vector<Component>& comps, const Contacts& contacts,
                   size_t maxCrumbVoxels) {
    DisjointSets islands(comps.size());
    for (const auto& [pair, count] : contacts) islands.unite(pair.first, pair.second);
    std::vector<size_t> islandVoxels(comps.size(), 0);
    for (size_t k = 0; k < comps.size(); ++k) islandVoxels[islands.find(uint32_t(k))] += comps[k].voxels;
    // The largest island is never a crumb (a smallest piece larger than the whole shell keeps it whole).
    const size_t largest =
        islandVoxels.empty() ? 0 : *std::max_element(islandVoxels.begin(), islandVoxels.end());
    auto isCrumb = [&](size_t voxels) {
        return voxels > kSpeckVoxels && voxels < maxCrumbVoxels && voxels < largest;
    };
    Dropped out;
    for (size_t k = 0; k < comps.size(); ++k)
        if (islands.find(uint32_t(k)) == k && isCrumb(islandVoxels[k])) ++out.crumbs;
    for (size_t s = 0; s < field.phi.size(); ++s) {
        if (!field.isInside(s)) continue;
        const size_t voxels = islandVoxels[islands.find(field.owner[s])];
        if (voxels > kSpeckVoxels && !isCrumb(voxels)) continue;
        field.phi[s] = -field.phi[s];
        ++(voxels > kSpeckVoxels ? out.crumbVoxels : out.speckVoxels);
    }
    return out;
}

/// Piece ids: roots ordered by the lowest group they hold (then by their first voxel).
std::vector<uint32_t> orderPieces(const std::vector<Component>& comps, DisjointSets& sets,
                                  std::vector<uint32_t>& roots) {
    std::map<uint32_t, uint32_t> lowestGroup;
    for (size_t k = 0; k < comps.size(); ++k) {
        const uint32_t r = sets.find(uint32_t(k));
        auto it = lowestGroup.find(r);
        if (it == lowestGroup.end())
            lowestGroup[r] = comps[k].group;
        else
            it->second = std::min(it->second, comps[k].group);
    }
    roots.clear();
    for (const auto& [r, g] : lowestGroup) roots.push_back(r);
    std::stable_sort(roots.begin(), roots.end(),
                     [&](uint32_t a, uint32_t b) { return lowestGroup[a] < lowestGroup[b]; });
    std::vector<uint32_t> idOfRoot(comps.size(), kNone), pieceOfComp(comps.size(), kNone);
    for (size_t i = 0; i < roots.size(); ++i) idOfRoot[roots[i]] = uint32_t(i);
    for (size_t k = 0; k < comps.size(); ++k) pieceOfComp[k] = idOfRoot[sets.find(uint32_t(k))];
    return pieceOfComp;
}

/// Voxel owners: inside voxels belong to their piece; band voxels outside the shell to the piece
/// of the nearest inside voxel of the same cell (up to the band's width, by layers, the lowest
/// piece id on ties), else to the piece holding most of their cell. Returns the number of pieces
/// per cell (a cell of several pieces is "shared").
std::vector<uint32_t> ownVoxels(VoxelField& field, const std::vector<Component>& comps,
                                const std::vector<uint32_t>& pieceOfComp, size_t cellCount) {
    std::vector<uint32_t> cellPieceCount(cellCount, 0), cellDefault(cellCount, kNone);
    {
        std::vector<size_t> best(cellCount, 0);
        std::vector<std::vector<uint32_t>> piecesOfCell(cellCount);
        for (size_t c = 0; c < comps.size(); ++c) {
            const uint32_t k = comps[c].cell, p = pieceOfComp[c];
            if (std::find(piecesOfCell[k].begin(), piecesOfCell[k].end(), p) == piecesOfCell[k].end())
                piecesOfCell[k].push_back(p);
            if (cellDefault[k] == kNone || comps[c].voxels > best[k])
                cellDefault[k] = p, best[k] = comps[c].voxels;
        }
        for (size_t k = 0; k < cellCount; ++k) cellPieceCount[k] = uint32_t(piecesOfCell[k].size());
    }
    const size_t slotCount = field.phi.size();
    for (size_t s = 0; s < slotCount; ++s)
        if (field.isInside(s)) field.owner[s] = pieceOfComp[field.owner[s]];
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
    for (size_t s = 0; s < slotCount; ++s)
        if (field.isActive[s] && field.owner[s] == kNone) field.owner[s] = cellDefault[field.cell[s]];
    return cellPieceCount;
}

/// The pieces' cells, requests and volumes, their cell sets, and who shares a cut face with whom.
void describePieces(Grouping& out, const std::vector<Component>& comps,
                    const std::vector<uint32_t>& pieceOfComp, const std::vector<uint32_t>& cellPieceCount,
                    size_t requestCount, double voxelMm) {
    const double voxelVolume = voxelMm * voxelMm * voxelMm;
    const size_t cellCount = cellPieceCount.size();
    for (size_t c = 0; c < comps.size(); ++c) {
        Piece& piece = out.pieces[pieceOfComp[c]];
        piece.cells.push_back(comps[c].cell);
        if (comps[c].group < requestCount) piece.requests.push_back(comps[c].group);
        piece.shellVolumeMm3 += double(comps[c].voxels) * voxelVolume;
        out.shellVolumeMm3 += double(comps[c].voxels) * voxelVolume;
    }
    out.cellSets.assign(out.pieces.size(), {});
    for (size_t p = 0; p < out.pieces.size(); ++p) {
        Piece& piece = out.pieces[p];
        for (auto* list : {&piece.cells, &piece.requests}) {
            std::sort(list->begin(), list->end());
            list->erase(std::unique(list->begin(), list->end()), list->end());
        }
        CellSet& set = out.cellSets[p];
        set.isMember.assign(cellCount, 0);
        for (uint32_t c : piece.cells) set.isMember[c] = 1;
        for (uint32_t k = 0; k < cellCount; ++k) {
            if (set.isMember[k]) set.members.push_back(k);
            if (!set.isMember[k] || cellPieceCount[k] > 1) set.cutters.push_back(k);
        }
    }
}

}  // namespace

FaceContacts faceContacts(const VoxelField& field, const GridCells& cells, const std::vector<CellSet>& sets,
                          std::vector<Piece>& pieces) {
    // Voxel faces per (lower piece, higher piece, lower's cell, higher's cell); a pair in one cell,
    // or in two cells both pieces have, is a re-cut face (its plane is one of their half-spaces).
    // With each, the sum of the unit steps from the lower piece's voxel to the higher's: where no
    // plane separates the two (pieces that share a cell), its direction is the face's mean normal.
    // A stave's border (detail/staves.h) wraps round the tunnel's corners and rim: its faces are
    // kept apart by the way the voxel step goes (one of six), so no mean normal points along a
    // way that runs into it.
    std::vector<uint8_t> isStave(sets.size(), 0);
    for (size_t p = 0; p < sets.size(); ++p) isStave[p] = isStavedLining(sets[p]) ? 1 : 0;
    std::map<std::tuple<uint32_t, uint32_t, uint32_t, uint32_t, int>, std::pair<size_t, Vec3d>> counts;
    forEachForwardPair(field, [&](size_t a, size_t b) {
        if (!field.isInside(a) || !field.isInside(b) || field.owner[a] == field.owner[b]) return;
        const Vec3d step = sub(field.world(field.coordOf(b)), field.world(field.coordOf(a)));
        const bool isSwapped = field.owner[a] > field.owner[b];
        if (isSwapped) std::swap(a, b);
        int way = 0;
        if (isStave[field.owner[a]] || isStave[field.owner[b]])
            for (int k = 0; k < 3; ++k)
                if (step[size_t(k)] != 0.0) way = 1 + 2 * k + ((step[size_t(k)] > 0) != isSwapped ? 1 : 0);
        auto& entry = counts[{field.owner[a], field.owner[b], field.cell[a], field.cell[b], way}];
        ++entry.first;
        entry.second = madd(entry.second, isSwapped ? -1.0 : 1.0, step);
    });
    FaceContacts faces;
    std::map<std::pair<uint32_t, uint32_t>, size_t> total;
    for (const auto& [key, entry] : counts) {
        const auto [pa, pb, ca, cb, way] = key;
        const size_t count = entry.first;
        Vec3d normal{0, 0, 0};
        // Two cells of one piece's region are not cut from each other: where each piece has both
        // cells, the pair lies across a plane they were re-cut along.
        // A lining carved along a tunnel (detail/prisms.h) is bounded by its prism, not by cells.
        const bool isLining = sets[pa].isLining || sets[pb].isLining;
        const bool isCellPlane = !isLining && ca != cb && !(sets[pa].isMember[cb] && sets[pb].isMember[ca]);
        if (isCellPlane) {
            normal = normalized(sub(cells.w[cb], cells.w[ca]));  // the plane s_ca = s_cb, into cb
        } else {
            // The plane a was re-cut along that b lies beyond (b's side of it).
            const auto& mine = sets[pa].halfSpaces;
            const auto& theirs = sets[pb].halfSpaces;
            for (const CellSet::HalfSpace& h : mine)
                for (const CellSet::HalfSpace& g : theirs)
                    if (dot(h.normal, g.normal) < -0.999999 && std::abs(h.offsetMm + g.offsetMm) < 1e-6)
                        normal = h.normal;
            // No plane: the border between two pieces in one cell follows the voxels.
            if (norm(normal) == 0.0 && norm(entry.second) > 0.0) normal = normalized(entry.second);
        }
        if (norm(normal) == 0.0) continue;
        auto& list = faces[{pa, pb}];
        auto same = std::find_if(list.begin(), list.end(),
                                 [&](const CutContact& c) { return dot(c.normal, normal) > 0.999999; });
        if (same == list.end())
            list.push_back({normal, count, way != 0});
        else
            same->voxelFaces += count;
        total[{pa, pb}] += count;
    }
    const double voxelArea = field.voxelMm * field.voxelMm;
    for (Piece& piece : pieces) piece.neighbors.clear();
    for (const auto& [pair, count] : total) {
        pieces[pair.first].neighbors.push_back({pair.second, double(count) * voxelArea});
        pieces[pair.second].neighbors.push_back({pair.first, double(count) * voxelArea});
    }
    for (Piece& piece : pieces) std::sort(piece.neighbors.begin(), piece.neighbors.end());
    return faces;
}

std::vector<Component> findComponents(VoxelField& field) {
    const size_t slotCount = field.phi.size();
    DisjointSets voxelSets(slotCount);
    forEachForwardPair(field, [&](size_t a, size_t b) {
        if (field.isInside(a) && field.isInside(b) && field.cell[a] == field.cell[b])
            voxelSets.unite(uint32_t(a), uint32_t(b));
    });
    std::vector<Component> comps;
    field.owner.assign(slotCount, kNone);
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
    return comps;
}

std::map<std::pair<uint32_t, uint32_t>, size_t> componentContacts(const VoxelField& field) {
    Contacts contacts;
    forEachForwardPair(field, [&](size_t a, size_t b) {
        if (!field.isInside(a) || !field.isInside(b)) return;
        const uint32_t ca = field.owner[a], cb = field.owner[b];
        if (ca != cb) ++contacts[{std::min(ca, cb), std::max(ca, cb)}];
    });
    return contacts;
}

double assignGroups(std::vector<Component>& comps, const VoxelField& field,
                    const std::vector<partition::Piece>& requests, size_t cellCount,
                    const Transform4d& gridToFrame, double grow, double voxelVolume) {
    std::vector<std::vector<uint32_t>> cellRequests(cellCount);
    for (size_t r = 0; r < requests.size(); ++r)
        for (uint32_t c : requests[r].cells) cellRequests[c].push_back(uint32_t(r));
    for (auto& list : cellRequests) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
    }
    double orphanVolume = 0.0;
    std::vector<std::vector<size_t>> votes(comps.size());
    bool needsVotes = false;
    for (size_t c = 0; c < comps.size(); ++c) {
        const auto& reqs = cellRequests[comps[c].cell];
        if (reqs.empty()) {
            comps[c].group = uint32_t(requests.size() + c);
            orphanVolume += double(comps[c].voxels) * voxelVolume;
        } else if (reqs.size() == 1) {
            comps[c].group = reqs[0];
        } else {
            votes[c].assign(reqs.size(), 0);
            needsVotes = true;
        }
    }
    if (!needsVotes) return orphanVolume;
    // A cell shared by several requests: each component goes to the request whose surface in that
    // cell (its patches, else its whole surface's box), grown by the wall's thickness, holds most
    // of its voxels.
    auto isNear = [&](const Box3d& box, const Vec3d& x) {
        if (box.isEmpty()) return false;
        for (int a = 0; a < 3; ++a)
            if (x[size_t(a)] < box.min[size_t(a)] - grow || x[size_t(a)] > box.max[size_t(a)] + grow)
                return false;
        return true;
    };
    for (size_t s = 0; s < field.phi.size(); ++s) {
        if (!field.isInside(s) || votes[field.owner[s]].empty()) continue;
        const uint32_t c = field.owner[s];
        const Vec3d x = gridToFrame.apply(field.world(field.coordOf(s)));
        const auto& reqs = cellRequests[comps[c].cell];
        for (size_t i = 0; i < reqs.size(); ++i) {
            const partition::Piece& r = requests[reqs[i]];
            bool isIn = r.patches.empty() && isNear(r.boundsMm, x);
            for (const partition::Piece::CellPatch& p : r.patches)
                isIn = isIn || (p.cell == comps[c].cell && isNear(p.boundsMm, x));
            if (isIn) ++votes[c][i];
        }
    }
    for (size_t c = 0; c < comps.size(); ++c) {
        if (votes[c].empty()) continue;
        const size_t best = size_t(std::max_element(votes[c].begin(), votes[c].end()) - votes[c].begin());
        comps[c].group = cellRequests[comps[c].cell][best];
    }
    return orphanVolume;
}

Grouping groupPieces(VoxelField& field, const GridCells& cells, const std::vector<partition::Piece>& requests,
                     const Transform4d& gridToFrame, double growMm, double minPieceVolumeMm3,
                     const RunContext& context) {
    const double voxelVolume = field.voxelMm * field.voxelMm * field.voxelMm;
    std::vector<Component> comps = findComponents(field);
    Contacts contacts = componentContacts(field);
    const auto maxCrumbVoxels = size_t(std::ceil(minPieceVolumeMm3 / voxelVolume));
    const Dropped dropped = dropSpecks(field, comps, contacts, maxCrumbVoxels);
    if (dropped.speckVoxels > 0)
        context.detail(formatNumber(double(dropped.speckVoxels) * voxelVolume, 4) +
                       " mm³ of the shell in specks of at most " + std::to_string(kSpeckVoxels) +
                       " voxels that touch nothing else dropped (the mesher would drop them)");
    if (dropped.crumbs > 0)
        context.warn(
            std::to_string(dropped.crumbs) + " island(s) of the wall under " +
            formatNumber(minPieceVolumeMm3, 4) + " mm³ that touch no other piece left out (" +
            formatNumber(double(dropped.crumbVoxels) * voxelVolume, 4) +
            " mm³ in all): too small for a tenon, with no face to glue them onto, nothing could hold them");
    if (dropped.speckVoxels + dropped.crumbVoxels > 0) {
        comps = findComponents(field);
        contacts = componentContacts(field);
    }
    if (comps.empty()) throw Error(ErrorCode::InvalidInput, "the shell has no inside");
    context.progress("pieces", 0.15);
    context.throwIfCancelled();
    Grouping out;
    out.isolatedSlivers = dropped.crumbs;
    out.outsideCellsVolumeMm3 =
        assignGroups(comps, field, requests, cells.count(), gridToFrame, growMm, voxelVolume);
    Merger merger(comps, contacts, requests.size(), voxelVolume);
    merger.mergeAll(minPieceVolumeMm3, out, context);
    std::vector<uint32_t> roots;
    const std::vector<uint32_t> pieceOfComp = orderPieces(comps, merger.sets, roots);
    out.pieces.resize(roots.size());
    for (size_t p = 0; p < roots.size(); ++p) {
        out.pieces[p].id = uint32_t(p);
        out.pieces[p].sliversMerged = merger.rootSlivers[roots[p]];
    }
    const std::vector<uint32_t> cellPieceCount = ownVoxels(field, comps, pieceOfComp, cells.count());
    describePieces(out, comps, pieceOfComp, cellPieceCount, requests.size(), field.voxelMm);
    out.faces = faceContacts(field, cells, out.cellSets, out.pieces);
    context.detail(std::to_string(out.pieces.size()) + " pieces from " + std::to_string(comps.size()) +
                   " components of " + std::to_string(cells.count()) + " cells (" +
                   std::to_string(out.sliversMerged) + " slivers merged)");
    return out;
}

}  // namespace zomefab::pieces::detail
