// SPDX-License-Identifier: GPL-3.0-or-later
// The verifier's driver: reading an output directory, the plan's own consistency, the report
// (verify.h, docs/mounting.md, "The verifier").
#include "zomefab/verify/verify.h"

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/io/file_io.h"
#include "zomefab/pieces/pieces_io.h"
#include "zomefab/verify/detail/geometry.h"
#include "zomefab/zome/structure_json.h"

namespace zomefab::verify {

namespace {

namespace fs = std::filesystem;

/// The plan itself: no problems recorded, every piece in one step along its own direction, the
/// pieces of a step joined by glued pairs that share a cut face.
CheckResult checkPlan(const Assembly& a, VerifyReport& report) {
    CheckResult c{"plan", "every piece in one mounting step along its direction; glued groups joined", 0, {}};
    const mount::InstallationPlan& plan = a.pieces.plan;
    for (const std::string& p : plan.problems) c.failures.push_back("the plan says: " + p);
    std::vector<int> stepOf(a.pieces.pieces.size(), -1);
    for (size_t s = 0; s < plan.steps.size(); ++s) {
        const mount::MountStep& step = plan.steps[s];
        ++c.checked;
        if (step.hole < 0) c.failures.push_back("step " + std::to_string(s + 1) + " has no direction");
        for (uint32_t p : step.pieces) {
            stepOf[p] = int(s);
            if (a.pieces.pieces[p].hole != step.hole)
                c.failures.push_back("piece " + std::to_string(p) + ": its direction is not its step's");
        }
        // The members are one group: connected through glued pairs of this step.
        std::set<uint32_t> reached{step.pieces[0]};
        for (bool isGrowing = true; isGrowing;) {
            isGrowing = false;
            for (const auto& [x, y] : plan.glued)
                if (reached.count(x) != reached.count(y) &&
                    std::count(step.pieces.begin(), step.pieces.end(), reached.count(x) ? y : x))
                    reached.insert(reached.count(x) ? y : x), isGrowing = true;
        }
        if (reached.size() != step.pieces.size())
            c.failures.push_back("step " + std::to_string(s + 1) +
                                 ": its pieces are not glued into one group");
    }
    auto shareFace = [&](uint32_t x, uint32_t y) {
        const auto& n = a.pieces.pieces[x].neighbors;
        return std::any_of(n.begin(), n.end(), [&](const auto& e) { return e.first == y; });
    };
    for (const auto& [x, y] : plan.glued)
        if (!shareFace(x, y))
            c.failures.push_back("pieces " + std::to_string(x) + " and " + std::to_string(y) +
                                 " are glued but share no cut face");
    for (uint32_t p = 0; p < stepOf.size(); ++p) {
        report.pieces[p].step = stepOf[p];
        if (stepOf[p] < 0) c.failures.push_back("piece " + std::to_string(p) + " is in no mounting step");
    }
    // A piece glued on goes on after its host, across a face they share.
    for (const auto& [host, piece] : plan.gluedOn) {
        if (!shareFace(host, piece))
            c.failures.push_back("piece " + std::to_string(piece) + " is glued onto piece " +
                                 std::to_string(host) + " but they share no cut face");
        else if (stepOf[host] < 0 || stepOf[piece] < 0 || stepOf[host] >= stepOf[piece])
            c.failures.push_back("piece " + std::to_string(piece) + " is glued onto piece " +
                                 std::to_string(host) + ", which is not put on before it");
    }
    return c;
}

void countBodies(const Assembly& a, VerifyReport& r) {
    r.bodies = a.pieces.plan.steps.size();
    for (const mount::MountStep& step : a.pieces.plan.steps) {
        size_t pegs = 0;
        for (uint32_t p : step.pieces) pegs += r.pieces[p].pegsSeated;
        if (pegs >= 2) ++r.bodiesWithTwoPegs;
        if (step.pieces.size() > 1)
            for (uint32_t p : step.pieces) r.pieces[p].isGlued = true;
    }
    for (const auto& [host, piece] : a.pieces.plan.gluedOn) r.pieces[piece].isGluedOn = true;
    for (const PieceResult& p : r.pieces) {
        r.tenons += p.tenons;
        if (p.pegsSeated >= 2) ++r.piecesWithTwoPegs;
        if (p.isGlued) ++r.gluedPieces;
        if (p.isGluedOn) ++r.gluedOnPieces;
    }
}

}  // namespace

bool VerifyReport::passed() const {
    return std::all_of(checks.begin(), checks.end(), [](const CheckResult& c) { return c.passed(); });
}

Assembly readAssembly(const std::string& outDir) {
    const std::string framePath = (fs::path(outDir) / "frame.json").string();
    const std::string piecesPath = (fs::path(outDir) / "pieces" / pieces::kPiecesFile).string();
    Assembly a;
    Transform4d frameTransform;
    try {
        a.frame = zome::structureFromJsonText(readInputBytes(framePath), {}, {}, &frameTransform);
    } catch (const Error& e) {
        throw e.withFile(framePath);
    }
    a.pieces = pieces::readPieces(piecesPath);
    a.frameToGridMm = a.pieces.gridTransformMm * affineInverse(frameTransform);
    if (!isNearlyEqual(a.frameToGridMm, a.pieces.frameToGridMm, 1e-6))
        throw Error(
            ErrorCode::InvalidInput,
            "frame_to_grid_mm disagrees with the frame's and the shell's transform_mm: the pieces were "
            "not made for this frame",
            piecesPath);
    return a;
}

VerifyReport verifyAssembly(const Assembly& a, const VerifyOptions& o, const RunContext& context) {
    VerifyReport r;
    r.pieces.resize(a.pieces.pieces.size());
    for (uint32_t p = 0; p < r.pieces.size(); ++p) {
        r.pieces[p].piece = p;
        r.pieces[p].hole = a.pieces.pieces[p].hole;
        r.pieces[p].tenons = a.pieces.pieces[p].tenons.size();
    }
    context.progress("verify", 0.0);
    r.checks.push_back(checkPlan(a, r));
    detail::checkTenons(a, r);
    const std::vector<detail::PieceGeometry> geometry = detail::pieceGeometries(a.pieces);
    detail::checkPegs(a, geometry, o, r, context);
    context.progress("verify", 0.3);
    detail::checkStruts(a, geometry, o, r, context);
    context.progress("verify", 0.4);
    detail::checkPaths(a, geometry, o, r, context);
    countBodies(a, r);
    CheckResult held{"held",
                     "every piece or glued group held by a seated peg or glued onto a piece put on before it",
                     0,
                     {}};
    for (const mount::MountStep& step : a.pieces.plan.steps) {
        ++held.checked;
        size_t pegs = 0;
        bool isGluedOn = false;
        for (uint32_t p : step.pieces) pegs += r.pieces[p].pegsSeated, isGluedOn |= r.pieces[p].isGluedOn;
        if (pegs == 0 && !isGluedOn)
            held.failures.push_back("step " + std::to_string(&step - a.pieces.plan.steps.data() + 1) +
                                    " (piece " + std::to_string(step.pieces[0]) +
                                    "): no peg holds it and it is glued onto nothing");
    }
    r.checks.push_back(held);
    context.progress("verify", 1.0);
    return r;
}

nlohmann::json verifyReportJson(const VerifyReport& r) {
    nlohmann::json checks = nlohmann::json::array();
    for (const CheckResult& c : r.checks)
        checks.push_back({{"name", c.name},
                          {"what", c.what},
                          {"checked", c.checked},
                          {"passed", c.passed()},
                          {"failures", c.failures}});
    nlohmann::json pieces = nlohmann::json::array();
    for (const PieceResult& p : r.pieces)
        pieces.push_back({{"piece", p.piece},
                          {"step", p.step < 0 ? nlohmann::json(nullptr) : nlohmann::json(p.step + 1)},
                          {"hole", p.hole},
                          {"tenons", p.tenons},
                          {"pegs_seated", p.pegsSeated},
                          {"worst_axis_deg", p.worstAxisDeg},
                          {"worst_clearance_mm", p.worstClearanceMm},
                          {"glued", p.isGlued},
                          {"glued_on", p.isGluedOn}});
    return {{"passed", r.passed()},
            {"bodies", r.bodies},
            {"bodies_with_two_pegs", r.bodiesWithTwoPegs},
            {"pieces", r.pieces.size()},
            {"pieces_with_two_pegs", r.piecesWithTwoPegs},
            {"glued_pieces", r.gluedPieces},
            {"glued_on_pieces", r.gluedOnPieces},
            {"tenons", r.tenons},
            {"checks", checks},
            {"per_piece", pieces}};
}

std::vector<std::string> verifySummaryLines(const VerifyReport& r) {
    std::vector<std::string> lines;
    std::string ok;
    for (const CheckResult& c : r.checks)
        if (c.passed()) ok += (ok.empty() ? "" : ", ") + c.name + " (" + std::to_string(c.checked) + ")";
    lines.push_back("verify: " + std::to_string(r.pieces.size()) + " pieces in " + std::to_string(r.bodies) +
                    " mounting steps (" + std::to_string(r.gluedPieces) + " pieces glued into groups, " +
                    std::to_string(r.gluedOnPieces) + " glued onto pieces already on); " +
                    std::to_string(r.bodiesWithTwoPegs) + " of " + std::to_string(r.bodies) +
                    " steps held by 2 or more pegs; passed: " + (ok.empty() ? "none" : ok));
    for (const CheckResult& c : r.checks) {
        if (c.passed()) continue;
        lines.push_back("verify: FAILED " + c.name + " (" + c.what +
                        "): " + std::to_string(c.failures.size()) + " problem(s)");
        for (size_t i = 0; i < c.failures.size() && i < 10; ++i) lines.push_back("  " + c.failures[i]);
        if (c.failures.size() > 10)
            lines.push_back("  ... and " + std::to_string(c.failures.size() - 10) + " more");
    }
    return lines;
}

}  // namespace zomefab::verify
