// SPDX-License-Identifier: GPL-3.0-or-later
// The options of `zomefab run` as the user gives them (tools/common/run_options.h): what the
// printed wall resolves to (docs/pieces.md, "1c").
#include "common/run_options.h"

#include <doctest/doctest.h>

#include "zomefab/core/error.h"

using namespace zomefab;

namespace {

/// `zomefab run m.stl -o out ARGS...` parsed and resolved.
pipeline::RunOptions runWith(std::vector<std::string> args) {
    CLI::App app("zomefab run");
    cli::RunCli run;
    run.addTo(app);
    args.insert(args.begin(), {"m.stl", "-o", "out"});
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 takes them last first
    app.parse(reversed);
    return run.resolve(1);
}

}  // namespace

TEST_CASE("run options: the printed wall is chosen by default, the shell's wall when --shell-mm is given") {
    CHECK(runWith({}).pieces.printWallMm == pieces::kPrintWallAuto);
    CHECK(runWith({"--shell-mm", "16"}).pieces.printWallMm == 0);  // the paper's setting
    CHECK(runWith({"--shell-mm", "16", "--print-wall-mm", "2.4"}).pieces.printWallMm == 2.4);
    CHECK(runWith({"--shell-mm", "10", "--print-wall-mm", "auto"}).pieces.printWallMm == 0);
    CHECK(runWith({"--print-wall-mm", "0"}).pieces.printWallMm == 0);
    CHECK(runWith({"--print-wall-mm", "2"}).pieces.printWallMm == 2);
    for (const char* bad : {"thin", "", "2.4mm", "-1", "nan", "0.5", "300"})
        CHECK_THROWS_WITH_AS(runWith({"--print-wall-mm", bad}),
                             doctest::Contains("--print-wall-mm must be auto"), Error);
    // zf-pieces has no --shell-mm: auto stays auto, resolved against the shell it reads.
    CHECK(cli::PiecesCli{}.resolve().printWallMm == pieces::kPrintWallAuto);
}
