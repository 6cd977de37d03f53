// SPDX-License-Identifier: GPL-3.0-or-later
// Pieces printed with a wall thinner than the shell's (detail/thin_wall.h; docs/pieces.md, "A
// thinner printed wall").
#include "zomefab/pieces/detail/thin_wall.h"

#include <cmath>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/stages.h"

namespace zomefab::pieces::detail {

namespace {

/// A thin piece keeps at least this share of W / wall of its thick voxels: a wall W thick over the
/// same outer surface has about that share; one with far fewer lies mostly away from the outer
/// surface exteriorBand found (another component of the object), and stays thick.
constexpr double kMinThinShare = 0.5;

/// Per slot: a wall voxel in the band 6-connected through the band's wall voxels to the outside
/// (exteriorBand): within the band's depth of the outer surface, not of the hollow's.
std::vector<uint8_t> nearOuterSurface(const VoxelField& field) {
    const std::vector<uint8_t> exterior = exteriorBand(field);
    std::vector<uint8_t> out(field.phi.size(), 0);
    const float deep = -field.background;
    // Flooded from the outside's band (not marked itself) through the band's wall voxels.
    std::vector<size_t> seeds;
    for (size_t s = 0; s < field.phi.size(); ++s)
        if (field.isActive[s] && exterior[s]) seeds.push_back(s);
    floodFaces(field, std::move(seeds), out,
               [&](size_t t) { return field.phi[t] < 0 && field.phi[t] > deep; });
    return out;
}

/// The thin wall's φ at @p p by trilinear interpolation of field.thinPhi; +background off the field.
double thinPhiAt(const VoxelField& field, const Vec3d& p) {
    double u[3];
    int base[3];
    for (size_t a = 0; a < 3; ++a) {
        const double x = (p[a] - field.originMm[a]) / field.voxelMm;
        base[a] = int(std::floor(x));
        u[a] = x - base[a];
    }
    double value = 0;
    for (int corner = 0; corner < 8; ++corner) {
        const int dx = corner >> 2, dy = (corner >> 1) & 1, dz = corner & 1;
        const size_t s = field.slotOf(Coord(base[0] + dx, base[1] + dy, base[2] + dz));
        const double v = s == SIZE_MAX ? double(field.background) : double(field.thinPhi[s]);
        value += v * (dx ? u[0] : 1 - u[0]) * (dy ? u[1] : 1 - u[1]) * (dz ? u[2] : 1 - u[2]);
    }
    return value;
}

/// Does the stem of @p t, from @p fromMm to its end, run through another piece's wall? 3 × 3 lines
/// across its section, every half voxel; the shell's voxels and owners.
bool crossesOtherPiece(const Tenon& t, const VoxelField& field, const TenonOptions& o, double fromMm) {
    const double step = 0.5 * field.voxelMm;
    for (double a = fromMm; a <= t.endMm; a += step)
        for (double fl : {-0.9, 0.0, 0.9})
            for (double fs : {-0.9, 0.0, 0.9}) {
                const size_t s = field.slotAt(stemPointMm(t, o, a, fl, fs));
                if (s != SIZE_MAX && field.isInside(s) && field.owner[s] != t.piece) return true;
            }
    return false;
}

/// @p piece's tenons grown again through the thin wall, or empty when one of them cannot be.
std::vector<Tenon> thinTenons(const Piece& piece, const VoxelField& field, const zome::Structure& frame,
                              const Transform4d& frameToGridMm, const ShellProbe& thin,
                              const TenonOptions& o) {
    std::vector<Tenon> out;
    for (const Tenon& t : piece.tenons) {
        const TenonCandidate c = tenonCandidate(frame, t.ball, t.hole, frameToGridMm, thin, o);
        if (!c.rejection.empty() || c.piece != int64_t(piece.id)) return {};
        // Up to the thick wall's inner surface the stem is the planned one (the same ball, hole and
        // taper); beyond it, it must stay in this piece's cells.
        if (crossesOtherPiece(c.tenon, field, o, t.baseMm)) return {};
        out.push_back(c.tenon);
    }
    return out;
}

/// Per piece of @p pieceCount: its inside voxels, of the shell (thick) and of the thin wall.
std::vector<std::pair<size_t, size_t>> voxelCounts(const VoxelField& field, size_t pieceCount) {
    std::vector<std::pair<size_t, size_t>> out(pieceCount, {0, 0});
    for (size_t s = 0; s < field.phi.size(); ++s) {
        if (!field.isInside(s) || field.owner[s] >= pieceCount) continue;
        ++out[field.owner[s]].first;
        out[field.owner[s]].second += field.thinPhi[s] < 0 ? 1 : 0;
    }
    return out;
}

}  // namespace

TenonOptions thinTenonOptions(const TenonOptions& o, double shellWallMm, double printWallMm) {
    TenonOptions thin = o;
    thin.maxLengthMm += (shellWallMm - printWallMm) / std::cos(o.maxTiltDeg * kPi / 180.0);
    return thin;
}

void checkPrintWall(double printWallMm, double shellWallMm, double backgroundMm, double voxelMm) {
    if (printWallMm == 0) return;
    const double most = backgroundMm - 0.5 * voxelMm;
    if (printWallMm > most)
        throw Error(ErrorCode::Usage,
                    "--print-wall-mm " + formatNumber(printWallMm) + " is deeper than the shell's band (" +
                        formatNumber(backgroundMm) + " mm at " + formatNumber(voxelMm) +
                        " mm voxels) allows: at most " + formatNumber(most) +
                        " mm; for a thicker wall make the shell itself thinner (--shell-mm)");
    if (shellWallMm < 2 * backgroundMm + voxelMm)
        throw Error(ErrorCode::Usage, "--print-wall-mm needs a shell wall of at least " +
                                          formatNumber(2 * backgroundMm + voxelMm) +
                                          " mm to thin (this one: " + formatNumber(shellWallMm) + " mm)");
    if (printWallMm >= shellWallMm)
        throw Error(ErrorCode::Usage, "--print-wall-mm " + formatNumber(printWallMm) +
                                          " is not thinner than the shell's wall (" +
                                          formatNumber(shellWallMm) + " mm)");
}

double resolvePrintWallMm(double requested, double shellWallMm, double backgroundMm, double voxelMm) {
    if (requested != kPrintWallAuto) {
        checkPrintWall(requested, shellWallMm, backgroundMm, voxelMm);
        return requested;
    }
    try {
        checkPrintWall(kDefaultPrintWallMm, shellWallMm, backgroundMm, voxelMm);
        return kDefaultPrintWallMm;
    } catch (const Error&) {
        return 0.0;  // a thin shell, or a band too narrow: the shell's wall is printed as it is
    }
}

std::vector<float> thinWallPhi(const VoxelField& field, double printWallMm) {
    const std::vector<uint8_t> isNearOuter = nearOuterSurface(field);
    const float wall = float(printWallMm), bg = field.background;
    std::vector<float> out(field.phi.size(), bg);
    for (size_t s = 0; s < field.phi.size(); ++s) {
        if (!field.isActive[s]) continue;
        const float phi = field.phi[s];
        if (phi >= 0)
            out[s] = phi;
        else if (isNearOuter[s])
            out[s] = std::max(phi, -phi - wall);
        else
            out[s] = bg - wall;  // deeper than the band: beyond the thin wall
    }
    return out;
}

ShellProbe thinWallProbe(const VoxelField& field, double printWallMm) {
    ShellProbe probe;
    probe.voxelMm = field.voxelMm;
    probe.wallMm = printWallMm;
    probe.signedDistanceMm = [&field](const Vec3d& p) { return thinPhiAt(field, p); };
    probe.pieceAt = [&field](const Vec3d& p) { return field.ownerNear(p); };
    return probe;
}

size_t thinPieces(Pieces& out, const VoxelField& field, const zome::Structure& frame,
                  const Transform4d& frameToGridMm, const ShellProbe& thin, double shellWallMm,
                  const TenonOptions& options) {
    std::vector<uint8_t> isGlued(out.pieces.size(), 0);
    for (const auto& [a, b] : out.plan.glued) isGlued[a] = isGlued[b] = 1;
    for (const auto& [a, b] : out.plan.gluedOn) isGlued[a] = isGlued[b] = 1;
    const std::vector<std::pair<size_t, size_t>> voxels = voxelCounts(field, out.pieces.size());
    const TenonOptions thinOptions = thinTenonOptions(options, shellWallMm, thin.wallMm);
    size_t count = 0;
    for (Piece& piece : out.pieces) {
        if (isGlued[piece.id] || !piece.pins.empty() || piece.tenons.empty()) continue;
        std::vector<Tenon> tenons = thinTenons(piece, field, frame, frameToGridMm, thin, thinOptions);
        if (tenons.size() != piece.tenons.size()) continue;
        const auto [thick, thinVoxels] = voxels[piece.id];
        if (double(thinVoxels) < kMinThinShare * thin.wallMm / shellWallMm * double(thick)) continue;
        piece.tenons = std::move(tenons);
        piece.wallMm = thin.wallMm;
        piece.isThinWall = true;
        ++count;
    }
    return count;
}

}  // namespace zomefab::pieces::detail
