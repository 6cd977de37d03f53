// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/print_estimate.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/fabrication.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/orientation.h"
#include "zomefab/report/mesh_clip.h"

namespace zomefab::report {

namespace {

void requirePositive(double value, const char* option) {
    if (!(value > 0.0) || !std::isfinite(value))
        throw Error(ErrorCode::Usage,
                    std::string(option) + " must be a positive number, got " + std::to_string(value));
}

}  // namespace

void PrintSettings::validate() const {
    requirePositive(layerHeightMm, "layer height");
    requirePositive(firstLayerHeightMm, "first layer height");
    requirePositive(nozzleMm, "nozzle diameter");
    requirePositive(extrusionWidthMm, "extrusion width");
    if (perimeters < 1) throw Error(ErrorCode::Usage, "perimeters must be at least 1");
    if (topLayers < 0 || bottomLayers < 0)
        throw Error(ErrorCode::Usage, "top/bottom layers must not be negative");
    if (!(infillPercent > 0.0 && infillPercent <= 100.0))
        throw Error(ErrorCode::Usage,
                    "infill must be in (0, 100] percent, got " + std::to_string(infillPercent));
    if (!(overhangDeg >= 10.0 && overhangDeg <= 80.0))
        throw Error(ErrorCode::Usage,
                    "the overhang must be in [10, 80] degrees, got " + std::to_string(overhangDeg));
}

void FilamentOptions::validate() const {
    requirePositive(diameterMm, "--filament-mm");
    requirePositive(densityGPerCm3, "--filament-density");
    if (!(usdPerM >= 0.0) || !std::isfinite(usdPerM))
        throw Error(ErrorCode::Usage,
                    "--filament-usd-per-m must not be negative, got " + std::to_string(usdPerM));
}

PrintEstimate& PrintEstimate::operator+=(const PrintEstimate& o) {
    seconds += o.seconds;
    filamentMm3 += o.filamentMm3;
    partVolumeMm3 += o.partVolumeMm3;
    perimeterMm3 += o.perimeterMm3;
    solidMm3 += o.solidMm3;
    infillMm3 += o.infillMm3;
    supportMm3 += o.supportMm3;
    layers += o.layers;
    parts += o.parts;
    return *this;
}

FilamentUse filamentUse(double filamentMm3, const FilamentOptions& filament) {
    const double crossSectionMm2 = 0.25 * kPi * filament.diameterMm * filament.diameterMm;
    FilamentUse use;
    use.lengthM = filamentMm3 / crossSectionMm2 / 1000.0;
    use.massG = filamentMm3 / 1000.0 * filament.densityGPerCm3;
    use.costUsd = use.lengthM * filament.usdPerM;
    return use;
}

pieces::PrintTimeModel printTimeModel(const PrintSettings& s, const PrintRates& rates) {
    s.validate();
    const double h = s.layerHeightMm, w = s.extrusionWidthMm;
    pieces::PrintTimeModel model;
    // Centre-line spacing of adjacent perimeters (PrusaSlicer's flow model: a rectangle with
    // semicircular ends, so neighbours overlap by h·(1 − π/4)).
    const double spacing = w - h * (1.0 - 0.25 * kPi);
    model.skin.perimeterMm = w + double(s.perimeters - 1) * spacing;  // t_w, horizontal
    model.skin.topMm = double(s.topLayers) * h;                       // t_s above
    model.skin.bottomMm = s.bottomLayers > 0 ? s.firstLayerHeightMm + double(s.bottomLayers - 1) * h : 0.0;
    model.skin.marginMm = rates.skinMarginMm;
    // A sloped surface is exposed in a strip h / tan(slope) wide in each layer; PrusaSlicer keeps
    // (and widens by the margin) only strips at least half an extrusion width wide.
    model.skin.maxSlopeTan = 2.0 * h / w;
    model.perimeterSPerMm3 = rates.perimeterSPerMm3;
    model.solidSPerMm3 = rates.solidSPerMm3;
    model.interiorSPerMm3 =
        s.infillPercent >= 100.0
            ? rates.solidInfillSPerMm3
            : rates.sparseInfillSPerMm3 * std::min(1.0, 0.01 * s.infillPercent * rates.sparseInfillFactor);
    return model;
}

PrintEstimate estimatePrint(const TriMesh& part, const PrintSettings& s, const PrintRates& rates) {
    const pieces::PrintTimeModel model = printTimeModel(s, rates);
    PrintEstimate e;
    e.parts = 1;
    if (part.triangles.empty()) return e;
    const double h = s.layerHeightMm;
    double zMin = 1e300, zMax = -1e300;
    for (const Vec3f& p : part.positions)
        zMin = std::min(zMin, double(p[2])), zMax = std::max(zMax, double(p[2]));
    const double volume = std::max(0.0, signedVolume(part));
    const pieces::SkinVolumes skin = pieces::skinVolumes(part, {0, 0, 1}, model.skin, volume);
    const double perimeterMm3 = skin.perimeterMm3, solidMm3 = skin.solidMm3;
    const double interior = std::max(0.0, volume - perimeterMm3 - solidMm3);
    const bool isSolid = s.infillPercent >= 100.0;
    e.partVolumeMm3 = volume;
    e.perimeterMm3 = perimeterMm3;
    e.solidMm3 = solidMm3;
    e.infillMm3 =
        isSolid ? interior : interior * std::min(1.0, 0.01 * s.infillPercent * rates.sparseInfillFactor);
    e.filamentMm3 = perimeterMm3 + solidMm3 + e.infillMm3;
    const double height = zMax - zMin;
    e.layers = height <= s.firstLayerHeightMm
                   ? 1
                   : 1 + size_t(std::ceil((height - s.firstLayerHeightMm) / h - 1e-9));
    e.seconds = e.perimeterMm3 * rates.perimeterSPerMm3 + e.solidMm3 * rates.solidSPerMm3 +
                e.infillMm3 * (isSolid ? rates.solidInfillSPerMm3 : rates.sparseInfillSPerMm3);
    if (s.supports) {
        e.supportMm3 = pieces::estimateSupport(part, {0, 0, -1}, s.overhangDeg, rates.support).filamentMm3;
        e.filamentMm3 += e.supportMm3;
        e.seconds += e.supportMm3 * rates.supportSPerMm3;
    }
    return e;
}

TriMesh orientOnBed(const TriMesh& part, const Vec3d& printerMm) {
    if (part.triangles.empty()) return part;
    const Box3d box = boundingBox(part);
    // Candidate "down" directions: axis k, sign −1 (the face at the minimum) or +1 (the maximum).
    // Flat facets count when their normal points that way and all corners lie within 0.01 mm of
    // the extreme.
    std::array<double, 6> area{};
    for (const Triangle& t : part.triangles) {
        const Vec3f &a = part.positions[t[0]], &b = part.positions[t[1]], &c = part.positions[t[2]];
        const double ux = double(b[0]) - a[0], uy = double(b[1]) - a[1], uz = double(b[2]) - a[2];
        const double vx = double(c[0]) - a[0], vy = double(c[1]) - a[1], vz = double(c[2]) - a[2];
        const std::array<double, 3> n = {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
        const double twice = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        if (twice == 0.0) continue;
        for (int k = 0; k < 3; ++k)
            for (int side = 0; side < 2; ++side) {
                const double sign = side == 0 ? -1.0 : 1.0;
                if (sign * n[size_t(k)] < twice * (1.0 - 1e-6)) continue;
                const double extreme = side == 0 ? box.min[size_t(k)] : box.max[size_t(k)];
                if (std::abs(a[size_t(k)] - extreme) <= 0.01 && std::abs(b[size_t(k)] - extreme) <= 0.01 &&
                    std::abs(c[size_t(k)] - extreme) <= 0.01)
                    area[size_t(2 * k + side)] += 0.5 * twice;
            }
    }
    // Order of preference on ties: −z (as given), +z, −x, +x, −y, +y.
    const int order[6] = {4, 5, 0, 1, 2, 3};
    const Vec3d size = box.size();
    int best = -1;
    double bestArea = 0.0;
    for (int candidate : order) {
        const int k = candidate / 2;
        const double height = size[size_t(k)], u = size[size_t((k + 1) % 3)], v = size[size_t((k + 2) % 3)];
        const bool fits =
            height <= printerMm[2] + 1e-6 && ((u <= printerMm[0] + 1e-6 && v <= printerMm[1] + 1e-6) ||
                                              (v <= printerMm[0] + 1e-6 && u <= printerMm[1] + 1e-6));
        if (fits && area[size_t(candidate)] > bestArea * (1.0 + 1e-9))
            best = candidate, bestArea = area[size_t(candidate)];
    }
    TriMesh out = part;
    if (best < 0) best = 4;
    // Rows of the rotation taking the chosen direction to −z (each a signed axis permutation, det +1).
    static const int rows[6][3][3] = {
        {{0, 0, -1}, {0, 1, 0}, {1, 0, 0}},   // −x down: x → z
        {{0, 0, 1}, {0, 1, 0}, {-1, 0, 0}},   // +x down: x → −z
        {{1, 0, 0}, {0, 0, -1}, {0, 1, 0}},   // −y down: y → z
        {{1, 0, 0}, {0, 0, 1}, {0, -1, 0}},   // +y down: y → −z
        {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}},    // −z down: as given
        {{1, 0, 0}, {0, -1, 0}, {0, 0, -1}},  // +z down: 180° about x
    };
    float zMin = std::numeric_limits<float>::max();
    for (Vec3f& p : out.positions) {
        const Vec3f q = p;
        for (int r = 0; r < 3; ++r)
            p[size_t(r)] = float(rows[best][r][0]) * q[0] + float(rows[best][r][1]) * q[1] +
                           float(rows[best][r][2]) * q[2];
        zMin = std::min(zMin, p[2]);
    }
    for (Vec3f& p : out.positions) p[2] -= zMin;
    return out;
}

namespace {

void splitUntilFits(const TriMesh& part, const Box3d& cell, const Vec3d& printerMm, int depthLeft,
                    std::vector<TriMesh>& out, RunContext& context) {
    context.throwIfCancelled();
    if (part.triangles.empty()) return;
    if (boxFitsPrinter(boundingBox(part).size(), printerMm, 0.0, 1e-6)) {
        out.push_back(orientOnBed(part, printerMm));
        return;
    }
    if (depthLeft == 0)
        throw Error(ErrorCode::Usage,
                    "the baseline cannot cut the object into parts that fit the printer "
                    "(octree too deep); is --printer-mm far too small?");
    const Vec3d mid{0.5 * (cell.min[0] + cell.max[0]), 0.5 * (cell.min[1] + cell.max[1]),
                    0.5 * (cell.min[2] + cell.max[2])};
    // Octants in x-major order: x halves, then y halves of each, then z halves.
    for (int ix = 0; ix < 2; ++ix) {
        const TriMesh px = clipByPlane(part, 0, mid[0], ix == 0);
        if (px.triangles.empty()) continue;
        for (int iy = 0; iy < 2; ++iy) {
            const TriMesh py = clipByPlane(px, 1, mid[1], iy == 0);
            if (py.triangles.empty()) continue;
            for (int iz = 0; iz < 2; ++iz) {
                const TriMesh pz = clipByPlane(py, 2, mid[2], iz == 0);
                Box3d child;
                child.min = {ix ? mid[0] : cell.min[0], iy ? mid[1] : cell.min[1], iz ? mid[2] : cell.min[2]};
                child.max = {ix ? cell.max[0] : mid[0], iy ? cell.max[1] : mid[1], iz ? cell.max[2] : mid[2]};
                splitUntilFits(pz, child, printerMm, depthLeft - 1, out, context);
            }
        }
    }
}

}  // namespace

std::vector<TriMesh> octreeParts(const TriMesh& object, const Vec3d& printerMm, int maxDepth,
                                 RunContext& context) {
    for (int i = 0; i < 3; ++i) requirePositive(printerMm[size_t(i)], "--printer-mm");
    std::vector<TriMesh> parts;
    splitUntilFits(object, boundingBox(object), printerMm, maxDepth, parts, context);
    return parts;
}

}  // namespace zomefab::report
