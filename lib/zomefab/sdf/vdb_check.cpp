// SPDX-License-Identifier: GPL-3.0-or-later
// A walk over the bytes of a .vdb stream that mirrors what OpenVDB 10 reads (openvdb/io/Archive.cc,
// GridDescriptor.cc, Compression.h, tree/RootNode.h, InternalNode.h, LeafNode.h), checking every
// size before OpenVDB would trust it. The layout, file format 222-224 (Stream, non-seekable):
//   header:  int64 magic, uint32 file version, uint32 x2 library version, char has-offsets, 36-char UUID
//   MetaMap: uint32 count, then per entry: string name, string type, uint32 size, size bytes
//   int32 grid count, then per grid: string unique name, string type, string instance parent,
//     int64 x3 stream offsets, uint32 compression, MetaMap, string map type + map data,
//     and unless an instance: int32 buffer count (1), root topology, leaf buffers.
// Strings are uint32 length + bytes. Numbers are little-endian (OpenVDB writes native order; the
// tools run on little-endian machines only).
#include "zomefab/sdf/vdb_check.h"

#include <zlib.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "zomefab/core/error.h"

namespace zomefab::sdf::detail {

namespace {

constexpr int64_t kMagic = 0x56444220;   // OPENVDB_MAGIC, " BDV"
constexpr uint32_t kFirstVersion = 222;  // OPENVDB_FILE_VERSION_NODE_MASK_COMPRESSION
constexpr uint32_t kLastVersion = 224;   // OPENVDB_FILE_VERSION_MULTIPASS_IO (OpenVDB 10)
constexpr size_t kUuidOffset = 8 + 4 + 4 + 4 + 1;
constexpr size_t kUuidLength = 36;

// Limits far above anything a real file holds, far below what would hurt.
constexpr uint32_t kMaxNameBytes = 4096;
constexpr uint32_t kMaxTypeBytes = 256;
constexpr uint32_t kMaxMetaEntries = 100000;
constexpr int32_t kMaxGrids = 4096;
constexpr int32_t kMaxCoord = 1 << 24;  // voxels from the origin; 16.7 m at 1 mm

// Compression flags (openvdb/io/Compression.h).
constexpr uint32_t kZip = 0x1, kActiveMask = 0x2, kBlosc = 0x4;

// Per-node compression metadata (Compression.h): what precedes the values of a node.
enum : int8_t {
    NoMaskOrInactiveVals,
    NoMaskAndMinusBg,
    NoMaskAndOneInactiveVal,
    MaskAndNoInactiveVals,
    MaskAndOneInactiveVal,
    MaskAndTwoInactiveVals,
    NoMaskAndAllVals
};

// Tree_float_5_4_3: node sizes in values, and what each costs in memory once parsed (values or
// child pointers, two masks, bookkeeping), for the memory estimate.
constexpr uint32_t kLeafValues = 512, kInternal4Values = 4096, kInternal5Values = 32768;
constexpr uint64_t kLeafBytes = kLeafValues * 4 + 2 * 64 + 64;
constexpr uint64_t kInternal4Bytes = kInternal4Values * 8 + 2 * 512 + 64;
constexpr uint64_t kInternal5Bytes = kInternal5Values * 8 + 2 * 4096 + 64;
constexpr int32_t kRootChildDim = 4096;  // voxels along a root child (1 << (5 + 4 + 3))

/// Reads the stream front to back; every read checks the bytes left first.
class Cursor {
public:
    Cursor(std::string_view bytes, const std::string& sourceName) : mBytes(bytes), mSource(sourceName) {}

    size_t pos() const { return mPos; }
    size_t left() const { return mBytes.size() - mPos; }
    std::string_view bytes() const { return mBytes; }

    template <typename T>
    T read(const char* what) {
        need(sizeof(T), what);
        T value;
        std::memcpy(&value, mBytes.data() + mPos, sizeof(T));
        mPos += sizeof(T);
        return value;
    }

    std::string_view take(uint64_t count, const char* what) {
        need(count, what);
        const std::string_view out = mBytes.substr(mPos, size_t(count));
        mPos += size_t(count);
        return out;
    }

    /// A uint32-length string of at most @p maxBytes.
    std::string_view string(const char* what, uint32_t maxBytes) {
        const size_t at = mPos;
        const uint32_t length = read<uint32_t>(what);
        if (length > maxBytes)
            fail(at, std::string(what) + " announces " + std::to_string(length) + " bytes (at most " +
                         std::to_string(maxBytes) + ")");
        return take(length, what);
    }

    void seek(size_t pos) { mPos = pos; }

    [[noreturn]] void error(const std::string& message) const {
        throw Error(ErrorCode::InvalidInput, message, mSource);
    }

    [[noreturn]] void fail(size_t at, const std::string& problem) const {
        throw Error(ErrorCode::InvalidInput,
                    "damaged .vdb stream: " + problem + " (at byte " + std::to_string(at) + " of " +
                        std::to_string(mBytes.size()) + ")",
                    mSource);
    }

private:
    void need(uint64_t count, const char* what) const {
        if (count > left())
            throw Error(ErrorCode::InvalidInput,
                        "truncated .vdb stream: " + std::string(what) + " at byte " + std::to_string(mPos) +
                            " needs " + std::to_string(count) + " bytes, " + std::to_string(left()) +
                            " are left",
                        mSource);
    }

    std::string_view mBytes;
    const std::string& mSource;
    size_t mPos = 0;
};

struct Header {
    uint32_t fileVersion = 0;
    bool hasOffsets = false;
    bool zomefabUuid = false;
};

Header readHeader(Cursor& c) {
    if (c.left() < 8 || c.read<int64_t>("the magic number") != kMagic) {
        c.error("cannot read the .vdb stream: not a .vdb file (no OpenVDB magic number)");
    }
    Header h;
    const size_t versionAt = c.pos();
    h.fileVersion = c.read<uint32_t>("the file version");
    if (h.fileVersion < kFirstVersion || h.fileVersion > kLastVersion)
        c.fail(versionAt, "file format version " + std::to_string(h.fileVersion) + " (this build reads " +
                              std::to_string(kFirstVersion) + " to " + std::to_string(kLastVersion) + ")");
    c.read<uint32_t>("the library major version");
    c.read<uint32_t>("the library minor version");
    const size_t offsetsAt = c.pos();
    const auto hasOffsets = c.read<uint8_t>("the has-offsets flag");
    if (hasOffsets > 1) c.fail(offsetsAt, "has-offsets flag " + std::to_string(hasOffsets));
    h.hasOffsets = hasOffsets == 1;
    const size_t uuidAt = c.pos();
    const std::string_view uuid = c.take(kUuidLength, "the archive UUID");
    for (char ch : uuid)
        if (ch < 0x20 || ch > 0x7e) c.fail(uuidAt, "the archive UUID is not text");
    h.zomefabUuid = uuid.substr(0, std::strlen(kVdbUuidMark)) == kVdbUuidMark;
    return h;
}

/// Size in bytes of the value of a metadata type OpenVDB reads with a fixed size (it ignores the
/// announced size for these, so a wrong one would shift everything after it); 0 = any size.
uint32_t fixedMetaSize(std::string_view type) {
    static const std::map<std::string_view, uint32_t> sizes = {
        {"bool", 1},   {"int32", 4},  {"int64", 8},  {"float", 4},  {"double", 8}, {"vec2i", 8},
        {"vec2s", 8},  {"vec2d", 16}, {"vec3i", 12}, {"vec3s", 12}, {"vec3d", 24}, {"vec4i", 16},
        {"vec4s", 16}, {"vec4d", 32}, {"mat4s", 64}, {"mat4d", 128}};
    const auto it = sizes.find(type);
    return it == sizes.end() ? 0 : it->second;
}

struct MetaEntry {
    std::string_view name, type;
    size_t entryStart = 0, valueStart = 0;
    uint32_t size = 0;
};

struct MetaMapRead {
    size_t countAt = 0;
    std::vector<MetaEntry> entries;
};

MetaMapRead readMetaMap(Cursor& c, const char* what) {
    MetaMapRead m;
    m.countAt = c.pos();
    const uint32_t count = c.read<uint32_t>(what);
    // An entry is at least two empty strings and a size: 12 bytes.
    if (count > kMaxMetaEntries || uint64_t(count) * 12 > c.left())
        c.fail(m.countAt, std::string(what) + " announces " + std::to_string(count) + " entries");
    for (uint32_t i = 0; i < count; ++i) {
        MetaEntry e;
        e.entryStart = c.pos();
        e.name = c.string("a metadata name", kMaxNameBytes);
        e.type = c.string("a metadata type name", kMaxTypeBytes);
        const size_t sizeAt = c.pos();
        e.size = c.read<uint32_t>("a metadata size");
        const uint32_t fixed = fixedMetaSize(e.type);
        if (fixed != 0 && e.size != fixed)
            c.fail(sizeAt, "metadata '" + std::string(e.name) + "' of type " + std::string(e.type) + " has " +
                               std::to_string(e.size) + " bytes, not " + std::to_string(fixed));
        e.valueStart = c.pos();
        const std::string_view value = c.take(e.size, "a metadata value");
        if (e.type == "bool" && uint8_t(value[0]) > 1)
            c.fail(e.valueStart, "metadata '" + std::string(e.name) + "' is not a bool");
        m.entries.push_back(e);
    }
    return m;
}

bool allFinite(std::string_view raw) {
    for (size_t i = 0; i + 8 <= raw.size(); i += 8) {
        double d;
        std::memcpy(&d, raw.data() + i, 8);
        if (!std::isfinite(d)) return false;
    }
    return true;
}

/// The transform: only the two maps zomefab takes (uniform voxels, no rotation), so the map data
/// has a known size. ScaleMap data: scale, voxel size, 1/scale, 1/scale^2, 1/(2 scale) (Vec3d
/// each); ScaleTranslateMap puts the translation first.
void readTransform(Cursor& c, const std::string& grid) {
    const std::string_view type = c.string("the transform's map type", kMaxTypeBytes);
    size_t translation = 0;
    if (type == "UniformScaleTranslateMap") {
        translation = 24;
    } else if (type != "UniformScaleMap") {
        c.error("grid '" + grid + "' has a " + std::string(type) +
                " transform; only uniform voxels without rotation are supported");
    }
    const size_t dataAt = c.pos();
    const std::string_view data = c.take(translation + 5 * 24, "the transform");
    double scale[3];
    std::memcpy(scale, data.data() + translation, sizeof(scale));
    if (!allFinite(data) || !(scale[0] > 0) || scale[0] != scale[1] || scale[0] != scale[2])
        c.fail(dataAt, "grid '" + grid + "' has an invalid voxel size");
}

/// One compressed block of @p valueCount values of @p valueBytes each (readData / bloscFromStream /
/// unzipFromStream): an int64 size, negative for raw bytes, then that many bytes.
void readData(Cursor& c, uint64_t valueCount, uint32_t valueBytes, uint32_t compression) {
    const uint64_t rawBytes = valueCount * valueBytes;
    if (!(compression & (kBlosc | kZip))) {
        c.take(rawBytes, "uncompressed values");
        return;
    }
    const size_t at = c.pos();
    const auto size = c.read<int64_t>("a compressed block size");
    if (size <= 0) {
        if (uint64_t(-size) != rawBytes)
            c.fail(at, "a raw block of " + std::to_string(-size) + " bytes where " +
                           std::to_string(rawBytes) + " are expected");
        c.take(rawBytes, "raw values");
        return;
    }
    const std::string_view block = c.take(uint64_t(size), "a compressed block");
    if (compression & kBlosc) {
        // Blosc 1 header: version, lz version, flags, type size, uint32 nbytes, blocksize, cbytes.
        uint32_t nbytes = 0, cbytes = 0;
        if (block.size() >= 16) {
            std::memcpy(&nbytes, block.data() + 4, 4);
            std::memcpy(&cbytes, block.data() + 12, 4);
        }
        if (block.size() < 16 || nbytes != rawBytes || cbytes != block.size())
            c.fail(at,
                   "a Blosc block that does not hold the " + std::to_string(rawBytes) + " bytes expected");
    }
}

/// Values on in a node mask (a multiple of 8 bytes).
uint64_t popcountBits(std::string_view mask) {
    uint64_t n = 0;
    for (size_t i = 0; i + 8 <= mask.size(); i += 8) {
        uint64_t word;
        std::memcpy(&word, mask.data() + i, 8);
        n += uint64_t(__builtin_popcountll(word));
    }
    return n;
}

/// readCompressedValues for @p count values under @p valueMask (one bit per value).
void readCompressedValues(Cursor& c, uint32_t count, std::string_view valueMask, uint32_t compression,
                          bool half) {
    const size_t at = c.pos();
    const auto meta = c.read<int8_t>("a node's compression flag");
    if (meta < NoMaskOrInactiveVals || meta > NoMaskAndAllVals)
        c.fail(at, "node compression flag " + std::to_string(int(meta)));
    if (meta == NoMaskAndOneInactiveVal || meta == MaskAndOneInactiveVal || meta == MaskAndTwoInactiveVals) {
        const auto inactive = c.read<float>("an inactive value");
        if (!std::isfinite(inactive)) c.fail(at, "a non-finite inactive value");
        if (meta == MaskAndTwoInactiveVals && !std::isfinite(c.read<float>("an inactive value")))
            c.fail(at, "a non-finite inactive value");
    }
    if (meta == MaskAndNoInactiveVals || meta == MaskAndOneInactiveVal || meta == MaskAndTwoInactiveVals)
        c.take(count / 8, "a selection mask");
    const uint64_t stored =
        (compression & kActiveMask) && meta != NoMaskAndAllVals ? popcountBits(valueMask) : count;
    if (half && stored == 0) return;  // HalfReader reads nothing for no values
    readData(c, stored, half ? 2 : 4, compression);
}

bool bitOn(std::string_view mask, uint32_t i) { return (uint8_t(mask[i >> 3]) >> (i & 7)) & 1; }

struct TreeWalk {
    uint32_t compression = 0;
    bool half = false;
    uint64_t leaves = 0, internal4 = 0, internal5 = 0;
};

/// InternalNode::readTopology for a node of 2^(3 log2Dim) values whose children are internal
/// nodes of @p childLog2Dim or, when that is 0, leaves (LeafNode::readTopology: a value mask).
void readInternalTopology(Cursor& c, TreeWalk& w, uint32_t log2Dim, uint32_t childLog2Dim) {
    const uint32_t values = 1u << (3 * log2Dim);
    const std::string_view childMask = c.take(values / 8, "an internal node's child mask");
    const std::string_view valueMask = c.take(values / 8, "an internal node's value mask");
    readCompressedValues(c, values, valueMask, w.compression, w.half);
    const uint64_t children = popcountBits(childMask);
    (log2Dim == 5 ? w.internal5 : w.internal4) += 1;
    if (childLog2Dim == 0) {
        c.take(children * (kLeafValues / 8), "leaf value masks");
        w.leaves += children;
        return;
    }
    for (uint32_t i = 0; i < values; ++i)
        if (bitOn(childMask, i)) readInternalTopology(c, w, childLog2Dim, 0);
}

using Origin = std::array<int32_t, 3>;

Origin readOrigin(Cursor& c, const char* what) {
    const size_t at = c.pos();
    Origin o;
    for (int32_t& v : o) {
        v = c.read<int32_t>(what);
        if (v % kRootChildDim != 0 || v > kMaxCoord || v < -kMaxCoord)
            c.fail(at, std::string(what) + " (" + std::to_string(v) + ") is not a root node position");
    }
    return o;
}

/// Tree::readTopology and readBuffers of a Tree_float_5_4_3. The root's table is a std::map
/// ordered by origin, and OpenVDB reads the buffers in that order, so origins must be increasing
/// (as OpenVDB writes them) for the buffers to belong to the nodes the topology announced.
void readFloatTree(Cursor& c, TreeWalk& w) {
    const size_t at = c.pos();
    if (c.read<int32_t>("the buffer count") != 1) c.fail(at, "a tree with other than one buffer");
    if (!std::isfinite(c.read<float>("the background value"))) c.fail(at, "a non-finite background value");
    const size_t countsAt = c.pos();
    const auto tiles = c.read<uint32_t>("the root tile count");
    const auto children = c.read<uint32_t>("the root child count");
    if (uint64_t(tiles) * 17 + uint64_t(children) * 12 > c.left())
        c.fail(countsAt, "the root announces " + std::to_string(tiles) + " tiles and " +
                             std::to_string(children) + " children");
    std::set<Origin> tileOrigins;
    for (uint32_t i = 0; i < tiles; ++i) {
        const Origin o = readOrigin(c, "a root tile origin");
        const size_t valueAt = c.pos();
        if (!std::isfinite(c.read<float>("a root tile value"))) c.fail(valueAt, "a non-finite tile value");
        if (c.read<uint8_t>("a root tile's active flag") > 1) c.fail(valueAt, "a root tile's active flag");
        if (!tileOrigins.empty() && !(*tileOrigins.rbegin() < o)) c.fail(valueAt, "root tiles out of order");
        tileOrigins.insert(o);
    }
    Origin previous{};
    for (uint32_t i = 0; i < children; ++i) {
        const size_t originAt = c.pos();
        const Origin o = readOrigin(c, "a root child origin");
        if ((i > 0 && !(previous < o)) || tileOrigins.count(o))
            c.fail(originAt, "root children out of order or on a tile");
        previous = o;
        readInternalTopology(c, w, 5, 4);
    }
    // LeafNode::readBuffers, depth first (the order of the topology): value mask, values.
    for (uint64_t i = 0; i < w.leaves; ++i) {
        const std::string_view mask = c.take(kLeafValues / 8, "a leaf's value mask");
        readCompressedValues(c, kLeafValues, mask, w.compression, w.half);
    }
}

constexpr size_t kChecksumLength = 8;  // hex digits of a CRC-32

/// CRC-32 of @p bytes with the checksum value at @p valueAt read as kVdbChecksumPlaceholder.
uint32_t checksumWithPlaceholder(std::string_view bytes, size_t valueAt) {
    uLong crc = crc32_z(0L, Z_NULL, 0);
    crc = crc32_z(crc, reinterpret_cast<const Bytef*>(bytes.data()), valueAt);
    crc = crc32_z(crc, reinterpret_cast<const Bytef*>(kVdbChecksumPlaceholder), kChecksumLength);
    crc = crc32_z(crc, reinterpret_cast<const Bytef*>(bytes.data() + valueAt + kChecksumLength),
                  bytes.size() - valueAt - kChecksumLength);
    return uint32_t(crc);
}

std::string hex8(uint32_t value) {
    char text[9];
    std::snprintf(text, sizeof(text), "%08x", value);
    return text;
}

/// The zomefab checksum entry of the file metadata, if any.
const MetaEntry* findChecksum(const MetaMapRead& fileMeta) {
    for (const MetaEntry& e : fileMeta.entries)
        if (e.name == kVdbChecksumKey) return &e;
    return nullptr;
}

/// Verifies zomefab's checksum when the file carries it (or zomefab's UUID mark).
void verifyChecksum(Cursor& c, const Header& header, const MetaMapRead& fileMeta) {
    const MetaEntry* entry = findChecksum(fileMeta);
    if (!entry) {
        if (header.zomefabUuid)
            c.fail(kUuidOffset, "written by zomefab but its checksum entry is missing or damaged");
        return;
    }
    const std::string_view bytes = c.bytes();
    if (entry->type != "string" || entry->size != kChecksumLength)
        c.fail(entry->entryStart, "the checksum entry is damaged");
    const std::string_view stored = bytes.substr(entry->valueStart, kChecksumLength);
    if (stored != hex8(checksumWithPlaceholder(bytes, entry->valueStart)))
        c.error(
            "damaged .vdb stream: its checksum does not match its contents (the file changed after zomefab "
            "wrote it)");
}

/// FNV-1a, 64 bits: the content hash behind the deterministic archive UUID.
uint64_t fnv1a(std::string_view data, uint64_t hash = 1469598103934665603ull) {
    for (char ch : data) {
        hash ^= uint8_t(ch);
        hash *= 1099511628211ull;
    }
    return hash;
}

/// Removes byte ranges from @p bytes and decrements the counts at the given offsets.
std::string withoutRanges(std::string_view bytes, const std::vector<std::pair<size_t, size_t>>& ranges,
                          const std::map<size_t, uint32_t>& countDrops) {
    std::string out(bytes);
    for (const auto& [at, drop] : countDrops) {
        uint32_t count;
        std::memcpy(&count, out.data() + at, 4);
        count -= drop;
        std::memcpy(out.data() + at, &count, 4);
    }
    for (auto it = ranges.rbegin(); it != ranges.rend(); ++it) out.erase(it->first, it->second - it->first);
    return out;
}

}  // namespace

VdbCheck checkVdbStream(std::string_view bytes, const std::string& sourceName) {
    Cursor c(bytes, sourceName);
    VdbCheck result;
    const Header header = readHeader(c);
    const MetaMapRead fileMeta = readMetaMap(c, "the file metadata");
    verifyChecksum(c, header, fileMeta);

    const size_t countAt = c.pos();
    const auto gridCount = c.read<int32_t>("the grid count");
    if (gridCount < 0 || gridCount > kMaxGrids) c.fail(countAt, "grid count " + std::to_string(gridCount));
    // The per-grid "file_delayed_load" entries only serve delayed loading from files, which a
    // stream does not do; OpenVDB trusts the counts inside them, so they are removed.
    std::vector<std::pair<size_t, size_t>> strip;
    std::map<size_t, uint32_t> countDrops;
    std::map<std::string, std::string> gridTypes;  // unique name -> type, for instances
    for (int32_t g = 0; g < gridCount; ++g) {
        const size_t gridAt = c.pos();
        const std::string name(c.string("a grid name", kMaxNameBytes));
        std::string type(c.string("a grid type", kMaxTypeBytes));
        const std::string parent(c.string("a grid's instance parent", kMaxNameBytes));
        std::array<int64_t, 3> offsets{};
        for (int64_t& o : offsets) o = c.read<int64_t>("a grid's stream offsets");
        if (gridTypes.count(name)) c.fail(gridAt, "two grids named '" + name + "'");
        const bool half = type.size() > 10 && type.compare(type.size() - 10, 10, "_HalfFloat") == 0;
        if (half) type.resize(type.size() - 10);
        if (!parent.empty() && gridTypes[parent] != type)
            c.fail(gridAt, "grid '" + name + "' is an instance of '" + parent + "', which is not before it");
        gridTypes[name] = type;
        if (type != "Tree_float_5_4_3") {
            // Another value type: skip it by its end offset when the writer stored one.
            const int64_t end = offsets[2];
            if (!header.hasOffsets || end <= int64_t(c.pos()) || uint64_t(end) > bytes.size())
                c.fail(gridAt, "grid '" + name + "' of type " + type +
                                   " cannot be skipped (zomefab reads float level sets only)");
            c.seek(size_t(end));
            continue;
        }
        TreeWalk walk;
        const size_t compressionAt = c.pos();
        walk.compression = c.read<uint32_t>("a grid's compression flags");
        walk.half = half;
        if (walk.compression & ~(kZip | kActiveMask | kBlosc))
            c.fail(compressionAt, "compression flags " + std::to_string(walk.compression));
        const MetaMapRead gridMeta = readMetaMap(c, "the grid metadata");
        for (const MetaEntry& e : gridMeta.entries) {
            if (e.name != "file_delayed_load") continue;
            strip.emplace_back(e.entryStart, e.valueStart + e.size);
            countDrops[gridMeta.countAt] += 1;
        }
        readTransform(c, name);
        if (!parent.empty()) continue;  // an instance shares its parent's tree
        readFloatTree(c, walk);
        result.treeBytes +=
            walk.leaves * kLeafBytes + walk.internal4 * kInternal4Bytes + walk.internal5 * kInternal5Bytes;
    }
    if (c.left() != 0) c.fail(c.pos(), std::to_string(c.left()) + " bytes after the last grid");
    result.sanitized = withoutRanges(bytes, strip, countDrops);
    return result;
}

void sealVdbStream(std::string& bytes) {
    const std::string internal = "(zomefab's own .vdb)";
    Cursor c(bytes, internal);
    MetaMapRead fileMeta;
    try {
        readHeader(c);
        fileMeta = readMetaMap(c, "the file metadata");
    } catch (const Error& e) {
        throw Error(ErrorCode::Internal, std::string("unexpected .vdb layout from OpenVDB: ") + e.what());
    }
    const MetaEntry* entry = findChecksum(fileMeta);
    if (!entry || entry->size != kChecksumLength ||
        bytes.compare(entry->valueStart, kChecksumLength, kVdbChecksumPlaceholder) != 0)
        throw Error(ErrorCode::Internal, "unexpected .vdb layout from OpenVDB: no checksum placeholder");
    const size_t valueAt = entry->valueStart;
    // The UUID (8-4-4-4-12 hex digits): the mark, then 28 digits of hash over everything after it.
    const std::string_view body = std::string_view(bytes).substr(kUuidOffset + kUuidLength);
    const uint64_t h1 = fnv1a(body);
    const uint64_t h2 = fnv1a(body, h1 ^ 0x9e3779b97f4a7c15ull);
    char uuid[kUuidLength + 1];
    std::snprintf(uuid, sizeof(uuid), "%s%04x-%04x-%04x-%012llx", kVdbUuidMark, unsigned(h1 >> 48),
                  unsigned((h1 >> 32) & 0xffff), unsigned(h1 & 0xffff),
                  static_cast<unsigned long long>(h2 & 0xffffffffffffull));
    std::memcpy(&bytes[kUuidOffset], uuid, kUuidLength);
    const std::string crc = hex8(checksumWithPlaceholder(bytes, valueAt));
    std::memcpy(&bytes[valueAt], crc.data(), kChecksumLength);
}

}  // namespace zomefab::sdf::detail
