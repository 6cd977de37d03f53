// SPDX-License-Identifier: GPL-3.0-or-later
/// @file PLY (ascii, binary_little_endian, binary_big_endian 1.0). Reads vertex x/y/z (any scalar
/// type), the face list `vertex_indices` (or `vertex_index`, any integer types, polygons
/// fan-triangulated) and an optional per-face `salient` flag; skips every other element and
/// property. Writes binary little-endian with float coordinates, `list uchar int` faces and, when
/// the mesh has salient faces, a `uchar salient` face property.
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "zomefab/core/version.h"
#include "zomefab/io/detail/mesh_formats.h"

namespace zomefab::detail {

namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

bool plyTypeFromName(std::string_view name, PlyType& type) {
    static const std::pair<const char*, PlyType> names[] = {
        {"char", PlyType::Int8},      {"int8", PlyType::Int8},       {"uchar", PlyType::UInt8},
        {"uint8", PlyType::UInt8},    {"short", PlyType::Int16},     {"int16", PlyType::Int16},
        {"ushort", PlyType::UInt16},  {"uint16", PlyType::UInt16},   {"int", PlyType::Int32},
        {"int32", PlyType::Int32},    {"uint", PlyType::UInt32},     {"uint32", PlyType::UInt32},
        {"float", PlyType::Float32},  {"float32", PlyType::Float32}, {"double", PlyType::Float64},
        {"float64", PlyType::Float64}};
    for (const auto& [n, t] : names)
        if (name == n) {
            type = t;
            return true;
        }
    return false;
}

size_t plyTypeSize(PlyType t) {
    switch (t) {
        case PlyType::Int8:
        case PlyType::UInt8:
            return 1;
        case PlyType::Int16:
        case PlyType::UInt16:
            return 2;
        case PlyType::Int32:
        case PlyType::UInt32:
        case PlyType::Float32:
            return 4;
        case PlyType::Float64:
            return 8;
    }
    return 1;
}

bool isIntegerType(PlyType t) { return t != PlyType::Float32 && t != PlyType::Float64; }

struct PlyProperty {
    std::string name;
    PlyType type = PlyType::Float32;
    bool isList = false;
    PlyType countType = PlyType::UInt8;
};

enum class Role { None, X, Y, Z, FaceIndices, Salient };

struct PlyElement {
    std::string name;
    uint64_t count = 0;
    std::vector<PlyProperty> properties;
};

enum class PlyFormat { Ascii, BinaryLE, BinaryBE };

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

/// Reads scalar values from the body. Binary: a byte stream. ASCII: one element per line, so a
/// wrong element count shows up on the line where the values stop fitting.
class BodyReader {
public:
    BodyReader(std::string_view body, PlyFormat format, size_t firstLine, const std::string& source)
        : mBody(body), mFormat(format), mLine(firstLine - 1), mSource(source) {}

    /// Starts element number @p index of @p element (ASCII: loads its line).
    void beginElement(const std::string& element, uint64_t index) {
        mElement = &element;
        mIndex = index;
        if (mFormat != PlyFormat::Ascii) return;
        mTokens.clear();
        mNext = 0;
        while (mTokens.empty()) {
            if (mPos >= mBody.size())
                fail(mSource, "PLY data ends early, in " + what() + " (element count wrong?)");
            size_t end = mBody.find('\n', mPos);
            if (end == std::string_view::npos) end = mBody.size();
            const std::string_view line = mBody.substr(mPos, end - mPos);
            mPos = end + 1;
            ++mLine;
            for (size_t i = 0; i < line.size();) {
                while (i < line.size() && isSpace(line[i])) ++i;
                const size_t s = i;
                while (i < line.size() && !isSpace(line[i])) ++i;
                if (i > s) mTokens.push_back(line.substr(s, i - s));
            }
        }
    }

    /// ASCII: the element's line must be used up.
    void endElement() {
        if (mFormat == PlyFormat::Ascii && mNext < mTokens.size())
            fail(mSource, "PLY line " + std::to_string(mLine) + ": " + what() +
                              " has more values than its properties (element count wrong?)");
    }

    /// One value of @p type as double (exact for every PLY integer type).
    double read(PlyType type) {
        if (mFormat == PlyFormat::Ascii) return readAscii(type);
        const size_t size = plyTypeSize(type);
        if (mBody.size() - mPos < size)
            fail(mSource, "PLY data ends early, in " + what() + " (element count wrong?)");
        const char* p = mBody.data() + mPos;
        mPos += size;
        const bool swap = mFormat == PlyFormat::BinaryBE;
        switch (type) {
            case PlyType::Int8:
                return loadScalar<int8_t>(p, swap);
            case PlyType::UInt8:
                return loadScalar<uint8_t>(p, swap);
            case PlyType::Int16:
                return loadScalar<int16_t>(p, swap);
            case PlyType::UInt16:
                return loadScalar<uint16_t>(p, swap);
            case PlyType::Int32:
                return loadScalar<int32_t>(p, swap);
            case PlyType::UInt32:
                return loadScalar<uint32_t>(p, swap);
            case PlyType::Float32:
                return loadScalar<float>(p, swap);
            case PlyType::Float64:
                return loadScalar<double>(p, swap);
        }
        return 0;
    }

    /// Throws unless only whitespace (ASCII) or nothing (binary) is left.
    void expectEnd() {
        if (mFormat == PlyFormat::Ascii)
            while (mPos < mBody.size() && isSpace(mBody[mPos])) ++mPos;
        if (mPos < mBody.size())
            fail(mSource, "PLY data continues after the last declared element (" +
                              std::to_string(mBody.size() - mPos) + " bytes left; element count wrong?)");
    }

    std::string what() const {
        return (mElement ? *mElement : std::string("?")) + " " + std::to_string(mIndex);
    }

private:
    double readAscii(PlyType type) {
        if (mNext >= mTokens.size())
            fail(mSource, "PLY line " + std::to_string(mLine) + ": too few values for " + what());
        std::string_view t = mTokens[mNext++];
        if (t[0] == '+') t.remove_prefix(1);
        double value = 0;
        std::from_chars_result r{};
        if (isIntegerType(type)) {
            int64_t i = 0;
            r = std::from_chars(t.data(), t.data() + t.size(), i);
            value = double(i);
        } else {
            r = std::from_chars(t.data(), t.data() + t.size(), value);
        }
        if (r.ec != std::errc() || r.ptr != t.data() + t.size())
            fail(mSource, "PLY line " + std::to_string(mLine) + ": bad value '" +
                              std::string(mTokens[mNext - 1]) + "' in " + what());
        return value;
    }

    std::string_view mBody;
    PlyFormat mFormat;
    size_t mPos = 0;
    size_t mLine;
    const std::string& mSource;
    const std::string* mElement = nullptr;
    uint64_t mIndex = 0;
    std::vector<std::string_view> mTokens;
    size_t mNext = 0;
};

/// A PLY header: its elements and format, and where the body starts.
struct PlyHeader {
    std::vector<PlyElement> elements;
    PlyFormat format = PlyFormat::Ascii;
    size_t bodyOffset = 0;
    size_t lineCount = 0;  ///< lines of the header, for the body's line numbers
};

/// The header: lines up to "end_header". @throw Error(InvalidInput) naming @p source and the line.
PlyHeader parsePlyHeader(std::string_view bytes, const std::string& source) {
    size_t pos = 0;
    size_t lineNo = 0;
    auto nextLine = [&](std::string_view& line) -> bool {
        if (pos >= bytes.size()) return false;
        size_t end = bytes.find('\n', pos);
        if (end == std::string_view::npos) end = bytes.size();
        line = bytes.substr(pos, end - pos);
        if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
        pos = std::min(bytes.size(), end + 1);
        ++lineNo;
        return true;
    };
    auto headerError = [&](const std::string& what) {
        fail(source, "PLY header line " + std::to_string(lineNo) + ": " + what);
    };
    std::string_view line;
    if (!nextLine(line) || line != "ply") fail(source, "not a PLY file: it does not start with 'ply'");

    std::vector<PlyElement> elements;
    bool haveFormat = false;
    bool haveEnd = false;
    PlyFormat format = PlyFormat::Ascii;
    std::vector<std::string_view> f;
    while (nextLine(line)) {
        f.clear();
        for (size_t i = 0; i < line.size();) {
            while (i < line.size() && isSpace(line[i])) ++i;
            const size_t s = i;
            while (i < line.size() && !isSpace(line[i])) ++i;
            if (i > s) f.push_back(line.substr(s, i - s));
        }
        if (f.empty()) continue;
        if (f[0] == "end_header") {
            haveEnd = true;
            break;
        }
        if (f[0] == "comment" || f[0] == "obj_info") continue;
        if (f[0] == "format") {
            if (f.size() != 3) headerError("expected 'format <type> 1.0'");
            if (f[1] == "ascii")
                format = PlyFormat::Ascii;
            else if (f[1] == "binary_little_endian")
                format = PlyFormat::BinaryLE;
            else if (f[1] == "binary_big_endian")
                format = PlyFormat::BinaryBE;
            else
                headerError("unknown format '" + std::string(f[1]) + "'");
            if (f[2] != "1.0") headerError("unsupported PLY version '" + std::string(f[2]) + "'");
            haveFormat = true;
        } else if (f[0] == "element") {
            if (f.size() != 3) headerError("expected 'element <name> <count>'");
            PlyElement e;
            e.name = std::string(f[1]);
            const auto r = std::from_chars(f[2].data(), f[2].data() + f[2].size(), e.count);
            if (r.ec != std::errc() || r.ptr != f[2].data() + f[2].size())
                headerError("bad element count '" + std::string(f[2]) + "'");
            elements.push_back(std::move(e));
        } else if (f[0] == "property") {
            if (elements.empty()) headerError("property before any element");
            PlyProperty p;
            if (f.size() >= 2 && f[1] == "list") {
                if (f.size() != 5) headerError("expected 'property list <count type> <item type> <name>'");
                p.isList = true;
                if (!plyTypeFromName(f[2], p.countType) || !plyTypeFromName(f[3], p.type))
                    headerError("unknown property type");
                if (!isIntegerType(p.countType)) headerError("list count type must be an integer type");
                p.name = std::string(f[4]);
            } else {
                if (f.size() != 3) headerError("expected 'property <type> <name>'");
                if (!plyTypeFromName(f[1], p.type))
                    headerError("unknown property type '" + std::string(f[1]) + "'");
                p.name = std::string(f[2]);
            }
            elements.back().properties.push_back(std::move(p));
        } else {
            headerError("unknown keyword '" + std::string(f[0]) + "'");
        }
    }
    if (!haveEnd) fail(source, "PLY header has no 'end_header'");
    if (!haveFormat) fail(source, "PLY header has no 'format' line");

    PlyHeader header{std::move(elements), format, pos, lineNo};
    return header;
}

}  // namespace

TriMesh parsePly(std::string_view bytes, const std::string& source) {
    const PlyHeader header = parsePlyHeader(bytes, source);
    const std::vector<PlyElement>& elements = header.elements;
    const PlyFormat format = header.format;
    const size_t pos = header.bodyOffset, lineNo = header.lineCount;
    // ---- which properties we use ----
    const PlyElement* vertexElement = nullptr;
    const PlyElement* faceElement = nullptr;
    for (const PlyElement& e : elements) {
        if (e.name == "vertex" && !vertexElement) vertexElement = &e;
        if (e.name == "face" && !faceElement) faceElement = &e;
    }
    if (!vertexElement) fail(source, "PLY has no 'vertex' element");
    if (!faceElement) fail(source, "PLY has no 'face' element (a point cloud, not a mesh)");
    if (vertexElement->count > UINT32_MAX) fail(source, "PLY declares more than 2^32 vertices");
    auto roleOf = [&](const PlyElement& e, const PlyProperty& p) -> Role {
        if (&e == vertexElement && !p.isList) {
            if (p.name == "x") return Role::X;
            if (p.name == "y") return Role::Y;
            if (p.name == "z") return Role::Z;
        }
        if (&e == faceElement) {
            if (p.isList && (p.name == "vertex_indices" || p.name == "vertex_index")) {
                if (!isIntegerType(p.type)) fail(source, "PLY face indices must be integers");
                return Role::FaceIndices;
            }
            if (!p.isList && p.name == "salient") return Role::Salient;
        }
        return Role::None;
    };
    int xyz = 0, indexLists = 0;
    for (const PlyProperty& p : vertexElement->properties) {
        const Role r = roleOf(*vertexElement, p);
        if (r == Role::X || r == Role::Y || r == Role::Z) ++xyz;
    }
    for (const PlyProperty& p : faceElement->properties)
        if (roleOf(*faceElement, p) == Role::FaceIndices) ++indexLists;
    if (xyz != 3) fail(source, "PLY vertex element needs exactly one each of the properties x, y and z");
    if (indexLists != 1) fail(source, "PLY face element needs one 'vertex_indices' list property");
    bool hasSalient = false;
    for (const PlyProperty& p : faceElement->properties)
        hasSalient |= roleOf(*faceElement, p) == Role::Salient;

    // ---- body ----
    const std::string_view body = bytes.substr(pos);
    BodyReader reader(body, format, lineNo + 1, source);
    TriMesh mesh;
    // Reserve no more than the body could hold, so a huge declared count cannot exhaust memory.
    mesh.positions.reserve(size_t(std::min<uint64_t>(vertexElement->count, body.size() / 3 + 1)));
    std::vector<uint32_t> polygon;
    for (const PlyElement& e : elements) {
        if (e.properties.empty()) continue;  // no data to read, whatever the count
        for (uint64_t i = 0; i < e.count; ++i) {
            reader.beginElement(e.name, i);
            Vec3f p{0, 0, 0};
            double salient = 0;
            size_t trianglesBefore = mesh.triangles.size();
            for (const PlyProperty& prop : e.properties) {
                const Role role = roleOf(e, prop);
                if (prop.isList) {
                    const double n = reader.read(prop.countType);
                    if (n < 0) fail(source, "negative list length in " + reader.what());
                    if (role != Role::FaceIndices) {
                        for (double k = 0; k < n; ++k) reader.read(prop.type);
                        continue;
                    }
                    if (n < 3)
                        fail(source, "face " + std::to_string(i) + " has " + std::to_string(int64_t(n)) +
                                         " vertices; a face needs at least 3");
                    polygon.clear();
                    for (double k = 0; k < n; ++k) {
                        const double v = reader.read(prop.type);
                        if (v < 0 || v >= double(vertexElement->count))
                            fail(source, "face " + std::to_string(i) + " refers to vertex " +
                                             std::to_string(int64_t(v)) + " but there are " +
                                             std::to_string(vertexElement->count) + " vertices");
                        polygon.push_back(uint32_t(v));
                    }
                    for (size_t k = 1; k + 1 < polygon.size(); ++k)
                        mesh.triangles.push_back({polygon[0], polygon[k], polygon[k + 1]});
                } else {
                    const double v = reader.read(prop.type);
                    if (role == Role::X)
                        p[0] = float(v);
                    else if (role == Role::Y)
                        p[1] = float(v);
                    else if (role == Role::Z)
                        p[2] = float(v);
                    else if (role == Role::Salient)
                        salient = v;
                }
            }
            reader.endElement();
            if (&e == vertexElement) {
                if (!isFinite(p))
                    fail(source,
                         "vertex " + std::to_string(i) + " has a non-finite coordinate (NaN or infinity)");
                mesh.positions.push_back(p);
            } else if (&e == faceElement && hasSalient) {
                mesh.salientFaces.resize(mesh.triangles.size(), 0);
                for (size_t k = trianglesBefore; k < mesh.triangles.size(); ++k)
                    mesh.salientFaces[k] = salient != 0 ? 1 : 0;
            }
        }
    }
    reader.expectEnd();
    return mesh;
}

std::string serializePly(const TriMesh& mesh) {
    const bool salient = !mesh.salientFaces.empty();
    std::string out = "ply\nformat binary_little_endian 1.0\ncomment written by ";
    out += generatorString();
    out += "\nelement vertex " + std::to_string(mesh.positions.size()) +
           "\nproperty float x\nproperty float y\nproperty float z\nelement face " +
           std::to_string(mesh.triangles.size()) + "\nproperty list uchar int vertex_indices\n";
    if (salient) out += "property uchar salient\n";
    out += "end_header\n";
    out.reserve(out.size() + mesh.positions.size() * 12 + mesh.triangles.size() * (salient ? 14 : 13));
    for (const Vec3f& p : mesh.positions)
        for (float x : p) appendScalar<float>(out, x);
    for (size_t i = 0; i < mesh.triangles.size(); ++i) {
        appendScalar<uint8_t>(out, 3);
        for (uint32_t v : mesh.triangles[i]) appendScalar<int32_t>(out, int32_t(v));
        if (salient) appendScalar<uint8_t>(out, i < mesh.salientFaces.size() ? mesh.salientFaces[i] : 0);
    }
    return out;
}

}  // namespace zomefab::detail
