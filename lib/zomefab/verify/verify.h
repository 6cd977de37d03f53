// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The project's own check that an output can be built (docs/mounting.md, "The verifier"):
/// from the written files alone (frame.json, pieces/pieces.json and the piece STLs) it recomputes
/// what a maker needs: every peg points along its piece's direction and fits its hole with the
/// clearance, no printed material but a peg enters a ball or a strut, every piece (or glued group)
/// can be pushed on along its direction without touching the frame or the pieces mounted before it,
/// and every one is held. It shares no code with the planner that made the plan except the Zome
/// tables and the depth rasters: the planner works on voxels and grown proxies, the verifier on
/// the printed triangles and the real radii.
///
/// @code
///   const verify::Assembly a = verify::readAssembly("out/bunny");
///   const verify::VerifyReport r = verify::verifyAssembly(a, {}, context);
///   if (!r.passed()) for (const std::string& line : verify::verifySummaryLines(r)) std::cerr << line <<
///   "\n";
/// @endcode
#pragma once

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/core/transform.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/zome/structure.h"

namespace zomefab::verify {

struct VerifyOptions {
    double pixelMm = 0.5;           ///< pixels of the path rasters
    double axisToleranceDeg = 1.0;  ///< a peg's measured axis may be this far from its direction
    /// A printed surface may reach this far into a ball or a strut, or past a hole's clearance,
    /// before it counts: the mesher's rounding (mm).
    double materialToleranceMm = 0.1;
    /// Overlap tolerated between a moving piece and one mounted before it: the two meshes of a
    /// shared cut face lie on one plane, a few hundredths of a millimetre apart (mm).
    double orderToleranceMm = 0.3;
    /// In that test both are drawn with their shadows shrunk by this (mm): a face slid along at a
    /// grazing angle, seen nearly edge-on, then draws nothing (docs/mounting.md).
    double orderShrinkMm = 0.2;
    /// Depth of the hole behind each ball face: our assumption (ZomeFab's LATCH 4 mm, plus 0.5 mm
    /// of room at the tip), mm.
    double holeDepthMm = 4.5;
    /// A peg is seated when it reaches this deep into its hole (mm; the design is 4).
    double minSeatedDepthMm = 3.0;
};

/// What the verifier checks: the frame in its own mm and the pieces as read back (meshes in
/// printer coordinates, each with its grid → printer transform).
struct Assembly {
    zome::Structure frame;
    Transform4d frameToGridMm;  ///< from the two files' transform_mm, not from pieces.json's copy
    pieces::Pieces pieces;
};

/// Reads @p outDir's frame.json and pieces/pieces.json with the piece STLs.
/// @throw Error(InvalidInput) naming the file that is missing or malformed.
Assembly readAssembly(const std::string& outDir);

/// One check over every piece, body or tenon it applies to.
struct CheckResult {
    std::string name;                   ///< "peg axes", "free path", ...
    std::string what;                   ///< one line: what it tests
    size_t checked = 0;                 ///< items it was applied to
    std::vector<std::string> failures;  ///< one line each, "piece 3: ..."
    bool passed() const { return failures.empty(); }
};

/// What the verifier measured on one piece.
struct PieceResult {
    uint32_t piece = 0;
    int step = -1;                ///< its mounting step (0-based), −1 when in none
    int hole = -1;                ///< its direction
    size_t tenons = 0;            ///< tenons pieces.json lists
    size_t pegsSeated = 0;        ///< pegs found in their hole at least minSeatedDepthMm deep
    double worstAxisDeg = 0.0;    ///< largest measured deviation of a peg from the direction
    double worstClearanceMm = 0;  ///< smallest gap found between a peg and its hole's walls
    bool isGlued = false;         ///< part of a glued group
    bool isGluedOn = false;       ///< glued onto a piece put on before it (no peg may hold it)
};

struct VerifyReport {
    std::vector<CheckResult> checks;
    std::vector<PieceResult> pieces;
    size_t bodies = 0;             ///< mounting steps: pieces or glued groups
    size_t bodiesWithTwoPegs = 0;  ///< held by at least two seated pegs
    size_t piecesWithTwoPegs = 0;
    size_t gluedPieces = 0;
    size_t gluedOnPieces = 0;
    size_t tenons = 0;
    bool passed() const;
};

/// Every check (docs/mounting.md, "The verifier"). Serial over checks, parallel inside.
VerifyReport verifyAssembly(const Assembly& assembly, const VerifyOptions& options,
                            const RunContext& context);

nlohmann::json verifyReportJson(const VerifyReport& report);
/// "verify: 11 pieces in 7 steps: peg axes ok (32), ..., FAILED free path: piece 3: ..." lines.
std::vector<std::string> verifySummaryLines(const VerifyReport& report);

}  // namespace zomefab::verify
