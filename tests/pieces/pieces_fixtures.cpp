// SPDX-License-Identifier: GPL-3.0-or-later
#include "pieces_fixtures.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "test_util.h"
#include "zomefab/core/json_values.h"
#include "zomefab/core/error.h"
#include "zomefab/core/run_context.h"
#include "zomefab/core/vec.h"
#include "zomefab/pieces/detail/box_distance.h"
#include "zomefab/sdf/vdb_file.h"
#include "zomefab/zome/golden.h"
#include "zomefab/zome/structure_json.h"

namespace zomefab::pieces::test {

using namespace detail;

namespace {

void writeFile(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) throw Error(ErrorCode::WriteFailed, "cannot write", path);
}

}  // namespace

sdf::LevelSet makeSphereShell(const Vec3d& c, double r, double t, double voxel) {
    sdf::MeshToLevelSetOptions o;
    o.voxelMm = voxel;
    o.interiorBandMm = t;
    const TriMesh sphere = zomefab::test::makeSphere(c, r, 96, 192);
    const sdf::LevelSet object = sdf::meshToLevelSet(sphere, o, RunContext::silent());
    Fabrication wall;
    wall.wallMm = t;
    return sdf::makeShell(object, wall, RunContext::silent());
}

zome::Structure makeCubeLattice(double maxRadiusMm) {
    zome::Structure s;
    const double b0 = s.scale().b0Mm;
    const int n = int(std::floor(maxRadiusMm / b0));
    const zome::Golden step(2, 2);  // B0 = 2 + 2φ units
    for (int i = -n; i <= n; ++i)
        for (int j = -n; j <= n; ++j)
            for (int k = -n; k <= n; ++k)
                if (std::sqrt(double(i * i + j * j + k * k)) * b0 <= maxRadiusMm)
                    s.addBall(zome::GoldenVector3(step * zome::Golden(i), step * zome::Golden(j),
                                                  step * zome::Golden(k)));
    for (zome::BallId a : s.ballIds())
        for (int hole : {0, 1, 2}) {
            const zome::GoldenVector3 end = s.ball(a).position + zome::strutVector(hole, 0);
            if (s.findBall(end) != zome::kNoId) s.addStrut(a, hole, 0);
        }
    return s;
}

namespace {

partition::PartitionResult piecePerCell(partition::LinearCells cells) {
    partition::PartitionResult r;
    r.cells = std::move(cells);
    r.pieces.resize(r.cells.cellCount());
    for (size_t k = 0; k < r.pieces.size(); ++k) {
        r.pieces[k].cells = {uint32_t(k)};
        r.pieces[k].fit.fits = true;  // as the partition's pieces are, for its printer (200 mm)
    }
    return r;
}

}  // namespace

partition::PartitionResult quadrantCells(double x, double z) {
    partition::LinearCells c;
    for (double sx : {1.0, -1.0})
        for (double sz : {1.0, -1.0}) {
            c.w.push_back({sx, 0, sz});
            c.b.push_back(-sx * x - sz * z);
        }
    return piecePerCell(std::move(c));
}

partition::PartitionResult halfSpaceCells(const Vec3d& n, double d) {
    partition::LinearCells c;
    c.w = {n, scale(n, -1.0)};
    c.b = {-d, d};
    return piecePerCell(std::move(c));
}

Fabrication printerOf(const Vec3d& printerMm) {
    Fabrication f;
    f.printerMm = printerMm;
    f.bedMarginMm = 0;
    return f;
}

namespace {

/// Möller–Trumbore: the ray parameter where o + t·d meets triangle @p t of @p m, if it does.
std::optional<double> rayTriangle(const TriMesh& m, const Triangle& t, const Vec3d& o, const Vec3d& d) {
    const Vec3d a = toD(m.positions[t[0]]), b = toD(m.positions[t[1]]), c = toD(m.positions[t[2]]);
    const Vec3d e1 = sub(b, a), e2 = sub(c, a);
    const Vec3d p = cross(d, e2);
    const double det = dot(e1, p);
    if (std::abs(det) < 1e-14) return std::nullopt;
    const Vec3d s = sub(o, a);
    const double u = dot(s, p) / det;
    if (u < 0 || u > 1) return std::nullopt;
    const Vec3d q = cross(s, e1);
    const double v = dot(d, q) / det;
    if (v < 0 || u + v > 1) return std::nullopt;
    return dot(e2, q) / det;
}

}  // namespace

std::optional<double> firstHit(const TriMesh& m, const Vec3d& o, const Vec3d& d) {
    std::optional<double> best;
    for (const Triangle& t : m.triangles) {
        const std::optional<double> tt = rayTriangle(m, t, o, d);
        if (tt && *tt > 0 && (!best || *tt < *best)) best = tt;
    }
    return best;
}

bool isInsideMesh(const TriMesh& m, const Vec3d& o) {
    const Vec3d d = normalized({0.5773, 0.5801, 0.5748});
    size_t crossings = 0;
    for (const Triangle& t : m.triangles) {
        const std::optional<double> tt = rayTriangle(m, t, o, d);
        if (tt && *tt > 0) ++crossings;
    }
    return crossings % 2 == 1;
}

TriMesh gridMesh(const Piece& piece) {
    TriMesh m = piece.mesh;
    transformInPlace(m, affineInverse(piece.gridToPrintMm));
    return m;
}

const sdf::LevelSet& sphereShell() {
    static const sdf::LevelSet s = makeSphereShell({0, 0, 0}, kSphereRadiusMm, kSphereShellMm, 1.0);
    return s;
}

const zome::Structure& sphereFrame() {
    static const zome::Structure s = makeCubeLattice(kSphereRadiusMm - kSphereShellMm - 8.85 - 3.0);
    return s;
}

void writeToolInputs(const std::string& dir) {
    const sdf::LevelSet shell = makeSphereShell({0, 0, 0}, 75.0, 8.0, 1.0);
    writeFile(dir + "/shell.vdb", sdf::serializeVdb({shell}));
    const zome::Structure frame = makeCubeLattice(75.0 - 8.0 - 8.85 - 3.0);
    writeFile(dir + "/frame.json", zome::structureToJson(frame).dump(1));
    const partition::LinearCells cells = quadrantCells(-5.3, 10.4).cells;
    auto partition = [&](const Transform4d& t) {
        nlohmann::json j;
        j["format"] = "zomefab.partition";
        j["version"] = 1;
        j["transform_mm"] = toJson(t);
        j["printer_mm"] = {200, 200, 200};
        for (size_t k = 0; k < cells.cellCount(); ++k) {
            j["cells"].push_back({{"cell", k}, {"w", cells.w[k]}, {"b", cells.b[k]}});
            j["pieces"].push_back({{"piece", k}, {"cells", {k}}});
        }
        return j.dump(1);
    };
    writeFile(dir + "/partition.json", partition(Transform4d::identity()));
    writeFile(dir + "/bad-transform.json", partition(Transform4d::scaleTranslate(1.0, {5, 0, 0})));
    writeFile(dir + "/not-partition.json", "{\"format\": \"zomefab.structure\", \"version\": 1}");
}

}  // namespace zomefab::pieces::test
