// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zf-zome: check a frame file (validity, collisions, parts list), export it to vZome's VEF,
/// or print its parts list. Parse, read, call, write; the model lives in lib/zomefab/zome.
#include <cstdio>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"
#include "zomefab/zome/parts.h"
#include "zomefab/zome/structure_json.h"

using namespace zomefab;

int main(int argc, char** argv) {
    cli::Tool tool("zf-zome", "Check a Zometool frame file, export it to vZome VEF, or list its parts");
    CLI::App& app = tool.app();
    app.require_subcommand(1);

    std::string input, output = "-";
    zome::ZomeScale physical;
    zome::CollisionOptions collision;
    zome::PriceOptions prices;

    CLI::App* check = app.add_subcommand("check", "Validate FRAME.json, find collisions, list parts (JSON)");
    CLI::App* vef = app.add_subcommand("vef", "Export FRAME.json to vZome's VEF text format");
    CLI::App* parts = app.add_subcommand("parts", "Print the parts list as a table like the paper's Table 2");
    for (CLI::App* sub : {check, vef, parts}) {
        sub->fallthrough();  // the common options (-q, -v, --report, ...) also work after the subcommand
        sub->add_option("frame", input, "Frame file (zomefab.structure JSON, - = stdin)")->required();
        sub->add_option("-o,--output", output, "Output file (- = stdout)")->default_val("-");
    }
    check->add_option("--clearance-mm", collision.clearanceMm, "Extra gap required between parts, mm")
        ->default_val(collision.clearanceMm)
        ->check(CLI::NonNegativeNumber);
    check->add_option("--ball-diameter-mm", physical.ballDiameterMm, "Ball diameter for collisions, mm")
        ->default_val(physical.ballDiameterMm)
        ->check(CLI::PositiveNumber);
    check->add_option("--blue-radius-mm", physical.blueRadiusMm, "Blue strut capsule radius, mm")
        ->default_val(physical.blueRadiusMm)
        ->check(CLI::NonNegativeNumber);
    check->add_option("--yellow-radius-mm", physical.yellowRadiusMm, "Yellow strut capsule radius, mm")
        ->default_val(physical.yellowRadiusMm)
        ->check(CLI::NonNegativeNumber);
    check->add_option("--red-radius-mm", physical.redRadiusMm, "Red strut capsule radius, mm")
        ->default_val(physical.redRadiusMm)
        ->check(CLI::NonNegativeNumber);
    for (CLI::App* sub : {check, parts}) {
        sub->add_option("--strut-usd", prices.strutUsd, "Price of one strut, USD")
            ->default_val(prices.strutUsd)
            ->check(CLI::NonNegativeNumber);
        sub->add_option("--ball-usd", prices.ballUsd, "Price of one ball, USD")
            ->default_val(prices.ballUsd)
            ->check(CLI::NonNegativeNumber);
    }

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        const Stopwatch clock;
        const zome::Structure frame = cli::readFrame(input, nullptr, physical, collision);
        report["input"] = input;
        report["balls"] = frame.ballCount();
        report["struts"] = frame.strutCount();
        const std::string summary = input + ": " + std::to_string(frame.ballCount()) + " balls, " +
                                    std::to_string(frame.strutCount()) + " struts";

        if (check->parsed()) {
            const std::vector<zome::Collision> collisions = zome::findCollisions(frame);
            const zome::PartsList list = zome::partsList(frame);
            const nlohmann::json out = zome::checkReportJson(frame, input, collisions, prices);
            tool.writeJsonOutput(output, out);
            report["collisions"] = collisions.size();
            report["seconds"] = clock.seconds();
            if (!collisions.empty()) {
                // The report is written (it lists every pair); the exit code says "not buildable".
                std::fprintf(stderr, "zf-zome: error: %s: %zu collision%s, first: %s\n", input.c_str(),
                             collisions.size(), collisions.size() == 1 ? "" : "s",
                             zome::describeCollision(collisions.front()).c_str());
                return exitCodeFor(ErrorCode::ProcessingFailed);
            }
            char cost[64];
            std::snprintf(cost, sizeof cost, "%.2f USD", zome::partsCostUsd(list, prices));
            cli::printInfo(tool, summary + ", 0 collisions, parts cost " + cost);
        } else if (vef->parsed()) {
            const std::string text = zome::structureToVef(frame);
            tool.writeOutput(output, [&](std::ostream& out) { out << text; });
            cli::printInfo(tool, summary + " -> " + output);
        } else {
            const std::string table = zome::partsTable(zome::partsList(frame), prices);
            tool.writeOutput(output, [&](std::ostream& out) { out << table; });
            cli::printInfo(tool, summary);
        }
        report["seconds"] = clock.seconds();
        return 0;
    });
}
