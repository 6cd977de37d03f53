// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Damaging .vdb bytes on purpose, for the reader's tests.
#pragma once

#include <doctest/doctest.h>

#include <cstdint>
#include <cstring>
#include <string>

namespace zomefab::test {

// Where things are in a stream zomefab wrote (vdb_check.cpp has the layout).
inline constexpr size_t kVdbUuidAt = 21;      ///< header: magic 8, versions 12, offsets flag 1
inline constexpr size_t kVdbFileMetaAt = 57;  ///< after the 36-character UUID: the file metadata count
/// The checksum entry: name "zomefab_crc32" (4 + 13), type "string" (4 + 6), size (4), 8 hex digits.
inline constexpr size_t kVdbChecksumEntryBytes = 4 + 13 + 4 + 6 + 4 + 8;
/// The first grid's name length in a file without the checksum entry: after the file metadata
/// count (4) and the grid count (4).
inline constexpr size_t kVdbGridNameAt = kVdbFileMetaAt + 4 + 4;

/// The same grids without zomefab's checksum: the file metadata entry dropped and the UUID mark
/// broken, which is what a file from another program looks like to the reader.
inline std::string withoutVdbChecksum(std::string bytes) {
    bytes[kVdbUuidAt] = 'f';
    uint32_t count;
    std::memcpy(&count, &bytes[kVdbFileMetaAt], 4);
    REQUIRE(count == 1);
    REQUIRE(bytes.compare(kVdbFileMetaAt + 8, 13, "zomefab_crc32") == 0);
    count = 0;
    std::memcpy(&bytes[kVdbFileMetaAt], &count, 4);
    bytes.erase(kVdbFileMetaAt + 4, kVdbChecksumEntryBytes);
    return bytes;
}

/// @p bytes with the uint32 at @p at set to @p value.
inline std::string withU32(std::string bytes, size_t at, uint32_t value) {
    std::memcpy(&bytes[at], &value, 4);
    return bytes;
}

}  // namespace zomefab::test
