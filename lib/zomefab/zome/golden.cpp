// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/golden.h"

#include <algorithm>
#include <cstdlib>
#include <limits>

#include "zomefab/core/error.h"

namespace zomefab::zome {

namespace detail {
void throwGoldenOverflow() {
    throw Error(ErrorCode::ProcessingFailed,
                "golden integer overflow: a coordinate a+b*phi left the 64-bit range");
}
}  // namespace detail

namespace {

// __extension__ keeps -Wpedantic quiet about the GCC/Clang 128-bit integer types.
__extension__ typedef unsigned __int128 u128;
__extension__ typedef __int128 i128;

uint64_t magnitude(int64_t x) { return x < 0 ? uint64_t(0) - uint64_t(x) : uint64_t(x); }

/// Sign of p − q·φ for p, q > 0 given as magnitudes. p − qφ > 0 ⟺ p > qφ. If p ≤ q the value is
/// negative (φ > 1). Otherwise p > q and, both sides being positive, p > qφ ⟺ p² − pq − q² > 0
/// (the norm; φ is the positive root of t² − t − 1), i.e. p(p − q) > q². Both products are below
/// 2^128, so unsigned 128-bit arithmetic decides it exactly. Equality is impossible: φ is irrational.
int signOfDifference(uint64_t p, uint64_t q) {
    if (p <= q) return -1;
    const u128 lhs = u128(p) * u128(p - q);
    const u128 rhs = u128(q) * u128(q);
    return lhs > rhs ? 1 : -1;
}

}  // namespace

int Golden::sign() const {
    const int sa = (a > 0) - (a < 0);
    const int sb = (b > 0) - (b < 0);
    if (sa == 0) return sb;
    if (sb == 0 || sa == sb) return sa;
    // Opposite signs: a + bφ = sa·(|a| − |b|φ).
    return sa * signOfDifference(magnitude(a), magnitude(b));
}

int64_t Golden::norm() const {
    const i128 n = i128(a) * a + i128(a) * b - i128(b) * b;
    if (n > std::numeric_limits<int64_t>::max() || n < std::numeric_limits<int64_t>::min())
        detail::throwGoldenOverflow();
    return int64_t(n);
}

Golden Golden::phiPower(int n) {
    Golden x{1, 0};
    for (int i = 0; i < n; ++i) x = x.timesPhi();
    for (int i = 0; i > n; --i) x = x.dividedByPhi();
    return x;
}

std::optional<Golden> Golden::dividedExactlyBy(const Golden& y) const {
    if (y.isZero()) return std::nullopt;
    // x / y = x·conj(y) / N(y), and N(y) is a non-zero integer.
    const int64_t n = y.norm();
    const Golden num = *this * y.conjugate();
    if (num.a % n != 0 || num.b % n != 0) return std::nullopt;
    return Golden{num.a / n, num.b / n};
}

std::optional<Golden> Golden::inverse() const { return Golden{1, 0}.dividedExactlyBy(*this); }

std::string Golden::toString() const {
    if (b == 0) return std::to_string(a);
    std::string s = a == 0 ? std::string() : std::to_string(a) + (b > 0 ? "+" : "");
    return s + std::to_string(b) + "phi";
}

int64_t GoldenVector3::maxAbsCoefficient() const {
    uint64_t m = 0;
    for (const Golden& g : c) {
        m = std::max(m, magnitude(g.a));
        m = std::max(m, magnitude(g.b));
    }
    return m > uint64_t(std::numeric_limits<int64_t>::max()) ? std::numeric_limits<int64_t>::max()
                                                             : int64_t(m);
}

std::string GoldenVector3::toString() const {
    return "(" + c[0].toString() + ", " + c[1].toString() + ", " + c[2].toString() + ")";
}

Golden dot(const GoldenVector3& x, const GoldenVector3& y) { return x[0] * y[0] + x[1] * y[1] + x[2] * y[2]; }

GoldenVector3 cross(const GoldenVector3& x, const GoldenVector3& y) {
    return {x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]};
}

bool areParallel(const GoldenVector3& x, const GoldenVector3& y) { return cross(x, y).isZero(); }

size_t GoldenVector3Hash::operator()(const GoldenVector3& v) const {
    // splitmix64-style mixing of the six coefficients: cheap and well spread for lattice points.
    uint64_t h = 0x9E3779B97F4A7C15ull;
    for (const Golden& g : v.c) {
        for (int64_t x : {g.a, g.b}) {
            h ^= uint64_t(x) + 0x9E3779B97F4A7C15ull + (h << 6) + (h >> 2);
            h *= 0xBF58476D1CE4E5B9ull;
            h ^= h >> 31;
        }
    }
    return size_t(h);
}

}  // namespace zomefab::zome
