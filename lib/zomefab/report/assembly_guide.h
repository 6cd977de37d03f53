// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The assembly guide (`assembly.md`): the paper's "highlight the connected struts for each
/// ball" (§7.3) as a step list in build order, breadth-first from the lowest ball, layer by layer;
/// then the installation plan: in its order, each printed piece (or glued group) with the
/// direction it is pushed on along and the ball and hole each of its pegs goes into (§6.1,
/// docs/mounting.md). Order rules: docs/report.md.
#pragma once

#include <cstddef>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/zome/holes.h"
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

/// Two pieces glued together before their group is mounted, with the pins that line them up.
struct GlueJoint {
    std::string a, b;  ///< piece names
    size_t pins = 0;
};

/// One step of the installation plan: a piece, or a group glued first, pushed onto the frame along
/// −d, d the direction of @p hole; its pegs go into the holes @p hole of the balls listed.
struct MountingStep {
    std::vector<std::string> pieces;  ///< one piece, or a glued group
    std::vector<GlueJoint> glue;      ///< how the group is glued (empty for one piece)
    int hole = -1;                    ///< the direction, 0..61
    std::vector<TenonLink> tenons;    ///< every peg of the step, by piece in step order
    /// Pieces already on that this step's pieces are glued onto as they go on (a: this step's
    /// piece, b: the one already on; the pins stand on b): a step no peg holds.
    std::vector<GlueJoint> gluedOnto;
    Vec3d slide{0, 0, 0};  ///< a stave's first leg (frame, unit): slid in along −slide
    double liftMm = 0.0;   ///< then pushed on this far (mm); 0: one straight push
};

struct AssemblyGuide {
    zome::PartsList parts;
    std::vector<BallStep> steps;         ///< every live ball exactly once, in build order
    size_t layers = 0;                   ///< number of layers of the largest component
    size_t components = 0;               ///< connected components of the frame
    std::vector<MountingStep> mounting;  ///< the installation plan, in order
};

/// The build order: start at the lowest ball (smallest z, then y, x, id); layer k+1 = the balls
/// first reached from layer k; within a layer by (z, y, x, id), so each layer goes bottom up. At
/// each ball, every strut not attached before is listed once. A frame in several pieces gets one
/// such walk per component, lowest component first. @p mounting is the installation plan as it is.
/// @throw Error(InvalidInput) naming the piece for a step without a direction, a peg along
///   another direction, into an unknown ball, or into a hole that holds a strut.
AssemblyGuide assemblyGuide(const zome::Structure& frame, const std::vector<MountingStep>& mounting = {});

/// The guide's sentences, shared by assembly.md and assembly.html (plain text, no markup).
std::string frameIntroduction();
std::string mountingIntroduction();
/// "ball-12 at (-36.7, -53.8, 96.4) mm".
std::string ballHeading(const BallStep& step);
/// "B0 (blue) in the blue hole pointing straight up (2) to ball-11 (new), its hole 17".
std::string strutSentence(const StrutStep& strut);
/// "piece-05 + piece-08": the pieces of a mounting step.
std::string mountingTitle(const MountingStep& step);
/// The glue, approach and pegs sentences of one mounting step.
std::vector<std::string> mountingSentences(const MountingStep& step);

/// `assembly.md`: the parts list (zome::partsTable, paper Table 2 layout), the layers with each
/// ball's id, position in mm and the struts to attach (part, the hole by its colour and direction
/// in words, the ball it leads to), and the mounting steps.
std::string assemblyGuideMarkdown(const AssemblyGuide& guide, const zome::PriceOptions& prices = {});

/// The same as JSON ({"start_balls", "layers", "steps": [{"ball", "mm", "layer", "struts": [...]}],
/// "mounting": [{"step", "pieces", "glue", "hole", "direction", ...}]}) for report.json.
nlohmann::json assemblyGuideToJson(const AssemblyGuide& guide);

}  // namespace zomefab::report
