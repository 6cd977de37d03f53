// SPDX-License-Identifier: GPL-3.0-or-later
// Cut faces and the print orientation of a piece.
#include "zomefab/pieces/orientation.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/box_distance.h"

namespace zomefab::pieces {

using namespace detail;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Rows of a rotation taking @p down (unit) to (0, 0, −1).
std::array<Vec3d, 3> rotationDown(const Vec3d& down) {
    const Vec3d z = scale(down, -1.0);
    // A deterministic perpendicular: cross with the axis least aligned with z.
    int least = 0;
    for (int k = 1; k < 3; ++k)
        if (std::abs(z[size_t(k)]) < std::abs(z[size_t(least)])) least = k;
    Vec3d helper{0, 0, 0};
    helper[size_t(least)] = 1.0;
    const Vec3d x = normalized(cross(helper, z));
    const Vec3d y = cross(z, x);
    return {x, y, z};
}

/// Convex hull (Andrew's monotone chain) of 2D points, counter-clockwise.
std::vector<std::array<double, 2>> convexHull(std::vector<std::array<double, 2>> p) {
    std::sort(p.begin(), p.end());
    p.erase(std::unique(p.begin(), p.end()), p.end());
    if (p.size() < 3) return p;
    std::vector<std::array<double, 2>> h(2 * p.size());
    auto turn = [](const std::array<double, 2>& o, const std::array<double, 2>& a,
                   const std::array<double, 2>& b) {
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
    };
    size_t k = 0;
    for (size_t i = 0; i < p.size(); ++i) {
        while (k >= 2 && turn(h[k - 2], h[k - 1], p[i]) <= 0) --k;
        h[k++] = p[i];
    }
    for (size_t i = p.size() - 1, t = k + 1; i > 0; --i) {
        while (k >= t && turn(h[k - 2], h[k - 1], p[i - 1]) <= 0) --k;
        h[k++] = p[i - 1];
    }
    h.resize(k - 1);
    return h;
}

struct Placement {
    double ratio = 1e30;  ///< max(ex/Px, ey/Py, ez/Pz)
    double angleRad = 0;
};

/// The best turn about the vertical of points already rotated so that "down" is −z.
Placement bestTurn(const std::vector<std::array<double, 2>>& hull, double heightMm, const Vec3d& printer) {
    auto ratioAt = [&](double angle) {
        const double c = std::cos(angle), s = std::sin(angle);
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (const auto& q : hull) {
            const double x = c * q[0] - s * q[1], y = s * q[0] + c * q[1];
            x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
        }
        return std::max({(x1 - x0) / printer[0], (y1 - y0) / printer[1], heightMm / printer[2]});
    };
    Placement best;
    // 1° steps over a half turn (a half turn maps the box onto itself), then 0.05° around the best.
    for (int i = 0; i < 180; ++i) {
        const double a = i * kPi / 180.0;
        const double r = ratioAt(a);
        if (r < best.ratio - 1e-12) best = {r, a};
    }
    const double centre = best.angleRad;
    for (int i = -20; i <= 20; ++i) {
        const double a = centre + i * 0.05 * kPi / 180.0;
        const double r = ratioAt(a);
        if (r < best.ratio - 1e-12) best = {r, a};
    }
    return best;
}

struct Candidate {
    Placement placement;
    std::array<Vec3d, 3> rows{};
};

Candidate evaluate(const std::vector<Vec3d>& points, const Vec3d& down, const Vec3d& printer) {
    Candidate c;
    c.rows = rotationDown(down);
    std::vector<std::array<double, 2>> projected;
    projected.reserve(points.size());
    double z0 = 1e300, z1 = -1e300;
    for (const Vec3d& p : points) {
        projected.push_back({dot(c.rows[0], p), dot(c.rows[1], p)});
        const double z = dot(c.rows[2], p);
        z0 = std::min(z0, z), z1 = std::max(z1, z);
    }
    c.placement = bestTurn(convexHull(std::move(projected)), z1 - z0, printer);
    return c;
}

/// The mesh in double precision, with each triangle's vector area (area × unit outward normal).
struct MeshD {
    std::vector<Vec3d> points;
    std::vector<Triangle> triangles;
    std::vector<Vec3d> vectorArea;
    explicit MeshD(const TriMesh& m) : triangles(m.triangles) {
        points.reserve(m.positions.size());
        for (const Vec3f& p : m.positions) points.push_back(toD(p));
        vectorArea.reserve(triangles.size());
        for (const Triangle& t : triangles) {
            const Vec3d& a = points[t[0]];
            vectorArea.push_back(scale(cross(sub(points[t[1]], a), sub(points[t[2]], a)), 0.5));
        }
    }
};

/// The smallest coordinate of the mesh's points along @p up, mm.
double lowestAlong(const MeshD& m, const Vec3d& up) {
    double lowest = 1e300;
    for (const Vec3d& p : m.points) lowest = std::min(lowest, dot(up, p));
    return lowest;
}

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

/// The outward normals of the largest facets, at most kFacetDirections, no two within 1°.
std::vector<Vec3d> facetDirections(const MeshD& m) {
    std::vector<std::pair<double, size_t>> bySize;  // (−area, index)
    for (size_t i = 0; i < m.triangles.size(); ++i) bySize.push_back({-norm(m.vectorArea[i]), i});
    std::sort(bySize.begin(), bySize.end());
    std::vector<Vec3d> out;
    for (const auto& [negArea, i] : bySize) {
        if (out.size() == kFacetDirections || negArea == 0.0) break;
        const Vec3d n = normalized(m.vectorArea[i]);
        if (std::none_of(out.begin(), out.end(),
                         [&](const Vec3d& d) { return dot(d, n) > kSameDirectionCos; }))
            out.push_back(n);
    }
    return out;
}

/// The 6 axis directions, then 250 on a Fibonacci sphere.
std::vector<Vec3d> sphereDirections() {
    std::vector<Vec3d> directions = {{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    const int n = 250;
    for (int i = 0; i < n; ++i) {
        const double z = 1.0 - (2.0 * i + 1.0) / n;
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = i * kPi * (3.0 - std::sqrt(5.0));
        directions.push_back({r * std::cos(phi), r * std::sin(phi), z});
    }
    return directions;
}

/// Hill-climbs contactMm2 from @p down by tilts of 2° down to 0.1° about two perpendicular axes,
/// keeping to directions where @p fits; @p contact is contactMm2 at @p down on entry and at the
/// result on return.
template <class Fits>
Vec3d tiltTowardsLargerBase(const MeshD& m, Vec3d down, double& contact, Fits&& fits) {
    for (const double stepDeg : {2.0, 1.0, 0.5, 0.25, 0.1}) {
        const double step = std::tan(stepDeg * kPi / 180.0);
        for (int iteration = 0; iteration < 10; ++iteration) {
            const std::array<Vec3d, 3> rows = rotationDown(down);
            std::vector<std::pair<double, Vec3d>> larger;  // the tilts that enlarge the contact
            for (const Vec3d& side : {rows[0], scale(rows[0], -1.0), rows[1], scale(rows[1], -1.0)}) {
                const Vec3d d = normalized(madd(down, step, side));
                const double a = contactMm2(m, d, kBaseHeightMm);
                if (a > contact * (1.0 + 1e-9) + 1e-9) larger.push_back({a, d});
            }
            // Largest first; ties keep the order of the sides.
            std::stable_sort(larger.begin(), larger.end(),
                             [](const auto& x, const auto& y) { return x.first > y.first; });
            bool isMoved = false;
            for (const auto& [a, d] : larger)
                if (fits(d)) {
                    down = d, contact = a, isMoved = true;
                    break;
                }
            if (!isMoved) break;
        }
    }
    return down;
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
                                  const Vec3d& printer, double flatToleranceMm) {
    PrintOrientation out;
    if (meshMm.positions.empty()) return out;
    const MeshD mesh(meshMm);
    const std::vector<Vec3d>& points = mesh.points;
    Candidate chosen;
    bool isChosen = false;
    // Why no cut face went down (reported when none does).
    size_t behind = 0, small = 0, tooLarge = 0;
    double leastBeyondMm = 1e300;
    auto beyondMm = [&](const CutFace& f) {
        double beyond = -1e300;
        for (const Vec3d& p : points) beyond = std::max(beyond, dot(f.outwardNormal, p) + f.offsetMm);
        return beyond;
    };
    for (const CutFace& f : cutFaces) {
        // Only a face the whole piece lies behind can rest on the bed: a piece made of several
        // cells (a merged sliver) may reach beyond the plane of one of its faces.
        const double beyond = beyondMm(f);
        if (beyond > flatToleranceMm) {
            ++behind;
            leastBeyondMm = std::min(leastBeyondMm, beyond);
            continue;
        }
        // A sliver of a face would hold the piece no better than a point: let the search decide.
        if (f.areaMm2 < kMinCutFaceAreaMm2) {
            ++small;
            continue;
        }
        Candidate c = evaluate(points, f.outwardNormal, printer);
        if (c.placement.ratio <= 1.0) {
            chosen = c;
            isChosen = true;
            out.isCutFaceDown = true;
            out.downNormal = f.outwardNormal;
            break;
        }
        ++tooLarge;
    }
    if (!isChosen) {
        // No cut face can go down. The old rule, "the direction with the most room", put pieces on
        // a corner or an edge (PrusaSlicer: "no extrusions in the first layer"). Instead: the
        // largest contact with the bed that fits. The candidates are every direction a flat part
        // of the piece faces (cut faces, even those the piece reaches beyond, and its largest
        // facets) and a sphere of directions; the best few that fit are tilted in small steps
        // towards a larger contact (a piece resting on several patches at once).
        std::vector<Vec3d> directions;
        for (const CutFace& f : cutFaces) directions.push_back(f.outwardNormal);
        for (const Vec3d& d : facetDirections(mesh)) directions.push_back(d);
        const size_t searchStart = directions.size();
        for (const Vec3d& d : sphereDirections()) directions.push_back(d);
        std::vector<std::pair<double, size_t>> byContact;  // (−contact, index): sorted, largest first
        for (size_t i = 0; i < directions.size(); ++i)
            byContact.push_back({-contactMm2(mesh, directions[i], kBaseHeightMm), i});
        std::sort(byContact.begin(), byContact.end());
        auto fits = [&](const Vec3d& d) { return evaluate(points, d, printer).placement.ratio <= 1.0; };
        // A large piece may fit the printer only in a few orientations, none on a flat side: the
        // starts are the best directions that fit.
        std::vector<Vec3d> starts;
        double bestContact = -1.0;
        for (const auto& [negContact, i] : byContact) {
            if (starts.size() == kRefineStarts) break;
            if (-negContact <= bestContact) break;  // tilting only enlarges: no later start can win
            const bool isNear = std::any_of(starts.begin(), starts.end(), [&](const Vec3d& s) {
                return dot(s, directions[i]) > kSameDirectionCos;
            });
            if (isNear || !fits(directions[i])) continue;
            starts.push_back(directions[i]);
            double contact = -negContact;
            const Vec3d refined = tiltTowardsLargerBase(mesh, directions[i], contact, fits);
            if (contact > bestContact) {
                bestContact = contact;
                out.downNormal = refined;
                isChosen = true;
            }
        }
        if (isChosen) chosen = evaluate(points, out.downNormal, printer);
        if (!isChosen) {
            // Nothing fits: report the direction with the most room (the caller fails with it).
            for (size_t i = searchStart; i < directions.size(); ++i) {
                Candidate c = evaluate(points, directions[i], printer);
                if (!isChosen || c.placement.ratio < chosen.placement.ratio - 1e-12) {
                    chosen = c;
                    isChosen = true;
                    out.downNormal = directions[i];
                }
            }
        }
        // A small cut face the piece lies behind may have won the search: it is still a cut face.
        for (const CutFace& f : cutFaces)
            if (dot(f.outwardNormal, out.downNormal) > 1.0 - 1e-12 && beyondMm(f) <= flatToleranceMm)
                out.isCutFaceDown = true;
    }
    // Rotation: turn about z by the angle after taking "down" to −z.
    const double ca = std::cos(chosen.placement.angleRad), sa = std::sin(chosen.placement.angleRad);
    const Vec3d r0 = sub(scale(chosen.rows[0], ca), scale(chosen.rows[1], sa));
    const Vec3d r1 = add(scale(chosen.rows[0], sa), scale(chosen.rows[1], ca));
    const Vec3d& r2 = chosen.rows[2];
    Box3d box;
    for (const Vec3d& p : points) box.expand({dot(r0, p), dot(r1, p), dot(r2, p)});
    const Vec3d t{0.5 * printer[0] - 0.5 * (box.min[0] + box.max[0]),
                  0.5 * printer[1] - 0.5 * (box.min[1] + box.max[1]), -box.min[2]};
    out.transformMm.m = {r0[0], r0[1], r0[2], t[0], r1[0], r1[1], r1[2], t[1],
                         r2[0], r2[1], r2[2], t[2], 0,     0,     0,     1};
    out.extentsMm = box.size();
    out.ratio = std::max(
        {out.extentsMm[0] / printer[0], out.extentsMm[1] / printer[1], out.extentsMm[2] / printer[2]});
    out.fits = out.ratio <= 1.0;
    out.baseAreaMm2 = sectionArea(mesh, out.downNormal, kBaseHeightMm);
    if (!out.isCutFaceDown) {
        std::ostringstream note;
        note.precision(4);
        note << "no cut face on the bed (of " << cutFaces.size() << ": " << behind
             << " with the piece beyond them";
        if (behind > 0) note << " by " << leastBeyondMm << " mm or more";
        if (!cutFaces.empty())
            note << "; the largest, " << cutFaces[0].areaMm2 << " mm², has it "
                 << std::max(0.0, beyondMm(cutFaces[0])) << " mm beyond";
        note << ", " << small << " under " << kMinCutFaceAreaMm2 << " mm², " << tooLarge
             << " too large for the printer); it rests on " << out.baseAreaMm2 << " mm²";
        out.note = note.str();
    }
    return out;
}

}  // namespace zomefab::pieces
