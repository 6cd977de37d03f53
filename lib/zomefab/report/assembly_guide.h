// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The assembly guide (`assembly.md`): the paper's "highlight the connected struts for each
/// ball" (§7.3) as a step list in build order, breadth-first from the lowest ball, layer by layer;
/// then, for each printed piece, the balls its tenons plug into (§6.1). Order rules: docs/report.md.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure.h"

namespace zomefab::report {

/// One tenon of a printed piece, plugged into a hole of a ball (plain values from the pieces stage).
struct TenonLink {
    std::string piece;      ///< piece name, e.g. "piece-03"
    zome::BallId ball = 0;  ///< frame ball id
    int hole = 0;           ///< 0..61 (zome/zome_system.h numbering)
};

/// One strut to attach at the current ball.
struct StrutStep {
    zome::StrutId strut = 0;
    zome::Color color = zome::Color::Blue;
    int size = 0;
    int hole = 0;             ///< hole of the current ball
    zome::BallId toBall = 0;  ///< the ball at the other end
    int toHole = 0;           ///< the hole it enters there
    bool isNewBall = false;   ///< the other ball is not in place yet: put a new ball on the strut
};

/// One ball of the build order, with the struts not attached yet.
struct BallStep {
    zome::BallId ball = 0;
    Vec3d positionMm{};
    size_t layer = 0;               ///< breadth-first distance (in struts) from its component's start ball
    size_t component = 0;           ///< 0 for a connected frame
    std::vector<StrutStep> struts;  ///< sorted by colour, size, hole
};

/// The balls one piece plugs into.
struct PieceStep {
    std::string piece;
    std::vector<TenonLink> tenons;  ///< in input order
};

struct AssemblyGuide {
    zome::PartsList parts;
    std::vector<BallStep> steps;    ///< every live ball exactly once, in build order
    size_t layers = 0;              ///< number of layers of the largest component
    size_t components = 0;          ///< connected components of the frame
    std::vector<PieceStep> pieces;  ///< pieces in order of first appearance in the tenon list
};

/// The build order: start at the lowest ball (smallest z, then y, x, id); layer k+1 = the balls
/// first reached from layer k; within a layer by (z, y, x, id), so each layer goes bottom up. At
/// each ball, every strut not attached before is listed once. A frame in several pieces gets one
/// such walk per component, lowest component first.
/// @param tenons (piece, ball, hole) triples; @p pieceOrder optionally lists every piece name, so
///   pieces without tenons appear too (with none)
/// @throw Error(InvalidInput) naming the piece for a tenon into an unknown ball, a hole outside
///   0..61 or a hole that holds a strut.
AssemblyGuide assemblyGuide(const zome::Structure& frame, const std::vector<TenonLink>& tenons = {},
                            const std::vector<std::string>& pieceOrder = {});

/// `assembly.md`: the parts list (zome::partsTable, paper Table 2 layout), the layers with each
/// ball's id, position in mm and the struts to attach (part, hole and its direction, the ball it
/// leads to), and the pieces' tenons.
std::string assemblyGuideMarkdown(const AssemblyGuide& guide, const zome::PriceOptions& prices = {});

/// The same as JSON ({"start_balls", "layers", "steps": [{"ball", "mm", "layer", "struts": [...]}],
/// "pieces": [...]}) for report.json.
nlohmann::json assemblyGuideToJson(const AssemblyGuide& guide);

}  // namespace zomefab::report
