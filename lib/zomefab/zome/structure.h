// SPDX-License-Identifier: GPL-3.0-or-later
/// @file A Zometool structure: balls at exact positions with 62-slot hole occupancy, struts between
/// them, and the collision model of the assembled kit with a spatial hash (docs/zome.md).
///
/// Hot-loop use (one annealing move that inserts a ball M and a strut A→M, paper §4.4); the
/// tables of zome_system.h (strutVector, oppositeHole, holeCosine) are plain array lookups:
/// @code
///   const GoldenVector3& a = s.ball(idA).position;
///   const GoldenVector3 m = a + strutVector(hole, size);   // exact, overflow-checked
///   if (s.findBall(m) == kNoId && s.isHoleFree(idA, hole)  // hole availability
///       && !s.ballCollides(m)                              // queries never modify s
///       && !s.strutCollides(idA, hole, size)) {
///       const BallId idM = s.addBall(m);                   // O(1) amortised
///       const StrutId t = s.addStrut(idA, hole, size);     // ends at the ball found at a + vector
///       // ...energy change rejected? undo in reverse order:
///       s.removeStrut(t);
///       s.removeBall(idM);
///   }
/// @endcode
/// Query, then insert, one element at a time: each query sees the elements inserted before it.
/// Ids are deterministic: a new element takes the most recently freed id, else the next new one.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include "zomefab/core/tri_mesh.h"
#include "zomefab/zome/detail/position_index.h"
#include "zomefab/zome/detail/spatial_grid.h"
#include "zomefab/zome/golden.h"
#include "zomefab/zome/zome_system.h"

namespace zomefab::zome {

using BallId = uint32_t;
using StrutId = uint32_t;
/// "No ball / no strut" (also marks a free hole).
inline constexpr uint32_t kNoId = 0xFFFFFFFFu;

/// 62 free holes.
inline std::array<StrutId, kHoleCount> freeHoles() {
    std::array<StrutId, kHoleCount> holes;
    holes.fill(kNoId);
    return holes;
}

struct Ball {
    GoldenVector3 position;                               ///< exact, vZome units
    Vec3d positionMm{};                                   ///< ZomeScale::toMm(position), cached
    std::array<StrutId, kHoleCount> holes = freeHoles();  ///< strut in each hole, kNoId = free
    uint16_t valence = 0;                                 ///< number of struts
    bool isAlive = false;
};

struct Strut {
    BallId a = kNoId;   ///< start ball
    BallId b = kNoId;   ///< end ball: position(b) = position(a) + strutVector(holeA, size)
    uint8_t holeA = 0;  ///< hole used at a
    uint8_t holeB = 0;  ///< hole used at b = oppositeHole(holeA)
    Color color = Color::Blue;
    uint8_t size = 0;  ///< 0, 1, 2
    bool isAlive = false;
    /// Collision proxy: the capsule axis runs from a's surface to b's surface (mm).
    Vec3d startMm{};
    Vec3d endMm{};
};

/// Thresholds of the collision model. Proxies: a ball is a sphere of ZomeScale::ballDiameterMm,
/// a strut a capsule of ZomeScale::strutRadiusMm(colour) from ball surface to ball surface. Two
/// elements collide when they come closer than touching plus @c clearanceMm:
///   ball–ball    centre distance        < ballDiameterMm + clearanceMm
///   strut–ball   centre to strut axis   < ballRadius + strutRadius + clearanceMm (ball not an end)
///   strut–strut  axis to axis           < radius1 + radius2 + clearanceMm
///                (struts sharing a ball are exempt when they use different holes of it)
struct CollisionOptions {
    double clearanceMm = 0.0;  ///< extra gap required between any two parts, mm (default 0)
    double gridCellMm = 0.0;   ///< spatial-hash cell edge, mm; 0 = automatic (b0Mm/√2)
};

enum class CollisionKind : uint8_t { BallBall, StrutBall, StrutStrut };

/// One colliding pair: BallBall (first < second are ball ids), StrutBall (first = strut,
/// second = ball), StrutStrut (first < second are strut ids).
struct Collision {
    CollisionKind kind = CollisionKind::BallBall;
    uint32_t first = kNoId;
    uint32_t second = kNoId;
    double distanceMm = 0.0;  ///< centre or axis distance
    double limitMm = 0.0;     ///< the threshold it is below
};

/// "ball–ball", "strut–ball", "strut–strut" (ASCII hyphen).
const char* collisionKindName(CollisionKind kind);

class Structure {
public:
    /// @throw Error(Usage) for invalid sizes (ZomeScale::validate) or a negative clearance.
    explicit Structure(const ZomeScale& scale = {}, const CollisionOptions& collision = {});

    const ZomeScale& scale() const { return mScale; }
    const CollisionOptions& collisionOptions() const { return mCollision; }

    // --- inspection --------------------------------------------------------------------------
    size_t ballCount() const { return mBallCount; }
    size_t strutCount() const { return mStrutCount; }
    /// Every ball id is below this bound (dead ids included).
    uint32_t ballIdBound() const { return uint32_t(mBalls.size()); }
    uint32_t strutIdBound() const { return uint32_t(mStruts.size()); }
    bool hasBall(BallId id) const { return id < mBalls.size() && mBalls[id].isAlive; }
    bool hasStrut(StrutId id) const { return id < mStruts.size() && mStruts[id].isAlive; }
    /// @pre hasBall(id)
    const Ball& ball(BallId id) const { return mBalls[id]; }
    /// @pre hasStrut(id)
    const Strut& strut(StrutId id) const { return mStruts[id]; }
    /// Live ids in increasing order.
    std::vector<BallId> ballIds() const;
    std::vector<StrutId> strutIds() const;

    /// The ball at exactly @p position, or kNoId. One hash probe on average.
    BallId findBall(const GoldenVector3& position) const {
        return mPositions.find(position,
                               [this](uint32_t id) -> const GoldenVector3& { return mBalls[id].position; });
    }
    /// @pre hasBall(id), 0 <= hole < 62
    bool isHoleFree(BallId id, int hole) const { return mBalls[id].holes[size_t(hole)] == kNoId; }
    /// The ball at the other end of the strut in @p hole of ball @p id, or kNoId.
    BallId neighbor(BallId id, int hole) const;

    // --- editing (O(1) amortised) ---------------------------------------------------------------
    /// Adds a ball at @p position. @throw Error(InvalidInput) when a ball is already there.
    BallId addBall(const GoldenVector3& position);
    /// Adds a ball with a chosen free id (readers keep file ids). Ids below the bound left unused
    /// become free ids, reused lowest first. @throw Error(InvalidInput) for a used id or position.
    BallId addBallWithId(BallId id, const GoldenVector3& position);
    /// Removes a ball. @throw Error(InvalidInput) unless it exists and has no struts.
    void removeBall(BallId id);

    /// Adds the strut joining balls @p a and @p b; its hole, colour and size follow from the exact
    /// vector. @throw Error(InvalidInput) naming the balls when the vector is not a Zome strut or a
    /// hole is taken.
    StrutId addStrut(BallId a, BallId b);
    /// Adds a size-@p size strut leaving ball @p a through @p hole; a ball must exist at its end.
    /// @throw Error(InvalidInput) as above, or when there is no ball at the end.
    StrutId addStrut(BallId a, int hole, int size);
    /// @throw Error(InvalidInput) unless the strut exists.
    void removeStrut(StrutId id);

    /// The strut that would join @p a and @p b if the vector is a Zome strut and both holes are
    /// free, else nullopt. @pre hasBall(a) && hasBall(b)
    std::optional<StrutMatch> strutBetween(BallId a, BallId b) const;

    // --- collision queries (never modify; safe to call concurrently on a const Structure) -------
    /// Would a new ball at @p position collide with a ball or strut of the structure? A ball
    /// already at @p position counts as a collision.
    bool ballCollides(const GoldenVector3& position) const;
    /// Would a new size-@p size strut from @p start through @p hole collide with the structure?
    /// Balls at either end and struts sharing an end ball in another hole are exempt; a strut
    /// already in the same hole of an end ball collides.
    bool strutCollides(const GoldenVector3& start, int hole, int size) const;
    /// The same from an existing ball (saves one position lookup). @pre hasBall(start)
    bool strutCollides(BallId start, int hole, int size) const;

    /// The collision thresholds in mm (see CollisionOptions).
    double ballBallLimitMm() const { return mBallBallMm; }
    double strutBallLimitMm(Color color) const { return mStrutBallMm[size_t(color)]; }
    double strutStrutLimitMm(Color x, Color y) const {
        return mScale.strutRadiusMm(x) + mScale.strutRadiusMm(y) + mCollision.clearanceMm;
    }

    /// The same structure with ids 0..n−1 in the order of the old ids. @p newBallIds, when given,
    /// receives the new id of every old ball id (kNoId for dead ones).
    Structure compacted(std::vector<BallId>* newBallIds = nullptr) const;

    /// Grid statistics for benchmarks: cell edge in mm and number of cells.
    double gridCellMm() const { return mGrid.cellMm(); }
    size_t gridCellCount() const { return mGrid.cellCount(); }
    /// Number of proxies stored over all cells (an element passing through k cells counts k).
    size_t gridEntryCount() const { return mGrid.entryCount(); }

private:
    friend std::vector<Collision> findCollisions(const Structure& structure);

    static constexpr uint32_t kStrutKeyBit = 0x80000000u;

    void ensureGridCovers(const Vec3d& p0, const Vec3d& p1);
    void rebuildGrid(const Vec3d& p0, const Vec3d& p1);
    void computeStrutProxy(Strut& s) const;
    detail::GridEntry ballEntry(BallId id) const;
    detail::GridEntry strutEntry(StrutId id) const;
    StrutId insertStrut(BallId a, BallId b, const StrutMatch& m);
    BallId placeBall(BallId id, const GoldenVector3& position);
    bool strutCollidesImpl(const GoldenVector3& start, BallId idA, const Vec3d& startMm, int hole,
                           int size) const;
    void refillFreeBalls();

    ZomeScale mScale;
    CollisionOptions mCollision;
    double mUnitMm = 0.0;
    double mBallBallMm = 0.0;
    std::array<double, kColorCount> mStrutBallMm{};
    double mBallReachMm = 0.0;                        ///< how far a ball query looks: its largest threshold
    std::array<double, kColorCount> mStrutReachMm{};  ///< the same for a strut of each colour

    std::vector<Ball> mBalls;
    std::vector<Strut> mStruts;
    std::vector<BallId> mFreeBalls;  ///< LIFO of free ids
    std::vector<StrutId> mFreeStruts;
    bool mFreeBallsStale = false;  ///< set by addBallWithId; refilled on next addBall
    size_t mBallCount = 0;
    size_t mStrutCount = 0;
    detail::PositionIndex mPositions;
    detail::SpatialGrid mGrid;
};

/// Every colliding pair of the structure, sorted by (kind, first, second); empty = buildable as
/// far as the collision model can tell. O(n) with the spatial hash.
std::vector<Collision> findCollisions(const Structure& structure);

/// Squared distance between segments [p0,p1] and [q0,q1] (Ericson, Real-Time Collision Detection
/// §5.1.9; handles parallel and degenerate segments).
double segmentSegmentDistanceSq(const Vec3d& p0, const Vec3d& p1, const Vec3d& q0, const Vec3d& q1);
/// Squared distance from @p p to the segment [a,b].
double pointSegmentDistanceSq(const Vec3d& p, const Vec3d& a, const Vec3d& b);

}  // namespace zomefab::zome
