// SPDX-License-Identifier: GPL-3.0-or-later
#include <doctest/doctest.h>

#include "zomefab/core/error.h"
#include "zomefab/core/run_context.h"

using namespace zomefab;

TEST_CASE("error: message names the file and maps to the documented exit code") {
    const Error e(ErrorCode::InvalidInput, "truncated binary STL", "bunny.stl");
    CHECK(std::string(e.what()) == "bunny.stl: truncated binary STL");
    CHECK(e.message() == "truncated binary STL");
    CHECK(exitCodeFor(e.code()) == 2);
    CHECK(exitCodeFor(ErrorCode::Usage) == 1);
    CHECK(exitCodeFor(ErrorCode::ProcessingFailed) == 3);
    CHECK(exitCodeFor(ErrorCode::WriteFailed) == 4);
    CHECK(exitCodeFor(ErrorCode::Cancelled) == 5);
    CHECK(std::string(Error(ErrorCode::Usage, "bad").withFile("x.obj").what()) == "x.obj: bad");
    CHECK(std::string(e.withFile("other.stl").what()) == "bunny.stl: truncated binary STL");
}

TEST_CASE("run_context: warnings are recorded and cancellation throws") {
    std::atomic<bool> cancel{false};
    std::vector<std::string> lines;
    RunContext ctx([&](LogLevel, const std::string& m) { lines.push_back(m); }, {}, &cancel);
    ctx.warn("dropped 2 degenerate triangles");
    CHECK(ctx.warnings().size() == 1);
    CHECK(lines.size() == 1);
    CHECK_NOTHROW(ctx.throwIfCancelled());
    cancel = true;
    CHECK_THROWS_AS(ctx.throwIfCancelled(), Error);
}
