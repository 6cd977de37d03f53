// SPDX-License-Identifier: GPL-3.0-or-later
// Damaged .vdb files through the four tools that read level sets (issue 18): bit flips anywhere in
// a file zomefab wrote, a huge length, a truncated header. Each is exit 2 with one line naming the
// file, no output, no signal, and a peak memory far below the 200 MB the issue allows.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "test_util.h"
#include "vdb_test_util.h"

using namespace zomefab;

namespace {

constexpr long kPeakLimitKb = 200 * 1024;

/// Damaged copies of @p good, each with a name for the messages.
std::vector<std::pair<std::string, std::string>> damagedVariants(const std::string& good) {
    std::vector<std::pair<std::string, std::string>> out;
    for (double at : {0.05, 0.25, 0.75}) {
        std::string bad = good;
        const size_t i = size_t(at * double(good.size()));
        bad[i] = char(bad[i] ^ 0x21);  // two bits
        out.emplace_back("two bits at " + std::to_string(int(at * 100)) + " %", bad);
    }
    std::string uuid = good;
    uuid[30] = char(uuid[30] ^ 0x01);
    out.emplace_back("one bit of the header", uuid);
    const size_t gridName = test::kVdbGridNameAt + test::kVdbChecksumEntryBytes;  // with the checksum entry
    out.emplace_back("huge grid-name length", test::withU32(good, gridName, 0xfffffff0u));
    out.emplace_back("truncated header", good.substr(0, 40));
    const std::string foreign = test::withoutVdbChecksum(good);
    out.emplace_back("huge grid-name length, no checksum",
                     test::withU32(foreign, test::kVdbGridNameAt, 0xfffffff0u));
    const size_t metaSize = foreign.find("class") + 5 + 4 + 6;
    out.emplace_back("huge metadata length, no checksum", test::withU32(foreign, metaSize, 0x7ffffff0u));
    out.emplace_back("truncated in the tree, no checksum", foreign.substr(0, foreign.size() / 2));
    return out;
}

}  // namespace

TEST_CASE("damaged .vdb: zf-shell, zf-mesh, zf-frame and zf-pieces refuse it in one line, in little memory") {
    test::ScratchDir dir("zomefab-damaged-vdb");
    const std::string object = dir.file("object.vdb"), shell = dir.file("shell.vdb");
    REQUIRE(test::runShell(test::toolPath("zf-sdf") + " " + test::dataPath("bunny_npm_3674.stl") +
                           " --height-mm 120 --up y --shell-mm 8 -q -o " + object) == 0);
    REQUIRE(test::runShell(test::toolPath("zf-shell") + " " + object + " --shell-mm 8 -q -o " + shell) == 0);
    test::writeBytes(dir.file("frame.json"), "{}");
    test::writeBytes(dir.file("partition.json"), "{}");
    const std::string out = dir.file("out");

    struct Reader {
        std::string tool;
        std::string good;  // the file it reads
        std::vector<std::string> extra;
    };
    const std::vector<Reader> readers = {
        {"zf-shell", test::readFile(object), {"--shell-mm", "8"}},
        {"zf-mesh", test::readFile(shell), {}},
        {"zf-frame", test::readFile(object), {}},
        {"zf-pieces", test::readFile(shell), {dir.file("frame.json"), dir.file("partition.json")}},
    };
    for (const Reader& r : readers) {
        for (const auto& [what, bytes] : damagedVariants(r.good)) {
            CAPTURE(r.tool);
            CAPTURE(what);
            const std::string input = dir.file("bad.vdb");
            test::writeBytes(input, bytes);
            std::vector<std::string> argv = {test::toolPath(r.tool), input};
            argv.insert(argv.end(), r.extra.begin(), r.extra.end());
            argv.insert(argv.end(), {"-o", r.tool == "zf-mesh"     ? out + ".stl"
                                           : r.tool == "zf-pieces" ? out
                                                                   : out + ".x"});
            const test::MeasuredRun run = test::runMeasured(argv);
            CHECK(run.signal == 0);
            CHECK(run.exitCode == 2);
            CHECK(run.peakRssKb < kPeakLimitKb);
            CHECK(run.stderrText.find(r.tool + ": error: " + input + ": ") == 0);
            CHECK(run.stderrText.find(".vdb stream") != std::string::npos);
            CHECK(std::count(run.stderrText.begin(), run.stderrText.end(), '\n') == 1);
            CHECK(!std::filesystem::exists(out + ".stl"));
            CHECK(!std::filesystem::exists(out + ".x"));
            CHECK(!std::filesystem::exists(out));
            if (run.exitCode != 2) MESSAGE(run.stderrText);
        }
    }
}
