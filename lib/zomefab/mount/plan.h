// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The installation plan: how each printed piece goes onto the built frame. Every piece has
/// one direction, a hole direction d: it is pushed on along −d, its tenons' pegs entering the holes
/// that point along d. Pieces glued together before mounting form a group that goes on as one
/// body; a body no peg can hold is glued onto pieces already in place as it goes on. The steps give
/// the order; `before` lists the blocking relation the order respects (a
/// piece cannot approach through a neighbour already in place). docs/mounting.md.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab::mount {

/// One mounting step: a piece, or a glued group, pushed on along −direction. A step of two legs
/// (a stave lining a tunnel: docs/mounting.md, "Three tunnels through one point") first slides in
/// along −slide, held liftMm off its place along the direction, then is pushed on along
/// −direction by liftMm onto its pegs: taken off, it is lifted off its pegs along +direction by
/// liftMm, then slid off along +slide.
struct MountStep {
    std::vector<uint32_t> pieces;  ///< one piece, or the members of a glued group
    int hole = -1;                 ///< the direction: zome hole 0..61
    Vec3d slide{0, 0, 0};          ///< the first leg, a unit vector in frame coordinates; 0: none
    double liftMm = 0.0;           ///< how far the last leg is (mm); 0: one straight push

    bool hasTwoLegs() const { return liftMm > 0.0; }
};

struct InstallationPlan {
    std::vector<int> holeOfPiece;   ///< per piece: its direction's hole, −1 when it has none
    std::vector<uint32_t> groupOf;  ///< per piece: its glued group (the lowest member's id)
    /// Pairs of pieces glued together before mounting (across their common cut face, with
    /// alignment pins): the edges that join each group, a < b.
    std::vector<std::pair<uint32_t, uint32_t>> glued;
    /// Pairs (host, piece): piece, which no peg can hold, is glued onto host as it goes on, host
    /// being a piece of an earlier step: across their common cut face, with alignment pins along
    /// piece's direction (an ear onto the head, the tip of a tail onto its root).
    std::vector<std::pair<uint32_t, uint32_t>> gluedOn;
    std::vector<MountStep> steps;  ///< in mounting order; every piece in exactly one
    /// (a, b): group a must be mounted before group b (b's path would cross a, or a's would cross
    /// b); groups by their names (groupOf).
    std::vector<std::pair<uint32_t, uint32_t>> before;
    /// What keeps the plan from being carried out (empty: it can be).
    std::vector<std::string> problems;

    bool isBuildable() const { return problems.empty(); }
    /// The step that mounts @p piece (0-based), or −1.
    int stepOf(uint32_t piece) const;
};

/// How one cut face between two pieces constrains their order. @p normal points from piece a into
/// piece b; @p da and @p db are their directions (unit). b can go on after a when its path does not
/// go into a (db·n ≥ −tolerance), a after b when da·n ≤ tolerance. The default is no tolerance:
/// a piece may slide along its neighbour's face, never into it (docs/mounting.md).
struct FaceOrder {
    bool isBAfterAOk = true;
    bool isAAfterBOk = true;
};
FaceOrder faceOrder(const Vec3d& normal, const Vec3d& da, const Vec3d& db, double tolerance = 0.0);

/// A mounting order of @p count bodies that respects every (a, b) of @p before: Kahn's algorithm,
/// among the ready bodies the one with the lowest @p priority (then the lowest id). Empty when the
/// relation has a cycle; @p cycle then receives the bodies of one.
std::vector<uint32_t> mountingOrder(size_t count, const std::vector<std::pair<uint32_t, uint32_t>>& before,
                                    const std::vector<double>& priority,
                                    std::vector<uint32_t>* cycle = nullptr);

}  // namespace zomefab::mount
