// SPDX-License-Identifier: GPL-3.0-or-later
// Tenons and engraved numbers planned against the shell (detail/stages.h, docs/pieces.md §2–3).
#include <openvdb/tools/Interpolation.h>

#include <algorithm>
#include <map>

#include "zomefab/pieces/detail/stages.h"

namespace zomefab::pieces::detail {

namespace {

/// One warning for the pieces short of tenons, with the reasons summed over them, most frequent
/// first. (Naming the first such piece's top reason misled: its reasons were often one each, and
/// the tie went to the alphabetically first, "crosses another piece", though on the bunny at
/// 400 mm that rejected 7 of 136 rays against 52 "too far from the wall".)
void warnShortfall(const Pieces& out, const TenonOptions& o, const RunContext& context) {
    size_t few = 0;
    std::map<std::string, int> reasons;
    for (const Piece& piece : out.pieces)
        if (piece.tenons.size() < size_t(o.minPerPiece)) {
            ++few;
            for (const auto& [why, count] : piece.tenonShortfall) reasons[why] += count;
        }
    if (few == 0) return;
    std::vector<std::pair<int, std::string>> ranked;
    for (const auto& [why, count] : reasons) ranked.push_back({-count, why});
    std::sort(ranked.begin(), ranked.end());
    std::string list;
    for (const auto& [negCount, why] : ranked)
        list += (list.empty() ? "" : ", ") + why + " " + std::to_string(-negCount);
    context.warn(std::to_string(few) + " of " + std::to_string(out.pieces.size()) +
                 " pieces have fewer than " + std::to_string(o.minPerPiece) +
                 " tenons (rejected rays: " + list + "); pieces.json lists why per piece");
}

}  // namespace

void planPieces(Pieces& out, const VoxelField& field, const FloatGrid& shell, const zome::Structure& frame,
                const Transform4d& frameToGridMm, const PiecesOptions& opt, const RunContext& context) {
    const size_t pieceCount = out.pieces.size();
    const FloatGrid::ConstAccessor probeAccessor = shell.getConstAccessor();
    const openvdb::tools::GridSampler<FloatGrid::ConstAccessor, openvdb::tools::BoxSampler> sampler(
        probeAccessor, shell.transform());
    ShellProbe probe;
    probe.voxelMm = field.voxelMm;
    probe.signedDistanceMm = [&](const Vec3d& p) {
        return double(sampler.wsSample(openvdb::Vec3d(p[0], p[1], p[2])));
    };
    // The owner of the nearest voxel, band voxels included: a point the trilinear φ puts just
    // inside the wall may have its nearest voxel centre just outside.
    probe.pieceAt = [&](const Vec3d& p) -> int64_t {
        const size_t s = field.slotAt(p);
        if (s == SIZE_MAX || field.owner[s] == kNone) return -1;
        return int64_t(field.owner[s]);
    };
    if (opt.tenons.maxPerPiece > 0) {
        const std::vector<TenonCandidate> candidates =
            findTenonCandidates(frame, frameToGridMm, probe, opt.tenons);
        TenonPlan plan = chooseTenons(candidates, pieceCount, opt.tenons);
        for (size_t p = 0; p < pieceCount; ++p) {
            out.pieces[p].tenons = std::move(plan.perPiece[p]);
            out.pieces[p].tenonShortfall = std::move(plan.shortfall[p]);
        }
        warnShortfall(out, opt.tenons, context);
    }
    context.throwIfCancelled();
    if (!opt.label.isEnabled) return;
    const double reach = frame.scale().ballRadiusMm() + 3.0 * frame.scale().b0Mm;
    const auto spots = innerSurfaceSpots(frame, frameToGridMm, probe, pieceCount, reach);
    size_t unlabelled = 0;
    for (size_t p = 0; p < pieceCount; ++p) {
        Piece& piece = out.pieces[p];
        piece.label = placeLabel(std::to_string(p), uint32_t(p), spots[p], piece.tenons, opt.tenons, probe,
                                 opt.label, &piece.labelNote);
        if (!piece.label) ++unlabelled;
    }
    if (unlabelled > 0)
        context.warn(std::to_string(unlabelled) + " of " + std::to_string(pieceCount) +
                     " pieces have no engraved number (no flat inner spot clear of cuts and tenons)");
}

}  // namespace zomefab::pieces::detail
