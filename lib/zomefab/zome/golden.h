// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Exact golden integers a + b·φ (φ = (1+√5)/2) and vectors of three, the coordinates of every
/// Zometool ball. All arithmetic is exact on int64 with overflow checks; the sign test never uses
/// floating point (docs/zome.md §1).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::zome {

/// φ = (1 + √5) / 2 in double precision, for conversions only.
inline constexpr double kPhi = 1.6180339887498948482;

namespace detail {
/// Throws Error(ProcessingFailed) "golden integer overflow" (out of line: keeps the hot paths small).
[[noreturn]] void throwGoldenOverflow();
inline int64_t addChecked(int64_t x, int64_t y) {
    int64_t r;
    if (__builtin_add_overflow(x, y, &r)) throwGoldenOverflow();
    return r;
}
inline int64_t subChecked(int64_t x, int64_t y) {
    int64_t r;
    if (__builtin_sub_overflow(x, y, &r)) throwGoldenOverflow();
    return r;
}
inline int64_t mulChecked(int64_t x, int64_t y) {
    int64_t r;
    if (__builtin_mul_overflow(x, y, &r)) throwGoldenOverflow();
    return r;
}
}  // namespace detail

/// The number a + b·φ with integer a, b: the ring Z[φ]. Every ball position of a frame built from
/// catalogue struts lies in Z[φ]³ when the unit is half a ball width (vZome's unit, docs/zome.md).
/// Operations throw Error(ProcessingFailed) instead of wrapping around when a coefficient leaves
/// int64; equality is exact.
struct Golden {
    int64_t a = 0;  ///< rational part
    int64_t b = 0;  ///< coefficient of φ

    constexpr Golden() = default;
    constexpr Golden(int64_t ones, int64_t phis = 0) : a(ones), b(phis) {}  // NOLINT: implicit from int

    static constexpr Golden phi() { return {0, 1}; }
    /// φⁿ for any integer n (φ⁻¹ = φ − 1), exact.
    static Golden phiPower(int n);

    bool isZero() const { return a == 0 && b == 0; }
    /// Exact sign of a + bφ: −1, 0 or +1, decided with integer arithmetic only.
    int sign() const;
    /// Nearest double (inexact for large cancelling coefficients; use sign() for decisions).
    double toDouble() const { return double(a) + double(b) * kPhi; }

    /// Galois conjugate a + bφ' with φ' = 1 − φ = −1/φ, written in the basis (1, φ): (a+b) − bφ.
    Golden conjugate() const { return {detail::addChecked(a, b), detail::subChecked(0, b)}; }
    /// Field norm x·conj(x) = a² + ab − b², an integer; zero only for x = 0.
    int64_t norm() const;
    /// x·φ = b + (a+b)φ (exact; φ is a unit of Z[φ]).
    Golden timesPhi() const { return {b, detail::addChecked(a, b)}; }
    /// x/φ = x·(φ−1) = (b−a) + aφ.
    Golden dividedByPhi() const { return {detail::subChecked(b, a), a}; }
    /// 1/x when it lies in Z[φ] (exactly when norm is ±1, i.e. x = ±φⁿ), otherwise nullopt.
    std::optional<Golden> inverse() const;
    /// x / y when the quotient lies in Z[φ], otherwise nullopt (also for y = 0).
    std::optional<Golden> dividedExactlyBy(const Golden& y) const;

    /// "a+bφ" in plain ASCII: "2+2phi", "-1", "0+3phi".
    std::string toString() const;

    friend bool operator==(const Golden& x, const Golden& y) { return x.a == y.a && x.b == y.b; }
    friend bool operator!=(const Golden& x, const Golden& y) { return !(x == y); }
    friend Golden operator+(const Golden& x, const Golden& y) {
        return {detail::addChecked(x.a, y.a), detail::addChecked(x.b, y.b)};
    }
    friend Golden operator-(const Golden& x, const Golden& y) {
        return {detail::subChecked(x.a, y.a), detail::subChecked(x.b, y.b)};
    }
    friend Golden operator-(const Golden& x) { return Golden{} - x; }
    /// (a+bφ)(c+dφ) = (ac+bd) + (ad+bc+bd)φ, using φ² = φ + 1.
    friend Golden operator*(const Golden& x, const Golden& y) {
        using namespace detail;
        const int64_t bd = mulChecked(x.b, y.b);
        return {addChecked(mulChecked(x.a, y.a), bd),
                addChecked(addChecked(mulChecked(x.a, y.b), mulChecked(x.b, y.a)), bd)};
    }
    Golden& operator+=(const Golden& y) { return *this = *this + y; }
    Golden& operator-=(const Golden& y) { return *this = *this - y; }
    Golden& operator*=(const Golden& y) { return *this = *this * y; }
    /// Exact order (x < y iff sign(y − x) > 0).
    friend bool operator<(const Golden& x, const Golden& y) { return (y - x).sign() > 0; }
    friend bool operator>(const Golden& x, const Golden& y) { return y < x; }
    friend bool operator<=(const Golden& x, const Golden& y) { return !(y < x); }
    friend bool operator>=(const Golden& x, const Golden& y) { return !(x < y); }
};

/// A point or vector with golden-integer coordinates, in vZome units (1 unit = half a ball width).
struct GoldenVector3 {
    std::array<Golden, 3> c{};

    constexpr GoldenVector3() = default;
    constexpr GoldenVector3(const Golden& x, const Golden& y, const Golden& z) : c{x, y, z} {}

    const Golden& operator[](int i) const { return c[size_t(i)]; }
    Golden& operator[](int i) { return c[size_t(i)]; }

    bool isZero() const { return c[0].isZero() && c[1].isZero() && c[2].isZero(); }
    /// The nearest double vector in the same units.
    Vec3d toDouble() const { return {c[0].toDouble(), c[1].toDouble(), c[2].toDouble()}; }
    /// Largest |a| or |b| over the six coefficients (cheap magnitude bound for range checks).
    int64_t maxAbsCoefficient() const;
    /// "(2+2phi, 0, -1+0phi)".
    std::string toString() const;

    friend bool operator==(const GoldenVector3& x, const GoldenVector3& y) { return x.c == y.c; }
    friend bool operator!=(const GoldenVector3& x, const GoldenVector3& y) { return !(x == y); }
    friend GoldenVector3 operator+(const GoldenVector3& x, const GoldenVector3& y) {
        return {x.c[0] + y.c[0], x.c[1] + y.c[1], x.c[2] + y.c[2]};
    }
    friend GoldenVector3 operator-(const GoldenVector3& x, const GoldenVector3& y) {
        return {x.c[0] - y.c[0], x.c[1] - y.c[1], x.c[2] - y.c[2]};
    }
    friend GoldenVector3 operator-(const GoldenVector3& x) { return GoldenVector3{} - x; }
    friend GoldenVector3 operator*(const Golden& s, const GoldenVector3& v) {
        return {s * v.c[0], s * v.c[1], s * v.c[2]};
    }
    GoldenVector3& operator+=(const GoldenVector3& y) { return *this = *this + y; }
    GoldenVector3& operator-=(const GoldenVector3& y) { return *this = *this - y; }
};

/// Exact dot product.
Golden dot(const GoldenVector3& x, const GoldenVector3& y);
/// Exact cross product; zero exactly when @p x and @p y are parallel (or one is zero).
GoldenVector3 cross(const GoldenVector3& x, const GoldenVector3& y);
/// True when @p x and @p y are exactly parallel (cross product zero), either sense.
bool areParallel(const GoldenVector3& x, const GoldenVector3& y);

/// Hash of the six coefficients (for exact-position maps).
struct GoldenVector3Hash {
    size_t operator()(const GoldenVector3& v) const;
};

}  // namespace zomefab::zome
