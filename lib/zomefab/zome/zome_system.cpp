// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/zome/zome_system.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/vec.h"

namespace zomefab::zome {

namespace {

/// Size-0 strut vector of each of the 31 axes in vZome units, as (a, b) pairs meaning a + bφ per
/// coordinate: rows 1..31 of ../shared/docs/zome-geometry.md §2. B0 = 2φ² = 2+2φ; Y0 = φ²√3;
/// R0 = φ²√(2+φ). The tests re-derive lengths, angles and the symmetry of this table.
constexpr int64_t kAxisTable[kAxisCount][3][2] = {
    // blue (2-fold axes)
    {{2, 2}, {0, 0}, {0, 0}},
    {{0, 0}, {2, 2}, {0, 0}},
    {{0, 0}, {0, 0}, {2, 2}},
    {{1, 1}, {1, 2}, {0, 1}},
    {{1, 1}, {1, 2}, {0, -1}},
    {{1, 1}, {-1, -2}, {0, 1}},
    {{1, 1}, {-1, -2}, {0, -1}},
    {{1, 2}, {0, 1}, {1, 1}},
    {{1, 2}, {0, 1}, {-1, -1}},
    {{1, 2}, {0, -1}, {1, 1}},
    {{1, 2}, {0, -1}, {-1, -1}},
    {{0, 1}, {1, 1}, {1, 2}},
    {{0, 1}, {1, 1}, {-1, -2}},
    {{0, 1}, {-1, -1}, {1, 2}},
    {{0, 1}, {-1, -1}, {-1, -2}},
    // yellow (3-fold axes)
    {{1, 1}, {1, 1}, {1, 1}},
    {{1, 1}, {1, 1}, {-1, -1}},
    {{1, 1}, {-1, -1}, {1, 1}},
    {{-1, -1}, {1, 1}, {1, 1}},
    {{1, 2}, {0, 0}, {0, 1}},
    {{1, 2}, {0, 0}, {0, -1}},
    {{0, 0}, {0, 1}, {1, 2}},
    {{0, 0}, {0, 1}, {-1, -2}},
    {{0, 1}, {1, 2}, {0, 0}},
    {{0, 1}, {-1, -2}, {0, 0}},
    // red (5-fold axes)
    {{1, 2}, {1, 1}, {0, 0}},
    {{1, 2}, {-1, -1}, {0, 0}},
    {{0, 0}, {1, 2}, {1, 1}},
    {{0, 0}, {1, 2}, {-1, -1}},
    {{1, 1}, {0, 0}, {1, 2}},
    {{1, 1}, {0, 0}, {-1, -2}},
};

/// Axis ranges per colour in the table above, and the first hole of each colour.
constexpr int kFirstAxis[kColorCount] = {0, 15, 25};
constexpr int kAxesOf[kColorCount] = {15, 10, 6};
constexpr int kFirstHole[kColorCount] = {0, 30, 50};

/// Exact catalogue lookup: the 186 strut vectors in an open-addressing table keyed by the exact
/// coefficients. Built once together with the tables.
struct Catalogue {
    static constexpr size_t kSlots = 512;  // power of two, load 0.36
    struct Slot {
        GoldenVector3 key;
        int8_t hole = -1;
        int8_t size = -1;
    };
    std::array<Slot, kSlots> slots{};
    int64_t maxCoefficient = 0;  ///< no catalogue vector has a larger |a| or |b|

    void insert(const GoldenVector3& v, int hole, int size) {
        size_t i = GoldenVector3Hash{}(v) & (kSlots - 1);
        while (slots[i].hole >= 0) i = (i + 1) & (kSlots - 1);
        slots[i] = {v, int8_t(hole), int8_t(size)};
        maxCoefficient = std::max(maxCoefficient, v.maxAbsCoefficient());
    }
    const Slot* find(const GoldenVector3& v) const {
        size_t i = GoldenVector3Hash{}(v) & (kSlots - 1);
        while (slots[i].hole >= 0) {
            if (slots[i].key == v) return &slots[i];
            i = (i + 1) & (kSlots - 1);
        }
        return nullptr;
    }
};

struct Built {
    ZomeTables tables;
    Catalogue catalogue;
};

Built build() {
    Built built;
    ZomeTables& t = built.tables;
    for (int color = 0; color < kColorCount; ++color) {
        for (int k = 0; k < kAxesOf[color]; ++k) {
            const int axis = kFirstAxis[color] + k;
            GoldenVector3 v0;
            for (int i = 0; i < 3; ++i) v0[i] = Golden{kAxisTable[axis][i][0], kAxisTable[axis][i][1]};
            const int plus = kFirstHole[color] + k;
            const int minus = plus + kAxesOf[color];
            for (int sign : {1, -1}) {
                HoleInfo& h = t.holes[size_t(sign > 0 ? plus : minus)];
                h.axis = axis;
                h.sign = sign;
                h.color = Color(color);
                h.opposite = sign > 0 ? minus : plus;
                GoldenVector3 v = sign > 0 ? v0 : -v0;
                for (int size = 0; size < kSizeCount; ++size) {
                    h.vector[size_t(size)] = v;
                    h.vectorUnits[size_t(size)] = v.toDouble();
                    v = Golden::phi() * v;  // size n+1 = φ × size n
                }
                const Vec3d d = h.vectorUnits[0];
                const double len = norm(d);
                h.direction = {d[0] / len, d[1] / len, d[2] / len};
                for (int size = 0; size < kSizeCount; ++size)
                    t.lengthUnits[size_t(color)][size_t(size)] = norm(h.vectorUnits[size_t(size)]);
            }
        }
    }
    for (int i = 0; i < kHoleCount; ++i) {
        for (int j = 0; j < kHoleCount; ++j) {
            const Vec3d& a = t.holes[size_t(i)].direction;
            const Vec3d& b = t.holes[size_t(j)].direction;
            t.cosine[size_t(i)][size_t(j)] = a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        }
    }
    for (int hole = 0; hole < kHoleCount; ++hole) {
        HoleInfo& h = t.holes[size_t(hole)];
        const Color target = h.color == Color::Red ? Color::Yellow : Color::Red;
        double best = -2.0;
        Vec3d u{};
        for (int other = kFirstHole[int(target)]; other < kFirstHole[int(target)] + 2 * kAxesOf[int(target)];
             ++other) {
            const double c = t.cosine[size_t(hole)][size_t(other)];
            if (c > best + 1e-9) {  // ties (symmetric neighbours): the lowest hole number
                best = c;
                const Vec3d& e = t.holes[size_t(other)].direction;
                u = {e[0] - c * h.direction[0], e[1] - c * h.direction[1], e[2] - c * h.direction[2]};
            }
        }
        const double len = norm(u);
        h.sectionAxis = {u[0] / len, u[1] / len, u[2] / len};
    }
    for (int hole = 0; hole < kHoleCount; ++hole)
        for (int size = 0; size < kSizeCount; ++size)
            built.catalogue.insert(t.holes[size_t(hole)].vector[size_t(size)], hole, size);
    return built;
}

const Built& built() {
    static const Built instance = build();
    return instance;
}

}  // namespace

const ZomeTables& zomeTables() { return built().tables; }

const char* colorName(Color color) {
    switch (color) {
        case Color::Blue:
            return "blue";
        case Color::Yellow:
            return "yellow";
        case Color::Red:
            return "red";
    }
    return "?";
}

std::optional<Color> colorFromName(std::string_view name) {
    if (name == "blue") return Color::Blue;
    if (name == "yellow") return Color::Yellow;
    if (name == "red") return Color::Red;
    return std::nullopt;
}

std::string partName(Color color, int size) {
    static const char kLetters[kColorCount] = {'B', 'Y', 'R'};
    return std::string(1, kLetters[int(color)]) + std::to_string(size);
}

std::pair<int, int> holeRange(Color color) {
    const int c = int(color);
    return {kFirstHole[c], kFirstHole[c] + 2 * kAxesOf[c]};
}

std::optional<StrutMatch> matchStrut(const GoldenVector3& v) {
    const Built& b = built();
    // Cheap exact pre-test: every catalogue vector has small coefficients.
    for (const Golden& g : v.c) {
        if (g.a > b.catalogue.maxCoefficient || g.a < -b.catalogue.maxCoefficient ||
            g.b > b.catalogue.maxCoefficient || g.b < -b.catalogue.maxCoefficient)
            return std::nullopt;
    }
    const Catalogue::Slot* slot = b.catalogue.find(v);
    if (!slot) return std::nullopt;
    return StrutMatch{slot->hole, b.tables.holes[size_t(slot->hole)].color, slot->size};
}

std::optional<int> parallelHole(const GoldenVector3& v) {
    if (v.isZero()) return std::nullopt;
    const ZomeTables& t = zomeTables();
    for (int hole = 0; hole < kHoleCount; ++hole) {
        const GoldenVector3& axis = t.holes[size_t(hole)].vector[0];
        if (areParallel(v, axis) && dot(v, axis).sign() > 0) return hole;
    }
    return std::nullopt;
}

double ZomeScale::unitMm() const {
    // B0 = 2φ² vZome units (docs/zome.md §2), so one unit is b0Mm / (2φ²).
    return b0Mm / (2.0 * kPhi * kPhi);
}

double ZomeScale::strutRadiusMm(Color color) const {
    switch (color) {
        case Color::Blue:
            return blueRadiusMm;
        case Color::Yellow:
            return yellowRadiusMm;
        case Color::Red:
            return redRadiusMm;
    }
    return blueRadiusMm;
}

double ZomeScale::strutLengthMm(Color color, int size) const {
    return zomeTables().lengthUnits[size_t(color)][size_t(size)] * unitMm();
}

Vec3d ZomeScale::toMm(const GoldenVector3& p) const {
    const double u = unitMm();
    return {p[0].toDouble() * u + originMm[0], p[1].toDouble() * u + originMm[1],
            p[2].toDouble() * u + originMm[2]};
}

void ZomeScale::validate() const {
    auto positive = [](double x, const char* name) {
        if (!(std::isfinite(x) && x > 0.0))
            throw Error(ErrorCode::Usage, std::string(name) + " must be a positive number of mm");
    };
    auto nonNegative = [](double x, const char* name) {
        if (!(std::isfinite(x) && x >= 0.0))
            throw Error(ErrorCode::Usage, std::string(name) + " must be a non-negative number of mm");
    };
    positive(b0Mm, "b0Mm");
    positive(ballDiameterMm, "ballDiameterMm");
    nonNegative(blueRadiusMm, "blueRadiusMm");
    nonNegative(yellowRadiusMm, "yellowRadiusMm");
    nonNegative(redRadiusMm, "redRadiusMm");
    for (double o : originMm)
        if (!std::isfinite(o)) throw Error(ErrorCode::Usage, "originMm must be finite");
}

}  // namespace zomefab::zome
