// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Print preparation: the planar cut faces of a piece mesh, and the rotation that puts the
/// largest cut face that allows it on the printer's bed with the piece inside the build volume, or
/// else the largest base the piece can rest on.
/// No OpenVDB here. docs/pieces.md, "Orientation".
#pragma once

#include <string>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::pieces {

/// A plane the piece was cut along: {x : n·x + d = 0} with n the unit outward normal of the piece.
struct CutFace {
    Vec3d outwardNormal{0, 0, 1};
    double offsetMm = 0.0;
    double areaMm2 = 0.0;  ///< area of the piece's triangles lying on the plane
};

/// The planar faces of @p meshMm on the given planes: the triangles whose three vertices lie within
/// @p toleranceMm of a plane and whose normal agrees with its outward normal. @p planes holds
/// candidate planes (area ignored); the result keeps those with area, largest first.
std::vector<CutFace> measureCutFaces(const TriMesh& meshMm, const std::vector<CutFace>& planes,
                                     double toleranceMm);

/// Height above the bed at which a piece's base is measured: about one first layer (PrusaSlicer
/// slices a 0.2–0.3 mm first layer at its middle). A piece whose cross-section there is a point
/// leaves the slicer "no extrusions in the first layer".
constexpr double kBaseHeightMm = 0.2;
/// How far a piece may reach beyond the plane of the cut face it lies on. The adaptive mesher
/// leaves vertices up to about 0.1 voxel off a cut plane (measured on the bunny: 0.016–0.093 mm at
/// 1 mm voxels, so a 10 µm limit refused most faces of multi-cell pieces); half kBaseHeightMm
/// keeps the whole face inside the first layer.
constexpr double kFlatToleranceMm = 0.5 * kBaseHeightMm;
/// A cut face smaller than this (a 10 × 10 mm patch) is not trusted to hold the piece on the bed
/// by itself: the base search below may find a larger one.
constexpr double kMinCutFaceAreaMm2 = 100.0;

/// Area of the cross-section of the closed mesh @p meshMm at @p heightMm above its lowest point
/// along @p down (unit): what would touch the bed, and be printed in the first layer, were @p down
/// to point down. mm².
double baseAreaMm2(const TriMesh& meshMm, const Vec3d& down, double heightMm = kBaseHeightMm);

/// A facet facing down more steeply than this from the vertical needs support (the usual 45° rule;
/// PrusaSlicer's automatic threshold at 0.3 mm layers is close to it): Fabrication::overhangDeg's
/// default, and the functions' below.
constexpr double kOverhangDeg = 45.0;
/// A piece whose first layer is smaller than this is advised a brim (about a 20 × 20 mm base).
constexpr double kBrimBelowMm2 = 400.0;

/// The support filament a slicer lays under overhangs, from the columns under them (SupportEstimate):
/// interfaceMm × footprint + bodyShare × columns + sheathMm × the footprint's edge × the columns' mean
/// height, mm³. Fitted (least squares on relative errors) to PrusaSlicer 2.5's automatic supports
/// (0.2 mm layers) on the 32 pieces of the default runs of the bunny at 400 mm and the armadillo and
/// elephant at 500 mm and on those three objects printed whole (docs/report.md, "Supports"). The edge
/// term is what makes thin walls costly: the overhang of a tilted 2.4 mm wall is a ragged strip on
/// the 2 mm grid, and PrusaSlicer's support under such a strip is several times the columns' share
/// under one large flat overhang (a column share alone was 50 % high on whole objects and 13 % low
/// on the pieces).
struct SupportModel {
    double interfaceMm = 2.6;  ///< per mm² of footprint: interface layers and the support's first layer
    double bodyShare = 0.115;  ///< per mm³ of columns: the sparse body
    double sheathMm = 0.63;    ///< per mm of footprint edge and mm of mean column height
};

/// What would need support were @p down (unit, the mesh's frame) to point down.
struct SupportEstimate {
    /// Facets facing down more steeply than the overhang (kOverhangDeg unless given) from the
    /// vertical and above the first layer: their area, mm².
    double areaMm2 = 0.0;
    /// The volume support columns under those facets fill, each from the first up-facing surface
    /// of the piece below it or from the bed (a slicer builds supports on the model too), sampled
    /// on a 2 mm grid, mm³. Solid: a slicer's sparse support uses a fraction of it.
    double volumeMm3 = 0.0;
    double footprintMm2 = 0.0;  ///< the grid cells those columns stand in, mm²
    double edgeMm = 0.0;        ///< the footprint's outline on the grid (cell sides), mm
    double filamentMm3 = 0.0;   ///< support filament by SupportModel, mm³
};
SupportEstimate estimateSupport(const TriMesh& meshMm, const Vec3d& down, double overhangDeg = kOverhangDeg,
                                const SupportModel& model = {});
/// @p model's support filament for columns of @p volumeMm3 in @p footprintMm2 outlined by @p edgeMm, mm³.
double supportFilamentMm3(double footprintMm2, double edgeMm, double volumeMm3, const SupportModel& model);

/// What a slicer lays along a part's surface, per facet (docs/report.md, the estimator's model): a
/// facet of area A whose normal makes an angle θ with "up" carries perimeters A·t_w·sin θ deep
/// and top or bottom solid layers A·max(0, t_s·|cos θ| + m·sin θ − t_w·sin θ) deep, m only on
/// shallow slopes (tan θ ≤ maxSlopeTan). Defaults: 0.45 mm lines, 3 perimeters, 0.2 mm layers, 5
/// top and 5 bottom layers with a 0.27 mm first layer (report::PrintSettings' defaults, from which
/// report::printTimeModel derives it; a test keeps the two equal).
struct SkinModel {
    double perimeterMm = 1.2642;  ///< t_w: 0.45 + 2 · (0.45 − 0.2 · (1 − π/4)), horizontal
    double topMm = 1.0;           ///< t_s above: 5 layers of 0.2 mm
    double bottomMm = 1.07;       ///< t_s below: 0.27 mm and 4 layers of 0.2 mm
    double marginMm = 1.5;        ///< m: solid layers reach this far past a shallow slope's strip
    double maxSlopeTan = 0.8889;  ///< 2h/w: a layer's exposed strip is at least half a line wide
};

/// Perimeter and solid-layer volumes of a part, mm³ (skinVolumes).
struct SkinVolumes {
    double perimeterMm3 = 0.0;
    double solidMm3 = 0.0;
};

/// The skins of the closed mesh @p meshMm printed with @p up (unit) up: summed over its facets as
/// SkinModel says, then, where they exceed @p volumeMm3 (walls thinner than two skins, all
/// perimeter or solid), both scaled down to it. O(F), deterministic.
SkinVolumes skinVolumes(const TriMesh& meshMm, const Vec3d& up, const SkinModel& model, double volumeMm3);

/// Seconds per mm³ the orientation search weighs a direction with: report::PrintRates' fitted
/// defaults at the default 20 % infill (report::printTimeModel derives them from any settings; a
/// test keeps the defaults equal), but for the perimeters. A thin wall printed flat is all solid
/// layers at 15–20 mm/s, standing it is perimeters at 30–60 mm/s: PrusaSlicer takes 3.2 h for a
/// 100 × 100 × 2.4 mm plate lying flat, 3.2 h tilted 30°, and 1.9, 1.7, 1.9 and 1.9 h tilted 45°,
/// 60°, 75° and standing, 0.24–0.28 s per mm³ of perimeters where the fit over thick parts
/// (PrintRates::perimeterSPerMm3, 0.381) would say 2.6 h standing (docs/pieces.md, "Orientation").
struct PrintTimeModel {
    SkinModel skin;
    double perimeterSPerMm3 = 0.27;  ///< a thin wall's perimeters (PrusaSlicer, 2.4 mm plates)
    double solidSPerMm3 = 0.553;
    double interiorSPerMm3 = 0.146 * 0.2 * 1.028;  ///< per mm³ of interior: sparse infill at 20 %
    /// What a mm³ of support columns costs the search, s: a third of the columns printed at
    /// 0.34 s/mm³, the estimator's support model before SupportModel. Kept: PrusaSlicer confirmed
    /// the poses it picks, while scoring by SupportModel's filament (at 0.28 s/mm³) turned two of
    /// the bunny's pieces off their supports onto poses 3 h slower (docs/pieces.md, "Orientation").
    double supportSPerColumnMm3 = 0.34 * 0.34;
};

/// Seconds to print the perimeters, solid layers and infill of the closed mesh @p meshMm with
/// @p up up (supports not included) by @p model. O(F).
double skinSeconds(const TriMesh& meshMm, const Vec3d& up, const PrintTimeModel& model = {});

/// How a piece sits in the printer.
struct PrintOrientation {
    bool fits = false;           ///< inside the build volume
    bool isCutFaceDown = false;  ///< a cut face lies on the bed
    /// No first layer of 25 mm²: it stands on its supports, which hold it (print it with them).
    bool isOnSupports = false;
    Vec3d downNormal{0, 0, -1};  ///< the outward normal (input frame) that points down
    Transform4d transformMm;     ///< input mm → printer mm: on the bed (z = 0), centred in x and y
    Vec3d extentsMm{0, 0, 0};    ///< size along the printer's x, y, z
    double ratio = 0.0;          ///< max over axes of extent / printer size (≤ 1 fits)
    double baseAreaMm2 = 0.0;    ///< baseAreaMm2() on the bed: the first layer's area
    SupportEstimate support;     ///< estimateSupport() of the chosen orientation
    /// Why no cut face lies on the bed, and what the piece rests on instead; empty when one does.
    std::string note;
};

/// The orientation of the closed mesh @p meshMm (a piece) for a printer of @p printerMm (x, y =
/// bed, z = height), each direction turned about the vertical for the best fit on the bed. The
/// candidates: the cut faces of at least kMinCutFaceAreaMm2 that no vertex lies beyond by more
/// than @p flatToleranceMm (a flat base), and directions the piece rests on (the normals of the
/// cut faces and of the mesh's largest facets, 256 sphere directions) with a first layer of at
/// least 25 mm². Of those that fit, the one with the least support and print time wins:
/// each is scored by estimateSupport's volume (columns down to the piece below or the bed) plus
/// skinSeconds by @p time in mm³ of columns that take as long, plus a penalty for a first layer
/// under kBrimBelowMm2, less a tie-break for a larger first layer; the best 8 resting directions
/// are tilted in small steps towards a smaller score. A cut face wins unless a resting direction
/// scores clearly better (by 10 % of its support and 2 cm³). A direction without the first layer competes too
/// (isOnSupports) when 400 mm² of its support stands on the bed, at 50 cm³ more. When no direction has the
/// first layer or that support, the largest contact that fits; when nothing fits, the orientation with the
/// most room, fits = false. Support is what overhangs more than @p overhangDeg from the vertical needs
/// (Fabrication::overhangDeg). Deterministic.
PrintOrientation orientForPrinter(const TriMesh& meshMm, const std::vector<CutFace>& cutFaces,
                                  const Vec3d& printerMm, double flatToleranceMm = kFlatToleranceMm,
                                  double overhangDeg = kOverhangDeg, const PrintTimeModel& time = {});

}  // namespace zomefab::pieces
