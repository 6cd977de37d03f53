// SPDX-License-Identifier: GPL-3.0-or-later
// Changes to the pieces kept only when they help: merges, pairs cut anew, glued groups
// (detail/replan.h, docs/mounting.md).
#include "zomefab/pieces/detail/replan.h"

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <tuple>

#include "zomefab/core/format.h"
#include "zomefab/pieces/detail/merges.h"
#include "zomefab/pieces/detail/staves.h"

namespace zomefab::pieces::detail {

size_t underHeld(const std::vector<size_t>& pegs, int minPerPiece) {
    return size_t(std::count_if(pegs.begin(), pegs.end(), [&](size_t n) { return n < size_t(minPerPiece); }));
}

std::vector<size_t> stepPegs(const mount::InstallationPlan& plan, const std::vector<size_t>& pegs) {
    std::vector<size_t> out;
    for (const mount::MountStep& step : plan.steps) {
        size_t n = 0;
        for (uint32_t p : step.pieces) n += pegs[p];
        out.push_back(n);
    }
    return out;
}

std::optional<size_t> Replanner::tryChange(const std::function<void()>& change, size_t before,
                                           const std::string& what, Change kind,
                                           const std::function<bool()>& refine) {
    const Stopwatch clock;
    State kept{out.pieces, grouping.cellSets, grouping.faces, field.owner, out.plan, candidates,
               lost,       preGlued,          std::nullopt};
    const bool isFrame = kind == Change::kFrame || kind == Change::kStaves;
    if (isFrame) kept.frame = frame;
    change();
    const bool steps = kind == Change::kGroups || kind == Change::kParts;
    if (kind == Change::kPieces || kind == Change::kMorePieces || kind == Change::kParts)
        grouping.faces = faceContacts(field, cells, grouping.cellSets, out.pieces);
    else if (isFrame)
        remakeSweeps();
    if (kind !=
        Change::kGroups)  // glued groups leave the pieces and the frame, so the candidates, as they are
        candidates = freshCandidates(frame, frameToGridMm, probe, opt, lost);
    out.plan = planOverCandidates(out, field, grouping, sweeps, candidates, lost, opt, context, preGlued);
    auto underHeldAfter = [&] {
        // Staves no peg holds; a plan that could be carried out must stay so.
        if (kind == Change::kStaves)
            return kept.plan.isBuildable() && !out.plan.isBuildable()
                       ? SIZE_MAX
                       : peglessStaves(out.plan, grouping.cellSets);
        return !out.plan.isBuildable() ? SIZE_MAX : steps ? underHeldStepsNow() : underHeldNow();
    };
    size_t after = underHeldAfter();
    if (after == before && refine && refine()) {
        // As many under-held as before: one change more on top, planned and judged with it.
        out.plan = planOverCandidates(out, field, grouping, sweeps, candidates, lost, opt, context, preGlued);
        after = underHeldAfter();
    }
    context.debug("mounting: " + what + ": " +
                  (kind == Change::kStaves ? std::string("staves no peg holds")
                                           : (steps ? "steps" : "pieces") + std::string(" under ") +
                                                 std::to_string(opt.tenons.minPerPiece) + " pegs") +
                  " " + std::to_string(before) + " -> " +
                  (after == SIZE_MAX ? std::string("no plan") : std::to_string(after)) + " in " +
                  formatNumber(clock.seconds(), 3) + " s");
    // kMorePieces: more pieces held (pieces less under-held ones), and no more under-held;
    // kParts: no more steps under-held.
    const bool isBetter = kind == Change::kMorePieces
                              ? after <= before && out.pieces.size() - after > kept.pieces.size() - before
                          : kind == Change::kParts ? after <= before
                                                   : after < before;
    if (isBetter) return after;
    out.pieces = std::move(kept.pieces);
    grouping.cellSets = std::move(kept.cellSets);
    grouping.faces = std::move(kept.faces);
    field.owner = std::move(kept.owner);
    out.plan = std::move(kept.plan);
    candidates = std::move(kept.candidates);
    lost = std::move(kept.lost);
    preGlued = std::move(kept.preGlued);
    if (kept.frame) {
        frame = std::move(*kept.frame);
        remakeSweeps();
    }
    return std::nullopt;
}

namespace {

using Pairs = std::vector<std::pair<uint32_t, uint32_t>>;

/// The rounds mergeUnderHeld and glueUnderHeld share: each lists the pairs worth trying, best first
/// (@p listPairs; none: done), tries those that share no member together (disjointPairs) and, when
/// that does not help (@p attempt returns false: undone), the first @p singles one by one. Stops
/// after @p rounds, or when a round keeps nothing.
void tryPairsInRounds(Replanner& r, int rounds, size_t singles, const std::function<Pairs()>& listPairs,
                      const std::function<bool(const Pairs&)>& attempt) {
    for (int round = 0; round < rounds && r.out.plan.isBuildable(); ++round) {
        r.context.throwIfCancelled();
        const Pairs options = listPairs();
        const Pairs batch = disjointPairs(options);
        if (batch.empty()) return;
        if (attempt(batch)) continue;
        bool isKept = false;
        for (size_t i = 0; i < options.size() && i < singles && !isKept; ++i) {
            if (batch.size() == 1 && batch[0] == options[i]) continue;
            r.context.throwIfCancelled();
            isKept = attempt({options[i]});
        }
        if (!isKept) return;
    }
}

/// Merge under-held pieces, plan again: at most this often (each piece merges once per round; the
/// elephant at 400 mm merges three specks into one piece in three rounds, 0.7 s each).
constexpr int kMergeRounds = 8;
/// When a round's merges together do not help, this many are tried one by one (each a plan).
constexpr size_t kSingleMergeTrials = 4;

/// Plane searches and cuts tried per run by recutUnderHeldPairs: each search takes up to 3 s on a
/// 400 mm bunny's pieces, each trial a plan (about 2 s).
constexpr size_t kPairSearches = 12;
constexpr size_t kPairTrials = 8;
/// Planes tried per pair, best first: a half the search counts two candidates for can lose one to
/// a neighbour's tenon when the plan is made again, and the next plane may not.
constexpr size_t kPlanesPerPair = 3;

/// Rounds of glueUnderHeld (each a plan; a round glues several pairs at once).
constexpr int kGlueRounds = 8;
/// When a round's glues together do not help, this many are tried one by one (each a plan; at
/// 700 mm a plan of 47 pieces takes 15–20 s). Fewer cost more than they save: with two, bunny_cgal
/// at 700 mm kept 39 of 48 steps held by two pegs instead of 40 of 41, bunny_npm 30 of 46 instead
/// of 31 of 33; halving a batch that does not help before the singles did no better.
constexpr size_t kSingleGlueTrials = 4;

/// For each step under minPerPiece pegs, the neighbouring steps it could be glued to before
/// mounting: a common cut face large enough for pins (GlueOnRule::minFaceMm2), at most
/// kMaxGluedPieces pieces together, and a free direction for the two with more tenon candidates
/// than the step has pegs and at least minPerPiece. Each step's options best first (most
/// candidates, then the largest face); steps smallest first.
Pairs glueUnderHeldOptions(const Replanner& r, const std::vector<size_t>& pegs) {
    const mount::InstallationPlan& plan = r.out.plan;
    const size_t minPegs = size_t(r.opt.tenons.minPerPiece);
    const PlannerInput input = plannerInput(r.out, r.field, r.candidates);
    const double minFaceVoxels = GlueOnRule{}.minFaceMm2 / (r.field.voxelMm * r.field.voxelMm);
    std::vector<MountBody> steps(plan.steps.size());
    std::vector<std::pair<double, size_t>> weak;  // (shell volume, step)
    for (size_t s = 0; s < plan.steps.size(); ++s) {
        steps[s].pieces = plan.steps[s].pieces;
        if (pegs[s] >= minPegs) continue;
        double volume = 0.0;
        for (uint32_t p : plan.steps[s].pieces) volume += r.out.pieces[p].shellVolumeMm3;
        weak.push_back({volume, s});
    }
    std::sort(weak.begin(), weak.end());
    Pairs options;  // (step, neighbour)
    for (const auto& [volume, s] : weak) {
        std::vector<std::tuple<size_t, size_t, uint32_t>> mine;  // (−candidates, −contact, neighbour)
        for (size_t t = 0; t < steps.size(); ++t) {
            if (t == s || steps[s].pieces.size() + steps[t].pieces.size() > kMaxGluedPieces) continue;
            const size_t contact = bodyContact(steps[s], steps[t], r.grouping.faces);
            if (contact == 0 || double(contact) < minFaceVoxels) continue;
            std::vector<uint32_t> members = steps[s].pieces;
            members.insert(members.end(), steps[t].pieces.begin(), steps[t].pieces.end());
            r.context.throwIfCancelled();
            const MountBody joined =
                makeBody(members, input, r.sweeps, r.field.voxelMm, r.opt.tenons.maxPerPiece, 1);
            const DirectionOption* best = joined.bestFree();
            if (!best || best->tenons < minPegs || best->tenons <= pegs[s]) {
                r.context.debug("mounting: step " + std::to_string(s) + " glued to step " +
                                std::to_string(t) + ": " +
                                (best ? std::to_string(best->tenons) + " tenon candidates at best"
                                      : std::string("no free direction with tenons")));
                continue;
            }
            mine.push_back({size_t(0) - best->tenons, size_t(0) - contact, uint32_t(t)});
        }
        std::sort(mine.begin(), mine.end());
        for (const auto& [negTenons, negContact, t] : mine) options.push_back({uint32_t(s), t});
    }
    return options;
}

/// Rounds of mergeGluedPairs (each a plan; a round merges one pair per piece).
constexpr int kGluedMergeRounds = 8;
/// When a round's merges together do not help, this many are tried one by one.
constexpr size_t kSingleGluedMergeTrials = 4;

/// The pairs of pieces the maker glues together anyway — neighbours in one glued group, or a piece
/// and the host it is glued onto — of which one at least is under minPerPiece pegs, that can be
/// merged (isMergeable) and whose union fits the printer. The smaller pair first (by the smaller
/// piece's shell volume, then the larger's); deterministic.
Pairs gluedMergeOptions(const Replanner& r, const Fabrication& fabrication) {
    const std::vector<size_t> pegs = r.pegs();
    const size_t minPegs = size_t(r.opt.tenons.minPerPiece);
    std::set<std::pair<uint32_t, uint32_t>> glued;
    for (const auto& [a, b] : r.out.plan.gluedOn)
        if (a != b) glued.insert({std::min(a, b), std::max(a, b)});
    for (const mount::MountStep& step : r.out.plan.steps)
        for (uint32_t a : step.pieces)
            for (const auto& [b, area] : r.out.pieces[a].neighbors)
                if (a < b && std::count(step.pieces.begin(), step.pieces.end(), b) > 0) glued.insert({a, b});
    const std::vector<std::vector<size_t>> slots = slotsOfPieces(r.field, r.out.pieces.size());
    std::vector<std::tuple<double, double, uint32_t, uint32_t>> options;  // (smaller, larger, a, b)
    for (const auto& [a, b] : glued) {
        if ((pegs[a] >= minPegs && pegs[b] >= minPegs) || !isMergeable(r.grouping.cellSets, a, b)) continue;
        r.context.throwIfCancelled();
        if (!coarseFit(coarseUnion(r.field, slots[a], slots[b]), fabrication.pieceBoxMm(),
                       fabrication.fitMarginMm)
                 .fits)
            continue;
        const double va = r.out.pieces[a].shellVolumeMm3, vb = r.out.pieces[b].shellVolumeMm3;
        options.push_back({std::min(va, vb), std::max(va, vb), a, b});
    }
    std::sort(options.begin(), options.end());
    Pairs out;
    for (const auto& [smaller, larger, a, b] : options) out.push_back({a, b});
    return out;
}

/// Merges in rounds (tryPairsInRounds) the pairs @p listPairs gives while pieces are under-held:
/// each trial merges (mergeAll) and plans again, and is kept only when fewer pieces are under-held
/// with a plan that can be carried out. The groups glued before planning (Replanner::preGlued)
/// follow the pieces' new numbers; a merged pair is no longer glued. @p what: the pairs, for the
/// message.
void mergeInRounds(Replanner& r, int rounds, size_t singles, const std::function<Pairs()>& listPairs,
                   const std::string& what) {
    size_t before = 0;
    auto attempt = [&](const Pairs& pairs) {
        const std::optional<size_t> after = r.tryChange(
            [&] {
                const std::vector<uint32_t> now = mergeAll(r.out.pieces, r.grouping.cellSets, r.field, pairs);
                std::vector<std::pair<uint32_t, uint32_t>> kept;
                for (const auto& [a, b] : r.preGlued)
                    if (now[a] != now[b]) kept.push_back({now[a], now[b]});
                r.preGlued = std::move(kept);
            },
            before, std::to_string(pairs.size()) + " merge(s)");
        if (!after) return false;
        r.out.mergedPieces += pairs.size();
        r.context.detail(std::to_string(pairs.size()) + " " + what + " (" + std::to_string(before) + " -> " +
                         std::to_string(*after) + " pieces under " +
                         std::to_string(r.opt.tenons.minPerPiece) + " pegs)");
        return true;
    };
    tryPairsInRounds(
        r, rounds, singles,
        [&] {
            before = r.underHeldNow();
            return before == 0 ? Pairs{} : listPairs();
        },
        attempt);
}

}  // namespace

std::vector<PairCut> pairCuts(const CoarseCells& cells, const std::vector<const TenonCandidate*>& candidates,
                              const FrameSweeps& sweeps, const SplitSearch& search,
                              const Fabrication& fabrication, size_t minPegs) {
    const Vec3d box = fabrication.pieceBoxMm();
    const double margin = fabrication.fitMarginMm;
    const HoldingSplits splits =
        findHoldingSplits(cells, candidates, sweeps, search, box, margin, minPegs, kPlanesPerPair);
    std::vector<PairCut> out;
    for (const SplitPlane& plane : splits.bothFit) out.push_back({plane, std::nullopt, 0});
    for (const SplitPlane& first : splits.oneFits) {
        std::array<CoarseCells, 2> halves;
        for (CoarseCells& h : halves) h.cellMm = cells.cellMm;
        for (const Vec3d& x : cells.centresMm)
            halves[dot(first.normal, x) > first.offsetMm].centresMm.push_back(x);
        const uint8_t large = coarseFit(halves[0], box, margin).fits ? 1 : 0;
        // The large half's candidates: those findHoldingSplits counted for it (clear of the plane).
        const double sign = large ? 1.0 : -1.0;
        std::vector<const TenonCandidate*> mine;
        for (const TenonCandidate* c : candidates)
            if (sign * (dot(first.normal, c->tenon.pointAt(c->tenon.baseMm)) - first.offsetMm) >=
                search.edgeMarginMm)
                mine.push_back(c);
        for (const SplitPlane& second :
             findHoldingSplits(halves[large], mine, sweeps, search, box, margin, minPegs, kPlanesPerPair)
                 .bothFit)
            out.push_back({first, second, large});
    }
    return out;
}

void mergeUnderHeld(Replanner& r, const Fabrication& fabrication) {
    const PiecesOptions& opt = r.opt;
    MergeSearch search;
    search.printerMm = fabrication.pieceBoxMm();
    search.fitMarginMm = fabrication.fitMarginMm;
    search.minPerPiece = opt.tenons.minPerPiece;
    search.maxPerPiece = opt.tenons.maxPerPiece;
    mergeInRounds(
        r, kMergeRounds, kSingleMergeTrials,
        [&] {
            Pairs pairs;
            for (const MergeOption& o :
                 mergeOptions(r.out.pieces, r.grouping.cellSets, r.field, r.pegs(),
                              plannerInput(r.out, r.field, r.candidates), r.sweeps, search))
                pairs.push_back({o.piece, o.neighbor});
            return pairs;
        },
        "piece(s) too few pegs would hold printed as one with a neighbour");
}

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
                const CoarseCells union_ = coarseUnion(r.field, slots[p], slots[q]);
                if (coarseFit(union_, fabrication.pieceBoxMm(), fabrication.fitMarginMm).fits)
                    continue;  // a merge would do; mergeUnderHeld found it no better
                search.voxelMm = union_.cellMm;
                ++searches;
                const Stopwatch clock;
                const std::vector<PairCut> cuts = pairCuts(union_, usableCandidates(r.candidates, {p, q}),
                                                           r.sweeps, search, fabrication, minPegs);
                r.context.debug("mounting: pieces " + std::to_string(p) + " and " + std::to_string(q) + ": " +
                                std::to_string(cuts.size()) + " cut(s) that hold every part, in " +
                                formatNumber(clock.seconds(), 3) + " s");
                const std::string pair = std::to_string(p) + " and " + std::to_string(q);
                for (size_t c = 0; c < cuts.size() && !isCut && trials < kPairTrials; ++c) {
                    ++trials;
                    const PairCut& cut = cuts[c];
                    const std::string into = cut.second ? "three pieces" : "two other pieces";
                    const std::optional<size_t> after = r.tryChange(
                        [&] {
                            const uint32_t kept = mergePieces(r.out.pieces, r.grouping.cellSets, r.field,
                                                              std::min(p, q), std::max(p, q));
                            const uint32_t beyond =
                                splitPiece(r.out.pieces, r.grouping.cellSets, r.field, kept, cut.first);
                            if (cut.second)
                                splitPiece(r.out.pieces, r.grouping.cellSets, r.field,
                                           cut.secondSide ? beyond : kept, *cut.second);
                        },
                        before, "pieces " + pair + " cut anew into " + into,
                        cut.second ? Replanner::Change::kMorePieces : Replanner::Change::kPieces);
                    if (!after) continue;
                    ++r.out.recutPairs;
                    // Pieces held by minPerPiece pegs or more: a cut into three adds one.
                    const size_t heldBefore = r.out.pieces.size() - (cut.second ? 1 : 0) - before;
                    r.context.detail("pieces " + pair + " cut anew into " + into + " (pieces under " +
                                     std::to_string(minPegs) + " pegs " + std::to_string(before) + " -> " +
                                     std::to_string(*after) + ", held by " + std::to_string(minPegs) +
                                     " or more " + std::to_string(heldBefore) + " -> " +
                                     std::to_string(r.out.pieces.size() - *after) + ")");
                    isCut = true;
                }
                if (trials == kPairTrials) return;
            }
        }
        if (!isCut) return;
    }
}

void glueUnderHeld(Replanner& r) {
    const size_t minPegs = size_t(r.opt.tenons.minPerPiece);
    // The groups the plan glued where no order existed start glued: the trials plan without
    // gluing more (planOverCandidates), so they must not need those rounds again.
    if (r.preGlued.empty()) r.preGlued = r.out.plan.glued;
    // A group that holds its step may take a peg from another step (the armadillo at 500 mm: its
    // leg glued to the hip is held, and the piece next to them loses a peg to the group's path):
    // that step's own best glue, on top, is tried with it (one plan more).
    auto refine = [&] {
        const Pairs more = glueUnderHeldOptions(r, stepPegs(r.out.plan, r.pegs()));
        if (more.empty()) return false;
        const mount::InstallationPlan& plan = r.out.plan;
        r.preGlued.push_back({plan.steps[more[0].first].pieces[0], plan.steps[more[0].second].pieces[0]});
        return true;
    };
    auto attempt = [&](const Pairs& batch, size_t before) {
        const mount::InstallationPlan plan = r.out.plan;
        const size_t gluedBefore = r.preGlued.size();
        const std::optional<size_t> after = r.tryChange(
            [&] {
                for (const auto& [step, neighbor] : batch)
                    r.preGlued.push_back({plan.steps[step].pieces[0], plan.steps[neighbor].pieces[0]});
            },
            before, std::to_string(batch.size()) + " glued group(s)", Replanner::Change::kGroups, refine);
        if (!after) return false;
        const size_t glued = r.preGlued.size() - gluedBefore;  // the batch, and refine's when it helped
        r.out.gluedForPegs += glued;
        r.context.detail(std::to_string(glued) +
                         " step(s) too few pegs would hold glued to a neighbour before mounting (" +
                         std::to_string(before) + " -> " + std::to_string(*after) + " steps under " +
                         std::to_string(minPegs) + " pegs)");
        return true;
    };
    size_t before = 0;
    tryPairsInRounds(
        r, kGlueRounds, kSingleGlueTrials,
        [&] {
            const std::vector<size_t> pegs = stepPegs(r.out.plan, r.pegs());
            before = underHeld(pegs, int(minPegs));
            return before == 0 ? Pairs{} : glueUnderHeldOptions(r, pegs);
        },
        [&](const Pairs& pairs) { return attempt(pairs, before); });
}

void mergeGluedPairs(Replanner& r, const Fabrication& fabrication) {
    mergeInRounds(
        r, kGluedMergeRounds, kSingleGluedMergeTrials, [&] { return gluedMergeOptions(r, fabrication); },
        "glued pair(s) with a piece too few pegs would hold printed as one");
}

}  // namespace zomefab::pieces::detail
