// SPDX-License-Identifier: GPL-3.0-or-later
/// @file STL: ASCII and binary reader (with vertex welding), binary writer with real facet normals.
#include <charconv>
#include <cmath>
#include <string>

#include "zomefab/core/version.h"
#include "zomefab/io/detail/mesh_formats.h"

namespace zomefab::detail {

namespace {

constexpr size_t kHeaderBytes = 84;  // 80-byte header + uint32 triangle count
constexpr size_t kFacetBytes = 50;   // normal, 3 corners (12 floats) + uint16 attribute

bool isSpace(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\f' || c == '\v'; }

/// Text, as opposed to binary: no control bytes other than whitespace in the first kilobyte.
/// Binary facets hold raw floats, which nearly always contain such bytes (e.g. 0x00).
bool looksLikeText(std::string_view bytes) {
    const size_t n = std::min<size_t>(bytes.size(), 1024);
    for (size_t i = 0; i < n; ++i) {
        const unsigned char c = static_cast<unsigned char>(bytes[i]);
        if ((c < 0x20 && !isSpace(char(c))) || c == 0x7f) return false;
    }
    return true;
}

bool startsWithSolid(std::string_view bytes) {
    size_t i = 0;
    while (i < bytes.size() && isSpace(bytes[i])) ++i;
    return bytes.substr(i, 5) == "solid" && (i + 5 == bytes.size() || isSpace(bytes[i + 5]));
}

/// Whitespace tokenizer that knows the current line for error messages.
class Tokenizer {
public:
    explicit Tokenizer(std::string_view text) : mText(text) {}

    /// The next token, empty at the end.
    std::string_view next() {
        while (mPos < mText.size() && isSpace(mText[mPos])) {
            if (mText[mPos] == '\n') ++mLine;
            ++mPos;
        }
        const size_t start = mPos;
        while (mPos < mText.size() && !isSpace(mText[mPos])) ++mPos;
        mTokenLine = mLine;
        return mText.substr(start, mPos - start);
    }
    /// Skips the rest of the current line (the solid's name).
    void skipLine() {
        while (mPos < mText.size() && mText[mPos] != '\n') ++mPos;
    }
    size_t line() const { return mTokenLine; }

private:
    std::string_view mText;
    size_t mPos = 0;
    size_t mLine = 1;
    size_t mTokenLine = 1;
};

TriMesh parseAsciiStl(std::string_view text, const std::string& source) {
    TriMesh mesh;
    Tokenizer tok(text);
    auto lineError = [&](const std::string& what) -> std::string {
        return "line " + std::to_string(tok.line()) + ": " + what;
    };
    auto expect = [&](std::string_view word) {
        const std::string_view t = tok.next();
        if (t != word)
            fail(source,
                 lineError("expected '" + std::string(word) + "' but found " +
                           (t.empty() ? std::string("the end of the file") : "'" + std::string(t) + "'") +
                           " in ASCII STL"));
    };
    auto number = [&]() -> float {
        std::string_view t = tok.next();
        if (!t.empty() && t[0] == '+') t.remove_prefix(1);
        double value = 0;
        const auto [end, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
        if (t.empty() || end != t.data() + t.size() || ec == std::errc::invalid_argument)
            fail(source,
                 lineError("expected a number but found " +
                           (t.empty() ? std::string("the end of the file") : "'" + std::string(t) + "'")));
        const float f = float(value);
        if (ec == std::errc::result_out_of_range || !std::isfinite(f))
            fail(source, lineError("non-finite or out-of-range coordinate '" + std::string(t) + "'"));
        return f;
    };

    bool sawSolid = false;
    for (;;) {
        std::string_view t = tok.next();
        if (t.empty()) break;
        if (t == "solid") {
            tok.skipLine();  // the rest of the line is the solid's name
            sawSolid = true;
            continue;
        }
        if (t == "endsolid") {
            tok.skipLine();
            continue;
        }
        if (t != "facet")
            fail(source,
                 lineError("expected 'facet' or 'endsolid' but found '" + std::string(t) + "' in ASCII STL"));
        expect("normal");
        for (int i = 0; i < 3; ++i)
            number();  // the stored normal is ignored: orientation comes from the winding
        expect("outer");
        expect("loop");
        Triangle tri;
        for (int c = 0; c < 3; ++c) {
            expect("vertex");
            Vec3f p;
            for (int i = 0; i < 3; ++i) p[i] = number();
            tri[c] = uint32_t(mesh.positions.size());
            mesh.positions.push_back(p);
        }
        expect("endloop");
        expect("endfacet");
        mesh.triangles.push_back(tri);
    }
    if (!sawSolid) fail(source, "not an ASCII STL: missing 'solid'");
    return mesh;
}

TriMesh parseBinaryStl(std::string_view bytes, const std::string& source) {
    if (bytes.size() < kHeaderBytes)
        fail(source, "truncated binary STL: " + std::to_string(bytes.size()) +
                         " bytes, shorter than the 84-byte header");
    const uint32_t count = loadScalar<uint32_t>(bytes.data() + 80, false);
    const uint64_t needed = kHeaderBytes + uint64_t(count) * kFacetBytes;
    if (needed > bytes.size())
        fail(source, "truncated binary STL: the header announces " + std::to_string(count) + " triangles (" +
                         std::to_string(needed) + " bytes) but the file has " + std::to_string(bytes.size()) +
                         " bytes");
    // Extra bytes after the last facet are ignored: some exporters pad the file.
    TriMesh mesh;
    mesh.positions.resize(size_t(count) * 3);
    mesh.triangles.resize(count);
    const char* p = bytes.data() + kHeaderBytes;
    for (uint32_t f = 0; f < count; ++f, p += kFacetBytes) {
        for (int c = 0; c < 3; ++c) {
            Vec3f& v = mesh.positions[size_t(f) * 3 + c];
            for (int i = 0; i < 3; ++i) v[i] = loadScalar<float>(p + 12 + 12 * c + 4 * i, false);
            if (!isFinite(v))
                fail(source,
                     "triangle " + std::to_string(f) + " has a non-finite coordinate (NaN or infinity)");
        }
        mesh.triangles[f] = {3 * f, 3 * f + 1, 3 * f + 2};
    }
    return mesh;
}

}  // namespace

TriMesh parseStl(std::string_view bytes, const std::string& source, bool weld) {
    // Binary when the size matches the announced count exactly (binary headers may begin with
    // "solid"); ASCII when it starts with "solid" and is text; binary otherwise.
    bool binary = true;
    if (bytes.size() >= kHeaderBytes &&
        kHeaderBytes + uint64_t(loadScalar<uint32_t>(bytes.data() + 80, false)) * kFacetBytes ==
            bytes.size()) {
        binary = true;
    } else if (looksLikeText(bytes)) {
        if (!startsWithSolid(bytes)) fail(source, "not an STL file: text that does not start with 'solid'");
        binary = false;
    }
    TriMesh mesh = binary ? parseBinaryStl(bytes, source) : parseAsciiStl(bytes, source);
    if (weld) weldIdenticalVertices(mesh);
    return mesh;
}

std::string serializeStl(const TriMesh& mesh) {
    std::string out;
    out.reserve(kHeaderBytes + mesh.triangles.size() * kFacetBytes);
    // The header must not start with "solid", or naive readers take the file for ASCII.
    std::string header = std::string("binary STL written by ") + generatorString();
    header.resize(80, ' ');
    out += header;
    appendScalar<uint32_t>(out, uint32_t(mesh.triangles.size()));
    for (const Triangle& t : mesh.triangles) {
        const Vec3f& a = mesh.positions[t[0]];
        const Vec3f& b = mesh.positions[t[1]];
        const Vec3f& c = mesh.positions[t[2]];
        // Unit facet normal (b - a) x (c - a), in double; zero for a degenerate triangle.
        const double u[3] = {double(b[0]) - a[0], double(b[1]) - a[1], double(b[2]) - a[2]};
        const double v[3] = {double(c[0]) - a[0], double(c[1]) - a[1], double(c[2]) - a[2]};
        double n[3] = {u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        for (double& x : n) x = (len > 0 && std::isfinite(len)) ? x / len : 0.0;
        for (double x : n) appendScalar<float>(out, float(x));
        for (const Vec3f* p : {&a, &b, &c})
            for (float x : *p) appendScalar<float>(out, x);
        appendScalar<uint16_t>(out, 0);
    }
    return out;
}

}  // namespace zomefab::detail
