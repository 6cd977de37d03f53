// SPDX-License-Identifier: GPL-3.0-or-later
// Cut faces and the print orientation of a piece.
#include "zomefab/pieces/orientation.h"

#include <algorithm>
#include <cmath>

#include "zomefab/pieces/detail/vec.h"

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
    auto turn = [](const std::array<double, 2>& o, const std::array<double, 2>& a, const std::array<double, 2>& b) {
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

}  // namespace

std::vector<CutFace> measureCutFaces(const TriMesh& mesh, const std::vector<CutFace>& planes, double tol) {
    std::vector<CutFace> faces = planes;
    for (CutFace& f : faces) f.areaMm2 = 0;
    for (const Triangle& t : mesh.triangles) {
        const Vec3d a = toD(mesh.positions[t[0]]), b = toD(mesh.positions[t[1]]), c = toD(mesh.positions[t[2]]);
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
    std::stable_sort(faces.begin(), faces.end(), [](const CutFace& x, const CutFace& y) { return x.areaMm2 > y.areaMm2; });
    return faces;
}

PrintOrientation orientForPrinter(const std::vector<Vec3d>& points, const std::vector<CutFace>& cutFaces,
                                  const Vec3d& printer, double flatToleranceMm) {
    PrintOrientation out;
    if (points.empty()) return out;
    Candidate chosen;
    bool isChosen = false;
    for (const CutFace& f : cutFaces) {
        // Only a face the whole piece lies behind can rest on the bed: a piece made of several
        // cells (a merged sliver) may reach beyond the plane of one of its faces.
        double beyond = -1e300;
        for (const Vec3d& p : points) beyond = std::max(beyond, dot(f.outwardNormal, p) + f.offsetMm);
        if (beyond > flatToleranceMm) continue;
        Candidate c = evaluate(points, f.outwardNormal, printer);
        if (c.placement.ratio <= 1.0) {
            chosen = c;
            isChosen = true;
            out.isCutFaceDown = true;
            out.downNormal = f.outwardNormal;
            break;
        }
    }
    if (!isChosen) {
        // The 6 axis directions, then a Fibonacci sphere: the one with the most room.
        std::vector<Vec3d> directions = {{0, 0, -1}, {0, 0, 1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
        const int n = 250;
        for (int i = 0; i < n; ++i) {
            const double z = 1.0 - (2.0 * i + 1.0) / n;
            const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
            const double phi = i * kPi * (3.0 - std::sqrt(5.0));
            directions.push_back({r * std::cos(phi), r * std::sin(phi), z});
        }
        for (const Vec3d& d : directions) {
            Candidate c = evaluate(points, d, printer);
            if (!isChosen || c.placement.ratio < chosen.placement.ratio - 1e-12) {
                chosen = c;
                isChosen = true;
                out.downNormal = d;
            }
        }
    }
    // Rotation: turn about z by the angle after taking "down" to −z.
    const double ca = std::cos(chosen.placement.angleRad), sa = std::sin(chosen.placement.angleRad);
    const Vec3d r0 = sub(scale(chosen.rows[0], ca), scale(chosen.rows[1], sa));
    const Vec3d r1 = add(scale(chosen.rows[0], sa), scale(chosen.rows[1], ca));
    const Vec3d& r2 = chosen.rows[2];
    Box3d box;
    for (const Vec3d& p : points) box.expand({dot(r0, p), dot(r1, p), dot(r2, p)});
    const Vec3d t{0.5 * printer[0] - 0.5 * (box.min[0] + box.max[0]), 0.5 * printer[1] - 0.5 * (box.min[1] + box.max[1]),
                  -box.min[2]};
    out.transformMm.m = {r0[0], r0[1], r0[2], t[0], r1[0], r1[1], r1[2], t[1], r2[0], r2[1], r2[2], t[2], 0, 0, 0, 1};
    out.extentsMm = box.size();
    out.ratio = std::max({out.extentsMm[0] / printer[0], out.extentsMm[1] / printer[1], out.extentsMm[2] / printer[2]});
    out.fits = out.ratio <= 1.0;
    return out;
}

}  // namespace zomefab::pieces
