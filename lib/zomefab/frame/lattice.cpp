// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/frame/lattice.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/frame/energy.h"
#include "zomefab/frame/frame_field.h"
#include "zomefab/frame/outermost.h"

namespace zomefab::frame {

namespace {

/// One placement of the lattice: which lattice points are balls, which edges are struts, which
/// cells are whole cubes.
struct Placement {
    double rotationDeg = 0;
    Vec3d offsetMm{0, 0, 0};  ///< frame mm of index (0,0,0)
    int lo[3] = {0, 0, 0};    ///< index range [lo, lo + n)
    int n[3] = {0, 0, 0};
    std::vector<uint8_t> isCube;  ///< per cell (i,j,k) in [lo, lo+n−1)
    std::vector<uint8_t> edge;    ///< [3·point + axis]: the strut to the +axis neighbour is in a cube
    std::vector<uint8_t> isBall;  ///< per point: a corner of a cube
    size_t cubes = 0;
    /// With no whole cube: the balls of the largest connected set of allowed balls and B0 struts
    /// (isBall and edge then hold that set); 0 when there are cubes.
    size_t strutFrameBalls = 0;
    /// Mean E_fid summand of the outermost cube balls: the tie-break between placements with as
    /// many cubes (the one whose boundary lies closer to the surface).
    double fidelity = 0;

    size_t index(int i, int j, int k) const {
        return (size_t(i - lo[0]) * size_t(n[1]) + size_t(j - lo[1])) * size_t(n[2]) + size_t(k - lo[2]);
    }
};

/// The holes of the B0 struts along +x, +y, +z and −x, −y, −z.
struct AxisHoles {
    int plus[3], minus[3];
    AxisHoles() {
        for (int a = 0; a < 3; ++a) {
            zome::GoldenVector3 v;
            v[a] = zome::Golden(2, 2);
            plus[a] = zome::matchStrut(v)->hole;
            minus[a] = zome::oppositeHole(plus[a]);
        }
    }
};
const AxisHoles& axisHoles() {
    static const AxisHoles holes;
    return holes;
}

/// Frame-space box of the field's box rotated by −rotation about z.
Box3d frameBox(const FrameField& ff) {
    const Box3d b = ff.field().boundsMm();
    Box3d out;
    for (int c = 0; c < 8; ++c) {
        const Vec3d p{(c & 1) ? b.max[0] : b.min[0], (c & 2) ? b.max[1] : b.min[1],
                      (c & 4) ? b.max[2] : b.min[2]};
        out.expand(ff.toFrameMm(p));
    }
    return out;
}

/// The neighbour of lattice point @p id along +axis @p a (in range when its edge flag is set).
size_t stepAlong(const Placement& pl, size_t id, int a) {
    const size_t s = size_t(pl.n[2]);
    return a == 0 ? id + size_t(pl.n[1]) * s : a == 1 ? id + s : id + 1;
}

/// With no whole cube: the largest connected set of allowed balls and allowed B0 struts (the first
/// largest in point order) as the placement's balls and edges, and its size. A thin object still
/// gets a frame: a few balls in a row or a square, or one ball.
void keepLargestStrutSet(Placement& pl, const std::vector<uint8_t>& ballOk,
                         const std::vector<uint8_t>& edgeOk) {
    const size_t count = ballOk.size();
    std::vector<size_t> parent(count);
    std::iota(parent.begin(), parent.end(), size_t(0));
    auto find = [&](size_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    for (size_t id = 0; id < count; ++id)
        for (int a = 0; a < 3; ++a)
            if (edgeOk[3 * id + size_t(a)]) {
                const size_t x = find(id), y = find(stepAlong(pl, id, a));
                if (x != y) parent[std::max(x, y)] = std::min(x, y);
            }
    std::vector<size_t> size(count, 0);
    size_t keep = SIZE_MAX;
    for (size_t id = 0; id < count; ++id)
        if (ballOk[id] && ++size[find(id)] > (keep == SIZE_MAX ? 0 : size[keep])) keep = find(id);
    if (keep == SIZE_MAX) return;
    pl.strutFrameBalls = size[keep];
    for (size_t id = 0; id < count; ++id) {
        if (!ballOk[id] || find(id) != keep) continue;
        pl.isBall[id] = 1;
        for (int a = 0; a < 3; ++a) pl.edge[3 * id + size_t(a)] = edgeOk[3 * id + size_t(a)];
    }
}

/// Evaluates one placement: ball and edge validity, whole cubes.
Placement evaluate(const FrameField& ff, double rotationDeg, const Vec3d& offsetMm) {
    Placement pl;
    pl.rotationDeg = rotationDeg;
    pl.offsetMm = offsetMm;
    const double b0 = ff.scale().b0Mm;
    const Box3d box = frameBox(ff);
    for (int a = 0; a < 3; ++a) {
        pl.lo[a] = int(std::floor((box.min[a] - offsetMm[a]) / b0));
        pl.n[a] = int(std::ceil((box.max[a] - offsetMm[a]) / b0)) - pl.lo[a] + 1;
    }
    const size_t count = size_t(pl.n[0]) * size_t(pl.n[1]) * size_t(pl.n[2]);
    std::vector<double> depth(count);
    std::vector<uint8_t> ballOk(count);
    auto pos = [&](int i, int j, int k) {
        return Vec3d{offsetMm[0] + b0 * i, offsetMm[1] + b0 * j, offsetMm[2] + b0 * k};
    };
    for (int i = pl.lo[0]; i < pl.lo[0] + pl.n[0]; ++i)
        for (int j = pl.lo[1]; j < pl.lo[1] + pl.n[1]; ++j)
            for (int k = pl.lo[2]; k < pl.lo[2] + pl.n[2]; ++k) {
                const size_t id = pl.index(i, j, k);
                depth[id] = ff.depthMm(pos(i, j, k));
                ballOk[id] = ff.isBallAllowed(depth[id]) ? 1 : 0;
            }
    // edgeOk[3·id + axis]: the B0 strut from (i,j,k) along +axis is clear.
    const double limit = ff.strutDepthLimitMm(zome::Color::Blue);
    std::vector<uint8_t> edgeOk(3 * count, 0);
    for (int i = pl.lo[0]; i < pl.lo[0] + pl.n[0]; ++i)
        for (int j = pl.lo[1]; j < pl.lo[1] + pl.n[1]; ++j)
            for (int k = pl.lo[2]; k < pl.lo[2] + pl.n[2]; ++k) {
                const size_t id = pl.index(i, j, k);
                if (!ballOk[id]) continue;
                const int ijk[3] = {i, j, k};
                for (int a = 0; a < 3; ++a) {
                    int e[3] = {i, j, k};
                    e[a] += 1;
                    if (e[a] >= pl.lo[a] + pl.n[a]) continue;
                    const size_t other = pl.index(e[0], e[1], e[2]);
                    if (!ballOk[other]) continue;
                    edgeOk[3 * id + size_t(a)] =
                        ff.isSegmentAllowed(pos(ijk[0], ijk[1], ijk[2]), depth[id], pos(e[0], e[1], e[2]),
                                            depth[other], limit)
                            ? 1
                            : 0;
                }
            }
    pl.isCube.assign(count, 0);
    for (int i = pl.lo[0]; i + 1 < pl.lo[0] + pl.n[0]; ++i)
        for (int j = pl.lo[1]; j + 1 < pl.lo[1] + pl.n[1]; ++j)
            for (int k = pl.lo[2]; k + 1 < pl.lo[2] + pl.n[2]; ++k) {
                // 12 edges: the 4 along each axis, starting at the cell's corners with that
                // axis coordinate at its low end.
                bool ok = true;
                for (int a = 0; a < 3 && ok; ++a) {
                    for (int c = 0; c < 4 && ok; ++c) {
                        int e[3] = {i, j, k};
                        e[(a + 1) % 3] += c & 1;
                        e[(a + 2) % 3] += (c >> 1) & 1;
                        ok = edgeOk[3 * pl.index(e[0], e[1], e[2]) + size_t(a)] != 0;
                    }
                }
                if (ok) {
                    pl.isCube[pl.index(i, j, k)] = 1;
                    ++pl.cubes;
                }
            }
    // Balls and struts of the whole cubes, the hole masks they give, and the fidelity tie-break.
    pl.isBall.assign(count, 0);
    pl.edge.assign(3 * count, 0);
    if (pl.cubes == 0) keepLargestStrutSet(pl, ballOk, edgeOk);
    for (int i = pl.lo[0]; i + 1 < pl.lo[0] + pl.n[0]; ++i)
        for (int j = pl.lo[1]; j + 1 < pl.lo[1] + pl.n[1]; ++j)
            for (int k = pl.lo[2]; k + 1 < pl.lo[2] + pl.n[2]; ++k) {
                if (!pl.isCube[pl.index(i, j, k)]) continue;
                for (int c = 0; c < 8; ++c)
                    pl.isBall[pl.index(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))] = 1;
                for (int a = 0; a < 3; ++a)
                    for (int c = 0; c < 4; ++c) {
                        int e[3] = {i, j, k};
                        e[(a + 1) % 3] += c & 1;
                        e[(a + 2) % 3] += (c >> 1) & 1;
                        pl.edge[3 * pl.index(e[0], e[1], e[2]) + size_t(a)] = 1;
                    }
            }
    const AxisHoles& holes = axisHoles();
    std::vector<uint64_t> mask(count, 0);
    const size_t stride[3] = {size_t(pl.n[1]) * size_t(pl.n[2]), size_t(pl.n[2]), 1};
    for (size_t id = 0; id < count; ++id)
        for (int a = 0; a < 3; ++a)
            if (pl.edge[3 * id + size_t(a)]) {
                mask[id] |= uint64_t(1) << holes.plus[a];
                mask[id + stride[a]] |= uint64_t(1) << holes.minus[a];
            }
    double sum = 0;
    size_t outermost = 0;
    for (size_t id = 0; id < count; ++id)
        if (pl.isBall[id] && isOutermostMask(mask[id])) {
            sum += fidelitySummand(depth[id], ff);
            ++outermost;
        }
    pl.fidelity = outermost ? sum / double(outermost) : 0.0;
    return pl;
}

/// Half the diagonal of one offset step (b0 / offsetSteps along each axis): every point lies within
/// it of a lattice point of some placement tried (mm).
double offsetStepDiagonalMm(const LatticeOptions& options) {
    return 0.5 * std::sqrt(3.0) * options.scale.b0Mm / double(options.offsetSteps);
}

}  // namespace

double cubeDepthMm(const LatticeOptions& options) {
    return ballDepthLimitMm(options.zone, options.scale) + 0.5 * std::sqrt(3.0) * options.scale.b0Mm +
           offsetStepDiagonalMm(options);
}

LatticeResult initialLattice(const sdf::InteriorField& field, const LatticeOptions& options,
                             RunContext& context) {
    if (options.offsetSteps < 1) throw Error(ErrorCode::Usage, "lattice offset steps must be at least 1");
    if (options.searchRotation && !(options.rotationStepDeg > 0))
        throw Error(ErrorCode::Usage, "lattice rotation step must be positive");
    if (field.empty()) throw Error(ErrorCode::ProcessingFailed, "the interior field is empty");
    options.scale.validate();
    context.progress("lattice", 0.0);

    std::vector<double> rotations{0.0};
    if (options.searchRotation)
        for (double r = options.rotationStepDeg; r < 90.0 - 1e-9; r += options.rotationStepDeg)
            rotations.push_back(r);
    const int steps = options.offsetSteps;
    const size_t perRotation = size_t(steps) * size_t(steps) * size_t(steps);
    const size_t total = rotations.size() * perRotation;
    const double b0 = options.scale.b0Mm;

    // Offsets are relative to the min corner of the frame-space box of each rotation.
    std::vector<size_t> cubes(total, 0), strutFrameBalls(total, 0);
    std::vector<double> fidelity(total, 0.0);
    std::vector<FrameField> fields;
    std::vector<Vec3d> corners;
    for (double r : rotations) {
        fields.emplace_back(field, r, options.scale, options.zone);
        corners.push_back(frameBox(fields.back()).min);
    }
    auto offsetOf = [&](size_t p) {
        const size_t r = p / perRotation, q = p % perRotation;
        const int oi = int(q / size_t(steps * steps)), oj = int((q / size_t(steps)) % size_t(steps)),
                  ok = int(q % size_t(steps));
        const Vec3d& c = corners[r];
        return Vec3d{c[0] + b0 * oi / steps, c[1] + b0 * oj / steps, c[2] + b0 * ok / steps};
    };
    tbb::parallel_for(size_t(0), total, [&](size_t p) {
        if (context.isCancelled()) return;
        const Placement pl = evaluate(fields[p / perRotation], rotations[p / perRotation], offsetOf(p));
        cubes[p] = pl.cubes;
        strutFrameBalls[p] = pl.strutFrameBalls;
        fidelity[p] = pl.fidelity;
    });
    context.throwIfCancelled();
    // Most cubes (with none: the most balls joined by struts), then the lowest boundary fidelity,
    // then the first in placement order: deterministic whatever the thread count.
    size_t best = 0;
    for (size_t p = 1; p < total; ++p) {
        const auto key = [&](size_t q) { return std::make_pair(cubes[q], strutFrameBalls[q]); };
        if (key(p) > key(best) || (key(p) == key(best) && fidelity[p] < fidelity[best])) best = p;
    }
    if (cubes[best] == 0 && strutFrameBalls[best] == 0) {
        const double deepest = deepestDepthMm(field);
        const double need = ballDepthLimitMm(options.zone, options.scale);
        // The lattice points of the placements tried lie within half an offset step's diagonal of
        // any point, so a ball lands deep enough when the deepest point is that much deeper still;
        // every placement failed, and the deepest point says by how much the object falls short.
        const double stepDiagonal = offsetStepDiagonalMm(options);
        const double wanted = need + stepDiagonal;
        std::string hint;
        if (deepest > 0 && deepest < wanted)
            hint = "; the object scaled up " + formatNumbers("%.2f", wanted / deepest) +
                   " times (--height-mm) holds one for sure, or use a smaller --frame-clearance-mm";
        throw Error(ErrorCode::ProcessingFailed,
                    "object too thin for a Zome frame: none of the " + std::to_string(total) +
                        " placements tried has a ball at least " + formatNumbers("%.1f", need) +
                        " mm inside the surface (dMin + ball radius); the deepest point is " +
                        formatNumbers("%.1f", deepest) + " mm inside, and a ball there needs " +
                        formatNumbers("%.1f", wanted) + " mm (" + formatNumbers("%.1f", need) +
                        " + the lattice's offset step " + formatNumbers("%.1f", stepDiagonal) + ")" + hint);
    }

    const FrameField& ff = fields[best / perRotation];
    const Placement pl = evaluate(ff, rotations[best / perRotation], offsetOf(best));

    // Union-find over lattice points for the connected parts.
    const size_t count = pl.isCube.size();
    const std::vector<uint8_t>& isBall = pl.isBall;
    const std::vector<uint8_t>& edge = pl.edge;
    std::vector<size_t> parent(count);
    std::iota(parent.begin(), parent.end(), size_t(0));
    auto find = [&](size_t x) {
        while (parent[x] != x) x = parent[x] = parent[parent[x]];
        return x;
    };
    auto step = [&](size_t id, int a) {
        const size_t s = size_t(pl.n[2]);
        return a == 0 ? id + size_t(pl.n[1]) * s : a == 1 ? id + s : id + 1;
    };
    for (size_t id = 0; id < count; ++id)
        for (int a = 0; a < 3; ++a)
            if (edge[3 * id + size_t(a)]) {
                const size_t x = find(id), y = find(step(id, a));
                if (x != y) parent[std::max(x, y)] = std::min(x, y);
            }
    std::vector<size_t> size(count, 0);
    for (size_t id = 0; id < count; ++id)
        if (isBall[id]) ++size[find(id)];
    size_t keep = 0;
    for (size_t id = 0; id < count; ++id)
        if (size[id] > size[keep]) keep = id;  // first largest: deterministic

    zome::ZomeScale scale = options.scale;
    scale.originMm = pl.offsetMm;
    LatticeResult result{zome::Structure(scale, options.collision)};
    result.rotationDeg = pl.rotationDeg;
    result.offsetMm = pl.offsetMm;
    result.cubes = pl.cubes;
    result.placementsTried = total;
    result.firstPlacementCubes = cubes[0];
    zome::Structure& s = result.structure;
    const zome::Golden b0Units(2, 2);  // B0 = 2φ² = 2 + 2φ vZome units
    std::vector<zome::BallId> ballId(count, zome::kNoId);
    for (int i = pl.lo[0]; i < pl.lo[0] + pl.n[0]; ++i)
        for (int j = pl.lo[1]; j < pl.lo[1] + pl.n[1]; ++j)
            for (int k = pl.lo[2]; k < pl.lo[2] + pl.n[2]; ++k) {
                const size_t id = pl.index(i, j, k);
                if (isBall[id] && find(id) == keep)
                    ballId[id] = s.addBall(
                        {b0Units * zome::Golden(i), b0Units * zome::Golden(j), b0Units * zome::Golden(k)});
            }
    for (size_t id = 0; id < count; ++id)
        for (int a = 0; a < 3; ++a)
            if (edge[3 * id + size_t(a)] && ballId[id] != zome::kNoId)
                s.addStrut(ballId[id], ballId[step(id, a)]);
    for (int i = pl.lo[0]; i + 1 < pl.lo[0] + pl.n[0]; ++i)
        for (int j = pl.lo[1]; j + 1 < pl.lo[1] + pl.n[1]; ++j)
            for (int k = pl.lo[2]; k + 1 < pl.lo[2] + pl.n[2]; ++k)
                if (pl.isCube[pl.index(i, j, k)] && find(pl.index(i, j, k)) == keep) ++result.keptCubes;
    context.progress("lattice", 1.0);
    return result;
}

}  // namespace zomefab::frame
