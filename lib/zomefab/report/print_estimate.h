// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Print time and filament of a closed part without a slicer: a shell/infill volume model
/// over the mesh's facets, timed with volumetric rates fitted to PrusaSlicer 2.5 (the model and
/// its calibration table: docs/report.md). Also the octree cut of the paper's baseline (§7.2) and
/// filament length, mass and cost.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/pieces/orientation.h"

namespace zomefab::report {

/// The slicer profile the numbers refer to: ../shared/docs/print-estimates.md's Ultimaker-3-like
/// profile (0.4 mm nozzle, 0.2 mm layers, 3 perimeters, 5 top and 5 bottom layers).
struct PrintSettings {
    double layerHeightMm = 0.2;
    double firstLayerHeightMm = 0.27;
    double nozzleMm = 0.4;
    /// Extrusion width; PrusaSlicer's automatic width is 1.125 × nozzle.
    double extrusionWidthMm = 0.45;
    int perimeters = 3;
    int topLayers = 5;
    int bottomLayers = 5;
    double infillPercent = 20.0;  ///< sparse infill density; 100 = solid (paper §7.2 "solid")
    /// Automatic supports under what overhangs (PrusaSlicer's --support-material
    /// --support-material-auto; the estimator: PrintRates::support's filament from the columns
    /// under the facets steeper than overhangDeg, pieces::estimateSupport).
    bool supports = false;
    /// The steepest overhang printed without support, degrees from the vertical: the printer's
    /// (Fabrication::overhangDeg; costReport sets it). The estimator supports what is steeper; at
    /// 45 PrusaSlicer keeps its automatic threshold, otherwise it gets
    /// --support-material-threshold 90 − this (its threshold is measured from the horizontal).
    double overhangDeg = pieces::kOverhangDeg;

    /// @throw Error(Usage) naming the option for non-positive sizes or infill outside (0, 100].
    void validate() const;
};

/// Rates of the time model and the infill factor: seconds per mm³ of each kind of extrusion.
/// Defaults: the least-squares fit (relative errors) to PrusaSlicer 2.5.0 over the 30 calibration
/// slices of docs/report.md; tests/report/report_calibration.cpp re-runs the fit. A per-layer
/// term was tried and fitted to zero, and the outer and inner perimeters cannot be told apart by
/// this model (their volumes are proportional), so each has one rate.
struct PrintRates {
    double perimeterSPerMm3 = 0.381;     ///< 2.6 mm³/s: loops at 30 (outer) and 60 mm/s
    double solidSPerMm3 = 0.553;         ///< 1.8 mm³/s: top/bottom solid layers at 15-20 mm/s
    double sparseInfillSPerMm3 = 0.146;  ///< 6.8 mm³/s: sparse infill at 80 mm/s
    double solidInfillSPerMm3 = 0.166;   ///< 6.0 mm³/s: the interior at 100 % (still infill speed)
    /// Plastic in sparse infill per mm³ of interior and per unit of nominal density: PrusaSlicer's
    /// triangles at 20 % lay down 2.8 % more than 20 % of the interior volume.
    double sparseInfillFactor = 1.028;
    /// How far solid layers reach past the exposed part of a sloped surface, horizontally, mm:
    /// PrusaSlicer widens top and bottom surfaces into the infill to anchor them. Applies to slopes
    /// whose per-layer exposed strip h / tan(slope) is at least half an extrusion width (41° at
    /// 0.2 mm layers); fitted to PrusaSlicer's solid-infill volumes (docs/report.md).
    double skinMarginMm = 1.5;
    /// Support filament from the columns under the overhangs (pieces::estimateSupport): the
    /// footprint, the columns and the footprint's edge, fitted to PrusaSlicer 2.5's automatic
    /// supports on 32 pieces and 3 whole objects (pieces::SupportModel, docs/report.md "Supports").
    pieces::SupportModel support;
    /// Support prints at 3.6 mm³/s: with these rates for the rest, PrusaSlicer's times of the
    /// bunny's pieces and of the bunny printed whole at 400 mm leave 0.26 and 0.31 s per mm³ of
    /// its support (G-code: 0.23 s/mm³ of support moves alone, before accelerations and travel).
    double supportSPerMm3 = 0.28;
};

/// Filament and its price. Default: the paper's 0.56 USD per metre of 2.85 mm PLA (§7.2).
struct FilamentOptions {
    double diameterMm = 2.85;
    double densityGPerCm3 = 1.24;  ///< PLA
    double usdPerM = 0.56;
    /// @throw Error(Usage) naming the option for non-positive values (a free filament is allowed).
    void validate() const;
};

/// Time and material of one part or a set of parts.
struct PrintEstimate {
    double seconds = 0.0;
    double filamentMm3 = 0.0;  ///< volume of plastic extruded
    // The model's breakdown (zero when the numbers come from a slicer):
    double partVolumeMm3 = 0.0;
    double perimeterMm3 = 0.0;  ///< perimeter loops
    double solidMm3 = 0.0;      ///< top/bottom solid layers
    double infillMm3 = 0.0;     ///< plastic in the interior
    /// Plastic in supports (part of filamentMm3): the estimator's, or the slicer's support
    /// extrusion (its ";TYPE:Support material" and "...interface" moves).
    double supportMm3 = 0.0;
    size_t layers = 0;  ///< summed over parts
    size_t parts = 0;

    double hours() const { return seconds / 3600.0; }
    PrintEstimate& operator+=(const PrintEstimate& o);
};

/// Length, mass and price of @p filamentMm3 of filament.
struct FilamentUse {
    double lengthM = 0.0;
    double massG = 0.0;
    double costUsd = 0.0;
};
FilamentUse filamentUse(double filamentMm3, const FilamentOptions& filament);

/// The per-facet model and rates estimatePrint uses for @p settings, as the pieces' orientation
/// search takes them (pieces::PrintTimeModel; its defaults are this at the default settings, but
/// for its thin-wall perimeter rate and its own weight of support columns).
/// @throw Error(Usage) as PrintSettings::validate.
pieces::PrintTimeModel printTimeModel(const PrintSettings& settings, const PrintRates& rates = {});

/// Estimates printing the closed, outward part @p part (mm, z up, as it will be printed).
/// The model (docs/report.md): per facet of area A and unit normal n at angle θ to +z, the
/// perimeters occupy A·t_w·sin θ and the top/bottom solid layers A·max(0, t_s·|cos θ| + m·sin θ −
/// t_w·sin θ), with t_w = w + (perimeters − 1)·(w − h(1 − π/4)), t_s the solid layers' height and
/// m = PrintRates::skinMarginMm on shallow slopes (0 on steep ones); both are scaled
/// down together when they exceed the part's volume (thin parts are solid). The rest of the volume
/// is infill at the given density. Time = Σ volume·rate. With settings.supports, the support
/// filament PrintRates::support makes of the columns under the overhangs (pieces::estimateSupport,
/// down = −z) at supportSPerMm3. O(F + bed cells), deterministic.
PrintEstimate estimatePrint(const TriMesh& part, const PrintSettings& settings, const PrintRates& rates = {});

/// The parts of the paper's baseline (§7.2): the object's bounding box is split as an octree and
/// each cell's part (the object clipped to the cell, capped) is split again until it fits the
/// printer in one of the six axis-aligned orientations. Empty cells are dropped; parts come in
/// octant order, each turned onto the bed by orientOnBed(). @throw Error(Usage) when @p printerMm
/// has a non-positive size or a part still does not fit after @p maxDepth levels; as
/// clipByPlane() for an open mesh.
std::vector<TriMesh> octreeParts(const TriMesh& object, const Vec3d& printerMm, int maxDepth = 10,
                                 RunContext& context = RunContext::silent());

/// @p part turned in 90° steps so that its largest flat face lies on the bed, as a user prints a
/// cut part (a cap down, not a tip: PrusaSlicer refuses a part with nothing in its first layer),
/// then moved to z = 0. Of the six axis directions, the one whose flat facets at the extreme cover
/// the most area becomes −z, among those orientations that fit @p printerMm (x and y may swap);
/// ties and parts without flat faces keep their orientation. Rotations are exact (axis swaps).
TriMesh orientOnBed(const TriMesh& part, const Vec3d& printerMm);

}  // namespace zomefab::report
