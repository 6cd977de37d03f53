// SPDX-License-Identifier: GPL-3.0-or-later
// Tenons and engraved numbers planned against the shell (detail/stages.h, docs/pieces.md §2–3).
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <functional>
#include <initializer_list>
#include <map>
#include <optional>
#include <set>

#include "zomefab/core/format.h"
#include "zomefab/core/run_context.h"
#include "zomefab/pieces/detail/merges.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/pins.h"
#include "zomefab/pieces/detail/splits.h"
#include "zomefab/pieces/detail/stages.h"

namespace zomefab::pieces::detail {

namespace {

/// One warning for the pieces short of tenons, with the reasons summed over them, most frequent
/// first. (Naming the first such piece's top reason misled: its reasons were often one each, and
/// the tie went to the alphabetically first, "crosses another piece", though on the bunny at
/// 400 mm that rejected 7 of 136 rays against 52 "too far from the wall".)
void warnShortfall(const Pieces& out, const TenonOptions& o, const RunContext& context) {
    size_t few = 0;
    std::map<std::string, int> reasons;
    for (const Piece& piece : out.pieces)
        if (piece.tenons.size() < size_t(o.minPerPiece)) {
            ++few;
            for (const auto& [why, count] : piece.tenonShortfall) reasons[why] += count;
        }
    if (few == 0) return;
    std::vector<std::pair<int, std::string>> ranked;
    for (const auto& [why, count] : reasons) ranked.push_back({-count, why});
    std::sort(ranked.begin(), ranked.end());
    std::string list;
    for (const auto& [negCount, why] : ranked)
        list += (list.empty() ? "" : ", ") + why + " " + std::to_string(-negCount);
    context.warn(std::to_string(few) + " of " + std::to_string(out.pieces.size()) +
                 " pieces have fewer than " + std::to_string(o.minPerPiece) +
                 " tenons (rejected rays: " + list + "); pieces.json lists why per piece");
}

constexpr int kRecutRounds = 5;  ///< plan, re-cut the blocked pieces, plan again: at most this often
/// Merge under-held pieces, plan again: at most this often (each piece merges once per round; the
/// elephant at 400 mm merges three specks into one piece in three rounds, 0.7 s each).
constexpr int kMergeRounds = 8;
/// When a round's merges together do not help, this many are tried one by one (each a plan).
constexpr size_t kSingleMergeTrials = 4;

/// The box every piece's voxels and every ball lie in (grid mm): the frame sweeps' rectangle.
Box3d planBounds(const VoxelField& field, const zome::Structure& frame, const Transform4d& frameToGridMm) {
    Box3d bounds;
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isInside(s)) bounds.expand(field.world(field.coordOf(s)));
    for (zome::BallId id : frame.ballIds()) bounds.expand(frameToGridMm.apply(frame.ball(id).positionMm));
    return bounds;
}

/// The pieces to re-cut: every piece the frame is in the way of along every direction with tenons,
/// and of the pieces that keep each other from any order (placed nowhere, though free alone) the
/// larger half (cutting them all multiplies the pieces: re-cutting some often frees the rest).
std::vector<uint32_t> piecesToRecut(const Pieces& out, const PlannerInput& input, const FrameSweeps& sweeps,
                                    double voxelMm, int maxPerPiece) {
    std::vector<uint32_t> list;
    std::vector<std::pair<double, uint32_t>> stuck;  // (−volume, piece)
    for (uint32_t p = 0; p < out.pieces.size(); ++p) {
        if (out.plan.holeOfPiece[p] >= 0 || input.candidatesByHole[p].empty()) continue;
        if (!makeBody({p}, input, sweeps, voxelMm, maxPerPiece, 1).bestFree())
            list.push_back(p);
        else
            stuck.push_back({-out.pieces[p].shellVolumeMm3, p});
    }
    std::sort(stuck.begin(), stuck.end());
    for (size_t k = 0; k < (stuck.size() + 1) / 2; ++k) list.push_back(stuck[k].second);
    std::sort(list.begin(), list.end());
    return list;
}

/// What the re-cuts of a piece (findSplit) and of a pair (findHoldingSplits) need besides the
/// voxels: the grid, halves of at least the smallest piece volume (and 1,000 voxels), candidates
/// within a tenon's width of the plane lost; voxelMm is the grid's, for cells the caller sets it.
SplitSearch splitSearchFor(const VoxelField& field, const PiecesOptions& opt) {
    SplitSearch search;
    search.voxelMm = field.voxelMm;
    search.originMm = field.originMm;
    search.minVolumeMm3 =
        std::max(opt.minPieceVolumeMm3, 1000.0 * field.voxelMm * field.voxelMm * field.voxelMm);
    search.edgeMarginMm = bodyRadiusMm(opt.tenons) + field.voxelMm;
    search.maxPerPiece = opt.tenons.maxPerPiece;
    return search;
}

/// The usable tenon candidates (not rejected) of the pieces @p members.
std::vector<const TenonCandidate*> usableCandidates(const std::vector<TenonCandidate>& candidates,
                                                    std::initializer_list<uint32_t> members) {
    std::vector<const TenonCandidate*> out;
    for (const TenonCandidate& c : candidates)
        if (c.rejection.empty() && c.piece >= 0 &&
            std::find(members.begin(), members.end(), uint32_t(c.piece)) != members.end())
            out.push_back(&c);
    return out;
}

/// Re-cuts the pieces the plan could not place (piecesToRecut). Returns how many were cut.
size_t recutBlocked(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                    const PlannerInput& input, const std::vector<TenonCandidate>& candidates,
                    const FrameSweeps& sweeps, const PiecesOptions& opt, const RunContext& context) {
    const SplitSearch search = splitSearchFor(field, opt);
    size_t cut = 0;
    for (uint32_t p : piecesToRecut(out, input, sweeps, field.voxelMm, opt.tenons.maxPerPiece)) {
        const std::vector<const TenonCandidate*> mine = usableCandidates(candidates, {p});
        context.throwIfCancelled();
        std::vector<Vec3d> voxels;
        for (size_t s = 0; s < field.phi.size(); ++s)
            if (field.isInside(s) && field.owner[s] == p) voxels.push_back(field.world(field.coordOf(s)));
        const std::optional<SplitPlane> plane = findSplit(voxels, mine, sweeps, search);
        if (!plane) continue;
        const uint32_t q = splitPiece(out.pieces, grouping.cellSets, field, p, *plane);
        context.detail("piece " + std::to_string(p) +
                       " cannot be put on (the frame or other pieces in the way): re-cut in two (" +
                       std::to_string(p) + " and " + std::to_string(q) + ")");
        ++cut;
    }
    out.recutPieces += cut;
    if (cut > 0) grouping.faces = faceContacts(field, cells, grouping.cellSets, out.pieces);
    return cut;
}

/// The steps that rely on pegs but got none from @p tenons (their candidates' prisms would meet
/// another piece's tenon): their candidates along their direction are marked lost in
/// @p candidates and added to @p lost (ball, hole). Returns how many steps.
size_t markLostTenons(const mount::InstallationPlan& plan, const TenonPlan& tenons,
                      std::vector<TenonCandidate>& candidates, std::set<std::pair<zome::BallId, int>>& lost) {
    size_t steps = 0;
    for (const mount::MountStep& step : plan.steps) {
        size_t pegs = 0;
        bool isGluedOn = false;
        for (uint32_t p : step.pieces) {
            pegs += tenons.perPiece[p].size();
            for (const auto& [host, piece] : plan.gluedOn) isGluedOn |= piece == p;
        }
        if (pegs > 0 || isGluedOn) continue;
        ++steps;
        for (TenonCandidate& c : candidates)
            if (c.rejection.empty() && c.tenon.hole == step.hole &&
                std::count(step.pieces.begin(), step.pieces.end(), uint32_t(c.piece))) {
                c.rejection = "another tenon in the way";
                lost.insert({c.tenon.ball, c.tenon.hole});
            }
    }
    return steps;
}

/// The installation plan over @p candidates, planned again while a step that relies on pegs gets
/// none (its candidates lost to other pieces' tenons: they are dropped; a few times).
mount::InstallationPlan planOverCandidates(const Pieces& out, const VoxelField& field,
                                           const FaceContacts& faces, const FrameSweeps& sweeps,
                                           std::vector<TenonCandidate>& candidates,
                                           std::set<std::pair<zome::BallId, int>>& lost,
                                           const PiecesOptions& opt, const RunContext& context) {
    for (int attempt = 0;; ++attempt) {
        const PlannerInput input = plannerInput(out, field, candidates);
        mount::InstallationPlan plan =
            planMounting(input, sweeps, faces, field.voxelMm, tenonHoleSet(opt.tenons.holes),
                         opt.tenons.maxPerPiece, context);
        if (!plan.isBuildable() || attempt == 8) return plan;
        const TenonPlan tenons = chooseTenons(candidates, plan.holeOfPiece, opt.tenons);
        const size_t steps = markLostTenons(plan, tenons, candidates, lost);
        if (steps == 0) return plan;
        context.debug("mounting: " + std::to_string(steps) +
                      " steps lost their tenons to other pieces' tenons; planning again without them");
    }
}

/// The tenon candidates of the pieces as they are now, those other pieces' tenons took (@p lost)
/// rejected.
std::vector<TenonCandidate> freshCandidates(const zome::Structure& frame, const Transform4d& frameToGridMm,
                                            const ShellProbe& probe, const PiecesOptions& opt,
                                            const std::set<std::pair<zome::BallId, int>>& lost) {
    std::vector<TenonCandidate> candidates = findTenonCandidates(frame, frameToGridMm, probe, opt.tenons);
    for (TenonCandidate& c : candidates)
        if (c.rejection.empty() && lost.count({c.tenon.ball, c.tenon.hole}))
            c.rejection = "another tenon in the way";
    return candidates;
}

/// The pegs each piece gets along its planned direction.
std::vector<size_t> pegCounts(const std::vector<TenonCandidate>& candidates,
                              const mount::InstallationPlan& plan, const TenonOptions& o) {
    const TenonPlan tenons = chooseTenons(candidates, plan.holeOfPiece, o);
    std::vector<size_t> pegs;
    for (const auto& list : tenons.perPiece) pegs.push_back(list.size());
    return pegs;
}

size_t underHeld(const std::vector<size_t>& pegs, int minPerPiece) {
    return size_t(std::count_if(pegs.begin(), pegs.end(), [&](size_t n) { return n < size_t(minPerPiece); }));
}

/// Changes to the pieces that are kept only when they help: each is made, the tenons and the plan
/// made again, and undone unless fewer pieces are under-held (fewer than minPerPiece pegs) and the
/// plan can be carried out. Merges and pairs cut anew go through it.
class Replanner {
public:
    Replanner(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
              const ShellProbe& probe, const zome::Structure& frame, const Transform4d& frameToGridMm,
              const FrameSweeps& sweeps, std::vector<TenonCandidate>& candidates,
              std::set<std::pair<zome::BallId, int>>& lost, const PiecesOptions& opt,
              const RunContext& context)
        : out(out),
          field(field),
          cells(cells),
          grouping(grouping),
          probe(probe),
          frame(frame),
          frameToGridMm(frameToGridMm),
          sweeps(sweeps),
          candidates(candidates),
          lost(lost),
          opt(opt),
          context(context) {}

    /// The pegs each piece gets along its planned direction.
    std::vector<size_t> pegs() const { return pegCounts(candidates, out.plan, opt.tenons); }
    size_t underHeldNow() const { return underHeld(pegs(), opt.tenons.minPerPiece); }

    /// Makes @p change (to the pieces, their cell sets and the voxels' owners), recomputes the
    /// faces and plans again. Returns the new count of under-held pieces when it is below
    /// @p before with a plan that can be carried out; else undoes everything and returns nothing.
    std::optional<size_t> tryChange(const std::function<void()>& change, size_t before,
                                    const std::string& what) {
        const Stopwatch clock;
        State kept{out.pieces, grouping.cellSets, grouping.faces, field.owner, out.plan, candidates, lost};
        change();
        grouping.faces = faceContacts(field, cells, grouping.cellSets, out.pieces);
        candidates = freshCandidates(frame, frameToGridMm, probe, opt, lost);
        out.plan = planOverCandidates(out, field, grouping.faces, sweeps, candidates, lost, opt, context);
        const size_t after = out.plan.isBuildable() ? underHeldNow() : SIZE_MAX;
        context.debug("mounting: " + what + ": pieces under " + std::to_string(opt.tenons.minPerPiece) +
                      " pegs " + std::to_string(before) + " -> " +
                      (after == SIZE_MAX ? std::string("no plan") : std::to_string(after)) + " in " +
                      formatNumber(clock.seconds(), 3) + " s");
        if (after < before) return after;
        out.pieces = std::move(kept.pieces);
        grouping.cellSets = std::move(kept.cellSets);
        grouping.faces = std::move(kept.faces);
        field.owner = std::move(kept.owner);
        out.plan = std::move(kept.plan);
        candidates = std::move(kept.candidates);
        lost = std::move(kept.lost);
        return std::nullopt;
    }

    Pieces& out;
    VoxelField& field;
    const GridCells& cells;
    Grouping& grouping;
    const ShellProbe& probe;
    const zome::Structure& frame;
    const Transform4d& frameToGridMm;
    const FrameSweeps& sweeps;
    std::vector<TenonCandidate>& candidates;
    std::set<std::pair<zome::BallId, int>>& lost;
    const PiecesOptions& opt;
    const RunContext& context;

private:
    /// What a change touches, kept to undo it.
    struct State {
        std::vector<Piece> pieces;
        std::vector<CellSet> cellSets;
        FaceContacts faces;
        std::vector<uint32_t> owner;
        mount::InstallationPlan plan;
        std::vector<TenonCandidate> candidates;
        std::set<std::pair<zome::BallId, int>> lost;
    };
};

/// Pieces fewer than minPerPiece pegs hold are printed as one with a neighbour (detail/merges.h) and
/// the plan made again, while that leaves fewer such pieces and a plan that can be carried out. Each
/// round tries every piece's best merge at once, and when that does not help, the merges one by one
/// (at most kSingleMergeTrials); a trial that does not help is undone.
void mergeUnderHeld(Replanner& r, const Fabrication& fabrication) {
    const PiecesOptions& opt = r.opt;
    MergeSearch search;
    search.printerMm = fabrication.pieceBoxMm();
    search.fitMarginMm = fabrication.fitMarginMm;
    search.minPerPiece = opt.tenons.minPerPiece;
    search.maxPerPiece = opt.tenons.maxPerPiece;
    const int minPegs = opt.tenons.minPerPiece;
    // Whether merging @p pairs helped (then it is kept).
    auto attempt = [&](const std::vector<std::pair<uint32_t, uint32_t>>& pairs, size_t before) {
        const std::optional<size_t> after =
            r.tryChange([&] { mergeAll(r.out.pieces, r.grouping.cellSets, r.field, pairs); }, before,
                        std::to_string(pairs.size()) + " merge(s)");
        if (!after) return false;
        r.out.mergedPieces += pairs.size();
        r.context.detail(std::to_string(pairs.size()) +
                         " piece(s) too few pegs would hold printed as one with a neighbour (" +
                         std::to_string(before) + " -> " + std::to_string(*after) + " pieces under " +
                         std::to_string(minPegs) + " pegs)");
        return true;
    };
    for (int round = 0; round < kMergeRounds && r.out.plan.isBuildable(); ++round) {
        r.context.throwIfCancelled();
        const std::vector<size_t> pegs = r.pegs();
        const size_t before = underHeld(pegs, minPegs);
        if (before == 0) return;
        const std::vector<MergeOption> options =
            mergeOptions(r.out.pieces, r.grouping.cellSets, r.field, pegs,
                         plannerInput(r.out, r.field, r.candidates), r.sweeps, search);
        const auto batch = disjointMerges(options);
        if (batch.empty()) return;
        if (attempt(batch, before)) continue;
        bool isMerged = false;
        for (size_t i = 0; i < options.size() && i < kSingleMergeTrials && !isMerged; ++i) {
            if (batch.size() == 1 && batch[0] == std::make_pair(options[i].piece, options[i].neighbor))
                continue;
            r.context.throwIfCancelled();
            isMerged = attempt({{options[i].piece, options[i].neighbor}}, before);
        }
        if (!isMerged) return;
    }
}

/// Plane searches and cuts tried per run by recutUnderHeldPairs: each search takes up to 3 s on a
/// 400 mm bunny's pieces, each trial a plan (about 2 s).
constexpr size_t kPairSearches = 12;
constexpr size_t kPairTrials = 8;
/// Planes tried per pair, best first: a half the search counts two candidates for can lose one to
/// a neighbour's tenon when the plan is made again, and the next plane may not.
constexpr size_t kPlanesPerPair = 3;

/// A piece fewer than minPerPiece pegs hold whose union with a neighbour does not fit the printer
/// (so no merge helps) is cut anew with it: the two become one and are cut again along a plane of
/// findHoldingSplits, which gives both halves minPerPiece tenons and fits them, and the plan is
/// made again; kept when fewer pieces are under-held, else the next plane is tried. Smallest
/// under-held piece first, its neighbours by the largest common face. docs/mounting.md, "Pairs
/// cut anew".
void recutUnderHeldPairs(Replanner& r, const Fabrication& fabrication) {
    const PiecesOptions& opt = r.opt;
    const size_t minPegs = size_t(opt.tenons.minPerPiece);
    SplitSearch search = splitSearchFor(r.field, opt);  // voxelMm: the union's cells, below
    size_t searches = 0, trials = 0;
    while (searches < kPairSearches && trials < kPairTrials && r.out.plan.isBuildable()) {
        const std::vector<size_t> pegs = r.pegs();
        const size_t before = underHeld(pegs, int(minPegs));
        if (before == 0) return;
        std::vector<std::pair<double, uint32_t>> weak;  // (volume, piece): smallest first
        for (uint32_t p = 0; p < pegs.size(); ++p)
            if (pegs[p] < minPegs) weak.push_back({r.out.pieces[p].shellVolumeMm3, p});
        std::sort(weak.begin(), weak.end());
        const std::vector<std::vector<size_t>> slots = slotsOfPieces(r.field, r.out.pieces.size());
        bool isCut = false;
        for (size_t w = 0; w < weak.size() && !isCut && searches < kPairSearches; ++w) {
            const uint32_t p = weak[w].second;
            std::vector<std::pair<double, uint32_t>> byFace;  // (−area, neighbour)
            for (const auto& [q, area] : r.out.pieces[p].neighbors)
                if (isMergeable(r.grouping.cellSets, p, q)) byFace.push_back({-area, q});
            std::sort(byFace.begin(), byFace.end());
            for (size_t k = 0; k < byFace.size() && !isCut && searches < kPairSearches; ++k) {
                r.context.throwIfCancelled();
                const uint32_t q = byFace[k].second;
                std::vector<size_t> both = slots[p];
                both.insert(both.end(), slots[q].begin(), slots[q].end());
                const CoarseCells union_ = coarseInside(r.field, both);
                if (coarseFit(union_, fabrication.pieceBoxMm(), fabrication.fitMarginMm).fits)
                    continue;  // a merge would do; mergeUnderHeld found it no better
                const std::vector<const TenonCandidate*> mine = usableCandidates(r.candidates, {p, q});
                search.voxelMm = union_.cellMm;
                ++searches;
                const Stopwatch clock;
                const std::vector<SplitPlane> planes =
                    findHoldingSplits(union_, mine, r.sweeps, search, fabrication.pieceBoxMm(),
                                      fabrication.fitMarginMm, minPegs, kPlanesPerPair);
                r.context.debug("mounting: pieces " + std::to_string(p) + " and " + std::to_string(q) + ": " +
                                std::to_string(planes.size()) + " plane(s) that hold both, in " +
                                formatNumber(clock.seconds(), 3) + " s");
                const std::string pair = std::to_string(p) + " and " + std::to_string(q);
                for (size_t k2 = 0; k2 < planes.size() && !isCut && trials < kPairTrials; ++k2) {
                    ++trials;
                    const std::optional<size_t> after = r.tryChange(
                        [&] {
                            const uint32_t kept = mergePieces(r.out.pieces, r.grouping.cellSets, r.field,
                                                              std::min(p, q), std::max(p, q));
                            splitPiece(r.out.pieces, r.grouping.cellSets, r.field, kept, planes[k2]);
                        },
                        before, "pieces " + pair + " cut anew");
                    if (!after) continue;
                    ++r.out.recutPairs;
                    r.context.detail("pieces " + pair +
                                     " cut anew along another plane, so that both are held (" +
                                     std::to_string(before) + " -> " + std::to_string(*after) +
                                     " pieces under " + std::to_string(minPegs) + " pegs)");
                    isCut = true;
                }
                if (trials == kPairTrials) return;
            }
        }
        if (!isCut) return;
    }
}

/// The installation plan, re-cutting blocked pieces and planning again (a few rounds), and the
/// tenons along each piece's direction.
void planMountingAndTenons(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                           const ShellProbe& probe, const zome::Structure& frame,
                           const Transform4d& frameToGridMm, const Fabrication& fabrication,
                           const PiecesOptions& opt, const RunContext& context) {
    const FrameSweeps sweeps(frame, frameToGridMm, planBounds(field, frame, frameToGridMm), field.voxelMm,
                             opt.mount.frameMarginMm);
    std::vector<TenonCandidate> candidates;
    std::set<std::pair<zome::BallId, int>> lost;  // candidates other pieces' tenons took
    size_t lastUnplaced = SIZE_MAX;
    for (int round = 0;; ++round) {
        const Stopwatch clock;
        candidates = freshCandidates(frame, frameToGridMm, probe, opt, lost);
        context.debug("mounting: " + std::to_string(candidates.size()) + " tenon candidates in " +
                      formatNumber(clock.seconds(), 3) + " s");
        context.throwIfCancelled();
        out.plan = planOverCandidates(out, field, grouping.faces, sweeps, candidates, lost, opt, context);
        const PlannerInput input = plannerInput(out, field, candidates);
        context.debug("mounting: plan " + std::to_string(round) + " in " + formatNumber(clock.seconds(), 3) +
                      " s");
        if (out.plan.isBuildable() || round == kRecutRounds) break;
        // Re-cutting that places no more pieces is given up: on the cheese at 700 mm the halves
        // of 116 pieces lining its tunnels were as stuck as the pieces (110 stuck bodies, then 225).
        const size_t unplaced =
            size_t(std::count(out.plan.holeOfPiece.begin(), out.plan.holeOfPiece.end(), -1));
        if (unplaced >= lastUnplaced) {
            context.detail("mounting: re-cutting placed no more pieces (" + std::to_string(unplaced) +
                           " without a direction, " + std::to_string(lastUnplaced) +
                           " before): no more rounds");
            break;
        }
        lastUnplaced = unplaced;
        const size_t cut = recutBlocked(out, field, cells, grouping, input, candidates, sweeps, opt, context);
        context.debug("mounting: re-cut " + std::to_string(cut) + " in " + formatNumber(clock.seconds(), 3) +
                      " s");
        if (cut == 0) break;
    }
    Replanner replanner(out, field, cells, grouping, probe, frame, frameToGridMm, sweeps, candidates, lost,
                        opt, context);
    mergeUnderHeld(replanner, fabrication);
    if (opt.isRecuttingPairs) recutUnderHeldPairs(replanner, fabrication);
    const size_t unpinned = placePins(out, field, cells, grouping.cellSets, opt, GlueOnRule{}.minCosine);
    if (unpinned > 0)
        context.warn(std::to_string(unpinned) + " of " +
                     std::to_string(out.plan.glued.size() + out.plan.gluedOn.size()) +
                     " glued pairs have fewer than " + std::to_string(opt.pins.perPair) +
                     " alignment pins (the face has no room): line them up by eye when gluing");
    TenonPlan plan = chooseTenons(candidates, out.plan.holeOfPiece, opt.tenons);
    for (size_t p = 0; p < out.pieces.size(); ++p) {
        out.pieces[p].hole = out.plan.holeOfPiece[p];
        out.pieces[p].tenons = std::move(plan.perPiece[p]);
        out.pieces[p].tenonShortfall = std::move(plan.shortfall[p]);
    }
    warnShortfall(out, opt.tenons, context);
    for (const std::string& problem : out.plan.problems) context.warn("installation plan: " + problem);
}

}  // namespace

void planPieces(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                const FloatGrid& shell, const zome::Structure& frame, const Transform4d& frameToGridMm,
                const Fabrication& fabrication, const PiecesOptions& opt, const RunContext& context) {
    const FloatGrid::ConstAccessor probeAccessor = shell.getConstAccessor();
    const openvdb::tools::GridSampler<FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
        probeAccessor, shell.transform());
    ShellProbe probe;
    probe.voxelMm = field.voxelMm;
    probe.wallMm = fabrication.wallMm;
    probe.signedDistanceMm = [&](const Vec3d& p) {
        return double(sampler.wsSample(openvdb::Vec3d(p[0], p[1], p[2])));
    };
    // The owner of the nearest voxel, band voxels included: a point the trilinear φ puts just
    // inside the wall may have its nearest voxel centre just outside.
    probe.pieceAt = [&](const Vec3d& p) -> int64_t {
        const size_t s = field.slotAt(p);
        if (s == SIZE_MAX || field.owner[s] == kNone) return -1;
        return int64_t(field.owner[s]);
    };
    if (opt.tenons.maxPerPiece > 0) {
        planMountingAndTenons(out, field, cells, grouping, probe, frame, frameToGridMm, fabrication, opt,
                              context);
    } else {
        out.plan = {};
        out.plan.holeOfPiece.assign(out.pieces.size(), -1);
        out.plan.problems.push_back("no tenons (--max-tenons 0): nothing holds the pieces on the frame");
    }
    const size_t pieceCount = out.pieces.size();
    context.throwIfCancelled();
    if (!opt.label.isEnabled) return;
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

}  // namespace zomefab::pieces::detail
