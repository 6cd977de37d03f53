// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/assembly_page.h"

#include <algorithm>
#include <map>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/core/version.h"
#include "zomefab/io/glb_write.h"
#include "zomefab/report/detail/html.h"
#include "zomefab/report/picture.h"
#include "zomefab/zome/holes.h"

namespace zomefab::report {

namespace {

using detail::escapeHtml;

constexpr int kPictureWidthPx = 640, kPictureHeightPx = 480;
const Rgb kGreyPart{0.72, 0.72, 0.72};
const Rgb kMountedPiece{0.82, 0.82, 0.80};
const Rgb kBall{0.93, 0.93, 0.90};
const Rgb kMark{0.85, 0.05, 0.45};  // magenta: in no strut's and no piece's colour
const Rgb kArrow{0.10, 0.10, 0.10};

std::string figure(const Picture& picture, const std::string& alt, const std::string& caption) {
    return "<figure><img class=\"step\" width=\"" + std::to_string(picture.width()) + "\" height=\"" +
           std::to_string(picture.height()) + "\" alt=\"" + escapeHtml(alt) +
           "\" src=\"data:image/png;base64," + base64Encode(picture.png()) + "\"><figcaption>" +
           escapeHtml(caption) + "</figcaption></figure>\n";
}

/// The frame and pieces in frame mm, looked up by the guide's names.
struct Scene {
    const zome::Structure& frame;
    const PreviewInput& input;
    std::map<std::string, size_t> pieceIndex;
    double ballRadiusMm;
    std::vector<Vec3d> framePoints,
        allPoints;  ///< what a picture must show: balls, every vertex (in no particular order)

    explicit Scene(const PreviewInput& in) : frame(*in.frame), input(in) {
        ballRadiusMm = frame.scale().ballRadiusMm();
        for (const zome::BallId id : frame.ballIds()) framePoints.push_back(frame.ball(id).positionMm);
        allPoints = framePoints;
        for (size_t i = 0; i < in.pieces.size(); ++i) {
            pieceIndex[in.pieceNames.empty() ? "piece-" + formatNumbers("%02.0f", double(i))
                                             : in.pieceNames[i]] = i;
            const TriMesh& m = *in.pieces[i];
            for (size_t v = 0; v < m.positions.size(); ++v) allPoints.push_back(vertex(i, v));
        }
    }
    Vec3d vertex(size_t piece, size_t v) const {
        const auto& p = input.pieces[piece]->positions[v];
        const Vec3d q = transform(piece).apply({double(p[0]), double(p[1]), double(p[2])});
        return {double(float(q[0])), double(float(q[1])), double(float(q[2]))};  // as Picture::mesh draws it
    }
    Transform4d transform(size_t piece) const {
        return input.pieceTransforms.empty() ? Transform4d::identity() : input.pieceTransforms[piece];
    }
    size_t piece(const std::string& name) const {
        const auto it = pieceIndex.find(name);
        if (it == pieceIndex.end())
            throw Error(ErrorCode::InvalidInput, "assembly.html: no piece named " + name);
        return it->second;
    }
    void strut(Picture& picture, zome::StrutId id, const Rgb& color) const {
        const zome::Strut& s = frame.strut(id);
        picture.cylinder(frame.ball(s.a).positionMm, frame.ball(s.b).positionMm,
                         frame.scale().strutRadiusMm(s.color), color);
    }
};

/// The frame from the front, a little from the right and above: x to the right, y away, z up.
Picture framePicture(const Scene& scene) {
    return Picture(kPictureWidthPx, kPictureHeightPx, scene.framePoints, scene.ballRadiusMm,
                   {-0.45, 1.0, -0.55}, {0, 0, 1});
}

/// Layer pictures: everything attached before @p layer of @p component grey, the layer's struts and
/// the balls they bring in colour (balls white), nothing of later layers.
std::string layerFigure(const Scene& scene, const AssemblyGuide& guide, size_t component, size_t layer) {
    Picture picture = framePicture(scene);
    // Every ball in place once: white where the layer works (its balls, the new ones it brings), grey before.
    std::map<zome::BallId, bool> isWhite;
    for (const BallStep& step : guide.steps) {
        const bool before = step.component < component || (step.component == component && step.layer < layer);
        const bool now = step.component == component && step.layer == layer;
        if (!before && !now) continue;
        isWhite[step.ball] |= now;
        for (const StrutStep& s : step.struts) {
            scene.strut(picture, s.strut, now ? strutColorSrgb(s.color) : kGreyPart);
            isWhite[s.toBall] |= now && s.isNewBall;
        }
    }
    for (const auto& [ball, white] : isWhite)
        picture.sphere(scene.frame.ball(ball).positionMm, scene.ballRadiusMm, white ? kBall : kGreyPart);
    const std::string name = "Layer " + std::to_string(layer);
    return figure(picture, name,
                  name + ": the struts to attach in colour (new balls white), the frame built so far grey.");
}

/// A view from the side the step's pieces come from, turned 40° away so the push shows as an arrow.
Picture stepPicture(const Scene& scene, const Vec3d& approach, const Vec3d& arrowTail) {
    Vec3d side = sub(Vec3d{0, 0, 1}, scale(approach, approach[2]));
    if (norm(side) < 0.3) side = sub(Vec3d{0, -1, 0}, scale(approach, -approach[1]));
    const Vec3d eye = add(approach, scale(normalized(side), 0.85));
    const Vec3d up = std::fabs(normalized(eye)[2]) > 0.9 ? Vec3d{0, 1, 0} : Vec3d{0, 0, 1};
    std::vector<Vec3d> fit = scene.allPoints;
    fit.push_back(arrowTail);
    return Picture(kPictureWidthPx, kPictureHeightPx, fit, scene.ballRadiusMm, scale(eye, -1.0), up);
}

std::string stepFigure(const Scene& scene, const AssemblyGuide& guide, size_t stepIndex) {
    const MountingStep& step = guide.mounting[stepIndex];
    const Vec3d approach = zome::holeDirection(step.hole);
    Box3d box;  // the step's pieces
    for (const std::string& name : step.pieces) {
        const size_t i = scene.piece(name);
        for (size_t v = 0; v < scene.input.pieces[i]->positions.size(); ++v) box.expand(scene.vertex(i, v));
    }
    // The arrow ends just outside the pieces, on the side they come from, and is as long as they are.
    const Vec3d centre = scale(add(box.min, box.max), 0.5);
    const double size = norm(box.size());
    const Vec3d head = add(centre, scale(approach, 0.55 * size)),
                tail = add(centre, scale(approach, 1.05 * size));
    // A stave is seen from between its slide and its lift, so that both arrows show along.
    Picture picture =
        stepPicture(scene, step.liftMm > 0 ? normalized(add(approach, step.slide)) : approach, tail);
    for (const zome::StrutId id : scene.frame.strutIds())
        scene.strut(picture, id, strutColorSrgb(scene.frame.strut(id).color));
    for (const zome::BallId id : scene.frame.ballIds())
        picture.sphere(scene.frame.ball(id).positionMm, scene.ballRadiusMm, kBall);
    for (size_t s = 0; s < stepIndex; ++s)
        for (const std::string& name : guide.mounting[s].pieces) {
            const size_t i = scene.piece(name);
            picture.mesh(*scene.input.pieces[i], scene.transform(i), kMountedPiece);
        }
    for (const std::string& name : step.pieces) {
        const size_t i = scene.piece(name);
        picture.mesh(*scene.input.pieces[i], scene.transform(i), pieceColorSrgb(i));
    }
    for (const TenonLink& t : step.tenons)
        picture.ring(scene.frame.ball(t.ball).positionMm, 11.0, 3.0, kMark);
    const std::string name = "Step " + std::to_string(stepIndex + 1);
    if (step.liftMm > 0) {
        // A stave: the long arrow along its tunnel to where it is held off its place, the short
        // one onto its pegs.
        const Vec3d held = add(centre, scale(approach, step.liftMm + 0.3 * size));
        picture.arrow(add(held, scale(step.slide, 0.9 * size)), add(held, scale(step.slide, 0.4 * size)), 5.0,
                      kArrow);
        picture.arrow(held, add(centre, scale(approach, 0.2 * size)), 4.0, kArrow);
        return figure(
            picture, name,
            name + ": " + mountingTitle(step) +
                " in colour, slid along its tunnel (the long arrow), then pushed onto its pegs "
                "(the short one); the balls its pegs go into are ringed; pieces already on are grey.");
    }
    picture.arrow(tail, head, 5.0, kArrow);
    return figure(picture, name,
                  name + ": " + mountingTitle(step) +
                      " in colour, pushed on along the arrow; the balls its pegs go "
                      "into are ringed; pieces already on are grey.");
}

std::string partsTableHtml(const zome::PartsList& parts, const zome::PriceOptions& prices) {
    static const char* kSizes[] = {"short", "medium", "long"};
    std::string html = "<table><tr><th>part</th><th>what it is</th><th>count</th></tr>\n";
    for (int c = 0; c < zome::kColorCount; ++c)
        for (int s = 0; s < zome::kSizeCount; ++s) {
            const size_t n = parts.count(zome::Color(c), s);
            if (n == 0) continue;
            html += "<tr><td>" + zome::partName(zome::Color(c), s) + "</td><td>" +
                    zome::colorName(zome::Color(c)) + " strut, " + kSizes[s] + "</td><td>" +
                    std::to_string(n) + "</td></tr>\n";
        }
    html +=
        "<tr><td>ball</td><td>Zometool ball (node)</td><td>" + std::to_string(parts.balls) + "</td></tr>\n";
    html +=
        "</table>\n<p>" +
        formatNumbers("Kit cost: %.0f struts × %.2f USD + %.0f balls × %.2f USD = %.2f USD.",
                      double(parts.strutTotal()), prices.strutUsd, double(parts.balls), prices.ballUsd,
                      double(parts.strutTotal()) * prices.strutUsd + double(parts.balls) * prices.ballUsd) +
        "</p>\n";
    return html;
}

constexpr const char* kStyle =
    "body { font: 15px/1.45 sans-serif; max-width: 60em; margin: 1em auto; padding: 0 1em; color: #222; }\n"
    "figure { margin: 1em 0; } figure img { max-width: 100%; height: auto; border: 1px solid #ccc; }\n"
    "figcaption { font-size: 13px; color: #555; } table { border-collapse: collapse; }\n"
    "td, th { border: 1px solid #ccc; padding: 2px 8px; text-align: left; } h3 { margin-top: 1.6em; }\n";

}  // namespace

std::string assemblyGuideHtml(const AssemblyGuide& guide, const PreviewInput& input, const std::string& title,
                              const zome::PriceOptions& prices) {
    if (!input.frame) throw Error(ErrorCode::InvalidInput, "assembly.html: the scene has no frame");
    const Scene scene(input);
    std::string html =
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>Assembly guide: " +
        escapeHtml(title) + "</title>\n<style>\n" + kStyle + "</style>\n</head>\n<body>\n";
    html +=
        "<h1>Assembly guide: " + escapeHtml(title) + "</h1>\n<p>Generated by " + generatorString() +
        ". The frame has " + std::to_string(guide.parts.balls) + " balls and " +
        std::to_string(guide.parts.strutTotal()) + " struts; " + std::to_string(guide.mounting.size()) +
        " mounting steps put the printed pieces on. The pictures look at the object from the front (x to "
        "the right, y away from you, z up) for the frame, and from the side each piece comes from for the "
        "mounting steps.</p>\n";
    html += "<h2>Parts list</h2>\n" + partsTableHtml(guide.parts, prices);
    html += "<h2>Frame</h2>\n<p>" + escapeHtml(frameIntroduction()) + "</p>\n";
    size_t component = size_t(-1), layer = size_t(-1);
    for (const BallStep& step : guide.steps) {
        if (step.component != component || step.layer != layer) {
            if (layer != size_t(-1)) html += "</ul>\n";
            if (step.component != component && guide.components > 1)
                html += "<h2>Frame part " + std::to_string(step.component + 1) + "</h2>\n";
            component = step.component;
            layer = step.layer;
            html += "<h3>Layer " + std::to_string(layer) + "</h3>\n" +
                    layerFigure(scene, guide, component, layer) + "<ul>\n";
        }
        html += "<li><b>" + escapeHtml(ballHeading(step)) + "</b>" +
                (step.struts.empty() ? ": nothing new to attach" : "");
        if (!step.struts.empty()) {
            html += "<ul>";
            for (const StrutStep& s : step.struts) html += "<li>" + escapeHtml(strutSentence(s)) + "</li>";
            html += "</ul>";
        }
        html += "</li>\n";
    }
    if (layer != size_t(-1)) html += "</ul>\n";
    if (!guide.mounting.empty()) {
        html += "<h2>Putting the pieces on</h2>\n<p>" + escapeHtml(mountingIntroduction()) + "</p>\n";
        for (size_t s = 0; s < guide.mounting.size(); ++s) {
            html += "<h3>Step " + std::to_string(s + 1) + ": " +
                    escapeHtml(mountingTitle(guide.mounting[s])) + "</h3>\n" + stepFigure(scene, guide, s) +
                    "<ul>\n";
            for (const std::string& line : mountingSentences(guide.mounting[s]))
                html += "<li>" + escapeHtml(line) + "</li>\n";
            html += "</ul>\n";
        }
    }
    html += "</body>\n</html>\n";
    return html;
}

}  // namespace zomefab::report
