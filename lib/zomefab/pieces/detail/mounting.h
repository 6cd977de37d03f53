// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The installation plan, made on the shell's voxels before the tenons are grown (internal to
/// lib/zomefab/pieces): for every piece the directions along which it can be pushed onto the frame
/// (its path free of balls and struts) and held (tenons of balls whose hole points that way); pieces
/// that cannot be held on their own glued to a neighbour into one body; one direction per body so
/// that an order exists, and the order. docs/mounting.md.
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/mount/plan.h"
#include "zomefab/mount/sweep.h"
#include "zomefab/pieces/detail/grouping.h"
#include "zomefab/pieces/detail/voxels.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces::detail {

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
    /// Per voxel: within two voxels of another piece (a cut face): left out of the sweeps against
    /// neighbours, whose order the faces decide.
    std::vector<uint8_t> isNearCut;
    Box3d bounds;
    std::vector<DirectionOption> options;

    /// The best direction with a free path and at least one tenon, or null.
    const DirectionOption* bestFree() const;
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
};
PlannerInput plannerInput(const Pieces& out, const VoxelField& field,
                          const std::vector<TenonCandidate>& candidates);

/// Direction options from tenon candidates per hole (count, summed score), best first: most tenons
/// (counted up to @p cap), then the score. Untested.
std::vector<DirectionOption> rankedOptions(const std::map<int, std::pair<size_t, double>>& byHole,
                                           size_t cap);
/// Tests the options of @p body not yet tested for a free path against the frame: all (in
/// parallel), or with @p isFirstFreeOnly in rank order up to the first free one (a trial body).
void testPaths(MountBody& body, const FrameSweeps& sweeps, double voxelMm, bool isFirstFreeOnly = false);

/// The body of @p members (the union of their voxels) with its direction options ranked and each
/// tested against the frame.
MountBody makeBody(const std::vector<uint32_t>& members, const PlannerInput& input, const FrameSweeps& sweeps,
                   double voxelMm, int maxPerPiece, bool isFirstFreeOnly = false);

/// Remembered sweeps between bodies that do not touch: (moving, still, hole) → it runs into it.
using SweepCache = std::map<std::tuple<std::vector<uint32_t>, std::vector<uint32_t>, int>, bool>;

/// What keeps a choice of directions from an order: pairs of bodies that block each other both
/// ways, the bodies of a cycle when the rest has one, and otherwise the order and its relation.
struct Trouble {
    std::vector<std::pair<uint32_t, uint32_t>> deadlocks;  ///< body indices
    std::vector<uint32_t> cycle;
    std::vector<uint32_t> order;
    std::vector<std::pair<uint32_t, uint32_t>> before;
    size_t count() const { return deadlocks.size() + cycle.size(); }
};

/// The order constraints between @p bodies for the directions @p holeOfBody (−1: none, no
/// constraint): neighbours by their cut faces (mount::faceOrder), other bodies by pushing one off
/// past the other's voxels; then an order, bottom first.
Trouble blockingTrouble(const std::vector<MountBody>& bodies, const std::vector<int>& holeOfBody,
                        const FaceContacts& faces, const Transform4d& frameToGridMm, double voxelMm,
                        SweepCache& cache);

/// Voxel faces between the pieces of two bodies (their contact area, in voxel faces).
size_t bodyContact(const MountBody& a, const MountBody& b, const FaceContacts& faces);

/// The plan: pieces that no free direction holds, then those held by fewer than @p minPerPiece
/// tenons, glued to the neighbour that gives their union the most tenons (when that is more); a free
/// direction per body, changed where bodies block each other until an order exists, bodies that still block
/// each other glued; the order (lowest first). What could not be resolved is in InstallationPlan::problems.
mount::InstallationPlan planMounting(const PlannerInput& input, const FrameSweeps& sweeps,
                                     const FaceContacts& faces, double voxelMm, int minPerPiece,
                                     int maxPerPiece, const RunContext& context);

}  // namespace zomefab::pieces::detail
