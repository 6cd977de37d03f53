// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/pipeline/pipeline.h"

#include <algorithm>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/version.h"
#include "zomefab/frame/frame.h"
#include "zomefab/frame/frame_field.h"
#include "zomefab/frame/outermost.h"
#include "zomefab/frame/reach.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/report/run_report.h"
#include "zomefab/sdf/interior_field.h"
#include "zomefab/zome/parts.h"

namespace zomefab::pipeline {

namespace {

/// Runs @p body as stage @p name: progress at its start and end, its wall time recorded.
template <class Body>
auto timedStage(const std::string& name, report::RunRecord& run, RunContext& context, Body&& body) {
    context.throwIfCancelled();
    context.progress(name, 0.0);
    Stopwatch clock;
    auto value = body();
    run.timings.push_back({name, clock.seconds()});
    context.progress(name, 1.0);
    return value;
}

/// Errors that stages raise about the object itself belong to the input file.
template <class Body>
auto aboutInput(const std::string& sourceName, Body&& body) {
    try {
        return body();
    } catch (const Error& e) {
        if (e.code() == ErrorCode::Usage || e.code() == ErrorCode::Cancelled ||
            e.code() == ErrorCode::Internal)
            throw;
        throw e.withFile(sourceName);
    }
}

/// Stage 2: level sets of the object (paper §6), exact as deep as the wall.
void levelSets(report::RunRecord& run, const RunOptions& options, RunContext& context) {
    run.field = timedStage("level sets", run, context, [&] {
        return aboutInput(run.sourceName, [&] {
            sdf::ObjectField field =
                sdf::makeObjectField(run.scaled.mesh, run.fabrication, options.field, context);
            for (sdf::LevelSet* levelSet : {&field.object, &field.interior}) {
                levelSet->info().sourceFile = run.sourceName;
                levelSet->info().generator = generatorString();
                levelSet->info().transformMm = run.scaled.transformMm;
            }
            return field;
        });
    });
    run.shell = timedStage("shell", run, context, [&] {
        sdf::LevelSet shell = sdf::makeShell(run.field.object, run.fabrication, context);
        shell.info().generator = generatorString();
        return shell;
    });
}

/// Stage 4: the frame (paper §4), in the frame's millimetres (the lattice may be rotated). Returns
/// the interior field, which the pieces stage grows the frame in.
sdf::InteriorField buildFrame(report::RunRecord& run, const RunOptions& options, RunContext& context) {
    sdf::InteriorField interior = sdf::makeInteriorField(run.field.interior, context);
    run.frame = timedStage("frame", run, context, [&] {
        return aboutInput(run.sourceName, [&] {
            return frame::buildFrame(interior, run.fabrication, options.frame, context);
        });
    });
    run.frameTransformMm = frame::frameTransformMm(run.scaled.transformMm, run.frame.rotationDeg);
    const frame::FrameField field(interior, run.frame.rotationDeg, run.frame.structure.scale(),
                                  run.frame.zone);
    run.frameMetrics = frame::measureFrame(run.frame.structure, field, options.frame.surfaceSampleSpacingMm);
    return interior;
}

/// Stage 5: the surface partition (paper §5) of the outer surface, in frame coordinates.
void partitionSurface(report::RunRecord& run, const RunOptions& options, RunContext& context) {
    run.surfaceFrameMm = run.scaled.mesh;
    transformInPlace(run.surfaceFrameMm, frame::rotationAboutZ(-run.frame.rotationDeg));
    run.partition = timedStage("partition", run, context, [&] {
        return aboutInput(run.sourceName, [&] {
            return partition::partitionSurface(run.surfaceFrameMm, run.frame.structure,
                                               frame::outermostBalls(run.frame.structure), run.fabrication,
                                               options.partition, context);
        });
    });
}

/// Stage 6: printable pieces (paper §6): the shell cut by the partition's cells, with tenons. The
/// frame may grow toward pieces too few pegs hold (in @p interior, with the frame stage's clearance
/// and collision tests); the grown frame is the one built and written.
void makePieces(report::RunRecord& run, const RunOptions& options, RunContext& context,
                const sdf::InteriorField& interior) {
    const frame::FrameField field(interior, run.frame.rotationDeg, run.frame.structure.scale(),
                                  run.frame.zone);
    const pieces::StrutTest canGrow = [&](const zome::Structure& s, zome::BallId a, int hole, int size) {
        return frame::canGrowStrut(s, field, a, hole, size);
    };
    run.pieces = timedStage("pieces", run, context, [&] {
        const Transform4d frameToGridMm = run.shell.info().transformMm * affineInverse(run.frameTransformMm);
        return pieces::makePieces(run.shell, run.frame.structure, frameToGridMm, run.partition,
                                  run.fabrication, options.pieces, context, canGrow);
    });
    pieces::requireBuildable(run.pieces);  // exit 3 with the plan's reasons; nothing is written
    if (run.pieces.grownFrame) {
        run.frame.structure = std::move(*run.pieces.grownFrame);
        run.pieces.grownFrame.reset();
        run.frameMetrics =
            frame::measureFrame(run.frame.structure, field, options.frame.surfaceSampleSpacingMm);
    }
    run.plates = pieces::packPlates(run.pieces);
}

/// How often the partition runs again for a piece that came out too large.
constexpr int kMaxRefits = 3;
/// By how much each of those runs grows the fit margin (mm; each side of a region's box).
constexpr double kReplanMarginStepMm = 3.0;
/// A run again that leaves at least this many problems more than the plan before it (and half as
/// many again) is the last (shouldPartitionAgain).
constexpr size_t kReplanProblemRise = 5;
/// The largest tenon tilt of those runs (degrees; pieces::TenonOptions::maxTiltDeg, default 60).
constexpr double kReplanTiltDeg = 35.0;

/// Why a frame with no whole B0 cube (a row or a square of balls) holds too few pieces, and how much
/// larger the object would hold a cube for sure (frame::cubeDepthMm against its deepest point).
std::string thinFrameReason(const report::RunRecord& run, const RunOptions& options,
                            const sdf::InteriorField& interior) {
    const double deepestMm = frame::deepestDepthMm(interior);
    const double cubeMm =
        frame::cubeDepthMm(frame::latticeOptionsFor(run.fabrication, options.frame.lattice));
    std::string depth;
    if (deepestMm > 0 && deepestMm < cubeMm)
        depth = formatNumbers(": its deepest point is %.1f mm inside, and a cube there needs %.1f mm",
                              deepestMm, cubeMm) +
                formatNumbers(" (the object scaled up %.2f times, --height-mm, holds one for sure)",
                              cubeMm / deepestMm);
    return "the object is thinner than one B0 cube and its " +
           formatNumbers("%.0f", run.fabrication.frameDMinMm()) + " mm clearance" + depth +
           ", so its frame is only " + std::to_string(run.frame.structure.ballCount()) + " balls and " +
           std::to_string(run.frame.structure.strutCount()) + " struts, too few to hold every piece";
}

/// Stages 5 and 6. A piece is its region of the surface plus the wall, the tenons and the pegs
/// inside it; now and then (seen at 700 mm: 3.1 mm) that is larger than the region the partition
/// fitted to the printer. The partition then runs again with its fit margin grown by the overshoot
/// (the margin grows each side of a region's box, so half of it, plus 1 mm), so the user gets
/// pieces instead of an error. Pieces that can be put on in no order (two that interlock, each in
/// the other's way along every direction that holds it, and no glue or cut the pieces stage tries
/// frees them) are a fact of these cuts, not of the object: the partition runs again with a larger
/// fit margin, whose smaller regions are cut elsewhere (the armadillo at 550 mm: no order at a
/// 2 mm or 4 mm margin, 18 pieces put on at 7 mm). With it the tenons keep to the paper's near-
/// perpendicular kReplanTiltDeg when the user allowed more: a wider tilt gives more pieces pegs
/// along more directions, and at 550 mm the armadillo's pieces then chose directions that lock
/// each other at every margin tried (2, 5, 8, 11 mm), while at 35° a 5 mm margin put them on.
/// Not when most pieces placed nowhere line tunnels that cross (NotBuildable::isInTheObject): other
/// cuts leave those tunnels as they are (the cheese at 700 mm: three partitions, each as stuck).
void partitionAndCut(report::RunRecord& run, const RunOptions& options, RunContext& context,
                     const sdf::InteriorField& interior) {
    int refits = 0, replans = 0;
    size_t problemsBefore = 0;     // of the last plan with no order, before the latest run again
    RunOptions attempt = options;  // the tenon tilt narrows on a replan; pieces.json records it
    for (;;) {
        partitionSurface(run, options, context);
        try {
            makePieces(run, attempt, context, interior);
            return;
        } catch (const pieces::NotBuildable& e) {
            // A frame of a few balls in a row (no B0 cube fits) reaches little of a large surface:
            // say first that this, not the plan, is why.
            if (run.frame.lattice.cubes == 0)
                throw pieces::NotBuildable(thinFrameReason(run, options, interior) + "; " + e.message(),
                                           e.problemCount());
            if (e.isInTheObject()) throw;  // tunnels that cross: other cuts do not free their linings
            if (!shouldPartitionAgain(replans, problemsBefore, e.problemCount())) {
                if (replans >= kMaxReplans) throw;
                throw pieces::NotBuildable(
                    e.message() +
                        formatNumbers(
                            " (partitioning again for smaller pieces, with a fit margin of %.1f mm, "
                            "left many more problems than before, ",
                            run.fabrication.fitMarginMm) +
                        std::to_string(e.problemCount()) + " against " + std::to_string(problemsBefore) +
                        ": smaller pieces do not free these)",
                    e.problemCount());
            }
            ++replans;
            problemsBefore = e.problemCount();
            const double before = run.fabrication.fitMarginMm;
            run.fabrication.fitMarginMm = before + kReplanMarginStepMm;
            double& tiltDeg = attempt.pieces.tenons.maxTiltDeg;
            const std::string tilt = tiltDeg > kReplanTiltDeg
                                         ? formatNumbers(
                                               " and tenons at most %.0f° off the wall's normal "
                                               "(was %.0f°)",
                                               kReplanTiltDeg, tiltDeg)
                                         : "";
            tiltDeg = std::min(tiltDeg, kReplanTiltDeg);
            context.info(
                e.message() +
                formatNumbers("; partitioning again for smaller pieces, with a fit margin of %.1f mm "
                              "(was %.1f)",
                              run.fabrication.fitMarginMm, before) +
                tilt);
        } catch (const pieces::PieceTooLarge& e) {
            if (++refits > kMaxRefits) throw;
            const double before = run.fabrication.fitMarginMm;
            run.fabrication.fitMarginMm = before + 0.5 * e.overshootMm + 1.0;
            context.info(
                formatNumbers("a piece came out %.1f mm larger than the printer in every orientation; "
                              "partitioning again with a fit margin of %.1f mm (was %.1f)",
                              e.overshootMm, run.fabrication.fitMarginMm, before));
        }
    }
}

/// Stage 7: what the user reads (paper §7): the assembly guide and the cost report (Table 1).
void reportRun(report::RunRecord& run, const RunOptions& options, RunContext& context) {
    report::RunReports reports = timedStage("report", run, context, [&] {
        return report::reportStage(run.frame.structure, run.pieces, run.scaled.mesh, run.fabrication,
                                   options.cost, context);
    });
    run.assembly = std::move(reports.assembly);
    run.cost = std::move(reports.cost);
}

}  // namespace

bool shouldPartitionAgain(int replansDone, size_t problemsBefore, size_t problemsNow) {
    if (replansDone >= kMaxReplans) return false;
    // A few problems more or less come and go with the cuts (the armadillo at 600 mm: 2, then 2,
    // then none); only a clear rise says smaller pieces are not the cure.
    const size_t rise = std::max<size_t>(kReplanProblemRise, problemsBefore / 2);
    return replansDone == 0 || problemsNow < problemsBefore + rise;
}

void checkRunOptions(const RunOptions& options) {
    checkFabrication(options.fabrication);
    mesh::checkScaleOptions(options.scale);
    sdf::checkObjectFieldOptions(options.field);
    zome::ZomeScale scale = options.frame.lattice.scale;
    scale.b0Mm = options.fabrication.b0Mm;
    partition::checkPartitionOptions(options.partition, options.fabrication, scale);
    pieces::checkPiecesOptions(options.pieces);
    if (options.frame.chains < 1) throw Error(ErrorCode::Usage, "--chains must be at least 1");
    // The pieces stage would find this out only after the level sets; say it before any work.
    const double maxVoxelMm = pieces::maxVoxelForTenonsMm(options.pieces.tenons);
    if (options.pieces.tenons.maxPerPiece > 0 && options.field.voxelMm > maxVoxelMm)
        throw Error(ErrorCode::Usage,
                    "--voxel-mm " + formatNumbers("%g", options.field.voxelMm) + ": the tenon prisms (" +
                        formatNumbers("%.2f", options.pieces.tenons.bodyWidthMm) +
                        " mm wide) need a voxel of at most " + formatNumbers("%.2f", maxVoxelMm) + " mm");
    report::checkCostOptions(options.cost);
}

report::RunRecord runPipeline(const TriMesh& input, const std::string& sourceName, const RunOptions& options,
                              RunContext& context) {
    checkRunOptions(options);
    report::RunRecord run;
    run.sourceName = sourceName;
    run.fabrication = options.fabrication;
    Stopwatch total;
    // Stage 1: validate and scale (paper §3: the input is a closed mesh at its target size).
    run.scaled = timedStage("input", run, context, [&] {
        run.inputReport = mesh::checkMesh(input);
        TriMesh valid = mesh::validateClosedMesh(input, options.validate, sourceName, context);
        return mesh::scaleToMillimetres(std::move(valid), options.scale);
    });
    levelSets(run, options, context);
    const sdf::InteriorField interior = buildFrame(run, options, context);
    partitionAndCut(run, options, context, interior);
    reportRun(run, options, context);
    run.totalSeconds = total.seconds();
    return run;
}

}  // namespace zomefab::pipeline
