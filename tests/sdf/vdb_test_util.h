// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Damaging .vdb bytes on purpose, for the reader's tests.
#pragma once

#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <string>

namespace zomefab::test {

/// The same grids without zomefab's checksum: the file metadata entry dropped and the UUID mark
/// broken, which is what a file from another program looks like to the reader.
inline std::string withoutVdbChecksum(std::string bytes) {
    const size_t uuid = 21, meta = 57;  // header: magic 8, versions 12, offsets flag 1; UUID 36
    bytes[uuid] = 'f';
    uint32_t count;
    std::memcpy(&count, &bytes[meta], 4);
    REQUIRE(count == 1);
    REQUIRE(bytes.compare(meta + 8, 13, "zomefab_crc32") == 0);
    const size_t entry = 4 + 13 + 4 + 6 + 4 + 8;  // name, type "string", size, 8 hex digits
    count = 0;
    std::memcpy(&bytes[meta], &count, 4);
    bytes.erase(meta + 4, entry);
    return bytes;
}

/// @p bytes with the uint32 at @p at set to @p value.
inline std::string withU32(std::string bytes, size_t at, uint32_t value) {
    std::memcpy(&bytes[at], &value, 4);
    return bytes;
}

}  // namespace zomefab::test
