// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The bytes of a .vdb stream checked before OpenVDB parses them (docs/sdf.md, "Damaged and
/// hostile files"). OpenVDB trusts every length and count it reads: one flipped bit can make it
/// allocate gigabytes or write past a buffer. checkVdbStream walks the whole stream (header,
/// metadata, descriptors, transforms, tree topology and the framing of every compressed block),
/// checking each announced size against the bytes left and sane limits, and verifies the checksum
/// zomefab writes into its own files. No OpenVDB here: the walk is plain byte reading, so it can be
/// fuzzed alone (fuzz/fuzz_vdb_check.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace zomefab::sdf::detail {

/// File-level metadata entry that holds the CRC-32 (8 lowercase hex digits) of the whole stream,
/// computed with the entry's own 8 value bytes set to '0'.
inline constexpr const char* kVdbChecksumKey = "zomefab_crc32";
/// The value the writer puts there before the checksum is known, and what the checksum reads it as.
inline constexpr const char* kVdbChecksumPlaceholder = "00000000";
/// The first 9 characters of the archive UUID of every file zomefab writes: a second mark, so a
/// file whose checksum entry was itself damaged is still known to be zomefab's.
inline constexpr const char* kVdbUuidMark = "7a6f6d65-";

/// What checkVdbStream found.
struct VdbCheck {
    std::string sanitized;   ///< the bytes for OpenVDB: per-grid "file_delayed_load" entries removed
    uint64_t treeBytes = 0;  ///< estimated memory of the trees once parsed
};

/// Checks @p bytes as a .vdb stream (file format 222-224, the one OpenVDB 10 writes). Float trees
/// (Tree_float_5_4_3, optionally saved as half) are walked node by node; grids of other types are
/// skipped by their stream offsets when the writer stored them, refused otherwise.
/// @throw Error(InvalidInput) naming @p sourceName with the problem and its byte offset: not a
///        .vdb, truncated, an implausible size, a checksum mismatch in a zomefab file.
VdbCheck checkVdbStream(std::string_view bytes, const std::string& sourceName);

/// Writer side: replaces OpenVDB's random archive UUID by kVdbUuidMark + a hash of the content
/// (same grids, same bytes) and fills in the kVdbChecksumKey entry, which must be present in the
/// file metadata with the value kVdbChecksumPlaceholder.
/// @throw Error(Internal) when the bytes do not have that layout.
void sealVdbStream(std::string& bytes);

}  // namespace zomefab::sdf::detail
