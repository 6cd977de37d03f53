// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Surface partition (paper §5): label the shell's outer triangles with the frame's outermost
/// balls by a multi-label graph cut (Eq. 1–4), cut the partitions that do not fit the printer again
/// at lower w_smoothness (the ones that fit are kept) until all fit, replace the zig-zag seams by
/// planar cuts from a multi-class linear SVM, and turn the cells into connected pieces that fit the
/// printer. docs/partition.md explains each step.
///
/// @code
///   TriMesh meshMm = readMesh(path);  transformInPlace(meshMm, transformMm);
///   const auto labels = frame::outermostBalls(structure);          // N_out
///   PartitionResult r = partitionSurface(meshMm, structure, labels, {}, ctx);
///   nlohmann::json j = partitionToJson(r, meshMm);
/// @endcode
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/partition/face_graph.h"
#include "zomefab/partition/linear_cells.h"
#include "zomefab/partition/partition_result.h"
#include "zomefab/partition/printer_fit.h"
#include "zomefab/zome/structure.h"

namespace zomefab::partition {

/// A sphere of faces the user wants kept whole (`--salient x,y,z,r`), in the mesh's mm frame.
struct SalientSphere {
    Vec3d centerMm{0, 0, 0};
    double radiusMm = 0.0;
};

struct PartitionOptions {
    // --- energy, Eq. (1)–(4) -----------------------------------------------------------------
    double dataWeight = 1.0;      ///< w_data (paper: 1.0 for all shapes)
    double saliencyWeight = 5.0;  ///< w_saliency (paper: 5.0)
    /// k: the candidate labels of a triangle are its k nearest label balls; every other label
    /// gets a prohibitive (infinite) data cost, so a piece always lies over balls near it.
    int candidateCount = 8;
    /// d(t, n) is measured in units of b0 and clamped below at this value, so D = log d is finite
    /// (a centroid cannot reach a ball centre anyway: the shell and the ball radius lie between).
    double minDistanceB0 = 0.05;
    /// θ is clamped below at this angle (radians) so −log(θ/π) is finite on flat parts (Eq. 3).
    double minDihedralRad = 1e-3;

    // --- fit schedule (§5.1) ------------------------------------------------------------------
    double smoothnessStart = 10.0;  ///< first w_smoothness (paper: 10)
    double smoothnessFactor = 0.1;  ///< w_smoothness *= this while a partition does not fit
    /// The schedule bottoms out when the next w_smoothness would fall below this; oversized
    /// partitions are then split (and the result says so).
    double smoothnessMin = 1e-3;
    /// true (default): only the partitions that do not fit are cut again at the next, lower
    /// w_smoothness; the ones that fit are kept as they are, so one oversized partition does not
    /// turn the whole surface into small pieces. false: every step cuts the whole surface again
    /// (the paper's schedule).
    bool refineOversizedOnly = true;
    int maxSweeps = 100;  ///< alpha-expansion passes per graph cut at most
    /// true (default): after the schedule, a region is merged into a neighbour (sharing a seam)
    /// whenever the union still fits the printer (same oriented-box test and margin), smallest
    /// regions first, each into the neighbour with the longest shared seam, until no merge fits.
    /// The re-cuts leave small leftover regions; each piece costs two printed cut walls per seam,
    /// assembly effort, and small pieces rarely get tenons. The merged regions keep their own SVM
    /// classes (cells); a piece is then made of several cells. false: one piece per region.
    bool mergeSmallRegions = true;
    /// A region must be mountable: along some hole direction its wall, pushed off, runs into the
    /// frame over at most this share of its area (docs/partition.md §4, "Mountable"); the others
    /// are cut again like regions too large for the printer. Negative: not tested (the paper).
    double mountBlockedShare = 0.005;

    // --- saliency (§5.1, Eq. 4): union of the mesh's salientFaces flags and these ---------------
    std::vector<SalientSphere> salientSpheres;  ///< faces touching a sphere are salient
    std::vector<uint32_t> salientFaceIndices;   ///< faces marked by index

    // --- planar cuts (§5.2) -------------------------------------------------------------------
    CellTrainingOptions svm;  ///< its seed is seedFor(fabrication, SeedStream::Partition)
    /// Training samples at most: above it, up to half go to faces within two rings of a class
    /// boundary and the rest to the other faces, each thinned evenly in face order (deterministic),
    /// which keeps training time flat on large meshes.
    size_t svmMaxSamples = 20000;
    /// Retraining rounds when a cut crosses a salient region (its samples weighted up each round).
    int salientRetries = 3;

    // --- pieces -------------------------------------------------------------------------------
    /// A piece smaller than this (mm², outer surface) is merged into the neighbour it shares the
    /// longest seam with, when the merged piece still fits: too small to carry a connector.
    double minPieceAreaMm2 = 400.0;
    int maxRepairRounds = 8;  ///< split-and-retrain rounds for pieces that do not fit

    // --- graph size -------------------------------------------------------------------------
    /// Above this many faces the graph cut first runs on about this many clusters of
    /// edge-connected faces (breadth-first from the lowest unassigned face, never across a salient
    /// boundary), starting from their nearest balls, then on the nodes within a band of rings
    /// around the clusters' seams (the rest held). 0 = one level.
    size_t graphNodeTarget = 5000;
    /// The nodes of the refinement (and of a one-level cut): faces, or above this many faces about
    /// this many small clusters, so the graph-cut cost stays flat on very fine meshes. 0 = faces.
    size_t refineNodeTarget = 2000000;
};

/// Partitions the outer surface @p meshMm (mm, in the frame's coordinates) with the balls
/// @p labelBalls of @p frame as labels, into pieces that fit the Fabrication's printer (with its
/// fit margin).
/// @throw Error(InvalidInput) for an empty mesh, no label balls, a label that is not a ball of
///   the frame, or a frame that does not sit inside the mesh (mesh/frame mismatch);
///   Error(Usage) for bad options (printer smaller than a ball, k < 1, bad weights, a salient face
///   index out of range); Error(Cancelled).
PartitionResult partitionSurface(const TriMesh& meshMm, const zome::Structure& frame,
                                 const std::vector<zome::BallId>& labelBalls, const Fabrication& fabrication,
                                 const PartitionOptions& options, const RunContext& context);

/// Checks @p options on their own (before any input is read), and that the Fabrication's printer
/// holds a ball of @p scale with the fit margin on every side. @throw Error(Usage)
void checkPartitionOptions(const PartitionOptions& options, const Fabrication& fabrication,
                           const zome::ZomeScale& scale = {});

/// The greedy region merge of PartitionOptions::mergeSmallRegions (docs/partition.md §4).
struct RegionMerge {
    std::vector<uint32_t> groupOf;  ///< per region: its group, numbered by lowest region
    uint32_t groupCount = 0;
    size_t merges = 0;  ///< = region count − groupCount
};

/// Repeatedly merges a region of @p regionOf (per face, < @p regionCount; regions need not be
/// connected) into an edge-adjacent one when their union's vertices fit @p printerMm with
/// @p marginMm (the schedule's fit test): the smallest region (by area, then id) that has a
/// neighbour it fits with goes into the one of those with the longest shared seam (then lowest id);
/// stops when no merge fits. Deterministic, whatever the thread count.
/// With @p blockedDirections (per face, bit h: along hole h its wall runs into the frame;
/// docs/partition.md §4, "Mountable"), a union must also leave some direction at most
/// @p blockedShare of its area blocked.
RegionMerge mergeRegionsThatFit(const TriMesh& meshMm, const FaceGraph& graph,
                                const std::vector<uint32_t>& regionOf, uint32_t regionCount,
                                const Vec3d& printerMm, double marginMm,
                                const std::vector<uint64_t>& blockedDirections = {},
                                double blockedShare = 0.0);

/// Per-face flags: the mesh's salientFaces, faces within a sphere (closest point of the triangle
/// within the radius) and the listed indices. @throw Error(Usage) for an index out of range.
std::vector<uint8_t> salientFaceFlags(const TriMesh& meshMm, const std::vector<SalientSphere>& spheres,
                                      const std::vector<uint32_t>& indices);

}  // namespace zomefab::partition
