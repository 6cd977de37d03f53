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
#include "zomefab/pieces/detail/keystone.h"
#include "zomefab/pieces/detail/merges.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/pins.h"
#include "zomefab/pieces/detail/replan.h"
#include "zomefab/pieces/detail/splits.h"
#include "zomefab/pieces/detail/stages.h"
#include "zomefab/pieces/detail/staves.h"
#include "zomefab/pieces/detail/thin_wall.h"
#include "zomefab/pieces/detail/tunnels.h"

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
/// Keystones cut after the re-cuts, each followed by a plan: a ring around a hole needs one, a few
/// rings a few.
constexpr int kKeystoneRounds = 3;
/// Keystones are tried only while at most this many pieces are placed nowhere: three rings of up to
/// eight pieces (the torus of docs/mounting.md: 7).
constexpr size_t kMaxKeystoneStuck = 24;
/// Tunnel linings are cut only while at most this many pieces are placed nowhere: a few tunnels'
/// linings (the 300 mm cube's: 19 pieces), not the cheese's hundreds (docs/benchmarks.md, "Tunnels").
constexpr size_t kMaxTunnelStuck = 100;

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

/// Re-cuts the pieces the plan could not place (piecesToRecut). Returns how many were cut.
size_t recutBlocked(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                    const PlannerInput& input, const std::vector<TenonCandidate>& candidates,
                    const FrameSweeps& sweeps, const PiecesOptions& opt, const RunContext& context) {
    const SplitSearch search = splitSearchFor(field, opt);
    size_t cut = 0;
    for (uint32_t p : piecesToRecut(out, input, sweeps, field.voxelMm, opt.tenons.maxPerPiece)) {
        if (isStaveSet(grouping.cellSets[p])) continue;  // its seams run along its lift
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

/// The plan made once more without gluing stuck bodies: the pieces stuck on their own (a plan's
/// glued groups hide which piece a ring turns on, or which pieces line a tunnel).
mount::InstallationPlan planUnglued(const PlannerInput& input, const FrameSweeps& sweeps,
                                    const Grouping& grouping, double voxelMm, const PiecesOptions& opt,
                                    const RunContext& context) {
    PlannerInput unglued = input;
    unglued.isGluingStuck = false;
    return planMounting(unglued, sweeps, grouping.faces, voxelMm, tenonHoleSet(opt.tenons.holes),
                        opt.tenons.maxPerPiece, context);
}

/// Cuts a keystone out of one piece that is free of the frame alone but placed nowhere (the
/// largest for which findKeystone finds one): the wedges along the faces that block it become
/// pieces of their own. Returns how many pieces were added (0: none found).
size_t cutKeystone(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                   const PlannerInput& input, const std::vector<TenonCandidate>& candidates,
                   const FrameSweeps& sweeps, const PiecesOptions& opt, const RunContext& context) {
    const SplitSearch search = splitSearchFor(field, opt);
    const mount::InstallationPlan plan = planUnglued(input, sweeps, grouping, field.voxelMm, opt, context);
    std::vector<std::pair<double, uint32_t>> stuck;  // (−volume, piece)
    for (uint32_t p = 0; p < out.pieces.size(); ++p)
        if (plan.holeOfPiece[p] < 0 && !input.candidatesByHole[p].empty() &&
            !isStaveSet(grouping.cellSets[p]))
            stuck.push_back({-out.pieces[p].shellVolumeMm3, p});
    std::sort(stuck.begin(), stuck.end());
    const std::vector<std::vector<size_t>> slots = slotsOfPieces(field, out.pieces.size());
    for (const auto& [negVolume, p] : stuck) {
        context.throwIfCancelled();
        const MountBody body = makeBody({p}, input, sweeps, field.voxelMm, opt.tenons.maxPerPiece);
        if (!body.bestFree()) continue;  // the frame is in its way: no cut of the faces frees it
        std::vector<Vec3d> voxels;
        std::map<uint32_t, std::vector<Vec3d>> touching;
        for (size_t s : slots[p]) {
            if (!field.isInside(s)) continue;
            const Vec3d x = field.world(field.coordOf(s));
            voxels.push_back(x);
            for (int axis = 0; axis < 3; ++axis)
                for (const double step : {-field.voxelMm, field.voxelMm}) {
                    Vec3d y = x;
                    y[size_t(axis)] += step;
                    const size_t t = field.slotAt(y);
                    if (t != SIZE_MAX && field.isInside(t) && field.owner[t] != p)
                        touching[field.owner[t]].push_back(x);
                }
        }
        const std::optional<Keystone> key =
            findKeystone(p, voxels, touching, body, grouping.faces, usableCandidates(candidates, {p}),
                         sweeps.frameToGridMm(), search);
        if (!key) continue;
        std::string made;
        for (const SplitPlane& plane : key->planes)
            made += " " + std::to_string(splitPiece(out.pieces, grouping.cellSets, field, p,
                                                    {scale(plane.normal, -1.0), -plane.offsetMm}));
        context.detail("piece " + std::to_string(p) +
                       " and its neighbours block each other around a hole: a keystone cut out of it "
                       "along its direction, the wedges beside it new pieces (" +
                       made.substr(1) + ")");
        out.recutPieces += key->planes.size();
        grouping.faces = faceContacts(field, cells, grouping.cellSets, out.pieces);
        return key->planes.size();
    }
    return 0;
}

/// Joins the pieces of each tunnel of @p groups that touch into one where the union is a cell
/// region again (isMergeable, or the two halves of one split: splitPlaneBetween), until no two can
/// be; the groups' piece ids follow. Returns how many joins.
size_t joinLinings(std::vector<TunnelGroup>& groups, Pieces& out, VoxelField& field, Grouping& grouping) {
    std::set<std::pair<uint32_t, uint32_t>> touching;  // (lower, higher) id, kept as ids change
    for (const auto& [pair, contacts] : grouping.faces) touching.insert(pair);
    size_t joins = 0;
    for (bool isJoined = true; isJoined;) {
        isJoined = false;
        for (TunnelGroup& g : groups) {
            for (size_t i = 0; i < g.pieces.size() && !isJoined; ++i)
                for (size_t j = i + 1; j < g.pieces.size() && !isJoined; ++j) {
                    const uint32_t keep = g.pieces[i], gone = g.pieces[j];  // sorted: keep < gone
                    if (!touching.count({keep, gone}) || (!isMergeable(grouping.cellSets, keep, gone) &&
                                                          !splitPlaneBetween(grouping.cellSets, keep, gone)))
                        continue;
                    mergePieces(out.pieces, grouping.cellSets, field, keep, gone);
                    auto now = [&](uint32_t id) { return id == gone ? keep : id > gone ? id - 1 : id; };
                    std::set<std::pair<uint32_t, uint32_t>> next;
                    for (const auto& [a, b] : touching)
                        if (now(a) != now(b))
                            next.insert({std::min(now(a), now(b)), std::max(now(a), now(b))});
                    touching = std::move(next);
                    for (TunnelGroup& h : groups) {
                        for (uint32_t& p : h.pieces) p = now(p);
                        std::sort(h.pieces.begin(), h.pieces.end());
                        h.pieces.erase(std::unique(h.pieces.begin(), h.pieces.end()), h.pieces.end());
                    }
                    isJoined = true, ++joins;
                }
            if (isJoined) break;
        }
    }
    return joins;
}

/// Cuts the linings of tunnels into slabs (detail/tunnels.h): the pieces a plan without gluing
/// leaves stuck that no peg holds, grouped by an axis each is free of the frame along, cut by planes
/// across the axis at the multiples of kTunnelSlabMm. Returns how many cuts.
size_t cutTunnelLinings(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                        const PlannerInput& input, const FrameSweeps& sweeps, const PiecesOptions& opt,
                        const RunContext& context) {
    const std::vector<int> holes = tenonHoleSet(opt.tenons.holes);
    const mount::InstallationPlan plan = planUnglued(input, sweeps, grouping, field.voxelMm, opt, context);
    std::vector<uint32_t> lining;
    std::vector<std::vector<Vec3d>> freeAlong;
    for (uint32_t p = 0; p < out.pieces.size(); ++p) {
        if (plan.holeOfPiece[p] >= 0) continue;
        context.throwIfCancelled();
        MountBody body = makeBody({p}, input, sweeps, field.voxelMm, opt.tenons.maxPerPiece, 1);
        if (body.bestFree()) continue;  // held by pegs: stuck between pieces, not a lining
        addGlueOptions(body, holes, sweeps, field.voxelMm);
        std::vector<Vec3d> dirs;
        for (const DirectionOption& o : body.glueOptions)
            if (o.isFree) dirs.push_back(gridDirection(o.hole, sweeps.frameToGridMm()));
        if (dirs.empty()) continue;
        lining.push_back(p);
        freeAlong.push_back(std::move(dirs));
    }
    std::vector<TunnelGroup> groups = tunnelGroups(lining, freeAlong);
    if (groups.empty()) return 0;
    // The lining pieces of a tunnel that touch become one, so that each slab is a ring: the seams
    // the partition left along the tunnel wander, and two slabs with such a seam between them
    // block each other along the tunnel both ways.
    const size_t joins = joinLinings(groups, out, field, grouping);
    const std::vector<std::vector<size_t>> slots = slotsOfPieces(field, out.pieces.size());
    const double voxelMm3 = field.voxelMm * field.voxelMm * field.voxelMm;
    const size_t minVoxels = size_t(std::ceil(splitSearchFor(field, opt).minVolumeMm3 / voxelMm3));
    size_t cuts = 0;
    for (const TunnelGroup& g : groups) {
        size_t groupCuts = 0;
        for (uint32_t p : g.pieces) {
            std::vector<double> t;
            for (size_t s : slots[p])
                if (field.isInside(s)) t.push_back(dot(g.axis, field.world(field.coordOf(s))));
            uint32_t rest = p;  // the part beyond the planes cut so far
            for (double at : slabOffsets(t, kTunnelSlabMm, minVoxels))
                rest = splitPiece(out.pieces, grouping.cellSets, field, rest, {g.axis, at}), ++groupCuts;
        }
        if (groupCuts == 0) continue;
        context.detail("mounting: " + std::to_string(g.lining) + " pieces line a tunnel along (" +
                       formatNumber(g.axis[0], 2) + ", " + formatNumber(g.axis[1], 2) + ", " +
                       formatNumber(g.axis[2], 2) + "), no peg holds them and no order exists: joined into " +
                       std::to_string(g.pieces.size()) + " and cut across it into slabs " +
                       std::to_string(int(kTunnelSlabMm)) + " mm long (" + std::to_string(groupCuts) +
                       " cuts)");
        cuts += groupCuts;
    }
    out.recutPieces += cuts;
    if (cuts > 0 || joins > 0) grouping.faces = faceContacts(field, cells, grouping.cellSets, out.pieces);
    return cuts;
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

}  // namespace

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

std::vector<const TenonCandidate*> usableCandidates(const std::vector<TenonCandidate>& candidates,
                                                    std::initializer_list<uint32_t> members) {
    std::vector<const TenonCandidate*> out;
    for (const TenonCandidate& c : candidates)
        if (c.rejection.empty() && c.piece >= 0 &&
            std::find(members.begin(), members.end(), uint32_t(c.piece)) != members.end())
            out.push_back(&c);
    return out;
}

mount::InstallationPlan planOverCandidates(const Pieces& out, const VoxelField& field,
                                           const Grouping& grouping, const FrameSweeps& sweeps,
                                           std::vector<TenonCandidate>& candidates,
                                           std::set<std::pair<zome::BallId, int>>& lost,
                                           const PiecesOptions& opt, const RunContext& context,
                                           const std::vector<std::pair<uint32_t, uint32_t>>& preGlued) {
    for (int attempt = 0;; ++attempt) {
        for (TenonCandidate& c : candidates)
            c.isStave = c.piece >= 0 && size_t(c.piece) < grouping.cellSets.size() &&
                        isStaveSet(grouping.cellSets[size_t(c.piece)]);
        PlannerInput input = plannerInput(out, field, candidates);
        input.preGlued = preGlued;
        for (size_t p = 0; p < out.pieces.size(); ++p)
            if (std::optional<Stave> st = staveOf(grouping.cellSets[p], input.pieces[p].voxels)) {
                input.staves.resize(out.pieces.size());
                input.staves[p] = st;
            } else if (std::optional<Vec3d> way =
                           mouthRingSlide(grouping.cellSets[p], input.pieces[p].voxels)) {
                input.sleeves.resize(out.pieces.size(), Vec3d{0, 0, 0});
                input.sleeves[p] = *way;
            }
        // A plan with glued groups of its own is a trial (glueUnderHeld): it gives up where no order
        // exists rather than glue more (each round of that took 4 s on the demo, and never helped).
        input.isGluingStuck = preGlued.empty();
        input.isGluingUnheldStaves = grouping.isGluingUnheldStaves;
        mount::InstallationPlan plan =
            planMounting(input, sweeps, grouping.faces, field.voxelMm, tenonHoleSet(opt.tenons.holes),
                         opt.tenons.maxPerPiece, context);
        if (!plan.isBuildable() || attempt == 8) return plan;
        const TenonPlan tenons = chooseTenons(candidates, plan.holeOfPiece, opt.tenons);
        const size_t inPaths = markTenonsInPaths(plan, tenons, input, sweeps.frameToGridMm(), opt.tenons,
                                                 field.voxelMm, candidates, lost);
        const size_t steps = markLostTenons(plan, tenons, candidates, lost);
        if (steps == 0 && inPaths == 0) return plan;
        context.debug("mounting: " + std::to_string(steps) +
                      " steps lost their tenons to other pieces' tenons, " + std::to_string(inPaths) +
                      " tenons lie in later pieces' paths; planning again without them");
    }
}

std::vector<TenonCandidate> freshCandidates(const zome::Structure& frame, const Transform4d& frameToGridMm,
                                            const ShellProbe& probe, const PiecesOptions& opt,
                                            const std::set<std::pair<zome::BallId, int>>& lost) {
    std::vector<TenonCandidate> candidates = findTenonCandidates(frame, frameToGridMm, probe, opt.tenons);
    for (TenonCandidate& c : candidates)
        if (c.rejection.empty() && lost.count({c.tenon.ball, c.tenon.hole}))
            c.rejection = "another tenon in the way";
    return candidates;
}

std::vector<size_t> pegCounts(const std::vector<TenonCandidate>& candidates,
                              const mount::InstallationPlan& plan, const TenonOptions& o) {
    const TenonPlan tenons = chooseTenons(candidates, plan.holeOfPiece, o);
    std::vector<size_t> pegs;
    for (const auto& list : tenons.perPiece) pegs.push_back(list.size());
    return pegs;
}

namespace {

/// The installation plan, re-cutting blocked pieces and planning again (a few rounds), and the
/// tenons along each piece's direction.
void planMountingAndTenons(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                           const ShellProbe& probe, zome::Structure& frame, const Transform4d& frameToGridMm,
                           const Fabrication& fabrication, const PiecesOptions& opt, const StrutTest& canGrow,
                           const RunContext& context) {
    std::optional<FrameSweeps> sweepsNow;  // made again when the frame grows
    auto remakeSweeps = [&] {
        sweepsNow.emplace(frame, frameToGridMm, planBounds(field, frame, frameToGridMm), field.voxelMm,
                          opt.mount.frameMarginMm);
    };
    remakeSweeps();
    const FrameSweeps& sweeps = *sweepsNow;
    // The hollow a ball needs behind a stave (detail/staves.h).
    const double thinGapMm =
        ballGapMm(frame.scale().ballRadiusMm(), fabrication.frameDMinMm(), fabrication.wallMm);
    std::vector<TenonCandidate> candidates;
    std::set<std::pair<zome::BallId, int>> lost;  // candidates other pieces' tenons took
    size_t lastUnplaced = SIZE_MAX;
    int keystones = 0;
    // Three tunnels through one point: their linings are carved into staves before any plan, which
    // the partition's pieces there would leave stuck whatever it did (the cheese at 700 mm: 215 s).
    const bool isCarved = carveCrossingLinings(out.pieces, grouping, field, cells, fabrication.wallMm,
                                               fabrication.frameDMinMm(), thinGapMm,
                                               splitSearchFor(field, opt).minVolumeMm3, context, true) > 0;
    for (int round = 0;; ++round) {
        const Stopwatch clock;
        candidates = freshCandidates(frame, frameToGridMm, probe, opt, lost);
        context.debug("mounting: " + std::to_string(candidates.size()) + " tenon candidates in " +
                      formatNumber(clock.seconds(), 3) + " s");
        context.throwIfCancelled();
        out.plan = planOverCandidates(out, field, grouping, sweeps, candidates, lost, opt, context);
        const PlannerInput input = plannerInput(out, field, candidates);
        context.debug("mounting: plan " + std::to_string(round) + " in " + formatNumber(clock.seconds(), 3) +
                      " s");
        if (out.plan.isBuildable()) break;
        const size_t unplaced =
            size_t(std::count(out.plan.holeOfPiece.begin(), out.plan.holeOfPiece.end(), -1));
        // Pieces lining a tunnel: cut across it into slabs once, before any re-cut (which would
        // cut them along it). Not where far more pieces are placed nowhere than a few tunnels' linings
        // (the cheese at 700 mm: cavity linings taken for tunnels, nothing freed, each plan minutes).
        context.debug("mounting: " + std::to_string(unplaced) + " pieces placed nowhere by plan " +
                      std::to_string(round));
        // Pieces placed nowhere line tunnels that cross (two at a time): their linings carved along
        // their prisms, as rings.
        if (round == 0 && !isCarved &&
            crossingTunnelLining(out, field, fabrication.wallMm, nullptr, false) > 0 &&
            carveCrossingLinings(out.pieces, grouping, field, cells, fabrication.wallMm,
                                 fabrication.frameDMinMm(), thinGapMm,
                                 splitSearchFor(field, opt).minVolumeMm3, context) > 0)
            continue;
        if (round == 0 && !isCarved && unplaced <= kMaxTunnelStuck &&
            cutTunnelLinings(out, field, cells, grouping, input, sweeps, opt, context) > 0)
            continue;
        // Staves no hole holds: no cut helps them, the frame must grow toward them (below).
        if (unplacedStaves(out.plan.holeOfPiece, grouping.cellSets) > 0) break;
        // A piece no hole reaches and nothing glues on stays so whatever is re-cut (the cheese at
        // 400 mm, on a frame of 4 balls: a re-cut round and a plan, 127 s, for nothing).
        if (const auto none = unplaceablePieces(out.plan, input, grouping.faces, field.voxelMm);
            !none.empty()) {
            context.detail("mounting: " + std::to_string(none.size()) + " piece(s) (piece " +
                           std::to_string(none[0]) + (none.size() > 1 ? ", …" : "") +
                           ") no ball's hole reaches and no cut face glues on: no re-cut places them");
            break;
        }
        if (keystones == 0 && round < kRecutRounds) {
            // Re-cutting that places no more pieces is given up: on the cheese at 700 mm the halves
            // of 116 pieces lining its tunnels were as stuck as the pieces (110 stuck bodies, then
            // 225).
            size_t cut = 0;
            if (unplaced >= lastUnplaced)
                context.detail("mounting: re-cutting placed no more pieces (" + std::to_string(unplaced) +
                               " without a direction, " + std::to_string(lastUnplaced) +
                               " before): no more rounds");
            else
                cut = recutBlocked(out, field, cells, grouping, input, candidates, sweeps, opt, context);
            lastUnplaced = unplaced;
            context.debug("mounting: re-cut " + std::to_string(cut) + " in " +
                          formatNumber(clock.seconds(), 3) + " s");
            if (cut > 0) continue;
        }
        // What re-cutting left stuck may be a ring of pieces around a hole: a keystone frees it.
        // Not where far more pieces are stuck than a few rings hold (the cheese at 700 mm: 281,
        // its tunnel linings, and each keystone's plan took 4 minutes there).
        if (keystones == kKeystoneRounds || unplaced > kMaxKeystoneStuck ||
            cutKeystone(out, field, cells, grouping, input, candidates, sweeps, opt, context) == 0)
            break;
        ++keystones;
    }
    Replanner replanner(out, field, cells, grouping, probe, frame, frameToGridMm, sweeps, remakeSweeps,
                        candidates, lost, opt, context);
    if (opt.isGrowingFrame && canGrow) out.frameStrutsGrown += growFrameForStaves(replanner, canGrow);
    if (unplacedStaves(out.plan.holeOfPiece, grouping.cellSets) > 0) {
        // What no peg holds and no stave on before it glues in place goes on with the rest, glued
        // in place onto what is on by then.
        grouping.isGluingUnheldStaves = true;
        out.plan = planOverCandidates(out, field, grouping, sweeps, candidates, lost, opt, context);
        context.debug("mounting: staves placed nowhere glued in place among the other pieces: " +
                      std::to_string(unplacedStaves(out.plan.holeOfPiece, grouping.cellSets)) +
                      " placed nowhere, " + std::to_string(out.plan.problems.size()) + " problems");
    }
    if (opt.isGrowingFrame && canGrow && opt.tenons.minPerPiece > 0)
        out.frameStrutsGrown += growFrameForPieces(replanner, canGrow);
    mergeUnderHeld(replanner, fabrication);
    if (opt.isRecuttingPairs) recutUnderHeldPairs(replanner, fabrication);
    if (opt.isCuttingForSupport) cutForSupport(replanner, fabrication);
    // Last: glued groups are pairs of piece numbers, which merges and cuts would change.
    if (opt.isGluingUnderHeld) {
        glueUnderHeld(replanner);
        mergeGluedPairs(replanner, fabrication);
    }
    if (opt.isCuttingForSupport && opt.isGluingUnderHeld) splitForPrint(replanner, fabrication);
    const size_t unpinned = placePins(out, field, cells, grouping.cellSets, opt, GlueOnRule{}.minCosine);
    if (unpinned > 0)
        context.warn(
            std::to_string(unpinned) + " of " +
            std::to_string(out.plan.glued.size() + out.plan.gluedOn.size()) +
            " glued pairs have fewer than " + std::to_string(opt.pins.perPair) +
            " alignment pins (the face has no room for them, or runs along the way the piece goes on, as a "
            "stave glued in place slides along its seams): line them up by eye when gluing");
    TenonPlan plan = chooseTenons(candidates, out.plan.holeOfPiece, opt.tenons);
    for (size_t p = 0; p < out.pieces.size(); ++p) {
        out.pieces[p].hole = out.plan.holeOfPiece[p];
        out.pieces[p].tenons = std::move(plan.perPiece[p]);
        out.pieces[p].tenonShortfall = std::move(plan.shortfall[p]);
    }
    setStaveLifts(out, grouping.cellSets, field, frameToGridMm, fabrication.frameDMinMm());
    warnShortfall(out, opt.tenons, context);
    for (const std::string& problem : out.plan.problems) context.warn("installation plan: " + problem);
}

}  // namespace

void planPieces(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
                const FloatGrid& shell, zome::Structure& frame, const Transform4d& frameToGridMm,
                const Fabrication& fabrication, const PiecesOptions& opt, const StrutTest& canGrow,
                const RunContext& context) {
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
    probe.pieceAt = [&](const Vec3d& p) { return field.ownerNear(p); };
    if (opt.tenons.maxPerPiece > 0) {
        planMountingAndTenons(out, field, cells, grouping, probe, frame, frameToGridMm, fabrication, opt,
                              canGrow, context);
    } else {
        out.plan = {};
        out.plan.holeOfPiece.assign(out.pieces.size(), -1);
        out.plan.problems.push_back("no tenons (--max-tenons 0): nothing holds the pieces on the frame");
    }
    const size_t pieceCount = out.pieces.size();
    for (Piece& piece : out.pieces) piece.wallMm = fabrication.wallMm, piece.isThinWall = false;
    // What follows is for pieces that will be made; a plan with problems is refused (requireBuildable),
    // unless there are no tenons to plan (--max-tenons 0: pieces without a plan, numbered all the same).
    if (opt.tenons.maxPerPiece > 0 && !out.plan.isBuildable()) {
        const double thinGapMm =
            ballGapMm(frame.scale().ballRadiusMm(), fabrication.frameDMinMm(), fabrication.wallMm);
        if (noteUnheldStaves(out, grouping.cellSets, field, thinGapMm) == 0)
            noteCrossingTunnels(out, field, fabrication.wallMm);
        grouping.unheldTunnels = unheldTunnels(out.plan.holeOfPiece, grouping.cellSets);
        return;
    }
    // The printed wall, where thinner than the plan's (thin_wall.h): after the plan, before numbers.
    const ShellProbe thin = field.thinPhi.empty() ? probe : thinWallProbe(field, opt.printWallMm);
    if (!field.thinPhi.empty() && opt.tenons.maxPerPiece > 0) {
        out.thinPieces = thinPieces(out, field, frame, frameToGridMm, thin, fabrication.wallMm, opt.tenons);
        context.info(std::to_string(out.thinPieces) + " of " + std::to_string(pieceCount) +
                     " pieces printed with a " + formatNumber(opt.printWallMm) +
                     " mm wall; the rest keep the " + formatNumber(fabrication.wallMm) +
                     " mm of the shell (glued, or a peg that does not reach through the thin wall)");
    }
    context.throwIfCancelled();
    if (!opt.label.isEnabled) return;
    const double reach = frame.scale().ballRadiusMm() + 3.0 * frame.scale().b0Mm;
    const auto spots = innerSurfaceSpots(frame, frameToGridMm, probe, pieceCount, reach);
    const auto thinSpots = out.thinPieces > 0
                               ? innerSurfaceSpots(frame, frameToGridMm, thin, pieceCount, reach)
                               : std::vector<std::vector<SurfaceSpot>>();
    size_t unlabelled = 0;
    for (size_t p = 0; p < pieceCount; ++p) {
        Piece& piece = out.pieces[p];
        const bool isThin = piece.isThinWall;
        piece.label = placeLabel(std::to_string(p), uint32_t(p), isThin ? thinSpots[p] : spots[p],
                                 piece.tenons, opt.tenons, isThin ? thin : probe,
                                 labelOptionsForWall(opt.label, piece.wallMm), &piece.labelNote);
        if (!piece.label) ++unlabelled;
    }
    if (unlabelled > 0)
        context.warn(std::to_string(unlabelled) + " of " + std::to_string(pieceCount) +
                     " pieces have no engraved number (no flat inner spot clear of cuts and tenons)");
}

}  // namespace zomefab::pieces::detail
