// SPDX-License-Identifier: GPL-3.0-or-later
#include "stage_options.h"

#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/io/file_io.h"
#include "zomefab/zome/structure_json.h"

namespace zomefab::cli {

Vec3d parsePrinterMm(const std::string& text) {
    Vec3d v{};
    char s1 = 0, s2 = 0, rest = 0;
    std::istringstream in(text);
    const auto isSeparator = [](char c) { return c == 'x' || c == 'X' || c == ','; };
    if (!(in >> v[0] >> s1 >> v[1] >> s2 >> v[2]) || !isSeparator(s1) || !isSeparator(s2) || (in >> rest) ||
        !(v[0] > 0 && v[1] > 0 && v[2] > 0))
        throw Error(
            ErrorCode::Usage,
            "--printer-mm: expected three positive sizes in mm, e.g. 200x200x200, got \"" + text + "\"");
    return v;
}

partition::SalientSphere parseSalientSphere(const std::string& text) {
    partition::SalientSphere s;
    char c1 = 0, c2 = 0, c3 = 0, rest = 0;
    std::istringstream in(text);
    if (!(in >> s.centerMm[0] >> c1 >> s.centerMm[1] >> c2 >> s.centerMm[2] >> c3 >> s.radiusMm) ||
        c1 != ',' || c2 != ',' || c3 != ',' || (in >> rest) || !(s.radiusMm > 0))
        throw Error(ErrorCode::Usage, "--salient: expected x,y,z,r in mm with r > 0, got \"" + text + "\"");
    return s;
}

std::vector<uint32_t> readSalientFaceList(const std::string& path, size_t faceCount) {
    nlohmann::json j = nlohmann::json::parse(readInputBytes(path), nullptr, false);
    if (j.is_discarded()) throw Error(ErrorCode::InvalidInput, "invalid JSON", path);
    if (j.is_object() && j.contains("salient_faces")) j = j["salient_faces"];
    if (!j.is_array())
        throw Error(ErrorCode::InvalidInput, "expected a list of face indices or {\"salient_faces\": [...]}",
                    path);
    std::vector<uint32_t> faces;
    for (const nlohmann::json& v : j) {
        if (!v.is_number_unsigned() || v.get<uint64_t>() >= faceCount)
            throw Error(
                ErrorCode::InvalidInput,
                "salient face " + v.dump() + " is not a face index below " + std::to_string(faceCount), path);
        faces.push_back(v.get<uint32_t>());
    }
    return faces;
}

zome::Structure readFrame(const std::string& path, Transform4d* transformMm, const zome::ZomeScale& physical,
                          const zome::CollisionOptions& collision) {
    const std::string bytes = readInputBytes(path);
    try {
        return zome::structureFromJsonText(bytes, physical, collision, transformMm);
    } catch (const Error& e) {
        throw e.withFile(path);
    }
}

partition::PartitionFile readPartition(const std::string& path) {
    return partition::parsePartitionFile(readInputBytes(path), path);
}

// --- what the user is making ----------------------------------------------------------------------

void FabricationCli::addTo(CLI::App& app, unsigned parts) {
    Fabrication& f = fabrication;
    if (parts & kPrinter) {
        app.add_option("--printer-mm", printer, "Printer build volume WxDxH in mm")
            ->default_str(formatNumbers("%gx%gx%g", f.printerMm[0], f.printerMm[1], f.printerMm[2]));
        app.add_option("--fit-margin-mm", f.fitMarginMm,
                       "Grow each side of a piece's box by this before the fit test")
            ->capture_default_str();
        app.add_option("--bed-margin-mm", f.bedMarginMm,
                       "Free border on every side of the bed (mm): every piece fits the bed less it, "
                       "room for the slicer's supports and a skirt")
            ->capture_default_str();
        app.add_option("--overhang-deg", f.overhangDeg,
                       "Steepest overhang the printer prints without support, degrees from the vertical "
                       "(pieces' orientation and every print's supports in the cost report)")
            ->capture_default_str();
    }
    if (parts & kWall)
        wallOption =
            app.add_option("--shell-mm", f.wallMm,
                           "Shell wall thickness in mm: the plan's and the frame's (the paper: 16, its "
                           "d_min; the frame keeps wall + --wall-gap-mm from the surface); given, it is "
                           "also the printed wall unless --print-wall-mm says otherwise")
                ->capture_default_str();
    if (parts & kFrameClearance) {
        app.add_option("--frame-clearance-mm", f.frameClearanceMm,
                       "Forbidden zone dMin: no ball or strut closer to the surface (mm)")
            ->capture_default_str();
        app.add_option("--wall-gap-mm", f.wallGapMm,
                       "Air between the inner wall and the frame: dMin is at least wall + this (mm)")
            ->capture_default_str();
        app.add_option("--b0-mm", f.b0Mm,
                       "Length of the B0 strut, centre to centre (the kit's scale; dMax = b0)")
            ->capture_default_str();
    }
}

Fabrication FabricationCli::resolve(uint64_t seed) const {
    Fabrication f = fabrication;
    if (!printer.empty()) f.printerMm = parsePrinterMm(printer);
    f.seed = seed;
    checkFabrication(f);
    return f;
}

// --- input and level sets -------------------------------------------------------------------------

void ValidateCli::addTo(CLI::App& app) {
    app.add_flag("--repair", options.repair, "Close small holes of an open mesh");
}

void FieldCli::addTo(CLI::App& app) {
    app.add_option(
           "--voxel-mm", options.voxelMm,
           formatNumbers("Voxel of the object and shell level sets (at most %.2f for the tenon prisms)",
                         pieces::maxVoxelForTenonsMm(pieces::TenonOptions{})))
        ->capture_default_str();
    app.add_option("--field-voxel-mm", options.fieldVoxelMm,
                   "Voxel size of the interior grid (frame optimisation)")
        ->capture_default_str();
    app.add_option(
           "--max-memory-gb", options.maxMemoryGb,
           "Refuse a size whose grids would need more memory than this, GB (0 = 75 % of this machine's)")
        ->capture_default_str();
}

// --- frame (paper §4) -----------------------------------------------------------------------------

void FrameCli::addTo(CLI::App& app) {
    frame::FrameOptions& o = options;
    app.add_option("--chains", o.chains, "Annealing chains run in parallel; the best is kept")
        ->capture_default_str()
        ->check(CLI::Range(1, 4096));
    app.add_option("--iterations", o.anneal.maxIterations,
                   "Annealing iterations per chain (0 = until T < --t-end)")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--time-limit", o.anneal.timeLimitSeconds,
                   "Wall-clock budget per chain in seconds (0 = none; makes the result timing-dependent)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    app.add_option("--t-init", o.anneal.initialTemperature, "Initial temperature T_init")
        ->capture_default_str();
    app.add_option("--t-end", o.anneal.finalTemperature, "Stop when T < T_end (0 = only the budgets stop)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    app.add_option("--cooling", o.anneal.coolingFactor, "Cooling factor C")->capture_default_str();
    app.add_option("--cooling-interval", o.anneal.coolingIntervalIterations,
                   "Iterations between two cooling steps")
        ->capture_default_str();
    app.add_option("--w-fid", o.energy.fidelityWeight, "Weight of E_fid")->capture_default_str();
    app.add_option("--w-reg", o.energy.regularityWeight, "Weight of E_reg")->capture_default_str();
    app.add_option("--w-val", o.energy.valenceWeight, "Weight of E_val")->capture_default_str();
    app.add_option("--w-sim", o.energy.simplicityWeight, "Weight of E_sim")->capture_default_str();
    app.add_option("--tau", o.target.fixedTargetCount, "Fix the target item count τ (0 = estimate it)")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    app.add_option("--offset-steps", o.lattice.offsetSteps, "Lattice offsets tried per axis")
        ->capture_default_str()
        ->check(CLI::Range(1, 64));
    app.add_flag("--search-rotation", o.lattice.searchRotation,
                 "Also search the lattice rotation about the up axis");
    app.add_flag(
        "!--no-reach", o.reach.isEnabled,
        "Keep the annealed frame as it is (the paper's): no growth toward the surface it does not reach");
    app.add_option(
           "--reach-min-gain", o.reach.minGainSamples,
           "Grow the frame by a strut only where it reaches this many more surface samples (8 mm apart)")
        ->capture_default_str()
        ->check(CLI::Range(1, 100000));
    app.add_flag(
        "--check-moves", o.checkEveryMove,
        "Debug: after every accepted move verify the frame and compare ΔE with a full recomputation (slow)");
}

// --- partition (paper §5) -------------------------------------------------------------------------

void PartitionCli::addTo(CLI::App& app) {
    partition::PartitionOptions& o = options;
    app.add_option("--salient", salientSpheres,
                   "Keep the surface within a sphere whole: x,y,z,r in the frame's mm (repeatable)");
    app.add_option("--salient-faces", salientFacesFile,
                   "JSON list of salient face indices of the input mesh (or {\"salient_faces\": [...]})");
    app.add_option("-k,--candidates", o.candidateCount, "Candidate labels per triangle: its k nearest balls")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_option("--w-smoothness", o.smoothnessStart, "First w_smoothness of the fit schedule")
        ->capture_default_str();
    app.add_option("--w-smoothness-factor", o.smoothnessFactor,
                   "Multiply w_smoothness by this while a partition does not fit")
        ->capture_default_str();
    app.add_option("--w-smoothness-min", o.smoothnessMin, "The schedule bottoms out below this w_smoothness")
        ->capture_default_str();
    app.add_option("--w-saliency", o.saliencyWeight, "w_saliency")->capture_default_str();
    app.add_option("--min-piece-area-mm2", o.minPieceAreaMm2,
                   "Merge smaller pieces into a neighbour when it fits")
        ->capture_default_str();
    app.add_option("--svm-cost", o.svm.cost, "liblinear C for the planar cuts")->capture_default_str();
    app.add_option("--svm-samples", o.svmMaxSamples, "Train the planar cuts on at most this many faces")
        ->capture_default_str()
        ->check(CLI::PositiveNumber);
    app.add_flag("--one-vs-rest", isOneVsRest,
                 "One-vs-rest SVMs instead of Crammer-Singer (both give argmax cells)");
    app.add_option("--graph-nodes", o.graphNodeTarget,
                   "Cluster faces above this many graph-cut nodes (0 = never)")
        ->capture_default_str();
}

partition::PartitionOptions PartitionCli::resolve() const {
    partition::PartitionOptions o = options;
    for (const std::string& s : salientSpheres) o.salientSpheres.push_back(parseSalientSphere(s));
    o.svm.useCrammerSinger = !isOneVsRest;
    return o;
}

void PartitionCli::resolveSalientFaces(partition::PartitionOptions& o, size_t faceCount) const {
    if (!salientFacesFile.empty()) o.salientFaceIndices = readSalientFaceList(salientFacesFile, faceCount);
}

// --- pieces (paper §6) ----------------------------------------------------------------------------

void PiecesCli::addTo(CLI::App& app) {
    pieces::PiecesOptions& o = options;
    app.add_option("--min-piece-volume-mm3", o.minPieceVolumeMm3, "Merge smaller pieces into a neighbour")
        ->capture_default_str();
    app.add_option("--adaptivity", o.adaptivity,
                   "Meshing: 0 = uniform triangles; up to 1 merges flat regions")
        ->capture_default_str();
    app.add_option("--min-tenons", o.tenons.minPerPiece, "Tenons wanted per piece (fewer are reported)")
        ->capture_default_str();
    app.add_option("--max-tenons", o.tenons.maxPerPiece, "Most tenons per piece (0 = none)")
        ->capture_default_str();
    app.add_option("--tenon-clearance-mm", o.tenons.clearanceMm, "Gap between peg and hole on every side")
        ->capture_default_str();
    app.add_option("--tenon-width-mm", o.tenons.bodyWidthMm, "Side of the square prism")
        ->capture_default_str();
    app.add_option("--peg-depth-mm", o.tenons.pegDepthMm, "How far the peg enters the blue hole")
        ->capture_default_str();
    app.add_option("--tenon-max-length-mm", o.tenons.maxLengthMm, "Longest prism, ball face to inner surface")
        ->capture_default_str();
    app.add_option("--tenon-max-tilt-deg", o.tenons.maxTiltDeg,
                   "Largest angle between hole axis and surface normal")
        ->capture_default_str();
    app.add_option("--tenon-holes", tenonHoles,
                   "Directions pieces go on along and tenons use: lattice (+-x +-y +-z, as the paper), "
                   "blue (30) or all (62: blue, yellow, red)")
        ->capture_default_str()
        ->check(CLI::IsMember({"lattice", "blue", "all"}));
    app.add_option("--seam-gap-mm", o.seamGapMm, "Each cut face moved this far into its piece (glue gap)")
        ->capture_default_str();
    app.add_option("--mount-margin-mm", o.mount.frameMarginMm,
                   "Balls and struts are taken this much larger when a piece's path is tested")
        ->capture_default_str()
        ->check(CLI::NonNegativeNumber);
    app.add_flag("--recut-pairs", o.isRecuttingPairs,
                 "Cut a piece fewer than --min-tenons pegs hold anew with a neighbour so both are held "
                 "(more pegs, more support to print)");
    app.add_flag(
        "--cut-for-support", o.isCuttingForSupport,
        "Cut a held piece that needs much support however it lies in two, where both halves stay held "
        "and need much less support; else print it in two parts glued together before mounting");
    app.add_flag("--no-glue-groups", isNotGluing,
                 "Do not glue a piece fewer than --min-tenons pegs hold to a neighbour before mounting, nor print "
                 "pieces glued together as one");
    app.add_option("--print-wall-mm", printWall,
                   "Print each piece with this wall (mm) where its pegs reach through it; the plan and the "
                   "frame keep --shell-mm. auto: 1.8 where the shell allows it, the shell's wall when "
                   "--shell-mm is given; 0 = print the shell's wall; at most 2.5 at 1 mm voxels")
        ->capture_default_str();
    app.add_flag("--no-label", isUnlabelled, "Do not engrave piece numbers");
    app.add_option("--label-height-mm", o.label.heightMm, "Height of the engraved digits")
        ->capture_default_str();
    app.add_option("--label-depth-mm", o.label.depthMm, "Engraving depth")->capture_default_str();
}

pieces::PiecesOptions PiecesCli::resolve(bool isWallGiven) const {
    pieces::PiecesOptions o = options;
    if (printWall == "auto") {
        o.printWallMm = isWallGiven ? 0.0 : pieces::kPrintWallAuto;
    } else {
        char* end = nullptr;
        o.printWallMm = std::strtod(printWall.c_str(), &end);
        if (printWall.empty() || end != printWall.c_str() + printWall.size() ||
            !std::isfinite(o.printWallMm) || o.printWallMm < 0)
            throw Error(ErrorCode::Usage, std::string("--print-wall-mm must be ") + pieces::kPrintWallValues +
                                              ", not \"" + printWall + "\"");
    }
    o.label.isEnabled = !isUnlabelled;
    o.isGluingUnderHeld = !isNotGluing;
    o.tenons.holes = *pieces::tenonHolesFromName(tenonHoles);
    pieces::checkPiecesOptions(o);
    return o;
}

// --- cost report (paper §7.2) ---------------------------------------------------------------------

void CostCli::addTo(CLI::App& app) {
    report::CostOptions& cost = options;
    app.add_option(
           "--slicer", slicer,
           "Print times and filament from: estimator (built in) or prusa-slicer (runs it on every part)")
        ->capture_default_str()
        ->check(CLI::IsMember({"estimator", "prusa-slicer"}));
    app.add_option("--filament-mm", cost.filament.diameterMm, "Filament diameter")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--filament-g-per-cm3", cost.filament.densityGPerCm3, "Filament density")
        ->check(CLI::PositiveNumber)
        ->capture_default_str();
    app.add_option("--filament-usd-per-m", cost.filament.usdPerM, "Filament price per metre")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--strut-usd", cost.prices.strutUsd, "Price of one Zometool strut")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
    app.add_option("--ball-usd", cost.prices.ballUsd, "Price of one Zometool ball")
        ->check(CLI::NonNegativeNumber)
        ->capture_default_str();
}

report::CostOptions CostCli::resolve() const {
    report::CostOptions o = options;
    if (slicer == "prusa-slicer") o.source = report::EstimateSource::PrusaSlicer;
    report::checkCostOptions(o);
    return o;
}

// --- preview --------------------------------------------------------------------------------------

void PreviewCli::addTo(CLI::App& app) {
    app.add_flag("--no-draco", isUncompressed,
                 "Store the preview's pieces uncompressed (no KHR_draco_mesh_compression)");
    app.add_option("--draco-bits", options.glb.dracoPositionBits, "Draco position quantisation, bits")
        ->capture_default_str()
        ->check(CLI::Range(8, 30));
}

report::PreviewOptions PreviewCli::resolve() const {
    report::PreviewOptions o = options;
    o.isPieceDracoCompressed = !isUncompressed;
    return o;
}

}  // namespace zomefab::cli
