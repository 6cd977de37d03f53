// SPDX-License-Identifier: GPL-3.0-or-later
// Printer beds: the pieces' footprints packed by stb_rect_pack's skyline packer (Debian's libstb),
// in 0.1 mm units, one plate after the other.
#include "zomefab/pieces/plates.h"

#define STB_RECT_PACK_IMPLEMENTATION
#include <stb/stb_rect_pack.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/version.h"
#include "zomefab/io/threemf.h"
#include "zomefab/pieces/pieces_io.h"

namespace zomefab::pieces {

namespace {

constexpr double kUnitsPerMm = 10.0;  // stb_rect_pack packs integers: 0.1 mm
constexpr double kFitToleranceMm = 1e-6;

/// A piece's footprint on the bed (x, y extents of its printed mesh), turned or not.
struct Footprint {
    size_t piece = 0;
    Box3d box;  ///< of Piece::mesh
    bool isTurned = false;
    double widthMm() const { return isTurned ? box.size()[1] : box.size()[0]; }
    double depthMm() const { return isTurned ? box.size()[0] : box.size()[1]; }
};

bool fits(double widthMm, double depthMm, double bedX, double bedY) {
    return widthMm <= bedX + kFitToleranceMm && depthMm <= bedY + kFitToleranceMm;
}

/// The first of (long side along the bed's longer side, turned the other way) that fits the margined
/// area, else the first that fits the whole bed, else the first (packPlates then refuses it).
Footprint footprintOf(const Pieces& all, size_t index, double usableX, double usableY) {
    Footprint f{index, boundingBox(all.pieces[index].mesh), false};
    const Vec3d size = f.box.size();
    const bool isAligned = (size[0] >= size[1]) == (usableX >= usableY);
    const bool choices[2] = {!isAligned, isAligned};  // isTurned, preferred first
    for (const auto& [x, y] : {std::pair{usableX, usableY}, std::pair{all.printerMm[0], all.printerMm[1]}})
        for (const bool isTurned : choices) {
            f.isTurned = isTurned;
            if (fits(f.widthMm(), f.depthMm(), x, y)) return f;
        }
    f.isTurned = choices[0];
    return f;
}

/// The transform that puts @p f's mesh with its footprint's lower corner at (xMm, yMm), on z = 0.
Transform4d placement(const Footprint& f, double xMm, double yMm) {
    Transform4d t;
    const Vec3d& lo = f.box.min;
    const Vec3d& hi = f.box.max;
    if (f.isTurned)  // (x, y) → (−y, x): a quarter turn about z
        t.m = {0, -1, 0, hi[1] + xMm, 1, 0, 0, yMm - lo[0], 0, 0, 1, -lo[2], 0, 0, 0, 1};
    else
        t.m = {1, 0, 0, xMm - lo[0], 0, 1, 0, yMm - lo[1], 0, 0, 1, -lo[2], 0, 0, 0, 1};
    return t;
}

/// Packs as many of @p pending as fit one bed's margined area; returns their (x, y) lower corners
/// in mm relative to that area, and removes them from @p pending.
std::vector<std::pair<Footprint, Vec3d>> packOneBed(std::vector<Footprint>& pending, double usableX,
                                                    double usableY) {
    // Each rectangle carries one spacing on its far sides; the area grows by one spacing to match.
    const int width = int(std::floor((usableX + kPlateSpacingMm) * kUnitsPerMm + 1e-6));
    const int depth = int(std::floor((usableY + kPlateSpacingMm) * kUnitsPerMm + 1e-6));
    std::vector<stbrp_node> nodes(size_t(std::max(width, 1)));
    stbrp_context context;
    stbrp_init_target(&context, width, depth, nodes.data(), int(nodes.size()));
    std::vector<stbrp_rect> rects(pending.size());
    for (size_t i = 0; i < pending.size(); ++i) {
        rects[i].id = int(i);
        rects[i].w = int(std::ceil((pending[i].widthMm() + kPlateSpacingMm) * kUnitsPerMm - 1e-6));
        rects[i].h = int(std::ceil((pending[i].depthMm() + kPlateSpacingMm) * kUnitsPerMm - 1e-6));
    }
    stbrp_pack_rects(&context, rects.data(), int(rects.size()));
    std::vector<std::pair<Footprint, Vec3d>> packed;
    std::vector<Footprint> rest;
    for (size_t i = 0; i < pending.size(); ++i) {
        if (rects[i].was_packed)
            packed.push_back({pending[i], {rects[i].x / kUnitsPerMm, rects[i].y / kUnitsPerMm, 0.0}});
        else
            rest.push_back(pending[i]);
    }
    pending = std::move(rest);
    return packed;
}

/// The plate of @p packed pieces, their group centred on the bed (which keeps every margin).
Plate centredPlate(const std::vector<std::pair<Footprint, Vec3d>>& packed, const Vec3d& bedMm) {
    double loX = 1e300, loY = 1e300, hiX = -1e300, hiY = -1e300;
    for (const auto& [f, corner] : packed) {
        loX = std::min(loX, corner[0]);
        loY = std::min(loY, corner[1]);
        hiX = std::max(hiX, corner[0] + f.widthMm());
        hiY = std::max(hiY, corner[1] + f.depthMm());
    }
    const double shiftX = (bedMm[0] - (hiX - loX)) / 2.0 - loX;
    const double shiftY = (bedMm[1] - (hiY - loY)) / 2.0 - loY;
    Plate plate;
    for (const auto& [f, corner] : packed) {
        PlacedPiece p{f.piece, f.isTurned, placement(f, corner[0] + shiftX, corner[1] + shiftY), {}, {}};
        p.minMm = {corner[0] + shiftX, corner[1] + shiftY, 0.0};
        p.maxMm = {p.minMm[0] + f.widthMm(), p.minMm[1] + f.depthMm(), f.box.size()[2]};
        plate.items.push_back(p);
    }
    std::sort(plate.items.begin(), plate.items.end(),
              [](const PlacedPiece& a, const PlacedPiece& b) { return a.piece < b.piece; });
    plate.edgeMm = std::min((bedMm[0] - (hiX - loX)) / 2.0, (bedMm[1] - (hiY - loY)) / 2.0);
    return plate;
}

}  // namespace

std::vector<Plate> packPlates(const Pieces& all) {
    const Vec3d& bed = all.printerMm;
    const double usableX = bed[0] - 2.0 * all.bedMarginMm, usableY = bed[1] - 2.0 * all.bedMarginMm;
    std::vector<Footprint> pending, alone;
    for (size_t i = 0; i < all.pieces.size(); ++i) {
        const Footprint f = footprintOf(all, i, usableX, usableY);
        if (fits(f.widthMm(), f.depthMm(), usableX, usableY))
            pending.push_back(f);
        else if (fits(f.widthMm(), f.depthMm(), bed[0], bed[1]))
            alone.push_back(f);
        else
            throw Error(ErrorCode::InvalidInput, pieceName(all, i) + " (" +
                                                     formatNumbers("%.1f × %.1f", f.widthMm(), f.depthMm()) +
                                                     " mm on the bed) does not fit the " +
                                                     formatNumbers("%g × %g", bed[0], bed[1]) + " mm bed");
    }
    // Largest footprint first: the big pieces decide how many beds there are, small ones fill gaps.
    std::stable_sort(pending.begin(), pending.end(), [](const Footprint& a, const Footprint& b) {
        return a.widthMm() * a.depthMm() > b.widthMm() * b.depthMm();
    });
    std::vector<Plate> plates;
    for (const Footprint& f : alone) plates.push_back(centredPlate({{f, Vec3d{0, 0, 0}}}, bed));
    while (!pending.empty()) {
        const auto packed = packOneBed(pending, usableX, usableY);
        if (packed.empty()) throw Error(ErrorCode::ProcessingFailed, "the plate packing placed nothing");
        plates.push_back(centredPlate(packed, bed));
    }
    // Plates in the order of their first piece, so plate 1 holds piece 00.
    std::sort(plates.begin(), plates.end(),
              [](const Plate& a, const Plate& b) { return a.items[0].piece < b.items[0].piece; });
    return plates;
}

std::string plateFileName(size_t index) {
    return "plates/plate-" + formatNumbers("%02.0f", double(index + 1)) + ".3mf";
}

void writePlates(const Pieces& all, const std::vector<Plate>& plates, const std::string& directory) {
    std::error_code ec;
    const std::string platesDirectory = directory + "/plates";
    if (!std::filesystem::is_directory(platesDirectory) &&
        !std::filesystem::create_directory(platesDirectory, ec))
        throw Error(ErrorCode::WriteFailed, "cannot create the directory: " + ec.message(), platesDirectory);
    for (size_t k = 0; k < plates.size(); ++k) {
        std::vector<ThreeMfObject> objects;
        for (const PlacedPiece& p : plates[k].items)
            objects.push_back({pieceName(all, p.piece), &all.pieces[p.piece].mesh, p.placementMm});
        writeThreeMf(objects, generatorString(), directory + "/" + plateFileName(k));
    }
}

nlohmann::json platesToJson(const Pieces& all, const std::vector<Plate>& plates) {
    nlohmann::json out = nlohmann::json::array();
    for (size_t k = 0; k < plates.size(); ++k) {
        nlohmann::json items = nlohmann::json::array();
        for (const PlacedPiece& p : plates[k].items)
            items.push_back({{"piece", pieceName(all, p.piece)},
                             {"turned", p.isTurned},
                             {"min_mm", toJson(p.minMm)},
                             {"max_mm", toJson(p.maxMm)}});
        out.push_back({{"file", plateFileName(k)},
                       {"bed_mm", toJson(all.printerMm)},
                       {"edge_mm", plates[k].edgeMm},
                       {"pieces", items}});
    }
    return out;
}

}  // namespace zomefab::pieces
