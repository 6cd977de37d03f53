// SPDX-License-Identifier: GPL-3.0-or-later
#include "run_options.h"

#include "zomefab/core/error.h"

namespace zomefab::cli {

void RunCli::addTo(CLI::App& run) {
    run.add_option("mesh", input, "Closed mesh (.stl .obj .ply .gltf .glb); - reads stdin")->required();
    run.add_option("-o,--output", outDir, "Output directory (created; a previous zomefab output is replaced)")
        ->required();
    run.add_option("--in-format", inFormat, "Input format (for -)")
        ->check(CLI::IsMember({"stl", "obj", "ply", "gltf", "glb"}, CLI::ignore_case));
    scale.addTo(run);
    validate.addTo(run);
    fabrication.addTo(run, kAllFabrication);
    field.addTo(run);
    frame.addTo(run);
    partition.addTo(run);
    pieces.addTo(run);
    // zomefab run only: zf-pieces has no object grid to keep a grown frame clear of the surface in.
    run.add_flag("!--no-frame-growth", pieces.options.isGrowingFrame,
                 "Do not grow the frame toward a piece fewer than --min-tenons pegs hold (a strut to a new "
                 "ball whose hole meets the piece's wall)");
    cost.addTo(run);
    preview.addTo(run);
}

pipeline::RunOptions RunCli::resolve(uint64_t seed) const {
    pipeline::RunOptions o;
    o.fabrication = fabrication.resolve(seed);
    o.scale = scale.resolve();
    o.validate = validate.options;
    o.field = field.options;
    o.frame = frame.options;
    o.partition = partition.resolve();
    o.pieces = pieces.resolve(fabrication.isWallGiven());
    o.cost = cost.resolve();
    o.preview = preview.resolve();
    pipeline::checkRunOptions(o);
    return o;
}

void checkRunArguments(const std::vector<std::string>& args) {
    CLI::App app("zomefab run", "zomefab");
    uint64_t seed = 1;
    int threads = 0, verbose = 0;
    bool quiet = false;
    app.add_option("--seed", seed);
    app.add_option("--threads", threads)->check(CLI::NonNegativeNumber);
    app.add_flag("-v,--verbose", verbose);
    app.add_flag("-q,--quiet", quiet);
    RunCli run;
    run.addTo(app);
    // CLI11 takes the arguments last first: `unused.stl -o unused ARGS...` reversed.
    std::vector<std::string> reversed(args.rbegin(), args.rend());
    reversed.insert(reversed.end(), {"unused", "-o", "unused.stl"});
    try {
        app.parse(reversed);
    } catch (const CLI::ParseError& e) {
        throw Error(ErrorCode::Usage, e.what());
    }
    run.resolve(seed);
}

}  // namespace zomefab::cli
