// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/assembly_guide.h"

#include <algorithm>
#include <map>
#include <string>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/core/version.h"

namespace zomefab::report {

namespace {

/// Bottom-up order of balls: z, then y, x, id.
bool lowerThan(const zome::Structure& frame, zome::BallId a, zome::BallId b) {
    const Vec3d &pa = frame.ball(a).positionMm, &pb = frame.ball(b).positionMm;
    if (pa[2] != pb[2]) return pa[2] < pb[2];
    if (pa[1] != pb[1]) return pa[1] < pb[1];
    if (pa[0] != pb[0]) return pa[0] < pb[0];
    return a < b;
}

std::string ballName(zome::BallId id) { return "ball-" + std::to_string(id); }

/// The plan's steps checked against the frame.
void checkMounting(const zome::Structure& frame, const std::vector<MountingStep>& mounting) {
    for (size_t s = 0; s < mounting.size(); ++s) {
        const MountingStep& step = mounting[s];
        const std::string who = step.pieces.empty() ? "step " + std::to_string(s + 1) : step.pieces[0];
        if (step.hole < 0 || step.hole >= zome::kHoleCount)
            throw Error(ErrorCode::InvalidInput, who + ": the mounting step has no direction (hole 0..61)");
        for (const TenonLink& t : step.tenons) {
            const std::string where =
                t.piece + ": peg into hole " + std::to_string(t.hole) + " of " + ballName(t.ball);
            if (t.hole != step.hole)
                throw Error(ErrorCode::InvalidInput, where + ": not along its step's direction");
            if (!frame.hasBall(t.ball))
                throw Error(ErrorCode::InvalidInput, where + ": no such ball in the frame");
            if (!frame.isHoleFree(t.ball, t.hole))
                throw Error(ErrorCode::InvalidInput,
                            where + ": the hole holds strut " +
                                std::to_string(frame.ball(t.ball).holes[size_t(t.hole)]));
        }
    }
}

/// "the blue hole pointing straight up": a hole as a builder sees it.
std::string holeWords(int hole) {
    return std::string("the ") + zome::colorName(zome::holeColor(hole)) + " hole pointing " +
           zome::directionName(zome::holeDirection(hole));
}

}  // namespace

AssemblyGuide assemblyGuide(const zome::Structure& frame, const std::vector<MountingStep>& mounting) {
    AssemblyGuide guide;
    guide.parts = zome::partsList(frame);
    const std::vector<zome::BallId> ids = frame.ballIds();
    std::vector<char> present(frame.ballIdBound(), 0);
    std::vector<char> attached(frame.strutIdBound(), 0);
    std::vector<zome::BallId> byHeight = ids;
    std::sort(byHeight.begin(), byHeight.end(),
              [&](zome::BallId a, zome::BallId b) { return lowerThan(frame, a, b); });

    for (zome::BallId start : byHeight) {
        if (present[start]) continue;
        const size_t component = guide.components++;
        present[start] = 1;
        std::vector<zome::BallId> layer = {start};
        for (size_t depth = 0; !layer.empty(); ++depth) {
            guide.layers = std::max(guide.layers, depth + 1);
            std::vector<zome::BallId> nextLayer;
            for (zome::BallId id : layer) {
                BallStep step;
                step.ball = id;
                step.positionMm = frame.ball(id).positionMm;
                step.layer = depth;
                step.component = component;
                const zome::Ball& ball = frame.ball(id);
                for (int hole = 0; hole < zome::kHoleCount; ++hole) {
                    const zome::StrutId sid = ball.holes[size_t(hole)];
                    if (sid == zome::kNoId || attached[sid]) continue;
                    attached[sid] = 1;
                    const zome::Strut& s = frame.strut(sid);
                    StrutStep st;
                    st.strut = sid;
                    st.color = s.color;
                    st.size = s.size;
                    st.hole = hole;
                    st.toBall = s.a == id ? s.b : s.a;
                    st.toHole = s.a == id ? s.holeB : s.holeA;
                    st.isNewBall = !present[st.toBall];
                    if (st.isNewBall) {
                        present[st.toBall] = 1;
                        nextLayer.push_back(st.toBall);
                    }
                    step.struts.push_back(st);
                }
                std::stable_sort(step.struts.begin(), step.struts.end(),
                                 [](const StrutStep& a, const StrutStep& b) {
                                     if (a.color != b.color) return a.color < b.color;
                                     if (a.size != b.size) return a.size < b.size;
                                     return a.hole < b.hole;
                                 });
                guide.steps.push_back(std::move(step));
            }
            std::sort(nextLayer.begin(), nextLayer.end(),
                      [&](zome::BallId a, zome::BallId b) { return lowerThan(frame, a, b); });
            layer.swap(nextLayer);
        }
    }

    checkMounting(frame, mounting);
    guide.mounting = mounting;
    return guide;
}

std::string mountingTitle(const MountingStep& step) {
    std::string names;
    for (const std::string& p : step.pieces) names += (names.empty() ? "" : " + ") + p;
    return names;
}

std::vector<std::string> mountingSentences(const MountingStep& step) {
    std::vector<std::string> lines;
    for (const GlueJoint& g : step.glue)
        lines.push_back("First glue " + g.a + " to " + g.b + " along their common cut face (" +
                        (g.pins == 0 ? std::string("no room for alignment pins: line the two up by eye")
                                     : std::to_string(g.pins) + " alignment pin" + (g.pins == 1 ? "" : "s")) +
                        ").");
    for (const GlueJoint& g : step.gluedOnto)
        lines.push_back("Put glue on the cut face of " + g.a + " that meets " + g.b +
                        " (already on): " + g.a + " is glued onto it as it goes on (" +
                        (g.pins == 0 ? std::string("no alignment pins (no room for them, or the face runs "
                                                   "along the way it goes on): line it up by eye")
                                     : std::to_string(g.pins) + " alignment pin" + (g.pins == 1 ? "" : "s") +
                                           " on " + g.b + " go into its sockets") +
                        ").");
    const Vec3d& d = zome::holeDirection(step.hole);
    if (step.liftMm > 0) {
        // A stave: it reaches its place only along its tunnel, held off its pegs.
        const Vec3d& s = step.slide;
        lines.push_back(
            "Slide it into the tunnel from its mouth on the side " + zome::directionName(s) +
            formatNumbers(" (direction %+.3f, %+.3f, %+.3f)", 0.0 - s[0], 0.0 - s[1], 0.0 - s[2]) +
            formatNumbers(", held %.0f mm off its place toward the tunnel's middle, pegs toward "
                          "the wall, until it is over its place; then push it onto its pegs.",
                          step.liftMm));
    }
    lines.push_back((step.liftMm > 0 ? "Push it on from: " : "Approach from: ") + zome::directionName(d) +
                    ". Push: " + zome::directionName(scale(d, -1.0)) +
                    formatNumbers(" (direction %+.3f, %+.3f, %+.3f).", 0.0 - d[0], 0.0 - d[1], 0.0 - d[2]));
    if (step.tenons.empty()) {
        lines.push_back("It has no pegs: the glue holds it.");
        return lines;
    }
    std::string pegs =
        "Its pegs go into " + holeWords(step.hole) + " (" + std::to_string(step.hole) + ") of ";
    for (size_t i = 0; i < step.tenons.size(); ++i)
        pegs += (i ? ", " : "") + ballName(step.tenons[i].ball) +
                (step.pieces.size() > 1 ? " (" + step.tenons[i].piece + ")" : "");
    lines.push_back(pegs + ".");
    return lines;
}

std::string ballHeading(const BallStep& step) {
    return ballName(step.ball) + " at " +
           formatNumbers("(%.1f, %.1f, %.1f) mm", step.positionMm[0], step.positionMm[1], step.positionMm[2]);
}

std::string strutSentence(const StrutStep& s) {
    return zome::partName(s.color, s.size) + " (" + zome::colorName(s.color) + ") in " + holeWords(s.hole) +
           " (" + std::to_string(s.hole) + ") to " + ballName(s.toBall) + (s.isNewBall ? " (new)" : "") +
           ", its hole " + std::to_string(s.toHole);
}

std::string frameIntroduction() {
    return "Build the frame ball by ball in the order below: breadth-first from the lowest ball, one layer "
           "of "
           "balls at a time, each layer from the bottom up. At each ball, attach the struts listed (the ones "
           "not "
           "attached yet); \"new\" means the strut carries a ball that is not in place yet: put a new ball "
           "on "
           "its free end. Positions are in millimetres; directions are as you face the model: x to the "
           "right, "
           "y away from you, z up. Every ball sits the same way round, so a hole that points straight up on "
           "one "
           "ball points straight up on all of them. The number after a hole is zomefab's (blue 0-29, yellow "
           "30-49, red 50-61).";
}

std::string mountingIntroduction() {
    return "With the frame built, put the printed pieces on one at a time, in this order. Each goes on along "
           "one "
           "direction, all its pegs at once: hold it on the side it approaches from, pegs toward the frame, "
           "line "
           "every peg up with its hole and push it straight in until the pegs are seated (4 mm). Glue a "
           "group's "
           "pieces together first, pins into sockets, and let the glue set. A piece no peg can hold (an "
           "ear, the tip of a tail) is glued onto the pieces already on as it goes on: glue on its cut face, "
           "then push it on so that its sockets slide over their pins.";
}

namespace {

std::string mountingMarkdown(const std::vector<MountingStep>& mounting) {
    std::string md = "\n## Putting the pieces on\n\n" + mountingIntroduction() + "\n";
    for (size_t s = 0; s < mounting.size(); ++s) {
        md += "\n### Step " + std::to_string(s + 1) + ": " + mountingTitle(mounting[s]) + "\n\n";
        for (const std::string& line : mountingSentences(mounting[s])) md += "- " + line + "\n";
    }
    return md;
}

}  // namespace

std::string assemblyGuideMarkdown(const AssemblyGuide& guide, const zome::PriceOptions& prices) {
    std::string md = "# Assembly guide\n\n";
    md += std::string("Generated by ") + generatorString() + ". The frame has " +
          std::to_string(guide.parts.balls) + " balls and " + std::to_string(guide.parts.strutTotal()) +
          " struts";
    if (guide.components > 1) md += " in " + std::to_string(guide.components) + " separate parts";
    md += ".\n\n";
    md += frameIntroduction() + "\n\n";
    md += "## Parts list\n\n```text\n" + zome::partsTable(guide.parts, prices) + "```\n\n";
    md += "## Frame\n";
    size_t component = size_t(-1), layer = size_t(-1);
    for (const BallStep& step : guide.steps) {
        if (step.component != component) {
            component = step.component;
            layer = size_t(-1);
            if (guide.components > 1) md += "\n## Frame part " + std::to_string(component + 1) + "\n";
        }
        if (step.layer != layer) {
            layer = step.layer;
            md += "\n### Layer " + std::to_string(layer) + "\n";
        }
        const std::string heading = ballHeading(step);
        const size_t at = heading.find(" at ");
        md += "\n**" + heading.substr(0, at) + "**" + heading.substr(at) +
              (step.struts.empty() ? ": nothing new to attach\n" : "\n");
        for (const StrutStep& s : step.struts) md += "- " + strutSentence(s) + "\n";
    }
    if (!guide.mounting.empty()) md += mountingMarkdown(guide.mounting);
    return md;
}

nlohmann::json assemblyGuideToJson(const AssemblyGuide& guide) {
    nlohmann::json steps = nlohmann::json::array();
    nlohmann::json starts = nlohmann::json::array();
    for (const BallStep& b : guide.steps) {
        if (b.layer == 0) starts.push_back(b.ball);
        nlohmann::json struts = nlohmann::json::array();
        for (const StrutStep& s : b.struts)
            struts.push_back({{"strut", s.strut},
                              {"part", zome::partName(s.color, s.size)},
                              {"hole", s.hole},
                              {"to_ball", s.toBall},
                              {"to_hole", s.toHole},
                              {"new_ball", s.isNewBall}});
        steps.push_back({{"ball", b.ball},
                         {"mm", b.positionMm},
                         {"layer", b.layer},
                         {"component", b.component},
                         {"struts", std::move(struts)}});
    }
    nlohmann::json mounting = nlohmann::json::array();
    for (size_t k = 0; k < guide.mounting.size(); ++k) {
        const MountingStep& m = guide.mounting[k];
        nlohmann::json pegs = nlohmann::json::array(), glue = nlohmann::json::array();
        for (const TenonLink& l : m.tenons)
            pegs.push_back({{"piece", l.piece}, {"ball", l.ball}, {"hole", l.hole}});
        for (const GlueJoint& g : m.glue) glue.push_back({{"pieces", {g.a, g.b}}, {"pins", g.pins}});
        nlohmann::json gluedOnto = nlohmann::json::array();
        for (const GlueJoint& g : m.gluedOnto)
            gluedOnto.push_back({{"piece", g.a}, {"onto", g.b}, {"pins", g.pins}});
        const Vec3d& d = zome::holeDirection(m.hole);
        mounting.push_back({{"step", k + 1},
                            {"pieces", m.pieces},
                            {"glue", std::move(glue)},
                            {"glued_onto", std::move(gluedOnto)},
                            {"hole", m.hole},
                            {"hole_color", zome::colorName(zome::holeColor(m.hole))},
                            {"from", zome::directionName(d)},
                            {"push", {0.0 - d[0], 0.0 - d[1], 0.0 - d[2]}},
                            {"push_name", zome::directionName(scale(d, -1.0))},
                            {"pegs", std::move(pegs)}});
        if (m.liftMm > 0) {  // a stave: slid in along its tunnel first, held lift_mm off its place
            mounting.back()["slide"] = {0.0 - m.slide[0], 0.0 - m.slide[1], 0.0 - m.slide[2]};
            mounting.back()["lift_mm"] = m.liftMm;
        }
    }
    return {{"start_balls", std::move(starts)},
            {"layers", guide.layers},
            {"components", guide.components},
            {"steps", std::move(steps)},
            {"mounting", std::move(mounting)}};
}

}  // namespace zomefab::report
