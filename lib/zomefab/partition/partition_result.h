// SPDX-License-Identifier: GPL-3.0-or-later
/// @file What the partition stage (paper §5) hands to the pieces stage, as it is: the argmax cells
/// of the planar cuts and the pieces made of them, plus the numbers the reports show. A light
/// header (no graph cut, no liblinear), so the next stage includes only this.
#pragma once

#include <cstdint>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/partition/linear_cells.h"
#include "zomefab/partition/printer_fit.h"
#include "zomefab/zome/structure.h"

namespace zomefab::partition {

/// One step of the fit schedule.
struct ScheduleStep {
    double smoothnessWeight = 0.0;
    /// E (face level, whole surface) at this weight of the starting labelling: the nearest ball on
    /// the faces this step cuts, the kept regions as they are.
    double energyNearest = 0.0;
    double energyGraphCut = 0.0;  ///< E after alpha-expansion
    size_t partitions = 0;        ///< connected label regions of the whole surface after this step
    size_t oversized = 0;         ///< regions that do not fit the printer
    size_t faces = 0;             ///< faces this step cut: all at a whole-surface cut, else those of
                                  ///< the regions that did not fit at the step before
    size_t kept = 0;              ///< regions this step kept (they fit; later steps leave them alone)
    int sweeps = 0;               ///< node-level passes (the band refinement with two levels)
    int expansions = 0;           ///< node-level max-flow solves
    // With two levels (graphNodeTarget): the cluster-level cut and the refinement band.
    int clusterSweeps = 0;
    int clusterExpansions = 0;
    double energyClusters = 0.0;  ///< E of the cluster-level result
    size_t bandNodes = 0;         ///< nodes free in the refinement
    double seconds = 0.0;
};

/// A physical piece: connected surface faces, one or more cells, fitting the printer.
struct Piece {
    std::vector<uint32_t> cells;      ///< the cells it is made of (several after a merge)
    std::vector<zome::BallId> balls;  ///< the label balls of those cells
    uint32_t faceCount = 0;
    double areaMm2 = 0.0;
    Box3d boundsMm;  ///< axis-aligned box of its faces' vertices
    PrinterFit fit;  ///< best orientation in the printer
    /// Its surface in each cell: one entry per connected part of its faces in one cell, with the
    /// box of their vertices. A cell whose region crosses a thin object twice has surface in two
    /// pieces; the pieces stage gives each part of the shell in that cell to the piece whose
    /// patch in that cell it lies under.
    struct CellPatch {
        uint32_t cell = 0;
        Box3d boundsMm;
    };
    std::vector<CellPatch> patches;
};

struct PartitionResult {
    double b0Mm = Fabrication{}.b0Mm;
    Vec3d printerMm = Fabrication{}.printerMm;  ///< the Fabrication's printer it was cut for
    double fitMarginMm = 0.0;
    std::vector<zome::BallId> labelBalls;  ///< label index → ball id (the input N_out order)
    std::vector<uint32_t> nearestLabels;   ///< per face: label of the nearest ball
    std::vector<uint32_t> graphCutLabels;  ///< per face: label after the fit schedule (each region as
                                           ///< the step that kept it cut it)
    LinearCells cells;                     ///< argmax cells in mm
    std::vector<zome::BallId> cellBalls;   ///< cell → the ball it attaches to
    std::vector<uint32_t> faceCells;       ///< per face: the cell containing its centroid
    std::vector<uint32_t> facePieces;      ///< per face: its piece
    std::vector<Piece> pieces;
    std::vector<uint8_t> salientFaces;  ///< per face (after spheres and indices)
    size_t salientRegions = 0;          ///< edge-connected salient regions
    size_t salientRegionsSplit = 0;     ///< regions a final seam still crosses (0 normally)

    std::vector<ScheduleStep> schedule;
    double smoothnessWeight = 0.0;       ///< w_smoothness of the last schedule step
    double energyNearest = 0.0;          ///< the last step's ScheduleStep::energyNearest
    double energyGraphCut = 0.0;         ///< the last step's ScheduleStep::energyGraphCut
    std::vector<double> sweepEnergies;   ///< of the last step's graph cut
    size_t nearestPartitions = 0;        ///< connected regions of the nearest-ball labelling
    size_t graphCutPartitions = 0;       ///< connected regions of graphCutLabels (before splits)
    bool isScheduleBottomedOut = false;  ///< the schedule ended without every partition fitting
    size_t splits = 0;                   ///< partitions/pieces split to fit the printer
    size_t merges = 0;                   ///< small pieces merged into a neighbour
    size_t regionMerges = 0;             ///< regions merged after the schedule (mergeSmallRegions)
    size_t svmSamples = 0;               ///< training samples used
    double svmAgreement = 0.0;           ///< fraction of faces whose cell matches its region
    size_t graphNodes = 0;               ///< nodes of the first graph cut (faces or clusters;
                                         ///< a salient region is one node)
    size_t refineNodes = 0;              ///< nodes of the refinement level (faces or small clusters)
    size_t candidatePairs = 0;           ///< Σ candidates over those nodes: "triangles × labels"
    double secondsGraphCut = 0.0;
    double secondsSvm = 0.0;
    double secondsTotal = 0.0;
};

}  // namespace zomefab::partition
