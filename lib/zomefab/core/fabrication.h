// SPDX-License-Identifier: GPL-3.0-or-later
/// @file What the user is making, as one value: the printer, the wall, the frame's clearance, the
/// kit's b0 and the seed. The tools fill it once (tools/common/fabrication_options.h) and every
/// stage that needs one of these takes the Fabrication itself, so no stage keeps its own copy and
/// no two defaults can disagree. The stage options hold only what is particular to one stage.
#pragma once

#include <cstdint>

#include "zomefab/core/tri_mesh.h"

namespace zomefab {

struct Fabrication {
    /// Printer build volume, mm: x and y are the bed, z the height (pieces may be turned, so the
    /// order of the sides does not limit which piece fits). Paper: Ultimaker 3, about a 200 mm cube (§7.1).
    Vec3d printerMm{200.0, 200.0, 200.0};
    /// Every side of a piece's oriented box is grown by this much before the partition's fit test,
    /// for the wall behind the surface and the tenons (mm).
    double fitMarginMm = 2.0;
    /// Free border kept on every side of the printer's bed, mm: every piece is cut to fit the bed
    /// less this margin (pieceBoxMm) and the plates keep it free. It is room for what a slicer
    /// prints around a piece: PrusaSlicer 2.5's automatic supports reach up to 5.7 mm beyond a
    /// piece's footprint (their first layer grows 3 mm, raft_first_layer_expansion), and a skirt
    /// 2 mm away (Prusa's printer profiles) with its line needs 2.5 mm more (docs/pieces.md, "Plates").
    double bedMarginMm = 9.0;
    /// Thickness of the printed shell's wall, mm (paper §6: the wall equals its d_min, 16 mm).
    /// Thinner walls (`--shell-mm 4`) print faster and the tenons' tapered stems bridge the gap
    /// to the frame, but on thin meshes fewer pieces then get two tenons (docs/pieces.md).
    double wallMm = 16.0;
    /// d_min of the forbidden zone (paper §4.3.1): no ball or strut comes closer to the outer
    /// surface than this, mm.
    double frameClearanceMm = 16.0;
    /// Air between the shell's inner wall and the frame, mm: a piece pushed onto the frame slides
    /// past balls and struts, so the frame keeps at least wall + gap from the outer surface.
    double wallGapMm = 3.0;
    /// The steepest overhang the printer prints without support, degrees from the vertical (the
    /// usual 45° rule). The pieces' orientation and the cost report's supports (estimator and
    /// slicer, for the pieces, the octree parts and the object printed whole alike) use it; at 45
    /// PrusaSlicer keeps its automatic threshold, otherwise it gets 90 − this from the horizontal.
    double overhangDeg = 45.0;
    /// Centre-to-centre length of the B0 strut, mm (paper §4.2: b0 = 47.3 measured; vZome's
    /// nominal 46.27). It sets the whole kit's scale and d_max = b0 of the forbidden zone.
    double b0Mm = 47.3;
    /// Seed of every random choice; the same input, fabrication and seed give the same files
    /// whatever the thread count.
    uint64_t seed = 1;

    /// The d_min the frame is built with: the forbidden zone, or the wall and its gap where that
    /// is deeper (a thick wall moves the frame inward).
    double frameDMinMm() const {
        return frameClearanceMm > wallMm + wallGapMm ? frameClearanceMm : wallMm + wallGapMm;
    }
    /// The box every printed piece must fit, mm: the bed less bedMarginMm on each side (x, y), the
    /// printer's full height (z). Pieces may be turned, so the order of the sides does not matter.
    Vec3d pieceBoxMm() const;
    /// d_max of the forbidden zone (paper §4.3.1): b0, the shortest blue strut, past d_min.
    double frameReachMm() const { return b0Mm > frameDMinMm() ? b0Mm : frameDMinMm() + b0Mm; }
};

/// The box a piece must fit on a bed of @p printerMm with @p bedMarginMm kept free on each side:
/// x and y less two margins, the full height (Fabrication::pieceBoxMm).
Vec3d pieceBoxMm(const Vec3d& printerMm, double bedMarginMm);

/// The random streams of the stages. Each stage draws from its own stream, derived from
/// Fabrication::seed by seedFor(), so adding randomness to one stage never shifts another's.
enum class SeedStream {
    Frame,      ///< τ runs and annealing chains (each chain derives its own from this)
    Partition,  ///< liblinear's shuffling in the planar cuts
};

/// The seed of @p stream. The frame and partition streams are the user's seed itself (as the
/// published benchmarks were made); streams added later are hashed from it.
uint64_t seedFor(const Fabrication& fabrication, SeedStream stream);

/// @throw Error(Usage) naming the option (--printer-mm, --fit-margin-mm, --shell-mm,
/// --frame-clearance-mm, --b0-mm) when a value is not finite or out of its range.
void checkFabrication(const Fabrication& fabrication);

/// Does a box of sides @p sizeMm, each grown by 2 · @p marginMm, fit @p printerMm after some
/// permutation of its axes? Sorted sides against sorted sides decide it (the best of the six
/// permutations); @p toleranceMm absorbs rounding. The one "box fits the printer" test.
bool boxFitsPrinter(const Vec3d& sizeMm, const Vec3d& printerMm, double marginMm = 0.0,
                    double toleranceMm = 0.0);

}  // namespace zomefab
