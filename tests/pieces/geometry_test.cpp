// SPDX-License-Identifier: GPL-3.0-or-later
// The OpenVDB-free parts of the pieces stage: tenon geometry and planning against an analytic
// shell, the print orientation, the label glyphs, and the 3MF package.
#include <doctest/doctest.h>
#include <zlib.h>

#include <cmath>
#include <cstring>
#include <map>
#include <set>

#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/core/transform.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/threemf.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/pieces/detail/support.h"
#include "zomefab/pieces/label.h"
#include "zomefab/pieces/orientation.h"
#include "zomefab/pieces/tenons.h"
#include "zomefab/report/slicer.h"
#include "zomefab/zome/golden.h"
#include "zomefab/zome/zome_system.h"

using namespace zomefab;
using namespace zomefab::pieces;
using namespace zomefab::pieces::detail;

namespace {

/// A spherical shell inner radius @p inner, outer @p outer around the origin, cut into two pieces
/// at z = @p cutZ (piece 0 above).
ShellProbe sphereProbe(double inner, double outer, double cutZ = 1e9) {
    ShellProbe p;
    p.voxelMm = 1.0;
    p.signedDistanceMm = [=](const Vec3d& x) {
        const double r = norm(x);
        return std::max(r - outer, inner - r);
    };
    p.pieceAt = [=](const Vec3d& x) -> int64_t {
        const double r = norm(x);
        if (r < inner || r > outer) return -1;
        return x[2] >= cutZ ? 0 : 1;
    };
    return p;
}

/// The largest @p past(q) over the points q of tenon @p t's solid on a 0.5 mm grid within 14 mm of
/// its end: how far the stem reaches past a surface (@p past: signed distance past it, mm).
template <class Past>
double farthestSolid(const Tenon& t, const TenonOptions& o, Past&& past) {
    const Vec3d e = t.pointAt(t.endMm);
    double worst = -1e9;
    for (double dx = -14; dx <= 14; dx += 0.5)
        for (double dy = -14; dy <= 14; dy += 0.5)
            for (double dz = -14; dz <= 14; dz += 0.5) {
                const Vec3d q = add(e, Vec3d{dx, dy, dz});
                if (tenonSignedDistanceMm(t, o, q) < 0) worst = std::max(worst, past(q));
            }
    return worst;
}

zome::Structure oneBall() {
    zome::Structure s;
    s.addBall(zome::GoldenVector3());
    return s;
}

uint32_t readU32(const std::string& s, size_t at) {
    uint32_t v = 0;
    for (int i = 3; i >= 0; --i) v = (v << 8) | uint8_t(s[at + size_t(i)]);
    return v;
}
uint16_t readU16(const std::string& s, size_t at) {
    return uint16_t(uint8_t(s[at]) | (uint8_t(s[at + 1]) << 8));
}

/// Entries of a zip archive (local headers walked in order; deflated data inflated, CRC checked).
std::map<std::string, std::string> unzip(const std::string& zip) {
    std::map<std::string, std::string> out;
    size_t at = 0;
    while (at + 4 <= zip.size() && readU32(zip, at) == 0x04034b50) {
        const uint16_t method = readU16(zip, at + 8);
        const uint32_t crc = readU32(zip, at + 14), csize = readU32(zip, at + 18),
                       usize = readU32(zip, at + 22);
        const uint16_t nameLen = readU16(zip, at + 26), extraLen = readU16(zip, at + 28);
        const std::string name = zip.substr(at + 30, nameLen);
        const std::string body = zip.substr(at + 30 + nameLen + extraLen, csize);
        std::string data;
        if (method == 0) {
            data = body;
        } else {
            REQUIRE(method == 8);
            data.resize(usize);
            z_stream z{};
            REQUIRE(inflateInit2(&z, -15) == Z_OK);
            z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(body.data()));
            z.avail_in = uInt(body.size());
            z.next_out = reinterpret_cast<Bytef*>(data.data());
            z.avail_out = uInt(data.size());
            CHECK(inflate(&z, Z_FINISH) == Z_STREAM_END);
            inflateEnd(&z);
        }
        CHECK(data.size() == usize);
        CHECK(uint32_t(crc32(0, reinterpret_cast<const Bytef*>(data.data()), uInt(data.size()))) == crc);
        out[name] = data;
        at += 30 + nameLen + extraLen + csize;
    }
    CHECK(readU32(zip, at) == 0x02014b50);  // the central directory follows the entries
    CHECK(readU32(zip, zip.size() - 22) == 0x06054b50);
    CHECK(readU16(zip, zip.size() - 22 + 10) == out.size());
    return out;
}

size_t countOf(const std::string& text, const std::string& what) {
    size_t n = 0;
    for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
    return n;
}

}  // namespace

TEST_CASE("transform: affineInverse undoes a rotation, scale and translation") {
    Transform4d t = Transform4d::yUpToZUp() * Transform4d::scaleTranslate(2.5, {3, -4, 7});
    const Transform4d inv = affineInverse(t);
    const Vec3d p{1.5, -2.0, 9.0};
    const Vec3d q = inv.apply(t.apply(p));
    for (int a = 0; a < 3; ++a) CHECK(q[size_t(a)] == doctest::Approx(p[size_t(a)]).epsilon(1e-12));
    Transform4d singular = Transform4d::scaleTranslate(0.0, {0, 0, 0});
    CHECK_THROWS_AS(affineInverse(singular), Error);
}

namespace {
/// A tenon of a ball at the origin along hole 2 (blue, +z: the section's long side along x).
Tenon tenonUp(const TenonOptions& o, double baseMm, double endMm) {
    Tenon t;
    t.hole = 2;
    t.axisGrid = {0, 0, 1};
    t.longSideGrid = {1, 0, 0};
    t.shoulderMm = 8.85;
    t.pegTipMm = 8.85 - o.pegDepthMm;
    t.baseMm = baseMm;
    t.endMm = endMm;
    return t;
}
}  // namespace

TEST_CASE("tenons: the prism's signed distance and the exact peg mesh") {
    TenonOptions o;
    o.taperDeg = 0;  // a straight prism here; the taper has its own test below
    const Tenon t = tenonUp(o, 30, 32);
    // Prism: 7 × 7 mm from 0.3 mm past the shoulder to z = 32; the peg is not in it.
    CHECK(tenonSignedDistanceMm(t, o, {3.4, 3.4, 20}) < 0);
    CHECK(tenonSignedDistanceMm(t, o, {3.6, 0, 20}) == doctest::Approx(0.1));
    CHECK(tenonSignedDistanceMm(t, o, {0, 0, 32.5}) == doctest::Approx(0.5));
    CHECK(tenonSignedDistanceMm(t, o, {0, 0, 8.85}) == doctest::Approx(0.3));
    CHECK(tenonSignedDistanceMm(t, o, {0, 0, 6}) > 0);
    const Box3d box = tenonBoundsMm(t, o);
    CHECK(box.min[2] == doctest::Approx(t.pegTipMm));
    CHECK(box.max[2] == doctest::Approx(32));
    CHECK(box.max[0] == doctest::Approx(3.5));

    // The peg: the hole's rectangle less the clearance, from the tip (4.85) 1.5 mm into the prism,
    // closed and outward, its tip chamfered.
    const TriMesh peg = pegMesh(t, o);
    const Box3d pb = boundingBox(peg);
    CHECK(pb.min[2] == doctest::Approx(t.pegTipMm).epsilon(1e-6));
    CHECK(pb.max[2] == doctest::Approx(t.shoulderMm + 1.5).epsilon(1e-6));
    CHECK(pb.max[0] == doctest::Approx(0.5 * pegLongMm(o)).epsilon(1e-6));
    CHECK(pb.max[1] == doctest::Approx(0.5 * pegShortMm(o)).epsilon(1e-6));
    const double length = t.shoulderMm + 1.5 - t.pegTipMm;
    const double full = pegLongMm(o) * pegShortMm(o) * length;
    CHECK(signedVolume(peg) > 0.95 * full);  // the chamfer takes a little
    CHECK(signedVolume(peg) < full);
    std::map<std::pair<uint32_t, uint32_t>, int> edges;  // every edge used once each way
    for (const auto& tri : peg.triangles)
        for (int e = 0; e < 3; ++e) ++edges[{tri[size_t(e)], tri[size_t((e + 1) % 3)]}];
    for (const auto& [edge, count] : edges) {
        CHECK(count == 1);
        CHECK(edges.count({edge.second, edge.first}) == 1);
    }
    // Yellow and red pegs follow their holes' triangle and pentagon.
    Tenon yellow = t;
    yellow.hole = zome::holeRange(zome::Color::Yellow).first;
    CHECK(pegMesh(yellow, o).positions.size() == 9);
    Tenon red = t;
    red.hole = zome::holeRange(zome::Color::Red).first;
    CHECK(pegMesh(red, o).positions.size() == 15);
}

TEST_CASE("tenons: options out of range are usage errors") {
    auto code = [](const TenonOptions& o) {
        try {
            checkTenonOptions(o);
        } catch (const Error& e) {
            return int(e.code());
        }
        return -1;
    };
    TenonOptions o;
    CHECK(code(o) == -1);
    o.clearanceMm = 0.8;
    CHECK(code(o) == int(ErrorCode::Usage));
    o = {};
    o.bodyWidthMm = 4.0;  // narrower than the peg's long side
    CHECK(code(o) == int(ErrorCode::Usage));
    o = {};
    o.maxLengthMm = 0;
    CHECK(code(o) == int(ErrorCode::Usage));
    o = {};
    o.maxPerPiece = 1;  // below the 2 wanted
    CHECK(code(o) == int(ErrorCode::Usage));
    o = {};
    o.maxTiltDeg = 80;
    CHECK(code(o) == int(ErrorCode::Usage));
}

TEST_CASE("tenons: the stem widens by tan(taper) per mm from the ball's face") {
    TenonOptions o;  // 7 mm at the face, 4°
    const Tenon t = tenonUp(o, 48.85, 50.85);
    const double slope = std::tan(4.0 * M_PI / 180.0);
    CHECK(stemHalfWidthMm(o, 0) == doctest::Approx(3.5));
    CHECK(stemHalfWidthMm(o, 40) == doctest::Approx(3.5 + 40 * slope));
    CHECK(stemHalfWidthMm(o, -3) == doctest::Approx(3.5));  // the peg side: no taper
    // On its side the zero set follows the taper: 20 mm from the face the half-width is 4.9 mm.
    const double half20 = 3.5 + 20 * slope;
    CHECK(tenonSignedDistanceMm(t, o, {half20 - 0.05, 0, 8.85 + 20}) < 0);
    CHECK(tenonSignedDistanceMm(t, o, {half20 + 0.05, 0, 8.85 + 20}) > 0);
    CHECK(tenonSignedDistanceMm(t, o, {3.6, 0, 8.85 + 1}) > 0);  // near the ball it is 7 mm wide
    // The strength rule of the default: w(ℓ) ≥ w₀ (ℓ/ℓ₀)^(1/3) from ℓ₀ = 4 + 7 mm up to the longest stem.
    for (double from = 0; from <= o.maxLengthMm; from += 5) {
        const double lever = o.pegDepthMm + from;
        CHECK(2 * stemHalfWidthMm(o, from) >= o.bodyWidthMm * std::cbrt(lever / 11.0) - 1e-9);
    }
    const Box3d box = tenonBoundsMm(t, o);
    CHECK(box.max[0] == doctest::Approx(stemHalfWidthMm(o, t.endMm - t.shoulderMm)));
}

TEST_CASE("tenons: rays from one ball in a spherical shell") {
    const zome::Structure frame = oneBall();
    TenonOptions o;
    o.taperDeg = 0;                 // straight stems: the cut at z = 5 then misses the horizontal ones
    o.holes = TenonHoles::Lattice;  // the paper's six
    const double inner = 30.0;
    const auto candidates =
        findTenonCandidates(frame, Transform4d::identity(), sphereProbe(inner, 40.0, 5.0), o);
    REQUIRE(candidates.size() == 6);
    for (const TenonCandidate& c : candidates) {
        INFO("hole " << c.tenon.hole);
        CHECK(c.rejection.empty());
        CHECK(c.tenon.baseMm == doctest::Approx(inner).epsilon(1e-6));
        CHECK(c.tenon.tiltDeg < 1.0);
        CHECK(c.tenon.shoulderMm == doctest::Approx(frame.scale().ballRadiusMm()));
        CHECK(c.tenon.lengthMm() == doctest::Approx(inner - frame.scale().ballRadiusMm()).epsilon(1e-6));
        CHECK(c.tenon.axisFrame == zome::holeDirection(c.tenon.hole));
        // Up (+z) meets piece 0, the rest piece 1 (the cut is at z = 5).
        CHECK(c.piece == (c.tenon.hole == 2 ? 0 : 1));
    }
    // All 30 blue holes: the six above plus 24 more. Each accepted one reaches the wall
    // straight on, in the piece its axis meets, with the peg's long side along the hole's rectangle;
    // the others are rays whose prism the cut at z = 5 runs through.
    TenonOptions allBlue = o;
    allBlue.holes = TenonHoles::Blue;
    const auto all =
        findTenonCandidates(frame, Transform4d::identity(), sphereProbe(inner, 40.0, 5.0), allBlue);
    REQUIRE(all.size() == 30);
    std::set<int> holes;
    int accepted = 0;
    for (const TenonCandidate& c : all) {
        INFO("hole " << c.tenon.hole);
        holes.insert(c.tenon.hole);
        CHECK(zome::holeColor(c.tenon.hole) == zome::Color::Blue);
        const double hitZ = inner * c.tenon.axisGrid[2];
        if (!c.rejection.empty()) {
            CHECK((c.rejection == "crosses another piece" || c.rejection == "too close to the piece's edge"));
            CHECK(std::abs(hitZ - 5.0) < bodyRadiusMm(o) + 1.0);
            continue;
        }
        ++accepted;
        CHECK(c.tenon.baseMm == doctest::Approx(inner).epsilon(1e-6));
        CHECK(c.tenon.tiltDeg < 1.0);
        CHECK(c.piece == (hitZ > 5.0 ? 0 : 1));
        const Vec3d& side = zome::holeSectionAxis(c.tenon.hole);
        for (int k = 0; k < 3; ++k)
            CHECK(c.tenon.longSideGrid[size_t(k)] == doctest::Approx(side[size_t(k)]));
    }
    CHECK(holes.size() == 30);
    CHECK(accepted >= 24);
    // Too far: a 15 mm limit (the rays look twice as far, so the wall 21 mm away is seen).
    TenonOptions shortOnes = o;
    shortOnes.maxLengthMm = 15;
    for (const TenonCandidate& c :
         findTenonCandidates(frame, Transform4d::identity(), sphereProbe(inner, 40.0), shortOnes))
        CHECK(c.rejection == "too far from the wall");
    // Nothing within reach.
    for (const TenonCandidate& c :
         findTenonCandidates(frame, Transform4d::identity(), sphereProbe(200, 210), o))
        CHECK(c.rejection == "no wall within reach");
}

TEST_CASE("tenons: used holes, obstacles, oblique walls and cut edges are rejected") {
    // Ball 0 at the origin with a B0 strut in +x to ball 1; ball 2 sits in the +y path.
    zome::Structure frame;
    const zome::BallId a = frame.addBall(zome::GoldenVector3());
    frame.addBall(zome::strutVector(0, 0));
    frame.addStrut(a, 0, 0);
    frame.addBall(zome::strutVector(1, 0));  // 47.3 mm along +y, no strut
    TenonOptions o;
    o.maxLengthMm = 80;
    const auto candidates = findTenonCandidates(frame, Transform4d::identity(), sphereProbe(70, 80), o);
    std::map<int, std::string> ofBall0;
    for (const TenonCandidate& c : candidates)
        if (c.tenon.ball == a) ofBall0[c.tenon.hole] = c.rejection;
    CHECK(ofBall0[0] == "hole holds a strut");
    CHECK(ofBall0[1] == "ball in the way");
    CHECK(ofBall0[2].empty());
    // The strut from ball 0 to ball 1 blocks ball 1's rays along ±z? No: they leave at 90°. But a
    // ray from ball 1 in −x runs along the strut itself (its −x hole holds it).
    for (const TenonCandidate& c : candidates)
        if (c.tenon.ball == 1 && c.tenon.hole == 15) CHECK(c.rejection == "hole holds a strut");
    CHECK(tenonObstruction(frame, candidates[1].tenon, o).rfind("ball 2", 0) == 0);

    // An off-centre ball sees the sphere obliquely along its side axes.
    zome::Structure off;
    off.addBall(zome::strutVector(0, 1));  // 76.5 mm along +x
    TenonOptions strict;
    strict.maxLengthMm = 100;
    strict.maxTiltDeg = 20;
    bool sawOblique = false;
    for (const TenonCandidate& c :
         findTenonCandidates(off, Transform4d::identity(), sphereProbe(100, 110), strict))
        if (c.tenon.hole == 1) {
            CHECK(c.rejection == "surface too oblique");
            CHECK(c.tenon.tiltDeg > 20);
            sawOblique = true;
        }
    CHECK(sawOblique);

    // A cut through the axis: the prism's end face straddles two pieces.
    const auto cut = findTenonCandidates(oneBall(), Transform4d::identity(), sphereProbe(30, 40, 0.5), o);
    for (const TenonCandidate& c : cut)
        if (c.tenon.hole == 0) CHECK(c.rejection == "crosses another piece");
}

TEST_CASE("tenons: a thin wall met obliquely holds a stem cut a skin inside its outer surface") {
    // A ball 76.5 mm off the centre of a 4 mm spherical wall (radii 96 and 100): its +y ray meets
    // the wall at 53°, where a square end cannot be buried in 4 mm. The stem runs through the wall
    // and is cut by a plane a skin inside the outer surface: it bonds across the whole wall and
    // nothing of it shows outside.
    zome::Structure off;
    off.addBall(zome::strutVector(0, 1));
    TenonOptions o;
    o.maxLengthMm = 100;
    o.holes = TenonHoles::Lattice;
    for (const double outer : {100.0, 40.0}) {
        // The second: a ball at the centre of a small sphere (radii 36 and 40) seen along its
        // axes straight on (no cut), and obliquely by an off-centre one (below).
        CAPTURE(outer);
        ShellProbe probe = sphereProbe(outer - 4.0, outer);
        probe.wallMm = 4.0;
        const zome::Structure& frame = outer > 50 ? off : oneBall();
        int cut = 0;
        for (const TenonCandidate& c : findTenonCandidates(frame, Transform4d::identity(), probe, o)) {
            CAPTURE(c.tenon.hole);
            if (!c.rejection.empty()) continue;
            const Tenon& t = c.tenon;
            if (t.isClipped()) {
                ++cut;
                CHECK(t.tiltDeg > 30.0);
                // The axis meets the cut inside the wall, past the inner surface.
                const double axisAtCut = t.clipAlongAxisMm();
                CHECK(axisAtCut > t.baseMm + 0.5);
                CHECK(norm(t.pointAt(axisAtCut)) < outer - 0.5);
                // The hull's wall-end corners lie on the cut.
                const std::vector<Vec3d> hull = tenonHullMm(t, o);
                for (size_t k = 4; k < 8; ++k) CHECK(std::abs(beyondCutMm(t, o, hull[k])) < 1e-6);
            }
            // Nothing of the solid outside the outer surface less 0.25 mm: sampled on a 0.5 mm
            // grid around its end; and it is solid at the axis halfway through the wall.
            CHECK(farthestSolid(t, o, [&](const Vec3d& q) { return norm(q) - outer; }) < -0.25);
            CHECK(tenonSignedDistanceMm(t, o, t.pointAt(t.baseMm + 1.0)) < 0);
        }
        if (outer > 50) CHECK(cut >= 1);
        if (outer < 50) CHECK(cut == 0);
    }
    // With the wall the planner is told is 16 mm deep, the same ray is buried as before: no cut.
    ShellProbe thick = sphereProbe(84.0, 100.0);
    for (const TenonCandidate& c : findTenonCandidates(off, Transform4d::identity(), thick, o))
        CHECK_FALSE(c.tenon.isClipped());
}

TEST_CASE("tenons: a 2.4 mm wall curved either way holds stems cut along its outer surface") {
    // Two walls 2.4 mm thick, each probed from a ball at the origin: a limb (a cylindrical wall of
    // outer radius 28 mm along z, its axis `offset` mm off in −x; the ±x and ±y rays meet it 16–24 mm
    // out, up to 25° off its normal), and a knob seen from outside (a spherical wall of radii 12
    // and 14.4 whose centre is 30 mm off in −x: the −x ray meets its outside and leaves through its
    // inside, which curves back towards the ball, so a plane a skin inside that surface leaves the
    // stem's corners in the air). The cut follows the surface: the stem bonds across the wall
    // and nothing shows past the surface it leaves by.
    struct Wall {
        Vec3d centre;
        bool isCylinder;
        double lo, hi;  ///< the material's radii
        int rays;       ///< the lattice rays that meet it
    };
    TenonOptions o;
    o.holes = TenonHoles::Lattice;
    for (const Wall& w : {Wall{{0, 0, 0}, true, 25.6, 28, 4}, Wall{{6, 0, 0}, true, 25.6, 28, 4},
                          Wall{{10, 0, 0}, true, 25.6, 28, 4}, Wall{{30, 0, 0}, false, 12, 14.4, 1}}) {
        CAPTURE(w.centre[0]);
        CAPTURE(w.isCylinder);
        auto radius = [=](const Vec3d& x) {
            return w.isCylinder ? std::hypot(x[0] + w.centre[0], x[1]) : norm(add(x, w.centre));
        };
        // How far past the surface the stems leave by (the outside of the limb, the inside of the knob).
        auto pastExit = [=](const Vec3d& x) { return w.isCylinder ? radius(x) - w.hi : w.lo - radius(x); };
        ShellProbe probe;
        probe.voxelMm = 1.0;
        probe.wallMm = w.hi - w.lo;
        probe.signedDistanceMm = [=](const Vec3d& x) { return std::max(radius(x) - w.hi, w.lo - radius(x)); };
        probe.pieceAt = [=](const Vec3d& x) -> int64_t {
            return radius(x) < w.lo || radius(x) > w.hi ? -1 : 0;
        };
        int accepted = 0;
        for (const TenonCandidate& c : findTenonCandidates(oneBall(), Transform4d::identity(), probe, o)) {
            const Tenon& t = c.tenon;
            CAPTURE(t.hole);
            if (c.rejection == "no wall within reach") continue;
            CHECK(c.rejection.empty());
            if (!c.rejection.empty()) continue;
            ++accepted;
            CHECK(t.isClipped());
            // Nothing of the solid within 0.25 mm of the surface it leaves by (a 0.5 mm grid around
            // the end), and solid halfway through the wall on every line of the stem's section.
            CHECK(farthestSolid(t, o, pastExit) < -0.25);
            int solid = 0, samples = 0;
            const Vec3d shortSide = cross(t.axisGrid, t.longSideGrid);
            auto at = [&](double a, double fl, double fs) {
                const double half = stemHalfWidthMm(o, a - t.shoulderMm);
                return madd(madd(t.pointAt(a), fl * half, t.longSideGrid), fs * half, shortSide);
            };
            for (double fl = -0.8; fl <= 0.81; fl += 0.4)
                for (double fs = -0.8; fs <= 0.81; fs += 0.4) {
                    double in = -1, out = -1;  // where the line enters and leaves the wall
                    for (double a = t.shoulderMm; a < t.endMm + 10 && out < 0; a += 0.05) {
                        const double phi = probe.signedDistanceMm(at(a, fl, fs));
                        if (phi < 0 && in < 0) in = a;
                        if (phi > 0 && in > 0) out = a;
                    }
                    if (out < 0) continue;
                    ++samples;
                    solid += tenonSignedDistanceMm(t, o, at(0.5 * (in + out), fl, fs)) < 0 ? 1 : 0;
                }
            CHECK(samples == 25);
            CHECK(solid == samples);
        }
        CHECK(accepted == w.rays);
    }
}

TEST_CASE("tenons: the choice keeps to each piece's direction, spreads the tenons, keeps prisms apart") {
    TenonOptions o;
    o.minPerPiece = 2;
    o.maxPerPiece = 3;
    auto make = [](zome::BallId ball, int hole, const Vec3d& center, int64_t piece, double score) {
        TenonCandidate c;
        c.piece = piece;
        c.score = score;
        c.tenon.ball = ball;
        c.tenon.hole = hole;
        c.tenon.piece = uint32_t(piece);
        c.tenon.axisGrid = zome::holeDirection(hole);
        c.tenon.ballCenterGridMm = center;
        c.tenon.shoulderMm = 8.85;
        c.tenon.baseMm = 30;
        c.tenon.endMm = 32;
        return c;
    };
    std::vector<TenonCandidate> candidates = {
        make(0, 2, {0, 0, 0}, 0, 0.9),     // A: piece 0's best, +z
        make(1, 1, {100, 0, 0}, 0, 0.99),  // B: piece 0 but +y, not its direction
        make(2, 2, {0, 100, 0}, 0, 0.5),   // C: piece 0, far from A
        make(6, 2, {30, 0, 0}, 0, 0.6),    // F: piece 0, scores above C but sits near A
        make(3, 2, {3, 0, 0}, 1, 0.95),    // D: piece 1, 3 mm beside A: the prisms would touch
        make(4, 2, {0, -200, 0}, 1, 0.7),  // E: piece 1
    };
    candidates.push_back(make(5, 2, {0, 300, 0}, 1, 0.99));
    candidates.back().rejection = "surface too oblique";
    // Alone, piece 0 takes its best (A), then the one farthest from it (C), then F.
    const TenonPlan alone = chooseTenons(candidates, {2, -1, -1}, o);
    REQUIRE(alone.perPiece[0].size() == 3);
    CHECK(alone.perPiece[0][0].ball == 0);
    CHECK(alone.perPiece[0][1].ball == 2);  // the spread outweighs F's better score
    CHECK(alone.perPiece[0][2].ball == 6);
    for (const Tenon& t : alone.perPiece[0]) CHECK(t.hole == 2);  // B never: another direction
    // With piece 1: each round, the piece with fewer candidates left chooses first. Piece 1 (D, E)
    // takes D, which A sits next to: piece 0 gets F and C, and both pieces two tenons.
    const TenonPlan plan = chooseTenons(candidates, {2, 2, -1}, o);
    REQUIRE(plan.perPiece.size() == 3);
    REQUIRE(plan.perPiece[0].size() == 2);
    CHECK(plan.perPiece[0][0].ball == 6);
    CHECK(plan.perPiece[0][1].ball == 2);
    REQUIRE(plan.perPiece[1].size() == 2);
    CHECK(plan.perPiece[1][0].ball == 3);
    CHECK(plan.perPiece[1][1].ball == 4);
    CHECK(plan.shortfall[0].empty());
    CHECK(plan.shortfall[1].empty());
    // One tenon wanted more than there are: the shortfall names each rejected ray.
    TenonOptions three = o;
    three.minPerPiece = 3;
    const TenonPlan short3 = chooseTenons(candidates, {2, 2, -1}, three);
    CHECK(short3.shortfall[0].at("another tenon in the way") == 1);  // A, next to D
    CHECK(short3.shortfall[1].at("surface too oblique") == 1);
    CHECK(plan.perPiece[2].empty());
    CHECK(plan.shortfall[2].count("no ball's hole along the piece's direction points at it") == 1);
    // No two chosen prisms come closer than twice their radius.
    std::vector<Tenon> all;
    for (const auto& list : plan.perPiece) all.insert(all.end(), list.begin(), list.end());
    for (size_t i = 0; i < all.size(); ++i)
        for (size_t j = i + 1; j < all.size(); ++j) {
            const double d2 = zome::segmentSegmentDistanceSq(
                all[i].pointAt(all[i].shoulderMm), all[i].pointAt(all[i].endMm),
                all[j].pointAt(all[j].shoulderMm), all[j].pointAt(all[j].endMm));
            CHECK(std::sqrt(d2) >= 2 * bodyRadiusMm(o));
        }
    // maxPerPiece 0: none at all.
    TenonOptions none = o;
    none.minPerPiece = 0;
    none.maxPerPiece = 0;
    for (const auto& list : chooseTenons(candidates, {2, 2, -1}, none).perPiece) CHECK(list.empty());
}

TEST_CASE("tenons: a rotated frame rotates the axes and the peg") {
    const double c = std::cos(0.35), s = std::sin(0.35);
    Transform4d rot;
    rot.m = {c, -s, 0, 5, s, c, 0, -3, 0, 0, 1, 2, 0, 0, 0, 1};
    auto probe = sphereProbe(30, 40);
    auto centred = probe;  // the shell is centred on the ball, which sits at (5, −3, 2) in the grid
    centred.signedDistanceMm = [&](const Vec3d& x) { return probe.signedDistanceMm(sub(x, {5, -3, 2})); };
    centred.pieceAt = [&](const Vec3d& x) { return probe.pieceAt(sub(x, {5, -3, 2})); };
    TenonOptions o;
    const auto candidates = findTenonCandidates(oneBall(), rot, centred, o);
    CHECK(candidates.size() == size_t(zome::kHoleCount));  // all 62 by default
    for (const TenonCandidate& cand : candidates) {
        CHECK(cand.rejection.empty());
        const Vec3d expected = applyLinear(rot, zome::holeDirection(cand.tenon.hole));
        for (int a = 0; a < 3; ++a)
            CHECK(cand.tenon.axisGrid[size_t(a)] == doctest::Approx(expected[size_t(a)]));
        const Vec3d longSide = applyLinear(rot, zome::holeSectionAxis(cand.tenon.hole));
        for (int a = 0; a < 3; ++a)
            CHECK(cand.tenon.longSideGrid[size_t(a)] == doctest::Approx(longSide[size_t(a)]));
        CHECK(cand.tenon.baseMm == doctest::Approx(30).epsilon(1e-6));
    }
}

TEST_CASE("orientation: the largest cut face goes down, turned to fit the bed") {
    // A 60 × 40 × 150 mm box; "cut" faces: x = 60 (40 × 150 mm²) and z = 0 (60 × 40 mm²).
    const TriMesh box = zomefab::test::makeBox({0, 0, 0}, {60, 40, 150});
    std::vector<CutFace> planes = {{{1, 0, 0}, -60, 0}, {{0, 0, -1}, 0, 0}, {{0, 1, 0}, -500, 0}};
    const std::vector<CutFace> faces = measureCutFaces(box, planes, 1e-3);
    REQUIRE(faces.size() == 2);
    CHECK(faces[0].outwardNormal == Vec3d{1, 0, 0});
    CHECK(faces[0].areaMm2 == doctest::Approx(40 * 150));
    CHECK(faces[1].areaMm2 == doctest::Approx(60 * 40));
    std::vector<Vec3d> points;
    for (const Vec3f& p : box.positions) points.push_back(toD(p));
    const PrintOrientation o = orientForPrinter(box, faces, {200, 200, 200});
    CHECK(o.fits);
    CHECK(o.isCutFaceDown);
    CHECK(o.downNormal == Vec3d{1, 0, 0});
    const Vec3d down = applyLinear(o.transformMm, {1, 0, 0});
    CHECK(down[2] == doctest::Approx(-1));
    CHECK(o.extentsMm[2] == doctest::Approx(60));
    // On the bed, centred.
    Box3d placed;
    for (const Vec3d& p : points) placed.expand(o.transformMm.apply(p));
    CHECK(placed.min[2] == doctest::Approx(0).epsilon(1e-9));
    CHECK(0.5 * (placed.min[0] + placed.max[0]) == doctest::Approx(100));
    CHECK(0.5 * (placed.min[1] + placed.max[1]) == doctest::Approx(100));

    // The largest face down needs a 150 mm bed side (more than a 100 mm bed's diagonal allows
    // for a 40 mm width): the next face is used.
    const PrintOrientation second = orientForPrinter(box, faces, {100, 100, 160});
    CHECK(second.fits);
    CHECK(second.isCutFaceDown);
    CHECK(second.downNormal == Vec3d{0, 0, -1});
    CHECK(second.extentsMm[2] == doctest::Approx(150));
    const PrintOrientation flat = orientForPrinter(box, faces, {250, 250, 45});
    CHECK(flat.fits);
    CHECK(!flat.isCutFaceDown);  // neither cut face fits: lying on a 40 mm side
    CHECK(flat.extentsMm[2] == doctest::Approx(40));
    CHECK(flat.baseAreaMm2 == doctest::Approx(60 * 150));
    CHECK(flat.note.find("2 too large for the printer") != std::string::npos);
}

TEST_CASE("orientation: a long piece fits diagonally; one too large fits nowhere") {
    const TriMesh rod = zomefab::test::makeBox({0, 0, 0}, {250, 20, 20});
    const PrintOrientation o = orientForPrinter(rod, {}, {200, 200, 200});
    CHECK(o.fits);
    CHECK(o.extentsMm[0] <= 200 + 1e-9);
    CHECK(o.extentsMm[1] <= 200 + 1e-9);
    CHECK(o.baseAreaMm2 == doctest::Approx(250 * 20));  // flat on a long side, across the bed
    const TriMesh big = zomefab::test::makeBox({0, 0, 0}, {300, 300, 300});
    const PrintOrientation none = orientForPrinter(big, {}, {200, 200, 200});
    CHECK(!none.fits);
    CHECK(none.ratio > 1);
}

TEST_CASE("orientation: the base is the cross-section one first layer above the lowest point") {
    const TriMesh cube = zomefab::test::makeBox({0, 0, 0}, {10, 10, 10});
    CHECK(baseAreaMm2(cube, {0, 0, -1}) == doctest::Approx(100));
    CHECK(baseAreaMm2(cube, {0, 1, 0}, 3.0) == doctest::Approx(100));
    // On an edge: a strip 2·h wide; on a corner: the triangle with corners at h·√3 on each edge.
    const double s = std::sqrt(0.5), h = kBaseHeightMm;
    CHECK(baseAreaMm2(cube, {-s, -s, 0}) == doctest::Approx(10 * 2 * h));
    const double c = 1 / std::sqrt(3.0), a = h * std::sqrt(3.0);
    CHECK(baseAreaMm2(cube, {-c, -c, -c}) == doctest::Approx(std::sqrt(3.0) / 2 * a * a));
}

TEST_CASE("orientation: a piece no cut face can carry rests on its largest side, not on a corner") {
    // A 30 × 30 × 190 mm bar whose one cut face lies across its middle (x = 15): the piece reaches
    // 15 mm beyond it, as a piece merged from several cells reaches beyond its faces. The old rule,
    // "the direction with the most room", stood the bar on a corner, where PrusaSlicer finds "no
    // extrusions in the first layer".
    const TriMesh bar = zomefab::test::makeBox({0, 0, 0}, {30, 30, 190});
    const std::vector<CutFace> faces = {{{1, 0, 0}, -15.0, 30 * 190}};
    const PrintOrientation o = orientForPrinter(bar, faces, {200, 200, 200});
    CHECK(o.fits);
    CHECK(!o.isCutFaceDown);
    INFO(o.note);
    CHECK(o.note.find("1 with the piece beyond them by 15 mm") != std::string::npos);
    CHECK(o.baseAreaMm2 == doctest::Approx(30 * 190));
    CHECK(o.extentsMm[2] == doctest::Approx(30));
    // Measured on the placed mesh: the facets on the bed, facing down.
    TriMesh placed = bar;
    transformInPlace(placed, o.transformMm);
    double bedMm2 = 0;
    for (const Triangle& t : placed.triangles) {
        const Vec3d a = toD(placed.positions[t[0]]), b = toD(placed.positions[t[1]]),
                    c = toD(placed.positions[t[2]]);
        const Vec3d n = cross(sub(b, a), sub(c, a));
        if (std::max({a[2], b[2], c[2]}) < 1e-3 && n[2] < 0) bedMm2 += 0.5 * norm(n);
    }
    CHECK(bedMm2 == doctest::Approx(30 * 190).epsilon(1e-4));
    // A cut face under kMinCutFaceAreaMm2 does not win over a large side either.
    const std::vector<CutFace> sliver = {{{0, 0, -1}, 0.0, 0.5 * kMinCutFaceAreaMm2}};
    const PrintOrientation side = orientForPrinter(bar, sliver, {200, 200, 200});
    CHECK(side.baseAreaMm2 == doctest::Approx(30 * 190));
    CHECK(side.note.find("1 under 100 mm²") != std::string::npos);

    if (!report::isSlicerAvailable()) {
        MESSAGE(
            "prusa-slicer is not installed (apt-get install --no-install-recommends prusa-slicer): skipped");
        return;
    }
    // The project's profile (report::prusaSlicerArguments); it throws on "no extrusions in the
    // first layer".
    const report::PrintEstimate e = report::sliceWithPrusaSlicer(placed, report::PrintSettings{}, "bar");
    CHECK(e.seconds > 0);
    CHECK(e.filamentMm3 > 0);
}

TEST_CASE("orientation: support decides: a shelf piece lies on its flat top, not on its cut face") {
    // A 10 mm slab standing on its cut face (x in [0, 10], 60 × 60 mm) carries a 50 mm shelf at the
    // top: on the cut face, the shelf's underside overhangs 50 mm above the bed (150 cm³ of
    // columns); upside down, the top (3,600 mm²) is the base and nothing overhangs.
    TriMesh shelf = zomefab::test::makeBox({0, 0, 0}, {10, 60, 60});
    appendMesh(shelf, zomefab::test::makeBox({10, 0, 50}, {60, 60, 60}));
    const std::vector<CutFace> faces = {{{0, 0, -1}, 0.0, 10 * 60}};
    const SupportEstimate onCutFace = estimateSupport(shelf, {0, 0, -1});
    CHECK(onCutFace.areaMm2 == doctest::Approx(50 * 60));
    CHECK(onCutFace.volumeMm3 == doctest::Approx(50 * 60 * 50).epsilon(0.05));  // 2 mm cells
    const PrintOrientation o = orientForPrinter(shelf, faces, {200, 200, 200});
    CHECK(o.fits);
    CHECK(!o.isCutFaceDown);
    CHECK(o.downNormal[2] == doctest::Approx(1.0));
    CHECK(o.support.volumeMm3 == doctest::Approx(0.0));
    CHECK(o.baseAreaMm2 == doctest::Approx(60 * 60));
    INFO(o.note);
    CHECK(o.note.find("needs 150 cm³ of support against 0 cm³ this way") != std::string::npos);
    // Columns stop on the piece below: a shelf over a floor needs only the gap between them.
    TriMesh table = shelf;
    appendMesh(table, zomefab::test::makeBox({10, 0, 0}, {60, 60, 10}));
    CHECK(estimateSupport(table, {0, 0, -1}).volumeMm3 == doctest::Approx(50 * 60 * 40).epsilon(0.05));
    // The columns standing on the bed: under the shelf, not over the floor (2 mm cells).
    using pieces::detail::MeshD, pieces::detail::supportColumns;
    CHECK(supportColumns(MeshD(shelf), {0, 0, -1}).bedMm2 == doctest::Approx(50 * 60).epsilon(0.1));
    CHECK(supportColumns(MeshD(table), {0, 0, -1}).bedMm2 == 0.0);
    // The footprint is the shelf's underside, outlined by its 220 mm rim, whether the columns stand
    // on the bed or on the floor; SupportModel weighs the three measures.
    for (const TriMesh* m : {&shelf, &table}) {
        const SupportEstimate e = estimateSupport(*m, {0, 0, -1});
        CHECK(e.footprintMm2 == doctest::Approx(50 * 60).epsilon(0.1));
        CHECK(e.edgeMm == doctest::Approx(2 * (50 + 60)).epsilon(0.1));
        const SupportModel model;
        CHECK(e.filamentMm3 ==
              doctest::Approx(model.interfaceMm * e.footprintMm2 + model.bodyShare * e.volumeMm3 +
                              model.sheathMm * e.edgeMm * e.volumeMm3 / e.footprintMm2));
    }
    // A ragged footprint (the same area in strips) weighs more than a compact one of equal columns.
    CHECK(supportFilamentMm3(3000, 1000, 3000 * 40, {}) > supportFilamentMm3(3000, 220, 3000 * 40, {}));
    CHECK(supportFilamentMm3(0, 0, 0, {}) == 0.0);
}

/// A spinning top of shell: two cones base to base, @p radiusMm wide at the rim and @p halfMm high
/// each, the lower tip at the origin, hollow with a wall about @p wallMm thick (the inner top is the
/// outer scaled about its centre).
TriMesh hollowTop(double radiusMm, double halfMm, double wallMm) {
    TriMesh m;
    const int around = 96;
    const double pi = std::acos(-1.0);
    const double inner = 1.0 - wallMm / (radiusMm * halfMm / std::hypot(radiusMm, halfMm));
    for (int side = 0; side < 2; ++side) {
        const double s = side == 0 ? 1.0 : inner;
        const uint32_t base = uint32_t(m.positions.size());
        m.positions.push_back(Vec3f{0, 0, float(halfMm * (1 - s))});  // lower tip
        m.positions.push_back(Vec3f{0, 0, float(halfMm * (1 + s))});  // upper tip
        for (int j = 0; j < around; ++j) {
            const double a = 2 * pi * j / around;
            m.positions.push_back(
                Vec3f{float(s * radiusMm * std::cos(a)), float(s * radiusMm * std::sin(a)), float(halfMm)});
        }
        for (uint32_t j = 0; j < uint32_t(around); ++j) {
            const uint32_t p = base + 2 + j, q = base + 2 + (j + 1) % uint32_t(around);
            if (side == 0) {
                m.triangles.push_back({base, q, p});
                m.triangles.push_back({base + 1, p, q});
            } else {  // the cavity's wall faces inward
                m.triangles.push_back({base, p, q});
                m.triangles.push_back({base + 1, q, p});
            }
        }
    }
    return m;
}

TEST_CASE("orientation: a piece that needs least support resting on a point rests on its supports") {
    // A hollow spinning top 190 mm tall and 120 mm wide, a 2.4 mm wall: on its lower tip no facet
    // outside or inside is more than 45° from the vertical, but a tip gives no first layer; every
    // pose with one (on a side) has the cavity's ceiling to support.
    TriMesh top = hollowTop(60.0, 95.0, 2.4);
    const double onSide = estimateSupport(top, {std::cos(0.56), 0, -std::sin(0.56)}).volumeMm3;
    CHECK(onSide > 200e3);
    // Alone, straight on its tip, nothing overhangs: no support stands on the bed to hold it, so
    // that pose is not "on its supports" (kMinHoldMm2).
    const pieces::detail::MeshD alone(top);
    CHECK(pieces::detail::supportColumns(alone, {0, 0, -1}).bedMm2 == 0.0);
    CHECK(baseAreaMm2(top, {0, 0, -1}) < 1.0);
    // With a fin 20 mm above the tip (30 × 30 × 2 mm, as the bunny's head at 400 mm with a 2.4 mm
    // wall rests on an ear's tip, docs/benchmarks.md), the fin's supports stand on the bed and hold
    // it: on its tip, with 18 cm³ of columns under the fin against 400 on a side.
    appendMesh(top, zomefab::test::makeBox({5, -15, 20}, {40, 15, 22}));
    const PrintOrientation o = orientForPrinter(top, {}, {200, 200, 200});
    INFO(o.note);
    CHECK(o.fits);
    CHECK(std::abs(o.downNormal[2]) > 0.95);  // on a tip
    CHECK(o.baseAreaMm2 < 25.0);
    CHECK(o.support.volumeMm3 < 30e3);
    CHECK(o.note.find("and its supports (print it with supports)") != std::string::npos);
    if (!report::isSlicerAvailable()) {
        MESSAGE(
            "prusa-slicer is not installed (apt-get install --no-install-recommends prusa-slicer): skipped");
        return;
    }
    // PrusaSlicer takes it with its automatic supports (it throws on "no extrusions in the first
    // layer").
    TriMesh placed = top;
    transformInPlace(placed, o.transformMm);
    report::PrintSettings withSupports;
    withSupports.supports = true;
    const report::PrintEstimate e = report::sliceWithPrusaSlicer(placed, withSupports, "top");
    CHECK(e.filamentMm3 > 0);
}

TEST_CASE(
    "orientation: a ball no pose gives a first layer rests on its supports, not on its largest contact") {
    // A solid ball 38 mm across: 0.2 mm above its lowest point its section is 24 mm² in every pose
    // (under kMinBaseMm2), and the columns under its lower half stand on about 570 mm² of the bed.
    const TriMesh ball = zomefab::test::makeSphere({0, 0, 0}, 19.0, 48, 96);
    const PrintOrientation o = orientForPrinter(ball, {}, {200, 200, 200});
    INFO(o.note);
    CHECK(o.fits);
    CHECK(o.baseAreaMm2 < 25.0);
    CHECK(o.note.find("and its supports (print it with supports)") != std::string::npos);
}

TEST_CASE(
    "support: an underside 50° from the vertical needs it at the 45° rule, not on a printer that takes 60°") {
    // A prism 20 mm long along y; its section in xz: A (0, 0), B (11.92, 10), C (0, 10). The face
    // A–B faces down and out, 50° from the vertical (its normal 40° from straight down).
    const double run = 10.0 * std::tan(50.0 * std::acos(-1.0) / 180.0);
    TriMesh prism;
    for (double y : {0.0, 20.0})
        for (const auto& [x, z] : {std::pair{0.0, 0.0}, std::pair{run, 10.0}, std::pair{0.0, 10.0}})
            prism.positions.push_back(Vec3f{float(x), float(y), float(z)});
    const uint32_t A = 0, B = 1, C = 2, A2 = 3, B2 = 4, C2 = 5;  // the same three at y = 20
    prism.triangles = {{A, B, C},  {A2, C2, B2}, {A, B2, B}, {A, A2, B2},
                       {C, B, B2}, {C, B2, C2},  {A, C, C2}, {A, C2, A2}};
    const double underside = std::hypot(run, 10.0) * 20.0;
    CHECK(estimateSupport(prism, {0, 0, -1}).areaMm2 == doctest::Approx(underside));
    CHECK(estimateSupport(prism, {0, 0, -1}, 45.0).volumeMm3 > 0.0);
    CHECK(estimateSupport(prism, {0, 0, -1}, 55.0).areaMm2 == 0.0);
    CHECK(estimateSupport(prism, {0, 0, -1}, 55.0).volumeMm3 == 0.0);
}

TEST_CASE("label: seven-segment strokes, an underline, centred") {
    LabelOptions o;
    const auto eight = labelStrokes("8", o);
    CHECK(eight.size() == 8);  // 7 segments + underline
    const auto one = labelStrokes("1", o);
    CHECK(one.size() == 3);
    const Vec3d size = labelSizeMm("12", o);
    Box3d box;
    for (const Stroke& s : labelStrokes("12", o)) {
        box.expand({s.centerX - s.halfWidth, s.centerY - s.halfHeight, 0});
        box.expand({s.centerX + s.halfWidth, s.centerY + s.halfHeight, 0});
    }
    CHECK(box.max[0] - box.min[0] == doctest::Approx(size[0]));
    CHECK(box.max[1] - box.min[1] == doctest::Approx(size[1]));
    CHECK(box.min[0] == doctest::Approx(-box.max[0]));
    CHECK(box.min[1] == doctest::Approx(-box.max[1]));
    CHECK_THROWS_AS(labelStrokes("A", o), Error);

    // The strokes' solid: inside a stroke from depth + flatness below the plane to above it (the
    // engraving is its part within the depth of the surface, wherever that lies in the flatness).
    PieceLabel label{"1", {0, 0, 0}, {0, 0, 1}, {0, 1, 0}, size[0], size[1]};
    const Stroke& s = one[0];
    CHECK(labelSignedDistanceMm(label, one, o, {s.centerX, s.centerY, -0.5 * o.depthMm}) < 0);
    CHECK(labelSignedDistanceMm(label, one, o, {s.centerX, s.centerY, -o.depthMm - 0.3}) < 0);
    CHECK(labelSignedDistanceMm(label, one, o, {s.centerX, s.centerY, -o.depthMm - o.flatnessMm - 0.3}) ==
          doctest::Approx(0.3));
    // Readable from the cavity (+z): the right side of the text is +x = up × normal.
    const auto two = labelStrokes("2", o);  // "2" has its upper vertical on the right
    bool hasUpperRight = false;
    for (const Stroke& st : two)
        if (st.halfHeight > st.halfWidth && st.centerX > 0 && st.centerY > 0) hasUpperRight = true;
    CHECK(hasUpperRight);
}

TEST_CASE("label: placed on a 1.8 mm wall whose surface lies within the flatness below the spot") {
    // A flat wall 1.8 mm thick: material for 0 > z > −1.8, the cavity above (+z), piece 3 everywhere.
    const double wall = 1.8;
    ShellProbe probe;
    probe.voxelMm = 1.0;
    probe.wallMm = wall;
    probe.signedDistanceMm = [wall](const Vec3d& p) { return std::max(p[2], -p[2] - wall); };
    probe.pieceAt = [](const Vec3d&) { return int64_t(3); };
    const LabelOptions o = labelOptionsForWall(LabelOptions{}, wall);  // 0.6 mm deep, within 0.3 mm
    CHECK(o.depthMm == doctest::Approx(0.6));
    CHECK(o.flatnessMm == doctest::Approx(0.3));
    // The 16 mm shell: 1.2 mm deep, within 2 mm; the solid ends 12.8 mm above the outer surface.
    const LabelOptions thick = labelOptionsForWall(LabelOptions{}, 16.0);
    CHECK(thick.depthMm == doctest::Approx(1.2));
    CHECK(thick.flatnessMm == doctest::Approx(2.0));
    // At most a third and a sixth of any wall: the solid (depth + flatness below the plane, the
    // surface up to flatness above it) ends a depth short of the outer surface.
    for (const double w : {1.2, 1.8, 2.4, 4.0, 16.0}) {
        const LabelOptions l = labelOptionsForWall(LabelOptions{}, w);
        CHECK(w - l.flatnessMm - (l.depthMm + l.flatnessMm) >= l.depthMm - 1e-12);
    }
    // The spot a ray found lies 0.25 mm inside the wall (the voxel surface is that far off): the
    // number is still placed, with more than half the wall behind its deepest point. (A probe a
    // whole voxel below the depth reached 1.85 mm, past the wall, and placed nothing.)
    const std::vector<SurfaceSpot> spots{{{0, 0, -0.25}, {0, 0, 1}}};
    std::string note;
    const auto label = placeLabel("7", 3, spots, {}, TenonOptions{}, probe, o, &note);
    REQUIRE(label.has_value());
    CHECK(note.empty());
    CHECK(-label->centerGridMm[2] + o.depthMm <= 0.5 * wall + 1e-9);
    // Another piece's wall behind the spot, or no wall: no number.
    probe.pieceAt = [](const Vec3d& p) { return p[2] < -1.0 ? int64_t(4) : int64_t(3); };
    CHECK_FALSE(placeLabel("7", 3, spots, {}, TenonOptions{}, probe, o, &note).has_value());
    probe.signedDistanceMm = [](const Vec3d& p) { return std::max(p[2], -p[2] - 0.9); };
    CHECK_FALSE(placeLabel("7", 3, spots, {}, TenonOptions{}, probe, o, &note).has_value());
}

TEST_CASE("3mf: a deterministic OPC zip with the model in millimetres") {
    const TriMesh a = zomefab::test::makeBox({0, 0, 0}, {10, 20, 30});
    const TriMesh b = zomefab::test::makeBox({-5, -5, 0}, {5, 5, 5});
    const std::vector<ThreeMfObject> objects = {
        {"piece-00", &a, Transform4d::identity()},
        {"piece<01>", &b, Transform4d::scaleTranslate(1, {210, 0, 0})}};
    const std::string bytes = threeMfBytes(objects, "zomefab test");
    CHECK(bytes == threeMfBytes(objects, "zomefab test"));
    const auto entries = unzip(bytes);
    REQUIRE(entries.size() == 3);
    REQUIRE(entries.count("[Content_Types].xml"));
    REQUIRE(entries.count("_rels/.rels"));
    REQUIRE(entries.count("3D/3dmodel.model"));
    CHECK(entries.at("_rels/.rels").find("Target=\"/3D/3dmodel.model\"") != std::string::npos);
    const std::string& model = entries.at("3D/3dmodel.model");
    CHECK(model.find("unit=\"millimeter\"") != std::string::npos);
    CHECK(countOf(model, "<object ") == 2);
    CHECK(countOf(model, "<vertex ") == a.positions.size() + b.positions.size());
    CHECK(countOf(model, "<triangle ") == a.triangles.size() + b.triangles.size());
    CHECK(model.find("name=\"piece&lt;01&gt;\"") != std::string::npos);
    CHECK(model.find("transform=\"1 0 0 0 1 0 0 0 1 210 0 0\"") != std::string::npos);
    CHECK(model.find("<vertex x=\"10\" y=\"20\" z=\"30\"/>") != std::string::npos);
    CHECK(bytes.size() < model.size());  // deflated

    const std::vector<ThreeMfObject> none = {{"empty", nullptr, Transform4d::identity()}};
    CHECK_THROWS_AS(threeMfBytes(none, "x"), Error);
}

TEST_CASE("zip: stored entries when deflate does not help") {
    const std::string zip = zipArchive({{"a.bin", "x"}, {"b.txt", std::string(1000, 'a')}});
    const auto entries = unzip(zip);
    CHECK(entries.at("a.bin") == "x");
    CHECK(entries.at("b.txt") == std::string(1000, 'a'));
    CHECK(readU16(zip, 8) == 0);  // the 1-byte entry is stored
}

namespace {

/// A spherical cap shell: radius @p radiusMm (outer), wall @p wallMm, polar angle up to @p capDeg
/// about +z, closed by its rim band; outward facets.
TriMesh capShell(double radiusMm, double wallMm, double capDeg, int rings = 24, int segments = 72) {
    TriMesh m;
    const double cap = capDeg * std::acos(-1.0) / 180.0;
    auto point = [&](double r, int ring, int segment) {
        const double polar = cap * ring / rings, azimuth = 2.0 * std::acos(-1.0) * segment / segments;
        return Vec3f{float(r * std::sin(polar) * std::cos(azimuth)),
                     float(r * std::sin(polar) * std::sin(azimuth)), float(r * std::cos(polar))};
    };
    // Vertex (side, ring, segment); ring 0 is the pole (one vertex per side).
    auto index = [&](int side, int ring, int segment) {
        return uint32_t(side * (1 + rings * segments) +
                        (ring == 0 ? 0 : 1 + (ring - 1) * segments + segment % segments));
    };
    for (int side = 0; side < 2; ++side) {
        const double r = side == 0 ? radiusMm : radiusMm - wallMm;
        m.positions.push_back(point(r, 0, 0));
        for (int ring = 1; ring <= rings; ++ring)
            for (int segment = 0; segment < segments; ++segment)
                m.positions.push_back(point(r, ring, segment));
    }
    for (int side = 0; side < 2; ++side)
        for (int ring = 0; ring < rings; ++ring)
            for (int s = 0; s < segments; ++s) {
                const uint32_t a = index(side, ring, s), b = index(side, ring, s + 1),
                               c = index(side, ring + 1, s), d = index(side, ring + 1, s + 1);
                // Outer side faces away from the centre, inner side towards it.
                auto add = [&](uint32_t x, uint32_t y, uint32_t z) {
                    m.triangles.push_back(side == 0 ? Triangle{x, y, z} : Triangle{x, z, y});
                };
                if (ring > 0) add(a, c, b);
                add(b, c, d);
            }
    for (int s = 0; s < segments; ++s) {  // the rim: outer ring to inner ring
        const uint32_t a = index(0, rings, s), b = index(0, rings, s + 1), c = index(1, rings, s),
                       d = index(1, rings, s + 1);
        m.triangles.push_back({a, b, c});
        m.triangles.push_back({b, d, c});
    }
    return m;
}

}  // namespace

TEST_CASE("orientation: print time counts: a thin cap is turned to print faster than for support alone") {
    // A cap of a 100 mm sphere, 60° about its pole, 2.4 mm thick (the thin printed wall). Scored
    // by support alone (every PrintTimeModel rate 0) it rests on 145 mm² of its rim, "down" 56°
    // from its axis, much of its wall shallow enough to print as solid layers; with the time model
    // it is turned further (76°, on its supports), its wall steeper and more of it perimeters
    // (PrusaSlicer prints a 2.4 mm plate at 60° in half the time it takes lying flat).
    const TriMesh cap = capShell(100.0, 2.4, 60.0);
    REQUIRE(signedVolume(cap) > 0.0);
    const double pi = std::acos(-1.0);
    const double volume =
        2.0 * pi / 3.0 * (1.0 - std::cos(pi / 3.0)) * (std::pow(100.0, 3) - std::pow(97.6, 3));
    CHECK(signedVolume(cap) == doctest::Approx(volume).epsilon(0.02));
    PrintTimeModel untimed;
    untimed.perimeterSPerMm3 = untimed.solidSPerMm3 = untimed.interiorSPerMm3 = 0.0;
    const PrintOrientation bySupport =
        orientForPrinter(cap, {}, {200, 200, 200}, kFlatToleranceMm, kOverhangDeg, untimed);
    const PrintOrientation o = orientForPrinter(cap, {}, {200, 200, 200});
    INFO(o.note);
    CHECK(o.fits);
    const double timed = skinSeconds(cap, scale(o.downNormal, -1.0));
    const double untimedSeconds = skinSeconds(cap, scale(bySupport.downNormal, -1.0));
    CHECK(timed < 0.95 * untimedSeconds);
    // Not at the price of more support here.
    CHECK(o.support.volumeMm3 < bySupport.support.volumeMm3);
    // Lying on either face takes longer still.
    for (const Vec3d& lying : {Vec3d{0, 0, -1}, Vec3d{0, 0, 1}})
        CHECK(timed < skinSeconds(cap, scale(lying, -1.0)));
}
