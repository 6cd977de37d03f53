// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Printable pieces (paper §6): the shell cut by the partition's cells with level-set CSG,
/// split into connected pieces, tenons grown from the inner surface into free blue holes of the
/// frame's balls (§6.1), an engraved piece number, meshing, and an orientation that fits the
/// printer. No OpenVDB in this header. docs/pieces.md explains each step.
///
/// @code
///   const Transform4d frameToGrid = shell.info().transformMm * affineInverse(frameTransformMm);
///   Pieces p = makePieces(shell, frame, frameToGrid, partitionResult, fabrication, options, context);
///   writePieces(p, "out/pieces", {"shell.vdb", "frame.json", "partition.json"});
/// @endcode
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/mount/plan.h"
#include "zomefab/partition/partition_result.h"
#include "zomefab/pieces/label.h"
#include "zomefab/pieces/tenons.h"
#include "zomefab/sdf/level_set.h"
#include "zomefab/zome/structure.h"

namespace zomefab::pieces {

/// How the pieces go onto the frame (docs/mounting.md).
struct MountOptions {
    /// Balls and struts are taken this much larger when a piece's path is tested (mm): what the
    /// voxels and printing may be off by.
    double frameMarginMm = 1.0;
};

/// Where two pieces glued before mounting meet: a printed pin on one, a socket in the other, across
/// their common cut face, so the two are glued in the one position they were cut in.
struct AlignmentPin {
    uint32_t partner = 0;         ///< the other piece of the pair
    bool isSocket = false;        ///< this piece has the hole; the partner has the pin
    Vec3d centerGridMm{0, 0, 0};  ///< on the cut face's plane (grid mm)
    Vec3d axisGrid{0, 0, 1};      ///< unit, out of the piece with the pin, into the one with the socket
    double radiusMm = 1.5;        ///< the pin's; the socket is this plus the clearance
    double lengthMm = 3.0;        ///< how far the pin stands out of its face
};

/// How glued pairs are pinned together (docs/mounting.md, "Glued groups").
struct PinOptions {
    double diameterMm = 3.0;    ///< the pin; less where the wall is thinner (never under 1.5)
    double lengthMm = 3.0;      ///< standing out of the face; the socket is 0.3 mm deeper
    double clearanceMm = 0.15;  ///< between pin and socket on every side
    int perPair = 2;            ///< pins per glued pair, as far apart as the face allows
};

/// PiecesOptions::printWallMm's "choose for me": kDefaultPrintWallMm where the shell allows it.
constexpr double kPrintWallAuto = -1.0;
/// The printed wall chosen for a 0.4 mm nozzle and printed PLA: four extrusion lines of 0.45 mm,
/// two perimeters on each face and nothing between (a fifth line, 2.0 mm, costs a quarter more
/// time standing); a curved piece bends about 0.1 mm under a hand's press (a shallow shell,
/// Reissner), the flat bound is 5.7 mm over 100 mm at 19 MPa, under what PLA takes across its
/// layers (docs/pieces.md, "Wall thickness"). Within the shell's band at voxels of at least 0.72 mm.
constexpr double kDefaultPrintWallMm = 1.8;
/// What --print-wall-mm takes, for the messages of the options' checks (checkPiecesOptions and the
/// tools' parser).
inline constexpr const char* kPrintWallValues = "auto, 0 (the shell's wall) or in [1, 200] mm";

struct PiecesOptions {
    /// Connected pieces with less volume are merged into the neighbour they share the largest cut
    /// face with (a 2 cm³ sliver is too small to carry a tenon or to print well). Never dropped:
    /// an isolated sliver stays a piece of its own, with a warning.
    double minPieceVolumeMm3 = 2000.0;
    TenonOptions tenons;
    LabelOptions label;
    MountOptions mount;
    PinOptions pins;
    /// Every cut face is moved this far into its piece (mm), so neighbours meet with twice this
    /// gap: room for glue and for the printer's few tenths, and where three cells meet the two
    /// meshes' voxel rounding does not make them overlap.
    double seamGapMm = 0.15;
    /// volumeToMesh adaptivity: 0 = one vertex per surface voxel; larger merges flat regions into
    /// larger triangles (cut faces, tenons and numbers stay at full resolution, the outer surface
    /// meshes at 3 % of it). 0.3 gives the demo 43 MB of STL where 0 gives about 120 MB (docs/pieces.md).
    double adaptivity = 0.3;
    /// Cut a piece too few pegs hold anew with a neighbour, along a plane that gives both halves
    /// minPerPiece pegs (docs/mounting.md, "Pairs cut anew"). Off by default: the halves print
    /// with more support (the demo: 12 of 12 pieces on two pegs instead of 10, 6 h more to print).
    bool isRecuttingPairs = false;
    /// Cut a held piece that needs much support however it lies (a cup of thin wall, a head with
    /// its ears) in two along a plane that holds both halves, where they need much less support
    /// (docs/pieces.md, "Cut for less support"); then, with glued groups, print a piece no such
    /// cut helps in two parts glued together before mounting ("Printed in parts").
    bool isCuttingForSupport = false;
    /// Glue a piece (or glued group) too few pegs hold to a neighbour before mounting, where the two
    /// go on as one body along a direction whose tenons hold both (docs/mounting.md, "Glued
    /// groups"). Nothing more to print but alignment pins; the maker glues a few pairs more.
    bool isGluingUnderHeld = true;
    /// Grow the frame toward a piece too few pegs hold: a strut to a new ball whose hole along the
    /// piece's direction meets its wall within a tenon's reach (docs/mounting.md, "Frame grown
    /// toward a piece"). Only where makePieces is given a StrutTest (zomefab run).
    bool isGrowingFrame = true;
    /// Print the pieces with this wall (mm) where it is thinner than the shell's; 0 = the shell's.
    /// The plan (paths, order, pegs) is made with the shell's wall, the frame's forbidden zone;
    /// a piece keeps only the outer printWallMm of it where each of its pegs grows again through
    /// the thin wall (docs/pieces.md, "A thinner printed wall"), and stays thick otherwise: a
    /// glued piece, one with alignment pins, or one whose stems cannot reach through. At most
    /// the shell's band less half a voxel (2.5 mm at 1 mm voxels). kPrintWallAuto (the default):
    /// kDefaultPrintWallMm where the shell allows it (a wall of two bands and a voxel, voxels
    /// of at least 0.72 mm), else the shell's wall.
    double printWallMm = kPrintWallAuto;
};

/// Whether a strut from ball a through hole, of size, to a new ball at its end may be added to a
/// frame: the frame stage's clearance from the surface and its collision tests
/// (frame::canGrowStrut). makePieces grows the frame only with one.
using StrutTest = std::function<bool(const zome::Structure& frame, zome::BallId a, int hole, int size)>;

/// @throw Error(Usage) naming the option when a value is out of its documented range.
void checkPiecesOptions(const PiecesOptions& options);

/// One printable piece.
struct Piece {
    uint32_t id = 0;
    std::vector<uint32_t> cells;     ///< cells it is cut from (sorted)
    std::vector<uint32_t> requests;  ///< the partition's pieces it comes from (sorted)
    /// Pieces sharing a cut face, with the face's area (mm², first order in the voxel).
    std::vector<std::pair<uint32_t, double>> neighbors;
    uint32_t sliversMerged = 0;   ///< small components merged into this piece
    double shellVolumeMm3 = 0.0;  ///< its part of the shell, counted in voxels

    /// The direction the piece goes on along (−d): the zome hole whose direction is d; every
    /// tenon of the piece uses it. −1 when no direction was found (the plan says why).
    int hole = -1;
    std::vector<Tenon> tenons;
    /// When fewer than TenonOptions::minPerPiece tenons were found: why each candidate ray failed
    /// ("hole holds a strut" → 3, ...); empty otherwise.
    std::map<std::string, int> tenonShortfall;

    /// Pins and sockets toward the pieces it is glued to (the plan's glued pairs).
    std::vector<AlignmentPin> pins;

    /// The wall it is printed with, mm: the shell's, or PiecesOptions::printWallMm (isThinWall).
    double wallMm = 0.0;
    bool isThinWall = false;

    std::optional<PieceLabel> label;  ///< the engraved number, when there was room
    std::string labelNote;            ///< why there is no label

    /// The printable mesh, in printer coordinates (on the bed z = 0, centred in x and y): closed,
    /// 2-manifold, outward-oriented.
    TriMesh mesh;
    Transform4d gridToPrintMm;         ///< shell-grid mm → printer mm (a rotation and a translation)
    bool isCutFaceDown = false;        ///< a planar cut face lies on the bed
    bool isOnSupports = false;         ///< it stands on its supports (PrintOrientation::isOnSupports)
    Vec3d downNormalGridMm{0, 0, -1};  ///< the outward normal (grid mm) that points down when printed
    /// Area of the piece's cross-section kBaseHeightMm (0.2 mm) above the bed: what the first
    /// layer prints. A cut face down gives its area; a piece with none rests on the largest base
    /// that fits (docs/pieces.md, "Orientation").
    double baseAreaMm2 = 0.0;
    /// What needs support printed this way (estimateSupport): the area of the facets facing down
    /// more than 45° from the vertical, and the volume of support columns under them from the bed.
    double supportAreaMm2 = 0.0;
    double supportVolumeMm3 = 0.0;
    bool isBrimAdvised = false;  ///< the first layer is under kBrimBelowMm2: print it with a brim
    Vec3d extentsMm{0, 0, 0};    ///< size of the printed piece along the printer's x, y, z
    double volumeMm3 = 0.0;      ///< of the mesh
    Box3d gridBoundsMm;          ///< of the mesh in the shell grid's mm
};

/// The result of makePieces.
struct Pieces {
    std::vector<Piece> pieces;
    Vec3d printerMm = Fabrication{}.printerMm;       ///< the Fabrication's printer they were oriented for
    double bedMarginMm = Fabrication{}.bedMarginMm;  ///< the Fabrication's, for the plates (plates.h)
    double voxelMm = 0.0;
    double shellVolumeMm3 = 0.0;  ///< the shell, counted in voxels
    /// Shell volume in cells no request names (no outer surface there): merged into neighbours.
    double outsideCellsVolumeMm3 = 0.0;
    size_t sliversMerged = 0;
    /// Islands of the wall under the smallest piece that touch no other piece: left out (the
    /// largest island is kept, and counted, when the smallest piece is larger than the shell).
    size_t isolatedSlivers = 0;
    /// Pieces cut in two because the frame was in the way of every direction (docs/mounting.md):
    /// each adds one piece to what the partition asked for.
    size_t recutPieces = 0;
    size_t mergedPieces = 0;  ///< under-held pieces printed as one with a neighbour (docs/mounting.md)
    /// Pairs of neighbours cut anew along another plane so that both are held (docs/mounting.md).
    size_t recutPairs = 0;
    /// Held pieces cut in two for less support (PiecesOptions::isCuttingForSupport).
    size_t supportCuts = 0;
    /// Pieces printed in two parts glued together before mounting, for less support (splitForPrint).
    size_t printSplits = 0;
    /// Pairs glued before mounting because one of them was held by too few pegs (docs/mounting.md).
    size_t gluedForPegs = 0;
    /// Pieces printed with PiecesOptions::printWallMm instead of the shell's wall.
    size_t thinPieces = 0;
    /// The frame with the struts grown toward pieces too few pegs hold (PiecesOptions::
    /// isGrowingFrame): the frame to build and to write. Empty when none was grown.
    std::optional<zome::Structure> grownFrame;
    size_t frameStrutsGrown = 0;
    /// A plan that failed: how many of the pieces it placed nowhere line tunnels that cross each
    /// other (docs/mounting.md, "What is not done"); 0 when they are not most of them.
    size_t crossingTunnelPieces = 0;
    Transform4d frameToGridMm;
    Transform4d gridTransformMm;  ///< the shell's LevelSetInfo::transformMm (input mesh → grid mm)
    PiecesOptions options;
    /// The installation plan: every piece's direction, the mounting order, and what (if anything)
    /// keeps the object from being built.
    mount::InstallationPlan plan;
    double seconds = 0.0;
};

/// What makePieces throws when a piece fits the printer in no orientation: its region of the
/// surface fitted (the partition's test), but the wall, tenons and pegs made it larger.
class PieceTooLarge : public Error {
public:
    PieceTooLarge(const std::string& message, double overshootMm)
        : Error(ErrorCode::ProcessingFailed, message), overshootMm(overshootMm) {}
    double overshootMm;  ///< by how much its best orientation exceeds the printer, mm
};

/// What requireBuildable throws: the installation plan has problems (exit 3).
class NotBuildable : public Error {
public:
    explicit NotBuildable(const std::string& message, size_t problemCount = 1, bool isInTheObject = false)
        : Error(ErrorCode::ProcessingFailed, message),
          mProblemCount(problemCount),
          mIsInTheObject(isInTheObject) {}
    /// How many problems the plan recorded (a piece no direction mounts, a group stuck in a cycle).
    size_t problemCount() const { return mProblemCount; }
    /// The problem lies in the object, not in where the partition cut it (pieces lining tunnels that
    /// cross): partitioning again does not help.
    bool isInTheObject() const { return mIsInTheObject; }

private:
    size_t mProblemCount;
    bool mIsInTheObject;
};

/// @throw NotBuildable "the pieces cannot be put on the frame: ..." naming the plan's problems,
/// when @p pieces' installation plan has any (a tool writes no such pieces).
void requireBuildable(const Pieces& pieces);

/// Cuts @p shell into printable pieces (paper §6) that fit the Fabrication's printer.
/// @param shell         the hollow shell level set (zf-shell), grid mm
/// @param frame         the Zometool frame, frame mm
/// @param frameToGridMm frame mm → grid mm: T_grid · T_frame⁻¹ of the two transform_mm; must be a
///                      rotation plus a translation (the two were scaled alike)
/// @param partition     the partition stage's result as it is: its argmax cells (frame mm) and
///                      its pieces (their cells and surface boxes); the shell in cells no piece
///                      names joins the neighbouring pieces. A piece's bounds tell apart the
///                      pieces that share a cell (a cell whose surface falls into separate patches).
/// @throw Error(Usage) for bad options or a voxel too coarse for the tenon pegs;
///        Error(InvalidInput) for an empty shell, a request naming an unknown cell, mismatched
///        cell arrays, or a frameToGridMm that scales; PieceTooLarge when a piece fits the
///        printer in no orientation (the partition must cut smaller); Error(ProcessingFailed)
///        when a piece mesh is not closed, or (tenons on) when the installation plan has
///        problems (requireBuildable, before any piece is meshed); Error(Cancelled).
/// @param canGrow       when given (and options.isGrowingFrame), the frame may grow toward pieces
///                      too few pegs hold; the result's grownFrame is then the frame to build
Pieces makePieces(const sdf::LevelSet& shell, const zome::Structure& frame, const Transform4d& frameToGridMm,
                  const partition::PartitionResult& partition, const Fabrication& fabrication,
                  const PiecesOptions& options, RunContext& context, const StrutTest& canGrow = {});

}  // namespace zomefab::pieces
