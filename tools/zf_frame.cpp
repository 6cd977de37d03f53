// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-frame: the Zometool frame of an object (paper §4). Reads the "interior" grid of a .vdb
/// written by zf-sdf, builds the B0 cube lattice, anneals it with parallel chains and writes the
/// frame file (zomefab.structure JSON, docs/formats.md) plus, with --report, the run's report.
#include <cstdio>
#include <string>

#include "common/cli.h"
#include "zomefab/core/error.h"
#include "zomefab/frame/frame.h"
#include "zomefab/io/file_io.h"
#include "zomefab/sdf/vdb_file.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;

int main(int argc, char** argv) {
    cli::Tool tool("zf-frame", "Fill an object with a Zometool frame: B0 cube lattice + simulated annealing");
    CLI::App& app = tool.app();
    std::string input, output, gridName = "interior";
    frame::FrameOptions o;
    bool checkMoves = false;
    app.add_option("object", input, "OBJECT.vdb from zf-sdf (- reads stdin)")->required();
    app.add_option("-o,--output", output, "Output frame file FRAME.json (- writes stdout)")->required();
    app.add_option("--grid", gridName, "Level set to read")->capture_default_str();
    app.add_option("--chains", o.chains, "Independent annealing chains run in parallel; the best is kept")
        ->capture_default_str()->check(CLI::Range(1, 4096));
    app.add_option("--iterations", o.anneal.maxIterations,
                   "Iteration budget per chain (0 = until T < --t-end)")->capture_default_str();
    app.add_option("--time-limit", o.anneal.timeLimitSeconds,
                   "Wall-clock budget per chain in seconds (0 = none; makes the result timing-dependent)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    app.add_option("--t-init", o.anneal.initialTemperature, "Initial temperature T_init")->capture_default_str();
    app.add_option("--t-end", o.anneal.finalTemperature, "Stop when T < T_end (0 = only the budgets stop)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    app.add_option("--cooling", o.anneal.coolingFactor, "Cooling factor C")->capture_default_str();
    app.add_option("--cooling-interval", o.anneal.coolingIntervalIterations,
                   "Iterations between two cooling steps")->capture_default_str();
    app.add_option("--w-fid", o.energy.fidelityWeight, "Weight of E_fid")->capture_default_str();
    app.add_option("--w-reg", o.energy.regularityWeight, "Weight of E_reg")->capture_default_str();
    app.add_option("--w-val", o.energy.valenceWeight, "Weight of E_val")->capture_default_str();
    app.add_option("--w-sim", o.energy.simplicityWeight, "Weight of E_sim")->capture_default_str();
    app.add_option("--tau", o.target.fixedTargetCount, "Fix the target item count τ (0 = estimate it)")
        ->capture_default_str()->check(CLI::NonNegativeNumber);
    app.add_option("--d-min-mm", o.lattice.zone.dMinMm, "Forbidden zone dMin")->capture_default_str();
    app.add_option("--d-max-mm", o.lattice.zone.dMaxMm, "Forbidden zone dMax")->capture_default_str();
    app.add_option("--offset-steps", o.lattice.offsetSteps, "Lattice offsets tried per axis")
        ->capture_default_str()->check(CLI::Range(1, 64));
    app.add_flag("--search-rotation", o.lattice.searchRotation, "Also search the lattice rotation about the up axis");
    app.add_flag("--check-moves", checkMoves,
                 "Debug: after every accepted move verify the frame and compare ΔE with a full recomputation (slow)");

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        RunContext& context = tool.context();
        o.seed = tool.common().seed;
        const std::string bytes = readInputBytes(input);
        const std::vector<sdf::LevelSet> grids = sdf::parseVdb(bytes, input, context);
        const sdf::LevelSet& levelSet = sdf::findLevelSet(grids, gridName, input);
        const sdf::InteriorField field = sdf::makeInteriorField(levelSet, context);

        o.checkEveryMove = checkMoves;
        const frame::FrameResult result = frame::buildFrame(field, o, context);
        const frame::FrameField ff(field, result.rotationDeg, result.lattice.structure.scale(), o.lattice.zone);
        const frame::FrameMetrics before = frame::measureFrame(result.lattice.structure, ff, o.surfaceSampleSpacingMm);
        const frame::FrameMetrics after = frame::measureFrame(result.structure, ff, o.surfaceSampleSpacingMm);
        report = frame::frameReportJson(result, o, before, after);
        report["input"] = input;
        report["output"] = output;
        const Transform4d transformMm = frame::frameTransformMm(levelSet.info().transformMm, result.rotationDeg);
        const nlohmann::json frameJson = zome::structureToJson(result.structure, transformMm);
        writeOutputAtomic(output, [&](std::ostream& out) { out << frameJson.dump(1) << '\n'; });

        const zome::PartsList parts = zome::partsList(result.structure);
        char buf[256];
        std::snprintf(buf, sizeof buf, "%zu balls, %zu struts; E %.4f -> %.4f (tau %.0f); %llu iterations in %.2f s",
                      parts.balls, parts.strutTotal(), result.initialEnergy.total, result.finalEnergy.total,
                      result.target.targetItemCount,
                      (unsigned long long)report["iterations"].get<uint64_t>(), result.annealSeconds);
        cli::printInfo(tool, buf);
        return 0;
    });
}
