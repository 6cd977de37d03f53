// SPDX-License-Identifier: GPL-3.0-or-later
// The fuzz corpora and every input a fuzzer ever crashed on (fuzz/corpus/<reader>/,
// fuzz/regressions/<reader>/), replayed through the same readers in the normal build: each is
// read or refused with a zomefab::Error, nothing else.
#include <doctest/doctest.h>

#include <filesystem>
#include <string>

#include "fuzz_readers.h"
#include "test_util.h"

namespace fs = std::filesystem;
using namespace zomefab;

namespace {

/// Replays every file under fuzz/<kind>/<reader>/; how many were read and how many refused.
std::pair<int, int> replay(const std::string& kind, const std::string& reader) {
    int read = 0, refused = 0;
    const fs::path dir = fs::path(ZOMEFAB_FUZZ_DIR) / kind / reader;
    if (!fs::is_directory(dir)) return {0, 0};
    for (const auto& entry : fs::directory_iterator(dir)) {
        if (!entry.is_regular_file()) continue;
        CAPTURE(entry.path().string());
        try {
            fuzz::readDocument(reader, test::readFile(entry.path().string()));
            ++read;
        } catch (const Error&) {
            ++refused;
        } catch (const std::exception& e) {
            FAIL_CHECK("not a zomefab::Error: " << e.what());
        }
    }
    return {read, refused};
}

}  // namespace

TEST_CASE("fuzz corpora: the seeds are read, the regressions refused or read, nothing else") {
    for (const char* reader : fuzz::kDocumentReaders) {
        CAPTURE(reader);
        const auto [seedsRead, seedsRefused] = replay("corpus", reader);
        CHECK(seedsRead >= 1);  // the seeds are valid files: the fuzzer starts from real ones
        CHECK(seedsRefused == 0);
        replay("regressions", reader);
    }
}
