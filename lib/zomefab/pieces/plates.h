// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The pieces on printer beds: one print job per bed (plates/plate-NN.3mf), as few beds as
/// the packing finds, every piece inside the bed with the Fabrication's bed margin where it has room.
/// docs/pieces.md, "Plates".
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/pieces/pieces.h"

namespace zomefab::pieces {

/// Free space between two pieces on one bed, mm: PrusaSlicer's own arrange keeps 6 mm; 5 mm is
/// enough for the nozzle to travel between them without a brim.
inline constexpr double kPlateSpacingMm = 5.0;

/// One piece on a plate: where its printed mesh (printer coordinates, Piece::mesh) goes on the bed.
struct PlacedPiece {
    size_t piece = 0;
    bool isTurned = false;    ///< turned 90° about the bed's normal (z), which changes no overhang
    Transform4d placementMm;  ///< Piece::mesh → bed mm (x, y in [0, bed]; z unchanged)
    Vec3d minMm{0, 0, 0}, maxMm{0, 0, 0};  ///< the placed mesh's bounding box on the bed
};

/// One bed's print job.
struct Plate {
    std::vector<PlacedPiece> items;  ///< in piece order
    /// Smallest distance of a piece to the bed's edge, mm: the bed margin, or less for a piece
    /// too large to leave it (such a piece is alone on its plate, centred).
    double edgeMm = 0.0;
};

/// Packs every piece of @p pieces onto beds of Pieces::printerMm (x, y), Pieces::bedMarginMm from
/// every edge and kPlateSpacingMm apart (skyline packing, stb_rect_pack): the largest first, onto the
/// first plate with room, each turned 90° where that fits better. Deterministic.
/// @throw Error(InvalidInput) for a piece that does not fit the bed at all.
std::vector<Plate> packPlates(const Pieces& pieces);

/// "plates/plate-01.3mf": the file of plate @p index (0-based) under an output directory.
std::string plateFileName(size_t index);

/// Writes plates/plate-NN.3mf for every plate into @p directory (which exists), each a 3MF with its
/// pieces placed on the bed (mm), sliceable as it is on a bed of Pieces::printerMm.
/// @throw Error(WriteFailed) naming the file.
void writePlates(const Pieces& pieces, const std::vector<Plate>& plates, const std::string& directory);

/// The plates for report.json: per plate its file, the bed, the edge distance and every piece with
/// its place ({"piece": "piece-03", "turned": false, "min_mm": [...], "max_mm": [...]}).
nlohmann::json platesToJson(const Pieces& pieces, const std::vector<Plate>& plates);

}  // namespace zomefab::pieces
