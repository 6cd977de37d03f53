// SPDX-License-Identifier: GPL-3.0-or-later
// The engraved piece number: seven-segment glyphs as boxes, its signed distance, and where it goes.
#include "zomefab/pieces/label.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/zome/zome_system.h"

namespace zomefab::pieces {

using namespace detail;

namespace {

/// Segments a b c d e f g (top, top right, bottom right, bottom, bottom left, top left, middle)
/// lit for each digit, as bits 0..6.
constexpr uint8_t kSegments[10] = {0x3F, 0x06, 0x5B, 0x4F, 0x66, 0x6D, 0x7D, 0x07, 0x7F, 0x6F};
/// How far the engraving solid reaches out of the wall into the cavity, so it cuts through the
/// surface wherever the surface bulges towards the reader (up to flatnessMm, far below this).
constexpr double kAboveSurfaceMm = 2.0;

double digitWidthMm(const LabelOptions& o) { return std::max(0.55 * o.heightMm, 3.0 * o.strokeMm); }
double digitGapMm(const LabelOptions& o) { return std::max(0.3 * o.heightMm, 1.5 * o.strokeMm); }
/// How far below the label's plane the strokes' solid reaches: the depth under a surface that may
/// lie flatnessMm below the plane.
double solidBottomMm(const LabelOptions& o) { return o.depthMm + o.flatnessMm; }

}  // namespace

void checkLabelOptions(const LabelOptions& o) {
    auto require = [](double v, double lo, double hi, const char* what) {
        if (!(v >= lo && v <= hi))
            throw Error(ErrorCode::Usage, std::string(what) + " must be in [" + formatNumber(lo) + ", " +
                                              formatNumber(hi) + "] mm, got " + formatNumber(v));
    };
    require(o.heightMm, 3.0, 50.0, "the label height");
    require(o.strokeMm, 0.5, o.heightMm / 3.0, "the label stroke");
    require(o.depthMm, 0.2, 5.0, "the label depth");
    require(o.flatnessMm, 0.0, 2.0, "the label flatness");
    require(o.marginMm, 0.0, 20.0, "the label margin");
}

Vec3d labelSizeMm(const std::string& text, const LabelOptions& o) {
    const double n = double(text.size());
    const double width = n * digitWidthMm(o) + (n - 1) * digitGapMm(o);
    // Digits, a stroke of space, the underline.
    return {width, o.heightMm + 2.0 * o.strokeMm, o.depthMm};
}

std::vector<Stroke> labelStrokes(const std::string& text, const LabelOptions& o) {
    std::vector<Stroke> strokes;
    const double h = o.heightMm, s = o.strokeMm, w = digitWidthMm(o);
    const Vec3d size = labelSizeMm(text, o);
    // Digits span y ∈ [−h/2, h/2] before centring; the underline sits 2s lower. Centre the whole.
    const double shiftY = s;
    double left = -0.5 * size[0];
    for (char ch : text) {
        if (ch < '0' || ch > '9')
            throw Error(ErrorCode::Internal, std::string("label character '") + ch + "' is not a digit");
        const uint8_t bits = kSegments[ch - '0'];
        const double cx = left + 0.5 * w;
        const double xl = cx - 0.5 * w + 0.5 * s, xr = cx + 0.5 * w - 0.5 * s;
        auto horizontal = [&](double y) { strokes.push_back({cx, y + shiftY, 0.5 * w, 0.5 * s}); };
        // Vertical segments span half the height each; they overlap the bars at their ends.
        auto vertical = [&](double x, double y) { strokes.push_back({x, y + shiftY, 0.5 * s, 0.25 * h}); };
        if (bits & 0x01) horizontal(0.5 * h - 0.5 * s);
        if (bits & 0x02) vertical(xr, 0.25 * h);
        if (bits & 0x04) vertical(xr, -0.25 * h);
        if (bits & 0x08) horizontal(-0.5 * h + 0.5 * s);
        if (bits & 0x10) vertical(xl, -0.25 * h);
        if (bits & 0x20) vertical(xl, 0.25 * h);
        if (bits & 0x40) horizontal(0.0);
        left += w + digitGapMm(o);
    }
    strokes.push_back({0.0, -0.5 * h - 1.5 * s + shiftY, 0.5 * size[0], 0.5 * s});  // underline
    return strokes;
}

double labelSignedDistanceMm(const PieceLabel& label, const std::vector<Stroke>& strokes,
                             const LabelOptions& o, const Vec3d& p) {
    const Vec3d right = cross(label.upGrid, label.normalGrid);
    const Vec3d d = sub(p, label.centerGridMm);
    const double x = dot(d, right), y = dot(d, label.upGrid), z = dot(d, label.normalGrid);
    const double bottom = solidBottomMm(o);
    const double zMid = 0.5 * (kAboveSurfaceMm - bottom), zHalf = 0.5 * (kAboveSurfaceMm + bottom);
    double best = 1e30;
    for (const Stroke& s : strokes)
        best = std::min(
            best, boxDistance({x - s.centerX, y - s.centerY, z - zMid}, {s.halfWidth, s.halfHeight, zHalf}));
    return best;
}

Box3d labelBoundsMm(const PieceLabel& label, const LabelOptions& o) {
    const Vec3d right = cross(label.upGrid, label.normalGrid);
    Box3d box;
    for (double x : {-0.5 * label.widthMm, 0.5 * label.widthMm})
        for (double y : {-0.5 * label.heightMm, 0.5 * label.heightMm})
            for (double z : {-solidBottomMm(o), kAboveSurfaceMm})
                box.expand(
                    madd(madd(madd(label.centerGridMm, x, right), y, label.upGrid), z, label.normalGrid));
    return box;
}

std::vector<std::vector<SurfaceSpot>> innerSurfaceSpots(const zome::Structure& frame,
                                                        const Transform4d& frameToGridMm,
                                                        const ShellProbe& probe, size_t pieceCount,
                                                        double maxDistanceMm) {
    std::vector<std::vector<SurfaceSpot>> spots(pieceCount);
    const double step = 0.5 * probe.voxelMm;
    const double start = frame.scale().ballRadiusMm();
    for (zome::BallId id : frame.ballIds()) {
        const Vec3d center = frameToGridMm.apply(frame.ball(id).positionMm);
        if (probe.signedDistanceMm(center) < 0) continue;
        for (int hole = 0; hole < zome::kHoleCount; ++hole) {
            const Vec3d u = normalized(applyLinear(frameToGridMm, zome::holeDirection(hole)));
            double t0 = -1;
            for (double t = start; t <= maxDistanceMm; t += step)
                if (probe.signedDistanceMm(madd(center, t, u)) < 0) {
                    t0 = t;
                    break;
                }
            if (t0 < 0) continue;
            double lo = t0 - step, hi = t0;
            for (int i = 0; i < 20; ++i) {
                const double m = 0.5 * (lo + hi);
                (probe.signedDistanceMm(madd(center, m, u)) < 0 ? hi : lo) = m;
            }
            const Vec3d p = madd(center, 0.5 * (lo + hi), u);
            const int64_t piece = probe.pieceAt(madd(p, 0.5 * probe.voxelMm, u));
            if (piece < 0 || size_t(piece) >= pieceCount) continue;
            const Vec3d n = probe.normalAt(p);
            if (-dot(n, u) < 0.5) continue;  // grazing: more than 60° off the surface normal
            spots[size_t(piece)].push_back({p, n});
        }
    }
    return spots;
}

LabelOptions labelOptionsForWall(const LabelOptions& options, double wallMm) {
    LabelOptions o = options;
    o.depthMm = std::min(o.depthMm, wallMm / 3.0);
    o.flatnessMm = std::min(o.flatnessMm, wallMm / 6.0);
    return o;
}

std::optional<PieceLabel> placeLabel(const std::string& text, uint32_t piece,
                                     const std::vector<SurfaceSpot>& spots, const std::vector<Tenon>& tenons,
                                     const TenonOptions& tenonOptions, const ShellProbe& probe,
                                     const LabelOptions& o, std::string* note) {
    const Vec3d size = labelSizeMm(text, o);
    const double halfW = 0.5 * size[0], halfH = 0.5 * size[1];
    const double sample = std::max(0.5 * o.strokeMm, 0.5 * probe.voxelMm);
    std::optional<PieceLabel> best;
    double bestScore = 1e30;
    size_t tried = 0;
    if (spots.empty()) {
        if (note) *note = "no inner surface of this piece is seen from the frame's balls";
        return std::nullopt;
    }
    for (const SurfaceSpot& spot : spots) {
        const Vec3d n = spot.normalGrid;
        // Text up = the grid's +z in the surface plane (else +y): upright when the frame stands.
        Vec3d up = sub({0, 0, 1}, scale(n, n[2]));
        if (norm(up) < 0.3) up = sub({0, 1, 0}, scale(n, n[1]));
        up = normalized(up);
        const Vec3d right = cross(up, n);
        auto at = [&](double x, double y) { return madd(madd(spot.pointGridMm, x, right), y, up); };
        // Cheap look at the corners first: most spots fail there.
        bool isOk = true;
        for (double x : {-halfW - o.marginMm, 0.0, halfW + o.marginMm})
            for (double y : {-halfH - o.marginMm, 0.0, halfH + o.marginMm})
                if (std::abs(probe.signedDistanceMm(at(x, y))) > 2 * o.flatnessMm + probe.voxelMm)
                    isOk = false;
        if (!isOk) continue;
        ++tried;
        double deviation = 0;
        // The wall must reach a quarter voxel below the deepest the engraving can go (depth below
        // a surface up to flatness below the plane): depth + flatness is at most half the wall
        // (labelOptionsForWall), and two thirds of it stay behind the number. A probe a whole voxel
        // below the depth asked for more than the wall has on a 1.8 mm wall (1.6 mm of it, within
        // 0.3 mm of the surface's deviation).
        const double wallProbe = solidBottomMm(o) + 0.25 * probe.voxelMm;
        for (double x = -halfW - o.marginMm; x <= halfW + o.marginMm + 1e-9 && isOk; x += sample) {
            for (double y = -halfH - o.marginMm; y <= halfH + o.marginMm + 1e-9 && isOk; y += sample) {
                const Vec3d q = at(x, y);
                const bool isUnderLabel = std::abs(x) <= halfW && std::abs(y) <= halfH;
                const double phi = probe.signedDistanceMm(q);
                // Under the label the surface stays within flatnessMm of the plane; in the margin it is
                // still this piece's inner surface (a cut face or the wall's edge would break either).
                if (isUnderLabel) deviation = std::max(deviation, std::abs(phi));
                if (std::abs(phi) > (isUnderLabel ? o.flatnessMm : 2 * o.flatnessMm + 0.5 * probe.voxelMm))
                    isOk = false;
                const Vec3d inWall = madd(q, -wallProbe, n);
                if (probe.signedDistanceMm(inWall) >= 0 || probe.pieceAt(inWall) != int64_t(piece))
                    isOk = false;
                for (const Tenon& t : tenons) {
                    const double d2 =
                        zome::pointSegmentDistanceSq(q, t.pointAt(t.pegTipMm), t.pointAt(t.endMm));
                    const double keepOut =
                        std::sqrt(2.0) * stemHalfWidthMm(tenonOptions, t.endMm - t.shoulderMm) + o.marginMm;
                    if (d2 < keepOut * keepOut) isOk = false;
                }
            }
        }
        if (!isOk) continue;
        if (deviation < bestScore) {
            bestScore = deviation;
            best = PieceLabel{text, spot.pointGridMm, n, up, size[0], size[1]};
            if (deviation < 0.05) break;  // flat enough: no need to look further
        }
    }
    if (!best && note) {
        *note = tried == 0 ? "no flat spot of the inner surface is large enough"
                           : "no flat spot clear of cut faces, wall edges and tenons";
    }
    return best;
}

}  // namespace zomefab::pieces
