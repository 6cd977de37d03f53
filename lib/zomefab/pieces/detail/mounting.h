// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The installation plan, made on the shell's voxels before the tenons are grown (internal to
/// lib/zomefab/pieces): for every piece the directions along which it can be pushed onto the frame
/// (its path free of balls and struts) and held (tenons of balls whose hole points that way); pieces
/// that cannot be held on their own glued to a neighbour into one body; one direction per body so
/// that an order exists, and the order. docs/mounting.md.
#pragma once

#include <array>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/mount/plan.h"
#include "zomefab/mount/sweep.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/staves.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces::detail {

/// Cut faces of fewer voxel faces than this do not order their two pieces by their plane: where three
/// cells meet, a few voxels of two pieces can lie across a plane that is not the seam's, with any
/// normal. Their voxels take part in the sweeps between the two instead (a voxel of tolerance).
inline constexpr size_t kMinOrderFaceVoxels = 50;

/// Voxel layers from a cut face (6-neighbours inward, the face's own voxels the first) that count as
/// near it: two neighbours' voxels this near their face are not swept against each other (the face
/// orders them); voxels this near are swept against the other's voxels beyond kWideCutLayers, which
/// may reach round the face's end. The wider band keeps a seam along a diagonal plane, whose layers
/// are thinner (1/√3 voxel), from meeting the layers just behind the other side.
inline constexpr uint8_t kNearCutLayers = 2;
inline constexpr uint8_t kWideCutLayers = 4;

/// A glued group has at most this many pieces: a maker glues a few pieces together, not half the
/// object (what more gluing would resolve is re-cut instead).
inline constexpr size_t kMaxGluedPieces = 4;

/// One direction a body could take: its hole, the tenons it would get, whether its path is free.
struct DirectionOption {
    int hole = -1;
    size_t tenons = 0;      ///< usable tenon candidates along it
    double score = 0.0;     ///< their scores summed
    bool isTested = false;  ///< the path test below was made
    bool isFree = false;    ///< the body's voxels pushed off along it touch no ball or strut
    std::string blockedBy;  ///< "ball 4", "strut 12" when not free
};

/// A body that goes on in one push: one piece, or pieces glued together. Its surface voxels' centres
/// (grid mm: a body pushed along a direction first meets things with its surface) and the directions it could
/// take, best first (most tenons up to maxPerPiece, then score).
struct MountBody {
    std::vector<uint32_t> pieces;  ///< sorted; the first is the body's name
    std::vector<Vec3d> voxels;
    /// Per voxel: the pieces whose cut face with this body's piece lies within kWideCutLayers
    /// voxels (up to two, kNone for none), and cutLayer how near each (1: on the face).
    /// A voxel within kNearCutLayers is left out of the sweep against a body holding such a piece,
    /// whose order that face decides; against every other body it is swept like any voxel (the dino
    /// at 350 mm: a piece's rim along its cut with a third piece, left out of every sweep, hid
    /// 25.6 mm of it in a neighbour's path).
    std::vector<std::array<uint32_t, 2>> nearCutOf;
    std::vector<std::array<uint8_t, 2>> cutLayer;
    /// How many layers voxel @p i lies from its nearest cut face with one of @p other's pieces
    /// (1: on it), 0 when it is within kWideCutLayers of none.
    uint8_t cutLayerWith(size_t i, const MountBody& other) const;
    /// Adds @p part's voxels with their cut-face marks, and its bounds (a member of a glued body).
    void addVoxelsOf(const MountBody& part);
    Box3d bounds;
    std::vector<DirectionOption> options;
    /// For a body no peg can hold (no free direction with a tenon), or one the order leaves stuck:
    /// every direction of the hole set, tested, for gluing it onto a piece already in place as it
    /// goes on. Empty otherwise.
    std::vector<DirectionOption> glueOptions;
    /// A mouth ring alone (PlannerInput::sleeves): its way out of its mouth (grid, unit), else zero.
    /// Along it (within a degree) the ring may be glued on across any face large enough, which the
    /// 60° of GlueOnRule would refuse: a sleeve slid into its mouth, glued round its outside to the
    /// pieces round the rim (its deep end opens into a crossing; docs/mounting.md, "Three tunnels
    /// through one point").
    Vec3d sleeveGrid{0, 0, 0};

    /// The best direction with a free path and at least one tenon, or null.
    const DirectionOption* bestFree() const;
    bool isHosted() const { return !bestFree(); }
};

/// The frame drawn along each hole direction (balls and struts grown by the margin), and the test
/// of a body's path against it. A direction's raster is drawn the first time it is asked for
/// (thread-safe); all share one rectangle.
class FrameSweeps {
public:
    /// Rasters over @p bounds (grid mm, every body and ball inside), pixels of @p pixelMm.
    FrameSweeps(const zome::Structure& frame, const Transform4d& frameToGridMm, const Box3d& bounds,
                double pixelMm, double marginMm);
    /// Whether @p body pushed off along @p hole meets nothing of the frame; else what it meets and
    /// by how much ("ball 4 by 12 mm").
    bool isFree(const MountBody& body, int hole, double voxelMm, std::string* blockedBy) const;
    const Transform4d& frameToGridMm() const { return mFrameToGrid; }

private:
    const mount::DepthRaster& raster(int hole) const;

    const zome::Structure* mFrame;
    Transform4d mFrameToGrid;
    Box3d mBounds;
    double mPixelMm, mMarginMm;
    mutable std::vector<std::unique_ptr<mount::DepthRaster>> mRasters;  ///< by hole
    mutable std::unique_ptr<std::once_flag[]> mOnce;
};

/// What the planner starts from: every piece as a body of its own, with its tenon candidates per
/// hole (counted and scored) and its voxels; the directions are not yet tested.
struct PlannerInput {
    std::vector<MountBody> pieces;
    /// Per piece: hole → (usable candidates, summed score).
    std::vector<std::map<int, std::pair<size_t, double>>> candidatesByHole;
    /// Pairs of pieces whose bodies are glued into one before the planning starts, in this order
    /// (pieces too few pegs hold glued to a neighbour that holds both: docs/mounting.md, "Glued
    /// groups"). Empty from plannerInput.
    std::vector<std::pair<uint32_t, uint32_t>> preGlued;
    /// Where no order exists, glue stuck bodies in each other's way into one and plan again (a few
    /// rounds). Off: such a plan is returned stuck at once (a trial that only wants a better plan).
    bool isGluingStuck = true;
    /// Per piece, the stave it is (detail/staves.h): staves go on first, in their order, along two
    /// legs; never glued. Empty: no piece is one.
    std::vector<std::optional<Stave>> staves;
    /// Per piece: a mouth ring's way out of its mouth along its tunnel (grid, unit; mouthRingSlide),
    /// else zero. Empty: no piece is one.
    std::vector<Vec3d> sleeves;
    /// A stave no hole holds and none on before it to glue it in place onto (glueStavesInPlace)
    /// goes on with the other pieces instead of before them: slid straight to its place along its
    /// tunnel and glued on across any face large enough (MountBody::sleeveGrid), onto whatever is
    /// on by then (a mouth ring at its deep end). Off: such a stave leaves the plan at once, placed
    /// nowhere, so that the frame grows toward it first (growFrameForStaves).
    bool isGluingUnheldStaves = false;
    /// Whether piece @p p is a stave (staves).
    bool isStave(uint32_t p) const { return p < staves.size() && staves[p].has_value(); }
    /// Whether piece @p p is a mouth ring (sleeves).
    bool isMouthRing(uint32_t p) const { return p < sleeves.size() && norm(sleeves[p]) > 0.0; }
};
PlannerInput plannerInput(const Pieces& out, const VoxelField& field,
                          const std::vector<TenonCandidate>& candidates);

/// Direction options from tenon candidates per hole (count, summed score), best first: most tenons
/// (counted up to @p cap), then the score. Untested.
std::vector<DirectionOption> rankedOptions(const std::map<int, std::pair<size_t, double>>& byHole,
                                           size_t cap);
/// Tests the options of @p body not yet tested for a free path against the frame: all (in
/// parallel) when @p freeWanted is 0, else in rank order until that many are free (a trial body).
void testPaths(MountBody& body, const FrameSweeps& sweeps, double voxelMm, size_t freeWanted = 0);

/// The body of @p members (the union of their voxels) with its direction options ranked and
/// tested against the frame as testPaths does.
MountBody makeBody(const std::vector<uint32_t>& members, const PlannerInput& input, const FrameSweeps& sweeps,
                   double voxelMm, int maxPerPiece, size_t freeWanted = 0);

/// The body of stave piece @p p (PlannerInput::staves) with its one direction: the hole of most
/// tenons (then score) that isStaveDirection allows; −1 when no such hole has a tenon.
MountBody staveBody(uint32_t p, const PlannerInput& input, const Transform4d& frameToGridMm, int maxPerPiece,
                    int* hole);

/// The staves of a plan in their mounting order, each one's direction (its hole; −1: none) and, for
/// a stave no peg holds that is glued in place (glueStavesInPlace), the staves it is glued onto.
struct StaveOrder {
    std::vector<uint32_t> pieces;
    std::vector<int> holes;
    std::vector<std::vector<uint32_t>> hosts;  ///< per stave; empty: its pegs hold it
};

/// The hole along @p stave's slide, out of its mouth (a stave glued in place is taken off along it,
/// straight), or −1.
int holeAlongSlide(const Stave& stave, const Transform4d& frameToGridMm);

/// @p order with its k-th stave (piece, hole, hosts) the old @p perm[k]-th.
StaveOrder permuted(const StaveOrder& order, const std::vector<size_t>& perm);

/// Staves no hole holds (−1 in @p order.holes) that share a seam or a ring's cut face large enough to
/// glue across (GlueOnRule) with staves held or glued in place on before them are glued in place
/// onto those: such a stave slides along its tunnel straight to its place, along its ring's seams,
/// after the staves of its ring that holes hold (and after those glued in place it is glued onto: a
/// chain round the ring); its hole is the one along its slide, out of its mouth (none there: it
/// stays unheld). The staves keep @p order's order of rings (orderStaveRings); in a ring those holes
/// hold come first, in @p order's order, then the glued ones as they were found, then those still
/// unheld. Returns the permutation applied (the new k-th stave is the old result[k]).
std::vector<size_t> glueStavesInPlace(StaveOrder& order, const PlannerInput& input, const FaceContacts& faces,
                                      const Transform4d& frameToGridMm, double voxelMm);

/// The staves of a plan as rings (runs of one ring in the rank's order) and what orders them.
struct StaveRings {
    std::vector<size_t> ringOf;  ///< per stave (its index in the order): its ring, numbered in rank order
    /// Per ring: the rings a stave of which lies in the way out of one of its own staves (or whose
    /// cut faces say so): they go on after it.
    std::vector<std::vector<size_t>> later;
    std::vector<uint8_t> isHeld;      ///< per stave: a hole holds it
    std::vector<uint8_t> canSlideIn;  ///< per stave: a hole lies along its slide (it can be glued in place)
    std::vector<std::vector<size_t>> seamMates;  ///< per stave: those it shares a seam to glue across with
};

/// The rings of @p order (its staves in rank order, each one's hole; @p bodies theirs): stave j lies
/// in stave k's way when k, slid out of its mouth along its tunnel, meets it (sweepHits, facesAllow;
/// the lift toward the axis meets only k's own ring). Staves j and k share a seam when it is large
/// enough to glue across (GlueOnRule).
StaveRings staveRings(const StaveOrder& order, const std::vector<MountBody>& bodies,
                      const PlannerInput& input, const FaceContacts& faces, const Transform4d& frameToGridMm,
                      double voxelMm);

/// An order of @p g's rings in which each goes on before those in its staves' ways (StaveRings::
/// later): of the rings whose ways allow it, the first in rank order all of whose staves are then
/// held or glued in place (glueStavesInPlace's rule onto the staves on before), else the first in
/// rank order. So a ring with a stave no hole holds waits, as long as its ways allow, for staves of
/// other tunnels it could be glued onto (the cheese at 700 mm: the rank put an x tunnel's ring before
/// the y and z staves round the crossing at its deep end). Where the ways make a cycle, the first
/// ring left in rank order goes on (@p cyclesBroken counts them). Returns the staves' indices in
/// the new order, ring by ring, each ring's in its own order.
std::vector<size_t> orderStaveRings(const StaveRings& g, size_t* cyclesBroken = nullptr);

/// For the debug output: per stave @p order places nowhere (its staves in the final order, the k-th
/// the @p rankOf[k]-th of @p byRank, which @p g and @p bodies follow), where it is and the staves it
/// shares a seam with: held, glued or not, before or after it, and whose way each lies in; then
/// every piece it touches, with the area.
std::vector<std::string> unheldStaveNotes(const StaveOrder& byRank, const StaveRings& g,
                                          const StaveOrder& order, const std::vector<size_t>& rankOf,
                                          const std::vector<MountBody>& bodies, const FaceContacts& faces,
                                          double voxelMm);

/// The staves (pieces @p staves) in the order they go on, their bodies appended to @p list: rings
/// in the order their ways allow (staveRings, orderStaveRings), in each the held staves, then those
/// glued in place onto staves on before them (glueStavesInPlace), then those placed nowhere (the
/// debug output says why, unheldStaveNotes). With PlannerInput::isGluingUnheldStaves, staves placed
/// nowhere that can slide in along their tunnel become movable bodies with one glue option along
/// it, their slide their sleeve (MountBody::sleeveGrid), put before the rest. Returns the order of
/// the fixed staves, whose bodies are the last of @p list.
StaveOrder placeStaves(std::vector<uint32_t> staves, const PlannerInput& input, const FrameSweeps& sweeps,
                       const FaceContacts& faces, double voxelMm, int maxPerPiece, const RunContext& context,
                       std::vector<MountBody>& list);

/// The staves at the end of a disassembly's bodies (StaveOrder, in their mounting order), as the
/// disassembly takes rings of them away.
struct FixedStaves {
    std::vector<size_t> ringOf;    ///< per stave: its ring, numbered in the order (a run of staves)
    std::vector<Vec3d> slideGrid;  ///< per stave: its way out of its mouth along its tunnel (grid, unit)
    std::vector<std::vector<size_t>> hosts;  ///< per stave: the staves (indices) it is glued in place onto
};
/// @p order's staves as FixedStaves: a ring is a run of staves of one ring (Stave::rank).
FixedStaves fixedStaves(const StaveOrder& order, const PlannerInput& input);

/// The steps of @p order's staves put among @p plan's: each slid in along its tunnel and held
/// kStaveLiftMm off its place, or, glued in place, slid straight to it (its hosts glued on); a
/// stave with no direction is a problem of the plan instead. @p slots: per stave in its mounting
/// order, (its index in @p order, how many of @p plan's steps go on before it); empty: all before
/// them, in @p order's order.
void addStaveSteps(mount::InstallationPlan& plan, const PlannerInput& input, const StaveOrder& order,
                   const Transform4d& frameToGridMm,
                   const std::vector<std::pair<size_t, size_t>>& slots = {});

/// The plan when staves have no direction (−1 in @p order.holes): the staves' steps and a problem
/// for each stave no hole holds; every other piece placed nowhere (no order is sought for them: the
/// frame must grow toward the staves first).
mount::InstallationPlan unheldStavesPlan(const PlannerInput& input, const StaveOrder& order,
                                         const Transform4d& frameToGridMm);

/// Hole @p hole's direction in the grid's mm (unit).
Vec3d gridDirection(int hole, const Transform4d& frameToGridMm);

/// Could the boxes meet when @p moving is pushed off along @p d past @p still? Their shadows on
/// the plane normal to d overlap, and something of @p still lies ahead of @p moving's rear.
bool shadowsMeet(const Box3d& moving, const Box3d& still, const Vec3d& d);

/// Does @p moving, pushed off along @p d, run into @p still's voxels? Only a voxel in the same column
/// along d is met, not one beside it (a cut face's two sides are a voxel apart; the face itself is
/// tested exactly by facesAllow): the pixels are voxels centred, along a grid axis, on the voxel
/// centres (the bounds grown by half a voxel), and an obstacle voxel is drawn just under half a voxel
/// wide. Drawn from the pixels' corners, it covered four pixels: the cheese at 700 mm, a mouth ring
/// slid out of its mouth met the face pieces beside its rim (docs/mounting.md, "Order"). Only asked
/// where shadowsMeet (blockersOf tests that first, before its cache). @p isTouching: the two share
/// a cut face (facesAllow), near which their voxels are swept apart.
bool sweepHits(const MountBody& moving, const MountBody& still, const Vec3d& d, double voxelMm,
               bool isTouching);

/// Whether the cut faces between @p still and @p moving let @p moving go on after @p still along
/// @p d (mount::faceOrder for every plane they share: its path does not go into still). True when
/// they share no face; @p isTouching says whether they do.
bool facesAllow(const MountBody& still, const MountBody& moving, const Vec3d& d, const FaceContacts& faces,
                bool* isTouching);

/// Fills @p body's glueOptions when no peg can hold it: every hole of @p holes, each tested for a
/// free path (in parallel).
void addGlueOptions(MountBody& body, const std::vector<int>& holes, const FrameSweeps& sweeps,
                    double voxelMm);

/// Remembered sweeps between bodies: (moving, still, hole) → moving, pushed off along hole, runs
/// into still's voxels.
using SweepCache = std::map<std::tuple<std::vector<uint32_t>, std::vector<uint32_t>, int>, bool>;

/// A mounting order found by taking the assembly apart (docs/mounting.md, "Order"). Whether a body
/// can go on after another depends on its own direction only, and taking bodies away never stops
/// another from leaving, so removing, while any can be removed, one that can (along a direction
/// it may take) finds an order whenever one exists for some choice of directions; the reverse is
/// the mounting order. The bodies that are left are @p stuck: none of them can go on last among them.
struct Disassembly {
    /// Mounting order of the bodies that could be placed: the staves (fixed bodies) left in place
    /// throughout first, in their order, then the reverse of the taking away (rings of staves
    /// taken away among the rest).
    std::vector<uint32_t> order;
    size_t ringsTakenAway = 0;  ///< rings of staves taken away among the other bodies (FixedStaves)
    /// For the debug output, where bodies are stuck: each ring of staves in their way that stays,
    /// and what keeps it (the bodies its staves' ways meet, "s" after a stave).
    std::vector<std::string> ringNotes;
    std::vector<int> holes;       ///< per body: its direction; −1 when it has none or is stuck
    /// (a, b): body a must go on before body b: along its chosen direction, a cannot go on after b.
    std::vector<std::pair<uint32_t, uint32_t>> before;
    std::vector<uint32_t> stuck;  ///< bodies with directions that no order can place
    /// Per stuck body: the stuck bodies in the way of its best direction.
    std::vector<std::vector<uint32_t>> stuckBlockers;
    /// (host piece, piece): a hosted body's piece glued onto a piece of a body placed before it.
    std::vector<std::pair<uint32_t, uint32_t>> gluedOn;
};

/// What glues a hosted body on: the smallest common cut face (mm²) and how straight its pins go
/// into it (the cosine of the largest angle between the direction and the face's normal).
struct GlueOnRule {
    double minFaceMm2 = 150.0;
    double minCosine = 0.5;
    /// A cut face of @p voxelFaces faces of @p voxelMm voxels is large enough to glue across.
    bool isLargeEnough(size_t voxelFaces, double voxelMm) const {
        return double(voxelFaces) * voxelMm * voxelMm >= minFaceMm2;
    }
};

/// The disassembly of @p bodies over the directions each may take (free and with tenons, in rank
/// order; among the bodies that can go on last, the one that can along its best-ranked direction,
/// then the highest). A hosted body (MountBody::glueOptions) goes on along a free direction while a
/// body it can be glued onto (@p glueOn) is in place; hosted bodies leave first, so they go on as
/// late as they can. Bodies with no direction at all take no part (Disassembly::holes −1).
/// The last @p fixedCount bodies are staves, put on first: in every other body's way where they
/// are, neither placed nor stuck. Without @p staves they are in place throughout; with it, where no
/// other body can leave, a whole ring of them is taken away (it goes on after the bodies left)
/// when every stave of it slid out along its tunnel meets no body left but its ring (facesAllow,
/// sweepHits), no stave left is glued in place onto it and no body left to be glued on has only
/// its staves to be glued onto. Of such rings, the last in the staves' order that is in the way of
/// a body left (or of a ring in such a way) goes; none such: the bodies left are stuck.
/// (docs/mounting.md, "Three tunnels through one point": the pieces between tunnels whose only
/// way out is through a tunnel go on before that tunnel's staves.)
Disassembly disassemble(const std::vector<MountBody>& bodies, const FaceContacts& faces,
                        const Transform4d& frameToGridMm, double voxelMm, const GlueOnRule& glueOn,
                        SweepCache& cache, const RunContext& context, size_t fixedCount = 0,
                        const FixedStaves* staves = nullptr);

/// Voxel faces between the pieces of two bodies (their contact area, in voxel faces).
size_t bodyContact(const MountBody& a, const MountBody& b, const FaceContacts& faces);

/// The pieces @p plan places nowhere that no cut can place: no usable tenon candidate along any
/// direction (@p input) and no cut face with any piece large enough to glue them on across
/// (GlueOnRule::minFaceMm2, @p faces). Re-cuts and keystones cut only pieces with candidates, and
/// cutting its neighbours leaves its wall and the frame as they are and only splits the faces it
/// shares, so such a piece stays placed nowhere until the pieces around it are joined (tunnel
/// linings) or the frame grows.
std::vector<uint32_t> unplaceablePieces(const mount::InstallationPlan& plan, const PlannerInput& input,
                                        const FaceContacts& faces, double voxelMm);

/// The plan: a body per piece, a piece no peg can hold glued onto a neighbour as it goes on
/// (along a direction of @p holes), the disassembly's directions and order, and bodies that are
/// stuck glued into one until an order exists. What could not be resolved is in
/// InstallationPlan::problems.
mount::InstallationPlan planMounting(const PlannerInput& input, const FrameSweeps& sweeps,
                                     const FaceContacts& faces, double voxelMm, const std::vector<int>& holes,
                                     int maxPerPiece, const RunContext& context);

}  // namespace zomefab::pieces::detail
