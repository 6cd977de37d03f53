// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Internal: a dense uniform grid over a box in millimetres for Structure's collision
/// queries. Each cell holds, inline, the collision proxy of every element passing through it (a
/// ball's centre, a strut's capsule axis), so a query reads contiguous memory and never follows a
/// pointer. Elements are stored in the cells their segment passes through; a query with reach R
/// visits the cells containing points within R of its own segment (slab clipping per cell row),
/// which finds every stored element closer than R, whatever the cell size.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::zome::detail {

/// A collision proxy as stored in the grid: a segment (a ball is a zero-length one) plus what the
/// exemption rules need. 64 bytes, one cache line.
struct GridEntry {
    Vec3d p0{};         ///< ball centre, or capsule axis start (mm)
    Vec3d p1{};         ///< ball centre, or capsule axis end (mm)
    uint32_t key = 0;   ///< ball id, or strut id | Structure::kStrutKeyBit
    uint32_t a = 0;     ///< strut: start ball; ball: its own id
    uint32_t b = 0;     ///< strut: end ball; ball: its own id
    uint8_t holeA = 0;  ///< strut: hole at a
    uint8_t holeB = 0;  ///< strut: hole at b
    uint8_t color = 0;  ///< strut colour (Color)
    uint8_t isStrut = 0;
};

class SpatialGrid {
public:
    /// Tolerance added when storing, so a segment grazing a cell boundary is listed on both sides.
    static constexpr double kStoreSlackMm = 1e-6;

    bool isEmpty() const { return mCells.empty(); }
    double cellMm() const { return mCellMm; }
    size_t cellCount() const { return mCells.size(); }
    /// Entries over all cells (an element is listed once per cell it passes through).
    size_t entryCount() const {
        size_t n = 0;
        for (const auto& c : mCells) n += c.size();
        return n;
    }

    /// Drops all entries and covers [@p lo, @p hi] with cells of @p cellMm.
    void reset(const Vec3d& lo, const Vec3d& hi, double cellMm) {
        mCellMm = cellMm;
        mInvCell = 1.0 / cellMm;
        mMin = lo;
        for (int i = 0; i < 3; ++i) {
            mN[i] = std::max(1, int(std::ceil((hi[i] - lo[i]) * mInvCell)) + 1);
            mMax[i] = mMin[i] + mN[i] * mCellMm;
        }
        mCells.clear();
        mCells.resize(size_t(mN[0]) * size_t(mN[1]) * size_t(mN[2]));
        mOccupied.assign((mCells.size() + 63) / 64, 0);
    }

    /// True when the segment [@p p0, @p p1] lies inside the grid with a margin of one cell.
    bool covers(const Vec3d& p0, const Vec3d& p1) const {
        if (mCells.empty()) return false;
        for (int i = 0; i < 3; ++i) {
            const double lo = std::min(p0[i], p1[i]), hi = std::max(p0[i], p1[i]);
            if (lo < mMin[i] + mCellMm || hi > mMax[i] - mCellMm) return false;
        }
        return true;
    }

    void insert(const GridEntry& e) {
        forEachCell<true>(e.p0, e.p1, kStoreSlackMm, [&](size_t index) {
            mCells[index].push_back(e);
            mOccupied[index >> 6] |= uint64_t(1) << (index & 63);
            return false;
        });
    }

    void remove(const GridEntry& e) {
        forEachCell<true>(e.p0, e.p1, kStoreSlackMm, [&](size_t index) {
            std::vector<GridEntry>& cell = mCells[index];
            for (size_t i = 0; i < cell.size(); ++i)
                if (cell[i].key == e.key) {
                    cell[i] = cell.back();
                    cell.pop_back();
                    break;
                }
            if (cell.empty()) mOccupied[index >> 6] &= ~(uint64_t(1) << (index & 63));
            return false;
        });
    }

    /// Calls @p visit(entry) for the entries of every cell holding a point within @p reachMm of
    /// the segment [@p p0, @p p1] (an entry listed in several cells is met once per cell) until it
    /// returns true; returns whether it did.
    template <class Visit>
    bool anyNear(const Vec3d& p0, const Vec3d& p1, double reachMm, Visit&& visit) const {
        return forEachCell<false>(p0, p1, reachMm, [&](size_t index) {
            for (const GridEntry& e : mCells[index])
                if (visit(e)) return true;
            return false;
        });
    }

private:
    /// Narrows [t0, t1] to the parameters t of p + t·d (1/d = @p invD) whose coordinate lies in
    /// [lo, hi]; false when that leaves nothing.
    static bool clip(double p, double d, double invD, double lo, double hi, double& t0, double& t1) {
        if (std::abs(d) < 1e-12) return p >= lo && p <= hi;
        double a = (lo - p) * invD, b = (hi - p) * invD;
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        return t0 <= t1;
    }

    int cellOf(double v, int axis) const {
        // Clamped floor without calling floor() (a library call on baseline x86-64).
        const double c = (v - mMin[axis]) * mInvCell;
        if (!(c > 0.0)) return 0;  // also NaN
        if (c >= double(mN[axis])) return mN[axis] - 1;
        return int(c);
    }

    /// Visits the cells containing a point within @p r of the segment: for each z slab and y row
    /// of cells (widened by r), the part of the segment inside both gives the x range (widened by r).
    /// Calls @p f(cell index) until it returns true; skips empty cells unless @p kAllCells (an
    /// occupancy bitmap of 1 bit per cell answers that without touching the cell).
    template <bool kAllCells, class F>
    bool forEachCell(const Vec3d& p0, const Vec3d& p1, double r, F&& f) const {
        if (mCells.empty()) return false;
        for (int i = 0; i < 3; ++i)
            if (std::max(p0[i], p1[i]) + r < mMin[i] || std::min(p0[i], p1[i]) - r > mMax[i]) return false;
        const Vec3d d{p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
        const double invDy = 1.0 / d[1], invDz = 1.0 / d[2];  // unused (inf) when d is ~0
        const int z0 = cellOf(std::min(p0[2], p1[2]) - r, 2), z1 = cellOf(std::max(p0[2], p1[2]) + r, 2);
        const int y0 = cellOf(std::min(p0[1], p1[1]) - r, 1), y1 = cellOf(std::max(p0[1], p1[1]) + r, 1);
        for (int z = z0; z <= z1; ++z) {
            double tz0 = 0.0, tz1 = 1.0;
            const double zlo = mMin[2] + z * mCellMm - r;
            if (!clip(p0[2], d[2], invDz, zlo, zlo + mCellMm + 2.0 * r, tz0, tz1)) continue;
            for (int y = y0; y <= y1; ++y) {
                double t0 = tz0, t1 = tz1;
                const double ylo = mMin[1] + y * mCellMm - r;
                if (!clip(p0[1], d[1], invDy, ylo, ylo + mCellMm + 2.0 * r, t0, t1)) continue;
                const double xa = p0[0] + t0 * d[0], xb = p0[0] + t1 * d[0];
                const int x0 = cellOf(std::min(xa, xb) - r, 0), x1 = cellOf(std::max(xa, xb) + r, 0);
                const size_t row = (size_t(z) * size_t(mN[1]) + size_t(y)) * size_t(mN[0]);
                for (int x = x0; x <= x1; ++x) {
                    const size_t index = row + size_t(x);
                    if (!kAllCells && !(mOccupied[index >> 6] >> (index & 63) & 1)) continue;
                    if (f(index)) return true;
                }
            }
        }
        return false;
    }

    Vec3d mMin{0.0, 0.0, 0.0};
    Vec3d mMax{0.0, 0.0, 0.0};
    double mCellMm = 1.0;
    double mInvCell = 1.0;
    int mN[3] = {0, 0, 0};
    std::vector<std::vector<GridEntry>> mCells;
    std::vector<uint64_t> mOccupied;  ///< bit i: cell i is not empty
};

}  // namespace zomefab::zome::detail
