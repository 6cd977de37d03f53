// SPDX-License-Identifier: GPL-3.0-or-later
/// @file libFuzzer entry point for one document reader of fuzz_readers.h, named at compile time by
/// ZOMEFAB_FUZZ_READER ("frame", "partition", "pieces", "manifest" or "vdb").
#include <cstdint>
#include <string_view>

#include "fuzz_readers.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    try {
        zomefab::fuzz::readDocument(ZOMEFAB_FUZZ_READER,
                                    std::string_view(reinterpret_cast<const char*>(data), size));
    } catch (const zomefab::Error&) {
    }
    return 0;
}
