// SPDX-License-Identifier: GPL-3.0-or-later
// Pieces from the cells, and the split-and-retrain rounds until every piece fits (docs/partition.md §6).
#include <tbb/parallel_for.h>

#include <algorithm>
#include <map>
#include <numeric>
#include <set>

#include "zomefab/core/disjoint_sets.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/detail/stage.h"

namespace zomefab::partition::detail {

/// A piece of @p faces: its cells, their balls, its area, the box of its vertices (@p pts receives
/// them) and its patches: its fragments (@p fragOf: connected faces of one cell), each with its
/// cell and box, in order of their lowest face.
Piece describePiece(const Surface& S, const Classes& C, const LinearCells& cells,
                    const std::vector<uint32_t>& faceCells, const std::vector<uint32_t>& fragOf,
                    const std::vector<uint32_t>& faces, FitTester& cx, std::vector<Vec3d>& pts) {
    Piece piece;
    piece.faceCount = uint32_t(faces.size());
    for (uint32_t f : faces) {
        piece.areaMm2 += S.graph.areasMm2[f];
        piece.cells.push_back(faceCells[f]);
    }
    std::sort(piece.cells.begin(), piece.cells.end());
    piece.cells.erase(std::unique(piece.cells.begin(), piece.cells.end()), piece.cells.end());
    for (uint32_t c : piece.cells) piece.balls.push_back(C.classBall[cells.classes[c]]);
    std::sort(piece.balls.begin(), piece.balls.end());
    piece.balls.erase(std::unique(piece.balls.begin(), piece.balls.end()), piece.balls.end());
    pts = faceVertices(S.mesh, faces, cx.stamp, cx.stampValue);
    for (const Vec3d& v : pts) piece.boundsMm.expand(v);
    std::map<uint32_t, size_t> patchOfFragment;
    for (uint32_t f : faces) {
        const auto [it, isNew] = patchOfFragment.emplace(fragOf[f], piece.patches.size());
        if (isNew) piece.patches.push_back({faceCells[f], Box3d{}});
        for (uint32_t v : S.mesh.triangles[f])
            piece.patches[it->second].boundsMm.expand(toD(S.mesh.positions[v]));
    }
    return piece;
}

/// Pieces from the cells: fragments (connected faces of one cell), merged for crossed salient
/// regions and small areas when the result fits, numbered by lowest face, with their fits.
/// @p pieceFaces receives each piece's faces.
std::vector<Piece> piecesFromCells(const Surface& S, const Classes& C, const Fabrication& fab,
                                   const PartitionOptions& opt, FitTester& fits, const LinearCells& cells,
                                   const std::vector<uint32_t>& faceCells,
                                   const std::vector<uint32_t>& crossed, std::vector<uint32_t>& facePieces,
                                   std::vector<std::vector<uint32_t>>& pieceFaces, size_t& merges) {
    FitTester& cx = fits;
    std::vector<uint32_t> fragOf;
    const uint32_t fragCount = labelComponents(S.graph, faceCells, fragOf);
    std::vector<uint32_t> fragOffsets, fragFaces;
    groupFaces(fragOf, fragCount, fragOffsets, fragFaces);
    std::vector<double> fragArea(fragCount, 0.0);
    for (uint32_t f = 0; f < S.faceCount; ++f) fragArea[fragOf[f]] += S.graph.areasMm2[f];

    DisjointSets dsu(fragCount);
    std::vector<std::vector<uint32_t>> members(fragCount);  // faces of each root
    for (uint32_t c = 0; c < fragCount; ++c)
        members[c].assign(fragFaces.begin() + fragOffsets[c], fragFaces.begin() + fragOffsets[c + 1]);
    std::vector<double> area(fragArea);
    merges = 0;
    // The faces of roots a and b, a's first (the order the fit test samples them in).
    auto facesOf = [&](uint32_t a, uint32_t b) {
        std::vector<uint32_t> joined(members[a]);
        joined.insert(joined.end(), members[b].begin(), members[b].end());
        return joined;
    };
    // Makes roots a and b one piece whose faces are @p joined.
    auto unite = [&](uint32_t a, uint32_t b, std::vector<uint32_t> joined) {
        dsu.unite(a, b);
        const uint32_t root = dsu.find(a), other = root == a ? b : a;
        members[root] = std::move(joined);
        members[other].clear();
        area[root] += area[other];
    };
    auto tryMerge = [&](uint32_t a, uint32_t b, bool isCounted = true) {
        a = dsu.find(a), b = dsu.find(b);
        if (a == b) return true;
        std::vector<uint32_t> joined = facesOf(a, b);
        if (!cx.fits(joined)) return false;
        unite(a, b, std::move(joined));
        merges += isCounted ? 1 : 0;
        return true;
    };
    // Merged regions (mergeSmallRegions): the fragments of one group that touch each other
    // become one piece. A fragment belongs to the group of most of its area (cells follow the
    // regions only approximately). Normally the whole connected set fits, as the regions' union
    // did: one test; otherwise pairwise, in fragment order, each merge only if it fits.
    if (!C.faceGroup.empty()) {
        std::vector<uint32_t> fragGroup(fragCount, kNone);
        {
            std::vector<std::map<uint32_t, double>> groupArea(fragCount);
            for (uint32_t f = 0; f < S.faceCount; ++f)
                groupArea[fragOf[f]][C.faceGroup[f]] += S.graph.areasMm2[f];
            for (uint32_t c = 0; c < fragCount; ++c) {
                double best = -1.0;
                for (const auto& [gr, a] : groupArea[c])
                    if (a > best) best = a, fragGroup[c] = gr;  // ties: lowest group
            }
        }
        std::set<std::pair<uint32_t, uint32_t>> touching;  // fragment pairs of one group
        for (uint32_t f = 0; f < S.faceCount; ++f)
            for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i) {
                const uint32_t a = fragOf[f], b = fragOf[S.graph.neighbors[i]];
                if (a < b && fragGroup[a] == fragGroup[b]) touching.insert({a, b});
            }
        DisjointSets linked(fragCount);
        for (const auto& [a, b] : touching) linked.unite(a, b);
        std::vector<std::vector<uint32_t>> setFaces(fragCount);
        for (uint32_t f = 0; f < S.faceCount; ++f) setFaces[linked.find(fragOf[f])].push_back(f);
        std::vector<uint32_t> setRoots;
        std::vector<std::vector<uint32_t>> sets;
        for (uint32_t c = 0; c < fragCount; ++c)
            if (linked.find(c) == c && setFaces[c].size() > members[c].size())
                setRoots.push_back(c), sets.push_back(std::move(setFaces[c]));
        const std::vector<char> setFits = fitsEach(cx, sets);  // in parallel, the same test
        std::vector<char> isWhole(fragCount, 0);
        for (size_t i = 0; i < setRoots.size(); ++i) isWhole[setRoots[i]] = setFits[i];
        for (const auto& [a, b] : touching) {
            if (isWhole[linked.find(a)]) {
                const uint32_t ra = dsu.find(a), rb = dsu.find(b);
                if (ra != rb)
                    unite(ra, rb, facesOf(std::min(ra, rb), std::max(ra, rb)));  // the lower id is the root
            } else {
                tryMerge(a, b, false);
            }
        }
    }
    // Salient regions a cut still crosses: keep them in one piece by merging the fragments of
    // their faces and of the faces around them (where corners in another cell lie), if it fits.
    for (uint32_t r : crossed) {
        const uint32_t first = fragOf[S.salientFacesOf[r].front()];
        for (uint32_t f : S.salientFacesOf[r]) {
            tryMerge(first, fragOf[f]);
            for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i)
                tryMerge(first, fragOf[S.graph.neighbors[i]]);
        }
    }
    // Small fragments, smallest first, into the neighbour they share the longest seam with.
    std::vector<uint32_t> order(fragCount);
    std::iota(order.begin(), order.end(), 0u);
    std::sort(order.begin(), order.end(), [&](uint32_t a, uint32_t b) {
        return fragArea[a] != fragArea[b] ? fragArea[a] < fragArea[b] : a < b;
    });
    for (uint32_t c : order) {
        const uint32_t root = dsu.find(c);
        if (area[root] >= opt.minPieceAreaMm2) continue;
        std::map<uint32_t, double> seam;  // neighbour root → shared edge length (mm)
        for (uint32_t f : members[root])
            for (uint32_t i = S.graph.offsets[f]; i < S.graph.offsets[f + 1]; ++i) {
                const uint32_t h = S.graph.neighbors[i];
                const uint32_t other = dsu.find(fragOf[h]);
                if (other == root) continue;
                seam[other] += sharedEdgeMm(S.mesh, f, h);  // graph neighbours share an edge
            }
        std::vector<std::pair<double, uint32_t>> byLength;
        for (const auto& [o, len] : seam) byLength.push_back({-len, o});
        std::sort(byLength.begin(), byLength.end());
        for (const auto& [negLen, o] : byLength)
            if (tryMerge(root, o)) break;
    }

    // Pieces in order of their lowest face.
    std::vector<uint32_t> pieceOfRoot(fragCount, kNone);
    facePieces.assign(S.faceCount, 0);
    uint32_t pieceCount = 0;
    for (uint32_t f = 0; f < S.faceCount; ++f) {
        const uint32_t root = dsu.find(fragOf[f]);
        if (pieceOfRoot[root] == kNone) pieceOfRoot[root] = pieceCount++;
        facePieces[f] = pieceOfRoot[root];
    }
    pieceFaces.assign(pieceCount, {});
    for (uint32_t f = 0; f < S.faceCount; ++f) pieceFaces[facePieces[f]].push_back(f);
    std::vector<Piece> pieces(pieceCount);
    std::vector<std::vector<Vec3d>> piecePts(pieceCount);
    for (uint32_t p = 0; p < pieceCount; ++p)
        pieces[p] = describePiece(S, C, cells, faceCells, fragOf, pieceFaces[p], cx, piecePts[p]);
    tbb::parallel_for(uint32_t(0), pieceCount, [&](uint32_t p) {
        pieces[p].fit = fitInPrinter(piecePts[p], fab.pieceBoxMm(), fab.fitMarginMm);
    });
    return pieces;
}

/// Salient regions whose faces lie in several pieces, or whose corners lie in a cell that is
/// not one of their piece's cells.
size_t countCrossedRegions(const Surface& S, const PartitionResult& res,
                           const std::vector<uint32_t>& crossed) {
    size_t count = 0;
    for (uint32_t r : crossed) {
        bool isSplit = false;
        const uint32_t p0 = res.facePieces[S.salientFacesOf[r].front()];
        const auto& cells = res.pieces[p0].cells;
        for (uint32_t f : S.salientFacesOf[r]) {
            if (res.facePieces[f] != p0) isSplit = true;
            for (uint32_t v : S.mesh.triangles[f])
                if (!std::binary_search(cells.begin(), cells.end(),
                                        res.cells.cellAt(toD(S.mesh.positions[v]))))
                    isSplit = true;
        }
        count += isSplit ? 1 : 0;
    }
    return count;
}

/// Cells, pieces, and split-and-retrain rounds until every piece fits.
void cutAndMakePieces(const Surface& S, Classes& C, const Fabrication& fab, const PartitionOptions& opt,
                      FitTester& fits, PartitionResult& res, const RunContext& run) {
    const Stopwatch clock;
    std::vector<size_t> tooLargeCounts;  // per round
    for (int round = 0;; ++round) {
        run.throwIfCancelled();
        std::vector<uint32_t> crossed;
        LinearCells cells = trainCells(S, C, fab, opt, res, run, crossed);
        std::vector<uint32_t> faceCells(S.faceCount);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, S.faceCount, 4096),
                          [&](const tbb::blocked_range<size_t>& r) {
                              for (size_t f = r.begin(); f < r.end(); ++f)
                                  faceCells[f] = cells.cellAt(S.graph.centroidsMm[f]);
                          });
        std::vector<uint32_t> facePieces;
        std::vector<std::vector<uint32_t>> pieceFaces;
        size_t merges = 0;
        std::vector<Piece> pieces =
            piecesFromCells(S, C, fab, opt, fits, cells, faceCells, crossed, facePieces, pieceFaces, merges);

        std::vector<uint32_t> tooLarge, unmountable;
        for (uint32_t p = 0; p < pieces.size(); ++p)
            if (!pieces[p].fit.fits)
                tooLarge.push_back(p);
            else if (!fits.isMountable(pieceFaces[p]))
                unmountable.push_back(p);
        // The rounds end after maxRepairRounds, or sooner when two rounds did not lower the number
        // of pieces too large (the cheese at 700 mm: 56, 49, 45, 41, 43, 47 … over 8 rounds and
        // 200 s of retraining).
        tooLargeCounts.push_back(tooLarge.size());
        const size_t n = tooLargeCounts.size();
        const bool isStalled = !tooLarge.empty() && n >= 3 && tooLargeCounts[n - 1] >= tooLargeCounts[n - 3];
        const bool isLastRound = round >= opt.maxRepairRounds || isStalled;
        // Pieces no direction mounts are cut again while rounds are left; after that the pieces
        // stage re-cuts or glues them (it knows the solid wall).
        if (isLastRound) unmountable.clear();
        // Cells that still meet the surface in a patch too large for the printer after the rounds
        // (seen on a cube with cavities, where a convex cell's surface stays connected): the pieces
        // stage cuts those pieces by planes (pieces::detail::splitTooLarge).
        if (!tooLarge.empty() && isLastRound) {
            run.info(std::to_string(tooLarge.size()) + " piece(s) still do not fit the printer " +
                     sizeText(fab.pieceBoxMm()) + " (the bed less its margins) after " +
                     std::to_string(round) + " repair rounds of the planar cuts (piece " +
                     std::to_string(tooLarge.front()) + " needs " +
                     sizeText(pieces[tooLarge.front()].fit.extentsMm) +
                     "); the pieces stage cuts them smaller by planes");
            tooLarge.clear();
        }
        if (tooLarge.empty() && unmountable.empty()) {
            size_t agree = 0;
            for (uint32_t f = 0; f < S.faceCount; ++f)
                agree += cells.classes[faceCells[f]] == C.trainClass[f] ? 1 : 0;
            res.svmAgreement = double(agree) / double(S.faceCount);
            res.cells = std::move(cells);
            res.cellBalls.clear();
            for (uint32_t c : res.cells.classes) res.cellBalls.push_back(C.classBall[c]);
            res.faceCells = std::move(faceCells);
            res.facePieces = std::move(facePieces);
            res.pieces = std::move(pieces);
            res.merges = merges;
            res.salientRegionsSplit = countCrossedRegions(S, res, crossed);
            if (res.salientRegionsSplit > 0)
                run.warn(std::to_string(res.salientRegionsSplit) +
                         " salient region(s) are crossed by a planar cut that could not be avoided");
            break;
        }
        // Split the pieces that do not fit into new classes and train again.
        run.detail(std::to_string(tooLarge.size()) + " piece(s) do not fit the printer and " +
                   std::to_string(unmountable.size()) +
                   " no direction mounts after the planar cuts; split and retrain");
        tooLarge.insert(tooLarge.end(), unmountable.begin(), unmountable.end());
        for (uint32_t p : tooLarge) {
            const uint32_t c =
                newClassFor(S, res, C, pieceFaces[p]);  // the piece's faces get one class of their own first
            for (uint32_t f : pieceFaces[p]) C.trainClass[f] = c;
            if (splitFaces(S, res, C, fits, pieceFaces[p])) ++res.splits;
            // Its parts leave their merged group (each part a group of its own), so the next
            // round does not join them into the piece that did not fit again.
            if (!C.faceGroup.empty())
                for (uint32_t f : pieceFaces[p]) C.faceGroup[f] = C.groupCount + C.trainClass[f];
        }
    }
    res.secondsSvm = clock.seconds();
}

}  // namespace zomefab::partition::detail
