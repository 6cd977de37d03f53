// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The Zometool system: 3 strut colours, 31 axes, 62 ball holes, strut sizes 0..2, the exact
/// strut vectors, the exact strut matcher and the physical scale in millimetres (docs/zome.md).
///
/// Hole numbering (used in frame files as `hole_a`, `hole_b`): holes are grouped by colour, and
/// within a colour the positive ends of the axes come first, then the negative ends:
///   blue   0..14 = +axis 0..14,   15..29 = −axis 0..14   (opposite hole = h ± 15)
///   yellow 30..39 = +axis 15..24, 40..49 = −axis 15..24  (opposite hole = h ± 10)
///   red    50..55 = +axis 25..30, 56..61 = −axis 25..30  (opposite hole = h ± 6)
/// Axis k is row k+1 of the table in ../shared/docs/zome-geometry.md §2 (vZome's orientation).
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/zome/golden.h"

namespace zomefab::zome {

/// Strut colour = the axis family: blue (2-fold axes, rectangular holes), yellow (3-fold,
/// triangular), red (5-fold, pentagonal).
enum class Color : uint8_t { Blue = 0, Yellow = 1, Red = 2 };

inline constexpr int kColorCount = 3;
inline constexpr int kAxisCount = 31;
inline constexpr int kHoleCount = 62;
/// Strut sizes 0, 1, 2 (B0 B1 B2, Y0..Y2, R0..R2); size n is φⁿ × size 0. R00 is not modelled.
inline constexpr int kSizeCount = 3;
/// b0 of vZome's nominal geometry: 2φ² units × 8.8365 mm (docs/zome.md §3).
inline constexpr double kVzomeNominalB0Mm = 46.27;

/// "blue", "yellow", "red" (the frame-file spelling).
const char* colorName(Color color);
/// Inverse of colorName(); nullopt for anything else.
std::optional<Color> colorFromName(std::string_view name);
/// Zometool part name: "B0", "Y2", "R1".
std::string partName(Color color, int size);
/// First hole and one past the last hole of @p color: blue [0,30), yellow [30,50), red [50,62).
std::pair<int, int> holeRange(Color color);

/// One hole of the ball: the axis it lies on, which end, and what a strut plugged into it is.
struct HoleInfo {
    int axis = 0;  ///< 0..30
    int sign = 1;  ///< +1 for the axis direction of the table, −1 for the opposite end
    Color color = Color::Blue;
    int opposite = 0;  ///< the hole on the other end of the same axis
    /// Exact vector from this ball's centre to the next ball's centre for a size-n strut in this
    /// hole, in vZome units (B0 along +x is (2+2φ, 0, 0)).
    std::array<GoldenVector3, kSizeCount> vector{};
    std::array<Vec3d, kSizeCount> vectorUnits{};  ///< the same in double precision
    Vec3d direction{};                            ///< unit direction (double)
    /// Unit vector normal to `direction` that orients the hole's section (the face of the ball, a
    /// small rhombicosidodecahedron: vertex figure triangle–rectangle–pentagon–rectangle): blue, the
    /// golden rectangle's long side, towards the two nearest red axes; yellow, a triangle corner,
    /// towards the nearest red axis; red, a pentagon corner, towards the nearest yellow axis. On +z
    /// the blue rectangle's long side is x (zome-geometry.md §2). Of two symmetric nearest axes the
    /// lower hole number is taken; for a blue rectangle both give the same line.
    Vec3d sectionAxis{};
};

/// All precomputed tables; built once, thread-safe, never changes. Hot loops keep a reference.
struct ZomeTables {
    std::array<HoleInfo, kHoleCount> holes{};
    /// cos of the angle between the directions of holes i and j (regularity energy, paper Eq. 3).
    std::array<std::array<double, kHoleCount>, kHoleCount> cosine{};
    /// Centre-to-centre length in vZome units by [colour][size].
    std::array<std::array<double, kSizeCount>, kColorCount> lengthUnits{};
};

/// The tables (built on first use).
const ZomeTables& zomeTables();

inline const HoleInfo& holeInfo(int hole) { return zomeTables().holes[size_t(hole)]; }
inline Color holeColor(int hole) { return holeInfo(hole).color; }
inline int oppositeHole(int hole) { return holeInfo(hole).opposite; }
/// Exact size-@p size strut vector leaving a ball through @p hole.
inline const GoldenVector3& strutVector(int hole, int size) { return holeInfo(hole).vector[size_t(size)]; }
inline const Vec3d& holeDirection(int hole) { return holeInfo(hole).direction; }
inline const Vec3d& holeSectionAxis(int hole) { return holeInfo(hole).sectionAxis; }
inline double holeCosine(int holeA, int holeB) { return zomeTables().cosine[size_t(holeA)][size_t(holeB)]; }

/// A catalogue strut: the hole it leaves the start ball from, its colour and size. The end ball
/// uses oppositeHole(hole).
struct StrutMatch {
    int hole = 0;
    Color color = Color::Blue;
    int size = 0;
    friend bool operator==(const StrutMatch& x, const StrutMatch& y) {
        return x.hole == y.hole && x.color == y.color && x.size == y.size;
    }
};

/// The catalogue strut whose exact vector is @p v, or nullopt. Exact: @p v matches iff it is
/// parallel to a hole axis (cross product zero) and its length is that colour's size-0, -1 or -2
/// length, which for Z[φ] vectors is the same as being equal to one of the 186 table vectors;
/// the test is a hash lookup of the exact coefficients (no tolerance).
std::optional<StrutMatch> matchStrut(const GoldenVector3& v);

/// The hole whose axis is exactly parallel to @p v in the same sense, whatever the length, or
/// nullopt (also for v = 0). Uses exact cross products; for diagnostics and tests, not hot loops.
std::optional<int> parallelHole(const GoldenVector3& v);

/// Physical sizes of the kit, all in millimetres. Defaults: the paper's measured b0 and ZomeFab's
/// ball diameter; capsule radii of the strut cross-sections from vZome's part models, rounded up
/// (docs/zome.md §3 lists sources).
struct ZomeScale {
    double b0Mm = Fabrication{}.b0Mm;  ///< B0 centre-to-centre (paper §4.2: b0 = 47.3; vZome nominal 46.27)
    double ballDiameterMm = 17.7;      ///< ball width across the blue holes (ZomeFab NODE_DIAMETER)
    double blueRadiusMm = 3.3;         ///< blue capsule radius (5.46 × 3.38 mm rectangle, circumradius 3.21)
    double yellowRadiusMm = 3.2;       ///< yellow capsule radius (lifelike model max radius 3.15)
    double redRadiusMm = 2.9;          ///< red capsule radius (lifelike model max radius 2.87)
    Vec3d originMm{0.0, 0.0, 0.0};     ///< millimetre position of the exact origin (0,0,0)

    /// One vZome unit in mm: b0Mm / (2φ²) (B0 is 2φ² units); 9.0335 mm by default.
    double unitMm() const;
    double ballRadiusMm() const { return 0.5 * ballDiameterMm; }
    double strutRadiusMm(Color color) const;
    /// Centre-to-centre length of a strut in mm.
    double strutLengthMm(Color color, int size) const;
    /// Exact point to millimetres: p·unitMm + originMm.
    Vec3d toMm(const GoldenVector3& p) const;
    /// @throw Error(Usage) when a size is not positive and finite (radii may be 0).
    void validate() const;
};

}  // namespace zomefab::zome
