// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/assembly_guide.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <string>

#include "zomefab/core/error.h"
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

std::string format(const char* fmt, double a, double b, double c) {
    char buf[128];
    std::snprintf(buf, sizeof buf, fmt, a, b, c);
    return buf;
}

std::string ballName(zome::BallId id) { return "ball-" + std::to_string(id); }

}  // namespace

AssemblyGuide assemblyGuide(const zome::Structure& frame, const std::vector<TenonLink>& tenons,
                            const std::vector<std::string>& pieceOrder) {
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

    std::map<std::string, size_t> pieceIndex;
    auto pieceSlot = [&](const std::string& name) {
        const auto it = pieceIndex.find(name);
        if (it != pieceIndex.end()) return it->second;
        guide.pieces.push_back({name, {}});
        pieceIndex.emplace(name, guide.pieces.size() - 1);
        return guide.pieces.size() - 1;
    };
    for (const std::string& name : pieceOrder) pieceSlot(name);
    for (const TenonLink& t : tenons) {
        const std::string where =
            t.piece + ": tenon into hole " + std::to_string(t.hole) + " of " + ballName(t.ball);
        if (!frame.hasBall(t.ball))
            throw Error(ErrorCode::InvalidInput, where + ": no such ball in the frame");
        if (t.hole < 0 || t.hole >= zome::kHoleCount)
            throw Error(ErrorCode::InvalidInput, where + ": holes are numbered 0..61");
        if (!frame.isHoleFree(t.ball, t.hole))
            throw Error(
                ErrorCode::InvalidInput,
                where + ": the hole holds strut " + std::to_string(frame.ball(t.ball).holes[size_t(t.hole)]));
        guide.pieces[pieceSlot(t.piece)].tenons.push_back(t);
    }
    return guide;
}

std::string assemblyGuideMarkdown(const AssemblyGuide& guide, const zome::PriceOptions& prices) {
    std::string md = "# Assembly guide\n\n";
    md += std::string("Generated by ") + generatorString() + ". The frame has " +
          std::to_string(guide.parts.balls) + " balls and " + std::to_string(guide.parts.strutTotal()) +
          " struts";
    if (guide.components > 1) md += " in " + std::to_string(guide.components) + " separate parts";
    md += ".\n\n";
    md +=
        "Build the frame ball by ball in the order below: breadth-first from the lowest ball, one layer of "
        "balls at a "
        "time, each layer from the bottom up. At each ball, attach the struts listed (the ones not attached "
        "yet); "
        "\"new\" means the strut carries a ball that is not in place yet: put a new ball on its free end. "
        "Positions "
        "are in millimetres, z up. Hole numbers are zomefab's (blue 0-29, yellow 30-49, red 50-61); the "
        "direction "
        "after each hole is the unit vector from the ball's centre through that hole.\n\n";
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
        md += "\n**" + ballName(step.ball) + "** at " +
              format("(%.1f, %.1f, %.1f) mm", step.positionMm[0], step.positionMm[1], step.positionMm[2]) +
              (step.struts.empty() ? ": nothing new to attach\n" : "\n");
        for (const StrutStep& s : step.struts) {
            const Vec3d& d = zome::holeDirection(s.hole);
            md += "- " + zome::partName(s.color, s.size) + " (" + zome::colorName(s.color) + ") in hole " +
                  std::to_string(s.hole) + format(" (%+.2f, %+.2f, %+.2f)", d[0], d[1], d[2]) + " to " +
                  ballName(s.toBall) + (s.isNewBall ? " (new)" : "") + ", its hole " +
                  std::to_string(s.toHole) + "\n";
        }
    }
    if (!guide.pieces.empty()) {
        md +=
            "\n## Pieces\n\nPlug each printed piece onto the frame: its tenons go into these free holes.\n\n";
        md += "| piece | tenons (ball, hole) |\n|---|---|\n";
        for (const PieceStep& p : guide.pieces) {
            md += "| " + p.piece + " | ";
            if (p.tenons.empty()) md += "none (held by its neighbours)";
            for (size_t i = 0; i < p.tenons.size(); ++i)
                md += (i ? ", " : "") + ballName(p.tenons[i].ball) + " hole " +
                      std::to_string(p.tenons[i].hole);
            md += " |\n";
        }
    }
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
    nlohmann::json pieces = nlohmann::json::array();
    for (const PieceStep& p : guide.pieces) {
        nlohmann::json t = nlohmann::json::array();
        for (const TenonLink& l : p.tenons) t.push_back({{"ball", l.ball}, {"hole", l.hole}});
        pieces.push_back({{"piece", p.piece}, {"tenons", std::move(t)}});
    }
    return {{"start_balls", std::move(starts)},
            {"layers", guide.layers},
            {"components", guide.components},
            {"steps", std::move(steps)},
            {"pieces", std::move(pieces)}};
}

}  // namespace zomefab::report
