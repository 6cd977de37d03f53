// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The steps of the partition stage (internal to lib/zomefab/partition), each a function of
/// what it needs, so each can be run and tested alone: the surface and its nearest balls
/// (surface.cpp), the graph-cut problems on one or two levels (graph_levels.cpp), the fit schedule
/// (schedule.cpp), the region merge (region_merge.cpp), the planar cuts (planar_cuts.cpp) and the
/// pieces from the cells (cell_pieces.cpp). docs/partition.md explains each.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/format.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/vec.h"
#include "zomefab/partition/alpha_expansion.h"
#include "zomefab/partition/face_graph.h"
#include "zomefab/partition/partition.h"
#include "zomefab/zome/structure.h"

namespace zomefab::partition::detail {

inline constexpr uint32_t kNone = 0xFFFFFFFFu;
/// Balls and struts are taken this much larger in the mountability test (mm): the pieces stage's
/// frame margin (1 mm) and a millimetre for the faces standing in for the wall's voxels.
inline constexpr double kMountMarginMm = 2.0;

/// "200 x 200 x 200 mm"
inline std::string sizeText(const Vec3d& v) {
    return formatNumbers("%.0f x %.0f x %.0f mm", v[0], v[1], v[2]);
}

// --- geometry helpers -------------------------------------------------------------------------

/// Closest point of triangle abc to p, squared distance (Ericson, Real-Time Collision Detection §5.1.5).
double pointTriangleDist2(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

/// For every query point its k nearest balls, sorted by (distance, label): labels[q*k + i],
/// distancesMm[q*k + i].
struct NearestBalls {
    int k = 0;
    std::vector<uint32_t> labels;
    std::vector<double> distancesMm;
};

NearestBalls nearestBalls(const std::vector<Vec3d>& queries, const std::vector<Vec3d>& balls, int k,
                          double cellMm);

/// Graph-cut nodes over faces: CSR node → faces.
struct Units {
    std::vector<uint32_t> unitOf;      ///< per face
    std::vector<uint32_t> offsets{0};  ///< CSR unit → faces
    std::vector<uint32_t> faces;
    size_t count() const { return offsets.size() - 1; }
};

/// Salient regions become one node each (a seam can never run inside them); the other faces are
/// single nodes, or breadth-first clusters of about @p clusterSize edge-connected faces.
Units buildUnits(const FaceGraph& g, const std::vector<uint8_t>& salient, size_t clusterSize);

/// Smoothness weight of Eq. (3) for the edge-adjacent faces a, b, before w_smoothness:
/// −log(θ/π)·φ + w_saliency·E_saliency, with θ the angle between the normals (clamped below),
/// φ the centroid distance in mm and E_saliency = 1 when either face is salient.
double edgeWeight(const FaceGraph& g, const std::vector<uint8_t>& salient, uint32_t a, uint32_t b,
                  const PartitionOptions& o);

/// The vertices of @p faces (each once, in first-use order).
std::vector<Vec3d> faceVertices(const TriMesh& mesh, const std::vector<uint32_t>& faces,
                                std::vector<uint32_t>& stamp, uint32_t& stampValue);

/// Groups faces by a per-face id: CSR id → faces (in increasing face order).
void groupFaces(const std::vector<uint32_t>& idOf, uint32_t idCount, std::vector<uint32_t>& offsets,
                std::vector<uint32_t>& faces);

/// Quick accept: an axis-aligned box that fits needs no orientation search.
bool fitsTrivially(const std::vector<Vec3d>& pts, const Vec3d& printer, double margin);

/// The schedule's fit test (docs/partition.md §4): the quick accept, else the oriented-box search.
bool fitsPrinter(const std::vector<Vec3d>& pts, const Vec3d& printer, double margin);

/// The printer-fit test of face sets (docs/partition.md §4), with one stamp array to gather
/// vertices without repeats.
/// Per face, the hole directions (bit h for zome hole h) along which the face's wall, pushed off
/// from its place, runs into the frame: one of its inner points (points of the face about
/// @p pixelMm apart, @p wallMm behind the surface) has a ball or a strut, grown by @p marginMm,
/// ahead of it on its line. Depth rasters of @p pixelMm, one per direction, in parallel
/// (docs/partition.md §4, "Mountable").
std::vector<uint64_t> frameBlockedDirections(const TriMesh& mesh, const FaceGraph& graph,
                                             const zome::Structure& frame, double wallMm, double marginMm,
                                             double pixelMm = 2.0);

/// A region's area that each hole direction cannot take (frameBlockedDirections): additive, so
/// the profile of a union is the sum of the profiles.
struct MountProfile {
    std::array<double, zome::kHoleCount> blockedMm2{};
    double areaMm2Total = 0.0;
    Vec3d normalMm2{0, 0, 0};  ///< the faces' normals weighted by their areas
    void addFace(double areaMm2, const Vec3d& normal, uint64_t blockedHoles);
    void add(const MountProfile& other);
    /// The direction with the least blocked area; of those, the one nearest the region's mean
    /// normal (the one tenons can use), then the lowest.
    int freestHole() const;
    /// Some direction leaves at most @p share of the area blocked.
    bool isMountable(double share) const;
};

struct FitTester {
    const TriMesh& mesh;
    const FaceGraph& graph;
    const Fabrication& fab;
    const RunContext& run;
    std::vector<uint32_t> stamp;
    uint32_t stampValue = 0;
    /// Per face: frameBlockedDirections; empty: regions are not tested for a direction.
    std::vector<uint64_t> blocked = {};
    double blockedShare = 0.0;  ///< PartitionOptions::mountBlockedShare

    PrinterFit fitOf(const std::vector<uint32_t>& faces) {
        const std::vector<Vec3d> pts = faceVertices(mesh, faces, stamp, stampValue);
        return fitInPrinter(pts, fab.pieceBoxMm(), fab.fitMarginMm);
    }
    MountProfile profileOf(const std::vector<uint32_t>& faces) const;
    /// Some hole direction pushes the region's wall off the frame (all but blockedShare of it).
    bool isMountable(const std::vector<uint32_t>& faces) const;
    /// Fits the printer and is mountable.
    bool fits(const std::vector<uint32_t>& faces) { return isMountable(faces) && fitOf(faces).fits; }
};

/// Splits @p faces, which fit the printer but no direction can mount, between the faces their
/// freest direction cannot take and the others: by the plane halfway between the two parts'
/// centroids, normal to the line joining them. False when that leaves a side empty.
bool splitUnmountable(const FitTester& cx, const std::vector<uint32_t>& faces, std::vector<uint32_t>& lo,
                      std::vector<uint32_t>& hi);

/// Does each of @p faceSets fit the printer (its vertices' oriented box, docs/partition.md §4)?
/// Vertex lists are gathered serially (one stamp array), the fit tests run in parallel; the result
/// does not depend on the thread count.
std::vector<char> fitsEach(FitTester& cx, const std::vector<std::vector<uint32_t>>& faceSets);

/// Splits @p faces (one class) into parts that each fit the printer, by recursive bisection
/// across the longest axis of the best oriented box, at its middle. Salient regions stay on one
/// side (the side of their first face). Appends the parts to @p parts.
void bisectUntilFit(FitTester& cx, const std::vector<uint32_t>& faces,
                    const std::vector<uint32_t>& salientRegionOf, std::vector<std::vector<uint32_t>>& parts,
                    int depth);

/// Length (mm) of the edge faces @p f and @p h share; 0 when they share fewer than two corners.
double sharedEdgeMm(const TriMesh& mesh, uint32_t f, uint32_t h);

// --- the stage's state, step by step ----------------------------------------------------------

/// The surface the stage labels: the mesh, its face graph, saliency, the k nearest label balls of
/// every face (Eq. 2) and the Eq. (3) weight of every face pair (prepareSurface).
struct Surface {
    const TriMesh& mesh;
    const std::vector<zome::BallId>& labelBalls;
    size_t faceCount = 0;
    uint32_t labelCount = 0;
    double b0 = 0.0;
    std::vector<Vec3d> ballMm;  ///< label → ball centre, mm
    FaceGraph graph;
    std::vector<uint32_t> salientRegionOf;  ///< per face, kNone when not salient
    std::vector<std::vector<uint32_t>> salientFacesOf;
    NearestBalls near;
    int k = 0;                            ///< candidates per face (at most the label count)
    std::vector<double> faceEdgeWeights;  ///< Eq. (3) weights aligned with graph.neighbors

    Surface(const TriMesh& m, const std::vector<zome::BallId>& labels, double b0Mm)
        : mesh(m),
          labelBalls(labels),
          faceCount(m.triangles.size()),
          labelCount(uint32_t(labels.size())),
          b0(b0Mm) {}
};

/// The graph-cut problems: faces (salient regions contracted) or small clusters, and with two
/// levels large clusters solved first (prepareProblems).
struct Problems {
    bool isTwoLevel = false;
    int bandRings = 3;
    Units units, clusters;
    LabelingProblem prob, clusterProb;
    std::vector<uint32_t> initial, clusterInitial;  ///< nearest-ball labellings
};

/// The schedule's outcome for the planar cuts: the SVM class of every face, each class's ball,
/// and the merged regions (groups).
struct Classes {
    std::vector<uint32_t> trainClass;     ///< per face: SVM class
    std::vector<zome::BallId> classBall;  ///< class → ball
    std::vector<uint32_t> faceGroup;      ///< per face: its merged region (empty: no merge)
    uint32_t groupCount = 0;              ///< groups of the region merge (ids above: repair parts)
};

void checkInputs(const zome::Structure& frame, const Fabrication& fab, const PartitionOptions& opt,
                 Surface& S, PartitionResult& res);

/// Face graph, salient regions, the k nearest balls of every face (Eq. 2) and the Eq. (3)
/// weight of every face pair.
void prepareSurface(Surface& S, const PartitionOptions& opt, PartitionResult& res);

/// Data term, Eq. (2): D(t, n) = w_data · log d(t, n), d in units of b0, clamped below.
double dataCost(const Surface& S, const PartitionOptions& opt, double dMm);

/// D summed over the faces of node @p u of @p units, with the true distances.
double unitCost(const Surface& S, const PartitionOptions& opt, const Units& units, size_t u, uint32_t label);

/// Graph-cut nodes: faces (salient regions contracted), or on very large meshes small clusters
/// of faces; with two levels, also large clusters solved first.
Problems prepareProblems(const Surface& S, const PartitionOptions& opt, PartitionResult& res,
                         const RunContext& run);

/// The labelling problem over @p units; @p initial receives each node's cheapest candidate
/// (the nearest ball, summed over a node's faces).
LabelingProblem makeProblem(const Surface& S, const PartitionOptions& opt, const Units& units,
                            std::vector<uint32_t>& initial);

/// The node-level problem with every node outside @p band held at its label in @p labels (its
/// only candidate) and every node inside also allowed its current label: the same energy as
/// P.prob for labellings that agree outside the band, and expansions only touch the band.
LabelingProblem restrictToBand(const Surface& S, const Problems& P, const PartitionOptions& opt,
                               const std::vector<uint32_t>& labels, const std::vector<char>& band);

/// Nodes within P.bandRings rings of faces of a seam of @p labels.
std::vector<char> seamBand(const Surface& S, const Problems& P, const std::vector<uint32_t>& labels);

/// One graph cut at w_smoothness @p ws from the nearest-ball labelling (two levels when set).
AlphaExpansionResult graphCut(const Surface& S, const Problems& P, const PartitionOptions& opt,
                              const RunContext& run, double ws, ScheduleStep& st);

/// A re-cut at w_smoothness @p ws of the faces flagged in @p isFree, every other face held at
/// its label in @p labels (its only candidate). Free nodes start from their nearest ball and may
/// take their k nearest. The problem keeps the face-level energy of the whole surface (held
/// nodes add constants), so the seam weight between a free face and a held neighbour counts:
/// free faces next to a kept partition join its label where that is cheaper than a new seam.
AlphaExpansionResult refineCut(const Surface& S, const Problems& P, const PartitionOptions& opt,
                               const RunContext& run, double ws, const std::vector<uint32_t>& labels,
                               const std::vector<char>& isFree, ScheduleStep& st);

/// The fit schedule (docs/partition.md §4). The first step cuts the whole surface at
/// w_smoothness = smoothnessStart and keeps every partition that fits the printer. Each further
/// step multiplies w_smoothness by smoothnessFactor and re-cuts only the faces of the partitions
/// that did not fit, the kept ones held: a single oversized partition no longer sends the whole
/// surface to a lower smoothness (which gave many small pieces), and what already fits stays
/// large and smooth. When w_smoothness would fall below smoothnessMin, what still does not fit
/// is bisected. With refineOversizedOnly = false every step re-cuts the whole surface (the paper).
void runSchedule(const Surface& S, const Problems& P, const PartitionOptions& opt, FitTester& fits,
                 Classes& C, PartitionResult& res, const RunContext& run);

/// PartitionOptions::mergeSmallRegions (docs/partition.md §4): the regions are the connected
/// regions of one training class (after any bisection); merged regions keep their classes, so
/// the SVM still sees each as it was cut, and form one group, which makePieces turns into one
/// piece of several cells.
void mergeRegions(const Surface& S, const FitTester& fits, const PartitionOptions& opt, Classes& C,
                  PartitionResult& res, const RunContext& run);

/// A new training class for @p faces, attached to the ball most of them are nearest to
/// (lowest label on ties).
uint32_t newClassFor(const Surface& S, const PartitionResult& res, Classes& C,
                     const std::vector<uint32_t>& faces);

/// Bisects @p faces until the parts fit; every part but the first gets a new class.
bool splitFaces(const Surface& S, const PartitionResult& res, Classes& C, FitTester& fits,
                const std::vector<uint32_t>& faces);

/// Training samples: face centroids. On large meshes, at most half the budget goes to the
/// faces within two rings of a class boundary (where the planes are decided) and the rest to
/// the other faces, each set thinned evenly in face order.
void trainingSamples(const Surface& S, const Classes& C, const PartitionOptions& opt,
                     std::vector<Vec3d>& samples, std::vector<uint32_t>& classes);

/// The salient regions some of whose corners lie in another cell than the others.
std::vector<uint32_t> crossedRegions(const Surface& S, const PartitionResult& res, const LinearCells& cells);

/// Trains the cells; retrains with the corners of crossed salient regions weighted up.
LinearCells trainCells(const Surface& S, const Classes& C, const Fabrication& fab,
                       const PartitionOptions& opt, PartitionResult& res, const RunContext& run,
                       std::vector<uint32_t>& crossed);

/// Pieces from the cells: fragments (connected faces of one cell), merged for crossed salient
/// regions and small areas when the result fits, numbered by lowest face, with their fits.
/// @p pieceFaces receives each piece's faces.
std::vector<Piece> piecesFromCells(const Surface& S, const Classes& C, const Fabrication& fab,
                                   const PartitionOptions& opt, FitTester& fits, const LinearCells& cells,
                                   const std::vector<uint32_t>& faceCells,
                                   const std::vector<uint32_t>& crossed, std::vector<uint32_t>& facePieces,
                                   std::vector<std::vector<uint32_t>>& pieceFaces, size_t& merges);

/// Salient regions whose faces lie in several pieces, or whose corners lie in a cell that is
/// not one of their piece's cells.
size_t countCrossedRegions(const Surface& S, const PartitionResult& res,
                           const std::vector<uint32_t>& crossed);

/// Cells, pieces, and split-and-retrain rounds until every piece fits.
void cutAndMakePieces(const Surface& S, Classes& C, const Fabrication& fab, const PartitionOptions& opt,
                      FitTester& fits, PartitionResult& res, const RunContext& run);

}  // namespace zomefab::partition::detail
