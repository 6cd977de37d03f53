// SPDX-License-Identifier: GPL-3.0-or-later
// Cut faces and the print orientation of a piece.
#include "zomefab/pieces/orientation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "zomefab/core/vec.h"
#include "zomefab/partition/printer_fit.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/pieces/detail/support.h"

namespace zomefab::pieces {

using namespace detail;

namespace {

/// The part of a triangle (corners @p v, heights @p z along "up") at or below @p top: a convex
/// polygon of up to 4 corners, in order, with their heights. Returns the number of corners.
int clipBelow(const Vec3d* const v[3], const double z[3], double top, Vec3d corner[4], double height[4]) {
    int n = 0;
    for (int e = 0; e < 3; ++e) {
        const int f = (e + 1) % 3;
        const bool isIn = z[e] <= top, isNextIn = z[f] <= top;
        if (isIn) corner[n] = *v[e], height[n] = z[e], ++n;
        if (isIn != isNextIn) {
            const double s = (top - z[e]) / (z[f] - z[e]);
            corner[n] = madd(*v[e], s, sub(*v[f], *v[e])), height[n] = top, ++n;
        }
    }
    return n;
}

/// Cross-section area of the closed mesh at @p h above its lowest point along @p down. The solid
/// below the section is closed by the section itself, so the section's area is minus the flux of
/// "up" through the part of the mesh below it: the triangles there, clipped at the section.
double sectionArea(const MeshD& m, const Vec3d& down, double h) {
    const Vec3d up = scale(down, -1.0);
    const double top = lowestAlong(m, up) + h;
    double flux = 0.0;
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        const Triangle& t = m.triangles[i];
        const Vec3d* v[3] = {&m.points[t[0]], &m.points[t[1]], &m.points[t[2]]};
        const double z[3] = {dot(up, *v[0]), dot(up, *v[1]), dot(up, *v[2])};
        if (std::min({z[0], z[1], z[2]}) > top) continue;
        if (std::max({z[0], z[1], z[2]}) <= top) {
            flux += dot(m.vectorArea[i], up);
            continue;
        }
        Vec3d poly[4];
        double height[4];
        const int n = clipBelow(v, z, top, poly, height);
        Vec3d area{0, 0, 0};
        for (int k = 1; k + 1 < n; ++k)
            area = add(area, cross(sub(poly[k], poly[0]), sub(poly[k + 1], poly[0])));
        flux += 0.5 * dot(area, up);
    }
    return std::max(0.0, -flux);
}

/// How well the piece would sit on the bed with @p down pointing down: the down-facing facets
/// within @p h of its lowest point, each by its area projected on the bed, weighted by 1 − z/h
/// (z its height over the lowest point): a facet on the bed counts fully, one a layer above not at
/// all. Unlike sectionArea, which grows as 1/cos of the tilt for a prism, this falls as soon as a
/// flat side tilts, so the search below settles on flat sides. mm².
double contactMm2(const MeshD& m, const Vec3d& down, double h) {
    const Vec3d up = scale(down, -1.0);
    const double lowest = lowestAlong(m, up);
    const double top = lowest + h;
    double sum = 0.0;
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        if (dot(m.vectorArea[i], up) >= 0) continue;  // faces up or sideways
        const Triangle& t = m.triangles[i];
        const Vec3d* v[3] = {&m.points[t[0]], &m.points[t[1]], &m.points[t[2]]};
        const double z[3] = {dot(up, *v[0]), dot(up, *v[1]), dot(up, *v[2])};
        if (std::min({z[0], z[1], z[2]}) > top) continue;
        // The part below the top, as a fan; the weight is linear, so its mean over a triangle is
        // its value at the centroid.
        Vec3d corner[4];
        double height[4];
        const int n = clipBelow(v, z, top, corner, height);
        for (int k = 1; k + 1 < n; ++k) {
            const double projected =
                -0.5 * dot(cross(sub(corner[k], corner[0]), sub(corner[k + 1], corner[0])), up);
            const double zMean = (height[0] + height[k] + height[k + 1]) / 3.0 - lowest;
            sum += projected * std::max(0.0, 1.0 - zMean / h);
        }
    }
    return sum;
}

/// Directions within 1° count as the same.
const double kSameDirectionCos = std::cos(kPi / 180.0);
/// Facet normals tried as "down": flat regions of the mesh come out as large facets (adaptive
/// meshing merges them), so the largest facets' normals find them.
constexpr size_t kFacetDirections = 128;
/// How many of the best directions are refined by tilting.
constexpr size_t kRefineStarts = 4;
/// How many of the best-scored resting directions are refined by tilting.
constexpr size_t kSupportStarts = 8;

/// @p d lies within 1° of one of @p directions.
bool isNearAny(const std::vector<Vec3d>& directions, const Vec3d& d) {
    return std::any_of(directions.begin(), directions.end(),
                       [&](const Vec3d& e) { return dot(e, d) > kSameDirectionCos; });
}

/// The outward normals of the largest facets, at most kFacetDirections, no two within 1°.
std::vector<Vec3d> facetDirections(const MeshD& m) {
    std::vector<std::pair<double, size_t>> bySize;  // (−area, index)
    for (size_t i = 0; i < m.triangles.size(); ++i) bySize.push_back({-norm(m.vectorArea[i]), i});
    std::sort(bySize.begin(), bySize.end());
    std::vector<Vec3d> out;
    for (const auto& [negArea, i] : bySize) {
        if (out.size() == kFacetDirections || negArea == 0.0) break;
        const Vec3d n = normalized(m.vectorArea[i]);
        if (!isNearAny(out, n)) out.push_back(n);
    }
    return out;
}

/// The 6 axis directions, then 250 on a Fibonacci sphere.
std::vector<Vec3d> sphereDirections() {
    std::vector<Vec3d> directions = {{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    for (const Vec3d& d : fibonacciSphere(250)) directions.push_back(d);
    return directions;
}

/// Hill-climbs contactMm2 from @p down by tilts of 2° down to 0.1°, keeping to directions where
/// @p fits; @p contact is contactMm2 at @p down on entry and at the result on return.
template <class Fits>
Vec3d tiltTowardsLargerBase(const MeshD& m, Vec3d down, double& contact, Fits&& fits) {
    double negative = -contact;
    down = tiltTowardsLess(
        down, negative, [&](const Vec3d& d) { return -contactMm2(m, d, kBaseHeightMm); }, fits,
        {2.0, 1.0, 0.5, 0.25, 0.1}, 10);
    contact = -negative;
    return down;
}

/// The smallest first layer a resting orientation may have (a 5 × 5 mm patch): below it slicers
/// find little to extrude in the first layer, and the piece's hold on the bed is its supports'.
constexpr double kMinBaseMm2 = 25.0;
/// What a first layer below kBrimBelowMm2 costs in the orientation score, per mm² missing, in mm³
/// of support columns: a 25 mm² base costs 94 cm³ of columns (about 20 cm³ of sparse support), so
/// a piece rests on little only where that saves much more support.
constexpr double kContactPenaltyMm3PerMm2 = 250.0;

/// What resting on its supports alone costs in the orientation score besides the small first
/// layer's penalty, in mm³ of support columns (about 10–25 cm³ of sparse support): the slicer's
/// supports then hold the piece on the bed, so a direction without kMinBaseMm2 of first layer wins
/// only where it saves much more support than that. A thin shell's head with both ears rests on an
/// ear's tip in the one pose that needs least support (the bunny at 400 mm, a 2.4 mm wall: 91
/// against 1,200 cm³ of columns; PrusaSlicer: 63 against 255 cm³ of support).
constexpr double kOnSupportsPenaltyMm3 = 50000.0;
/// Resting on its supports, a piece needs at least this much of them standing on the bed (with its
/// own first layer), mm² (a brim's worth, kBrimBelowMm2). A piece on a tip with little overhanging
/// near the bed would stand on nothing the slicer prints ("no extrusions in the first layer").
constexpr double kMinHoldMm2 = 400.0;

/// What a mm² of first layer is worth in the orientation score, in mm³ of support columns: about
/// half a second of print (PrintTimeModel's 0.116 s per mm³ of columns). A larger first layer
/// holds a part better, so between orientations whose times differ by less than that the larger
/// first layer wins: a solid bar lies on its side, although standing its long sides would be
/// perimeters (2–4 % faster), while a thin wall, twice as fast standing as lying, is turned up
/// onto its rim (its first layer is small either way).
constexpr double kBaseTieBreakMm3PerMm2 = 4.3;

/// A cut face on the bed is kept unless resting elsewhere saves more than this share of its
/// support and this volume: a flat first layer is worth a little support.
constexpr double kCutFaceSupportShare = 0.9;
constexpr double kCutFaceSupportSlackMm3 = 2000.0;

/// orientForPrinter's search over one piece (docs/pieces.md, "Orientation").
class OrientationSearch {
public:
    OrientationSearch(const TriMesh& meshMm, const std::vector<CutFace>& cutFaces, const Vec3d& printer,
                      double flatToleranceMm, double overhangDeg, const PrintTimeModel& time)
        : mesh(meshMm, overhangDeg),
          volumeMm3(std::max(0.0, signedVolume(meshMm))),
          time(time),
          cutFaces(cutFaces),
          printer(printer),
          flatToleranceMm(flatToleranceMm) {
        for (const CutFace& f : cutFaces) directions.push_back(f.outwardNormal);
        for (const Vec3d& d : facetDirections(mesh)) directions.push_back(d);
        searchStart = directions.size();
        for (const Vec3d& d : sphereDirections()) directions.push_back(d);
    }

    bool fits(const Vec3d& d) const { return fitsOnBed(mesh.points, d, printer); }
    double firstLayerMm2(const Vec3d& d) const { return sectionArea(mesh, d, kBaseHeightMm); }
    bool hasFirstLayer(const Vec3d& d) const { return firstLayerMm2(d) >= kMinBaseMm2; }
    /// The time the piece's perimeters, solid layers and infill take with @p d down, in mm³ of
    /// support columns that take as long (PrintTimeModel): a thin wall standing prints in about
    /// half the time it takes lying flat, which is worth more than a little support.
    double skinScore(const Vec3d& d) const {
        return skinSeconds(mesh, scale(d, -1.0), time, volumeMm3) / time.supportSPerColumnMm3;
    }
    /// Support volume and skinScore plus what a first layer of @p baseMm2 costs below a brim's
    /// worth (kContactPenaltyMm3PerMm2), less a tie-break for the larger base.
    double score(const Vec3d& d, double baseMm2) const {
        return score(supportColumnsMm3(mesh, d) + skinScore(d), baseMm2);
    }
    static double score(double supportMm3, double baseMm2) {
        return supportMm3 + kContactPenaltyMm3PerMm2 * std::max(0.0, kBrimBelowMm2 - baseMm2) -
               kBaseTieBreakMm3PerMm2 * baseMm2;
    }
    double score(const Vec3d& d) const { return score(d, firstLayerMm2(d)); }
    /// How far the piece reaches beyond the plane of @p f, mm.
    double beyondMm(const CutFace& f) const {
        double beyond = -1e300;
        for (const Vec3d& p : mesh.points) beyond = std::max(beyond, dot(f.outwardNormal, p) + f.offsetMm);
        return beyond;
    }

    /// 1. Flat bases: the cut faces the whole piece lies behind (a piece made of several cells, a
    /// merged sliver, may reach beyond the plane of one of its faces), not slivers, that fit; the
    /// one scoring best. Counts why the others cannot (for the note).
    void findFlatBase() {
        for (const CutFace& f : cutFaces) {
            const double beyond = beyondMm(f);
            if (beyond > flatToleranceMm) {
                ++behind;
                leastBeyondMm = std::min(leastBeyondMm, beyond);
            } else if (f.areaMm2 < kMinCutFaceAreaMm2) {
                ++small;
            } else if (!fits(f.outwardNormal)) {
                ++tooLarge;
            } else if (const double s = score(f.outwardNormal); s < baseScore) {
                base = &f, baseScore = s;
            }
        }
    }

    /// 2. Resting directions with a first layer: the kSupportStarts best-scored that fit, each
    /// tilted by the cheap estimate (columns down to the bed) and kept where the score agrees.
    void findResting() {
        std::vector<std::pair<double, size_t>> byScore;  // least first
        for (size_t i = 0; i < directions.size(); ++i)
            if (const double base = firstLayerMm2(directions[i]); base >= kMinBaseMm2)
                byScore.push_back({score(directions[i], base), i});
            else if (const SupportColumns c = supportColumns(mesh, directions[i]);
                     base + c.bedMm2 >= kMinHoldMm2)
                onSupports.push_back(
                    {score(c.volumeMm3 + skinScore(directions[i]), base) + kOnSupportsPenaltyMm3, i});
        std::sort(byScore.begin(), byScore.end());
        std::vector<Vec3d> starts;
        for (const auto& [score0, i] : byScore) {
            if (starts.size() == kSupportStarts) break;
            const Vec3d& direction = directions[i];
            if (isNearAny(starts, direction) || !fits(direction)) continue;
            starts.push_back(direction);
            // Tilted by the cheap estimate (columns down to the bed), kept where the score agrees.
            const auto cheap = [&](const Vec3d& d) { return supportOf(mesh, d).volumeMm3 + skinScore(d); };
            double cheapScore = cheap(direction);
            const Vec3d tilted = tiltTowardsLess(direction, cheapScore, cheap,
                                                 [&](const Vec3d& d) { return hasFirstLayer(d) && fits(d); });
            const double tiltedScore = score(tilted);
            const double best = std::min(tiltedScore, score0);
            if (best < restScore) restScore = best, rest = tiltedScore < score0 ? tilted : direction;
        }
        hasRest = !starts.empty();
    }

    /// 2b. Resting on its supports (no first layer of kMinBaseMm2, kOnSupportsPenaltyMm3 more):
    /// the best-scored direction that fits, when it scores better than findResting's choice or
    /// findResting found none.
    void findOnSupports() {
        std::sort(onSupports.begin(), onSupports.end());
        for (const auto& [s, i] : onSupports) {
            if (hasRest && s >= restScore) break;
            if (!fits(directions[i])) continue;
            rest = directions[i], restScore = s, hasRest = true, isOnSupports = true;
            break;
        }
    }

    /// 3. No direction has a first layer, or supports enough on the bed to hold it: the largest
    /// contact that fits, if any.
    bool largestContact(Vec3d& down) const {
        std::vector<std::pair<double, size_t>> byContact;  // (−contact, index): largest first
        for (size_t i = 0; i < directions.size(); ++i)
            byContact.push_back({-contactMm2(mesh, directions[i], kBaseHeightMm), i});
        std::sort(byContact.begin(), byContact.end());
        std::vector<Vec3d> starts;
        double bestContact = -1.0;
        for (const auto& [negContact, i] : byContact) {
            if (starts.size() == kRefineStarts) break;
            if (-negContact <= bestContact) break;  // tilting only enlarges: no later start can win
            const Vec3d& direction = directions[i];
            if (isNearAny(starts, direction) || !fits(direction)) continue;
            starts.push_back(direction);
            double contact = -negContact;
            const Vec3d refined =
                tiltTowardsLargerBase(mesh, direction, contact, [&](const Vec3d& d) { return fits(d); });
            if (contact > bestContact) bestContact = contact, down = refined;
        }
        return bestContact >= 0;
    }

    /// 4. No direction tried so far fits: the direction with the most room, of the best box's
    /// six sides (fitInPrinter: a search over every rotation, which the sphere's 256 directions
    /// may miss by a few mm) and the sphere. The caller fails when even that does not fit.
    Vec3d mostRoom() const {
        std::vector<Vec3d> tried;
        for (const Vec3d& axis : partition::fitInPrinter(mesh.points, printer).axes) {
            tried.push_back(axis);
            tried.push_back(scale(axis, -1.0));
        }
        tried.insert(tried.end(), directions.begin() + std::ptrdiff_t(searchStart), directions.end());
        Vec3d down = tried[0];
        double ratio = 1e300;
        for (const Vec3d& d : tried) {
            const double r = placeOnBed(mesh.points, d, printer).ratio;
            if (r < ratio - 1e-12) ratio = r, down = d;
        }
        return down;
    }

    /// The cut face scores no worse than resting elsewhere with kCutFaceSupportShare of its
    /// support and kCutFaceSupportSlackMm3 more, the larger first layer's tie-break aside (a flat
    /// cut face on the bed is worth that).
    bool isCutFaceWorthIt() const {
        const double restSupportMm3 = supportColumnsMm3(mesh, rest);
        const double baseUntied = baseScore + kBaseTieBreakMm3PerMm2 * firstLayerMm2(base->outwardNormal);
        const double restUntied = restScore + kBaseTieBreakMm3PerMm2 * firstLayerMm2(rest);
        return baseUntied <=
               restUntied + (1.0 / kCutFaceSupportShare - 1.0) * restSupportMm3 + kCutFaceSupportSlackMm3;
    }

    /// Why no cut face lies on the bed, and what the piece rests on instead.
    std::string note(const PrintOrientation& out) const {
        std::ostringstream note;
        note.precision(4);
        note << "no cut face on the bed (of " << cutFaces.size() << ": " << behind
             << " with the piece beyond them";
        if (behind > 0) note << " by " << leastBeyondMm << " mm or more";
        if (!cutFaces.empty())
            note << "; the largest, " << cutFaces[0].areaMm2 << " mm², has it "
                 << std::max(0.0, beyondMm(cutFaces[0])) << " mm beyond";
        note << ", " << small << " under " << kMinCutFaceAreaMm2 << " mm², " << tooLarge
             << " too large for the printer";
        if (base)
            note << ", and the best that fits needs " << supportColumnsMm3(mesh, base->outwardNormal) / 1000.0
                 << " cm³ of support against " << out.support.volumeMm3 / 1000.0 << " cm³ this way";
        note << "); it rests on " << out.baseAreaMm2 << " mm²";
        if (out.isOnSupports) note << " and its supports (print it with supports)";
        return note.str();
    }

    const MeshD mesh;
    const double volumeMm3;
    const PrintTimeModel time;
    const std::vector<CutFace>& cutFaces;
    const Vec3d printer;
    const double flatToleranceMm;
    std::vector<Vec3d> directions;  ///< cut-face normals, facet normals, then the sphere (searchStart)
    size_t searchStart = 0;
    const CutFace* base = nullptr;  ///< findFlatBase's choice
    double baseScore = 1e300;
    size_t behind = 0, small = 0, tooLarge = 0;  ///< cut faces that cannot be the base, and why
    double leastBeyondMm = 1e300;
    std::vector<std::pair<double, size_t>> onSupports;  ///< (score, direction) without a first layer
    bool hasRest = false;                               ///< findResting's (or findOnSupports') choice
    bool isOnSupports = false;                          ///< findOnSupports chose rest
    Vec3d rest{0, 0, -1};
    double restScore = 1e300;
};

/// Fills @p out's transform, extents and fit for the piece resting on @p out.downNormal: turned
/// about z for the most room, on the bed (z = 0), centred in x and y.
void place(const MeshD& mesh, const Vec3d& printer, PrintOrientation& out) {
    const BedPlacement chosen = placeOnBed(mesh.points, out.downNormal, printer);
    const double ca = std::cos(chosen.angleRad), sa = std::sin(chosen.angleRad);
    const Vec3d r0 = sub(scale(chosen.rows[0], ca), scale(chosen.rows[1], sa));
    const Vec3d r1 = add(scale(chosen.rows[0], sa), scale(chosen.rows[1], ca));
    const Vec3d& r2 = chosen.rows[2];
    Box3d box;
    for (const Vec3d& p : mesh.points) box.expand({dot(r0, p), dot(r1, p), dot(r2, p)});
    const Vec3d t{0.5 * printer[0] - 0.5 * (box.min[0] + box.max[0]),
                  0.5 * printer[1] - 0.5 * (box.min[1] + box.max[1]), -box.min[2]};
    out.transformMm.m = {r0[0], r0[1], r0[2], t[0], r1[0], r1[1], r1[2], t[1],
                         r2[0], r2[1], r2[2], t[2], 0,     0,     0,     1};
    out.extentsMm = box.size();
    out.ratio = std::max(
        {out.extentsMm[0] / printer[0], out.extentsMm[1] / printer[1], out.extentsMm[2] / printer[2]});
    out.fits = out.ratio <= 1.0;
    out.baseAreaMm2 = sectionArea(mesh, out.downNormal, kBaseHeightMm);
}

}  // namespace

std::vector<CutFace> measureCutFaces(const TriMesh& mesh, const std::vector<CutFace>& planes, double tol) {
    std::vector<CutFace> faces = planes;
    for (CutFace& f : faces) f.areaMm2 = 0;
    for (const Triangle& t : mesh.triangles) {
        const Vec3d a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]),
                    c = toD(mesh.positions[t[2]]);
        const Vec3d n2 = cross(sub(b, a), sub(c, a));
        const double area2 = norm(n2);
        if (area2 <= 0) continue;
        for (CutFace& f : faces) {
            const Vec3d& n = f.outwardNormal;
            if (std::abs(dot(n, a) + f.offsetMm) > tol || std::abs(dot(n, b) + f.offsetMm) > tol ||
                std::abs(dot(n, c) + f.offsetMm) > tol)
                continue;
            if (dot(n2, n) < 0.99 * area2) continue;  // on the plane but facing the other way
            f.areaMm2 += 0.5 * area2;
            break;
        }
    }
    faces.erase(std::remove_if(faces.begin(), faces.end(), [](const CutFace& f) { return f.areaMm2 <= 0; }),
                faces.end());
    std::stable_sort(faces.begin(), faces.end(),
                     [](const CutFace& x, const CutFace& y) { return x.areaMm2 > y.areaMm2; });
    return faces;
}

double baseAreaMm2(const TriMesh& mesh, const Vec3d& down, double heightMm) {
    return sectionArea(MeshD(mesh), down, heightMm);
}

PrintOrientation orientForPrinter(const TriMesh& meshMm, const std::vector<CutFace>& cutFaces,
                                  const Vec3d& printer, double flatToleranceMm, double overhangDeg,
                                  const PrintTimeModel& time) {
    PrintOrientation out;
    if (meshMm.positions.empty()) return out;
    OrientationSearch search(meshMm, cutFaces, printer, flatToleranceMm, overhangDeg, time);
    search.findFlatBase();
    search.findResting();
    search.findOnSupports();
    // A cut face wins unless resting elsewhere scores clearly better: a flat first layer is worth
    // a little support.
    if (search.base && (!search.hasRest || search.isCutFaceWorthIt())) {
        out.isCutFaceDown = true;
        out.downNormal = search.base->outwardNormal;
    } else if (search.hasRest) {
        out.downNormal = search.rest;
        out.isOnSupports = search.isOnSupports;
    } else if (!search.largestContact(out.downNormal)) {
        out.downNormal = search.mostRoom();
    }
    // A cut face the piece lies behind may have won the search: it is still a cut face.
    for (const CutFace& f : cutFaces)
        if (!out.isCutFaceDown && dot(f.outwardNormal, out.downNormal) > 1.0 - 1e-12 &&
            search.beyondMm(f) <= flatToleranceMm)
            out.isCutFaceDown = true, out.isOnSupports = false;
    out.support = estimateSupport(search.mesh, out.downNormal);
    place(search.mesh, printer, out);
    if (!out.isCutFaceDown) out.note = search.note(out);
    return out;
}

}  // namespace zomefab::pieces
