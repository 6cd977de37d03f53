// SPDX-License-Identifier: GPL-3.0-or-later
// write_tool_inputs DIR: the zf-pieces inputs of pieces_fixtures.h, for the CLI tests.
// The fixtures use the shared mesh builders of tests/test_util (zomefab_test_main), whose header
// includes doctest: this program carries doctest's implementation, but not its main, so that
// the linker never pulls in doctest's main from zomefab_test_main.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>

#include <cstdio>
#include <exception>

#include "pieces_fixtures.h"

int main(int argc, char** argv) {
    if (argc != 2) {
        std::fprintf(stderr, "usage: write_tool_inputs DIR\n");
        return 1;
    }
    try {
        zomefab::pieces::test::writeToolInputs(argv[1]);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "write_tool_inputs: %s\n", e.what());
        return 1;
    }
    return 0;
}
