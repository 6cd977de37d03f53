// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Changes to the pieces and their plan that are kept only when they help (internal to
/// lib/zomefab/pieces): under-held pieces merged with a neighbour, pairs cut anew along a plane,
/// steps glued to a neighbour before mounting; and what they share with the planning of
/// pieces/plan.cpp (the plan over the tenon candidates, the pegs it gives). docs/mounting.md.
#pragma once

#include <functional>
#include <initializer_list>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/mounting.h"
#include "zomefab/pieces/detail/splits.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/tenons.h"

namespace zomefab::pieces::detail {

/// What the re-cuts of a piece (findSplit) and of a pair (findHoldingSplits) need besides the
/// voxels: the grid, halves of at least the smallest piece volume (and 1,000 voxels), candidates
/// within a tenon's width of the plane lost; voxelMm is the grid's, for cells the caller sets it.
SplitSearch splitSearchFor(const VoxelField& field, const PiecesOptions& opt);

/// The usable tenon candidates (not rejected) of the pieces @p members.
std::vector<const TenonCandidate*> usableCandidates(const std::vector<TenonCandidate>& candidates,
                                                    std::initializer_list<uint32_t> members);

/// The installation plan over @p candidates, planned again while a step that relies on pegs gets
/// none (its candidates lost to other pieces' tenons: they are dropped; a few times). The pieces
/// of @p preGlued are glued into one body before planning (PlannerInput::preGlued), and then no
/// stuck bodies are glued (a trial of glueUnderHeld).
mount::InstallationPlan planOverCandidates(const Pieces& out, const VoxelField& field,
                                           const Grouping& grouping, const FrameSweeps& sweeps,
                                           std::vector<TenonCandidate>& candidates,
                                           std::set<std::pair<zome::BallId, int>>& lost,
                                           const PiecesOptions& opt, const RunContext& context,
                                           const std::vector<std::pair<uint32_t, uint32_t>>& preGlued = {});

/// The tenons of pieces already on that lie in the path of a later step (the step pushed off along
/// its direction would run into the stem, which reaches from its piece's wall into the hollow, away
/// from the seam the planner's sweeps look at: the dino at 350 mm, a stem 25.6 mm into the path of
/// the last piece). Their candidates are marked lost ("in another piece's path"), so the plan made
/// again holds that piece by other pegs or puts it on later. Returns how many tenons.
size_t markTenonsInPaths(const mount::InstallationPlan& plan, const TenonPlan& tenons,
                         const PlannerInput& input, const Transform4d& frameToGridMm, const TenonOptions& o,
                         double voxelMm, std::vector<TenonCandidate>& candidates,
                         std::set<std::pair<zome::BallId, int>>& lost);

/// The tenon candidates of the pieces as they are now, those other pieces' tenons took (@p lost)
/// rejected.
std::vector<TenonCandidate> freshCandidates(const zome::Structure& frame, const Transform4d& frameToGridMm,
                                            const ShellProbe& probe, const PiecesOptions& opt,
                                            const std::set<std::pair<zome::BallId, int>>& lost);

/// The pegs each piece gets along its planned direction.
std::vector<size_t> pegCounts(const std::vector<TenonCandidate>& candidates,
                              const mount::InstallationPlan& plan, const TenonOptions& o);

/// How many of @p pegs are below @p minPerPiece.
size_t underHeld(const std::vector<size_t>& pegs, int minPerPiece);

/// The pegs of each step of @p plan: its pieces' pegs summed (a glued group is held by all of them).
std::vector<size_t> stepPegs(const mount::InstallationPlan& plan, const std::vector<size_t>& pegs);

/// Changes to the pieces that are kept only when they help: each is made, the tenons and the plan
/// made again, and undone unless fewer pieces are under-held (fewer than minPerPiece pegs) and the
/// plan can be carried out. Merges and pairs cut anew go through it.
class Replanner {
public:
    Replanner(Pieces& out, VoxelField& field, const GridCells& cells, Grouping& grouping,
              const ShellProbe& probe, zome::Structure& frame, const Transform4d& frameToGridMm,
              const FrameSweeps& sweeps, std::function<void()> remakeSweeps,
              std::vector<TenonCandidate>& candidates, std::set<std::pair<zome::BallId, int>>& lost,
              const PiecesOptions& opt, const RunContext& context)
        : out(out),
          field(field),
          cells(cells),
          grouping(grouping),
          probe(probe),
          frame(frame),
          frameToGridMm(frameToGridMm),
          sweeps(sweeps),
          remakeSweeps(std::move(remakeSweeps)),
          candidates(candidates),
          lost(lost),
          opt(opt),
          context(context) {}

    /// The pegs each piece gets along its planned direction.
    std::vector<size_t> pegs() const { return pegCounts(candidates, out.plan, opt.tenons); }
    size_t underHeldNow() const { return underHeld(pegs(), opt.tenons.minPerPiece); }
    /// The steps (pieces or glued groups) under minPerPiece pegs.
    size_t underHeldStepsNow() const { return underHeld(stepPegs(out.plan, pegs()), opt.tenons.minPerPiece); }

    /// What a change touches, and so what it is judged by.
    enum class Change {
        kPieces,  ///< the pieces, their cell sets and the voxels' owners: pieces under-held count
        kGroups,  ///< preGlued only (the pieces, faces and candidates stay): steps under-held count
        kFrame,   ///< the frame (grown): its sweeps and the tenon candidates; pieces under-held count
        /// as kPieces, for a change that adds pieces: judged by the pieces held (minPerPiece pegs
        /// or more), which must grow, and the under-held ones, which must not
        kMorePieces,
        /// as kPieces, for a piece cut into parts glued before mounting (splitForPrint): judged by
        /// the steps under-held (kGroups), which must not grow
        kParts,
        /// as kFrame, for the frame grown toward staves: judged by the staves no peg holds (placed
        /// nowhere or glued in place), which must be fewer; the plan need not be one that can be
        /// carried out (more rounds may follow), but one that could must stay so
        kStaves,
    };
    /// Makes @p change, recomputes what it touched (for kPieces the faces and the tenon candidates,
    /// for kFrame the sweeps and the candidates) and plans again. Returns the new count of under-held pieces
    /// (kGroups: steps) when it is below
    /// @p before with a plan that can be carried out (kMorePieces: not above @p before, with more
    /// pieces held); else undoes everything and returns nothing.
    /// @p refine (kGroups): when the change leaves as many under-held as before, a further change on
    /// top (true when it made one), planned and judged together with the first.
    std::optional<size_t> tryChange(const std::function<void()>& change, size_t before,
                                    const std::string& what, Change kind = Change::kPieces,
                                    const std::function<bool()>& refine = {});

    Pieces& out;
    VoxelField& field;
    const GridCells& cells;
    Grouping& grouping;
    const ShellProbe& probe;
    zome::Structure& frame;  ///< changed only by kFrame changes (growFrameForPieces)
    const Transform4d& frameToGridMm;
    const FrameSweeps& sweeps;  ///< of the frame as it is: made again by remakeSweeps
    std::function<void()> remakeSweeps;
    std::vector<TenonCandidate>& candidates;
    std::set<std::pair<zome::BallId, int>>& lost;
    const PiecesOptions& opt;
    const RunContext& context;
    /// Pieces glued into one before planning (glueUnderHeld); every plan made here uses them.
    std::vector<std::pair<uint32_t, uint32_t>> preGlued;

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
        std::vector<std::pair<uint32_t, uint32_t>> preGlued;
        std::optional<zome::Structure> frame;  ///< kFrame changes only
    };
};

/// Where the plan places staves nowhere (no hole behind a stave's wall holds it): struts to new
/// balls whose holes along a direction the stave may take (isStaveDirection, the nearest its lift
/// first) are its tenon candidates, up to --min-tenons per stave, found as growFrameForPieces
/// finds them; kept when the plan made again places fewer staves nowhere, in rounds while it does
/// (a ball grown for one stave may be in another's way, or take the spot it needed). Returns how
/// many struts were kept.
size_t growFrameForStaves(Replanner& r, const StrutTest& canGrow);

/// Grows the frame toward the pieces fewer than minPerPiece pegs hold along their planned direction
/// (docs/mounting.md, "Frame grown toward a piece"): for each, the strut (from any ball, any hole and
/// size that @p canGrow allows: clearance, collisions) to a new ball whose hole along the piece's
/// direction is the piece's best tenon candidate, one per missing peg; all at once, as one kFrame
/// change (kept only when fewer pieces are under-held with a plan that can be carried out). A few
/// rounds. Returns how many struts were added.
size_t growFrameForPieces(Replanner& r, const StrutTest& canGrow);

/// Pieces fewer than minPerPiece pegs hold are printed as one with a neighbour (detail/merges.h) and
/// the plan made again, while that leaves fewer such pieces and a plan that can be carried out. Each
/// round tries every piece's best merge at once, and when that does not help, the merges one by one
/// (at most kSingleMergeTrials); a trial that does not help is undone.
void mergeUnderHeld(Replanner& r, const Fabrication& fabrication);

/// A union of two pieces cut anew: along @p first, and where that leaves a half too large for the
/// printer, that half (secondSide: 0 the side normal·x ≤ offset, 1 beyond) along @p second.
struct PairCut {
    SplitPlane first;
    std::optional<SplitPlane> second;
    uint8_t secondSide = 0;
};

/// The cuts recutUnderHeldPairs tries on a union (@p cells, its coarse cells; @p candidates, its
/// usable tenon candidates; @p search.voxelMm the cells' side), best first: the planes of
/// findHoldingSplits whose halves are both held (@p minPegs candidates along a free direction) and
/// fit the printer; where there is none, three pieces: a plane whose halves are both held and of
/// which one fits, then a plane of the same search through the other half (with its candidates,
/// those clear of the first plane) whose halves are both held and fit — a limb glued to a body too
/// large to print with it gets a part of the body its pegs can reach. At most 3 planes each.
std::vector<PairCut> pairCuts(const CoarseCells& cells, const std::vector<const TenonCandidate*>& candidates,
                              const FrameSweeps& sweeps, const SplitSearch& search,
                              const Fabrication& fabrication, size_t minPegs);

/// A piece fewer than minPerPiece pegs hold whose union with a neighbour does not fit the printer
/// (so no merge helps) is cut anew with it: the two become one and are cut again along a plane of
/// findHoldingSplits, which gives both halves minPerPiece tenons and fits them, and the plan is
/// made again; kept when fewer pieces are under-held, else the next plane is tried. Smallest
/// under-held piece first, its neighbours by the largest common face. docs/mounting.md, "Pairs
/// cut anew".
void recutUnderHeldPairs(Replanner& r, const Fabrication& fabrication);

/// The least support a solid of @p cells (cubes of side @p cellMm) needs, resting at its lowest
/// cell, over @p sphereDirections directions spread over the sphere and @p ups along which it fits @p boxMm
/// (placeOnBed): restingSupportMm3, mm³ of solid columns; infinite when it fits none
/// (support_cuts.cpp).
double leastSupportMm3(const std::vector<Vec3d>& cells, double cellMm, const std::vector<Vec3d>& ups,
                       const Vec3d& boxMm, int sphereDirections = 256);

/// A plane that cuts a piece into two halves that need much less support than the piece.
struct SupportCut {
    SplitPlane plane;
    double beforeMm3 = 0.0;  ///< the piece's least support (leastSupportMm3 on 4 mm cells)
    double afterMm3 = 0.0;   ///< its halves', each also lying on the new cut face or with it up
};
/// For a piece (@p cells: its coarse cells; @p candidates: its usable tenon candidates) whose least
/// support is at least a quarter of its volume and 30 cm³: of findHoldingSplits's planes that hold both
/// halves with @p minPegs and fit the printer, the one whose halves need the least support, when
/// they need at most 60 % of the piece's and 30 cm³ less. Empty otherwise.
std::optional<SupportCut> supportCut(const CoarseCells& cells,
                                     const std::vector<const TenonCandidate*>& candidates,
                                     const FrameSweeps& sweeps, SplitSearch search,
                                     const Fabrication& fabrication, size_t minPegs);

/// Held pieces that need much support however they lie are cut in two along supportCut's plane,
/// the one that saves the most first, and the plan made again; kept when more pieces are held and
/// none more under-held (Change::kMorePieces). At most 6 plans. docs/pieces.md, "Cut for less
/// support". PiecesOptions::isCuttingForSupport.
void cutForSupport(Replanner& r, const Fabrication& fabrication);

/// A piece (@p cells: its coarse cells) whose least support (leastSupportMm3 on 4 mm cells) is at
/// least 30 cm³: of connectedSplitPlanes's planes (median and thirds), the one whose halves need the
/// least support, each lying any way that fits or on the new cut face or with it up, when they
/// need at most 60 % of the piece's and 30 cm³ less. Unlike supportCut the halves need not be held
/// on their own: they are glued into one body before mounting. Empty otherwise.
std::optional<SupportCut> printSplit(const CoarseCells& cells, SplitSearch search,
                                     const Fabrication& fabrication);

/// Pieces that need much support however they lie, held or not, are printed in two parts glued
/// together before mounting (a glued group, Replanner::preGlued, mounted as the piece was): cut
/// along printSplit's plane, the one that saves the most first, and the plan made again; kept when
/// no more steps are under-held with a plan that can be carried out (Change::kParts). At most 10
/// plans. Run after glueUnderHeld and mergeGluedPairs (which would print the parts as one again).
/// docs/pieces.md, "Printed in parts". PiecesOptions::isCuttingForSupport.
void splitForPrint(Replanner& r, const Fabrication& fabrication);

/// Steps (pieces or glued groups) fewer than minPerPiece pegs hold, a piece glued on as it goes on
/// among them, are glued to a neighbouring step before mounting, so the two go on as one body
/// along a direction whose tenons hold both (docs/mounting.md, "Glued groups"); kept when fewer
/// steps are under-held with a plan that can be carried out. The pieces themselves do not change
/// (nothing more to print but the pins). Each round tries every step's best option at once (each
/// step in one pair), then, when that does not help, the options one by one (kSingleGlueTrials).
void glueUnderHeld(Replanner& r);

/// Pieces glued together (neighbours in one glued group, or a piece and the host it is glued onto)
/// of which one at least has fewer than minPerPiece pegs, whose union fits the printer, are printed
/// as one and the plan made again: the maker glues them anyway, and one piece fewer is under-held
/// (the dino at 500 mm: two toes glued to a leg glued to the body). Kept when fewer pieces are under-held
/// with a plan that can be carried out; the groups glued before planning (Replanner::preGlued) follow the
/// pieces' new numbers. Rounds as mergeUnderHeld's. Run after glueUnderHeld, whose groups it merges.
void mergeGluedPairs(Replanner& r, const Fabrication& fabrication);

}  // namespace zomefab::pieces::detail
