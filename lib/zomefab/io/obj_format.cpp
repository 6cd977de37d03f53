// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Wavefront OBJ: `v` and `f` records (v, v/vt, v//vn, v/vt/vn; negative = relative), polygons
/// fan-triangulated; everything else (vt, vn, groups, materials, lines) is skipped. Writer: v + f.
#include <charconv>
#include <cmath>
#include <string>
#include <vector>

#include "zomefab/core/version.h"
#include "zomefab/io/detail/mesh_formats.h"

namespace zomefab::detail {

namespace {

bool isBlank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

/// Splits one line into whitespace-separated fields.
void splitFields(std::string_view line, std::vector<std::string_view>& fields) {
    fields.clear();
    size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && isBlank(line[i])) ++i;
        const size_t start = i;
        while (i < line.size() && !isBlank(line[i])) ++i;
        if (i > start) fields.push_back(line.substr(start, i - start));
    }
}

}  // namespace

TriMesh parseObj(std::string_view text, const std::string& source) {
    TriMesh mesh;
    std::vector<std::string_view> fields;
    std::vector<uint32_t> polygon;
    // Positive indices may point at vertices defined further down; check them at the end.
    struct ForwardRef {
        size_t line;
        int64_t index;
    };
    std::vector<ForwardRef> forwardRefs;
    size_t lineNo = 0;
    size_t pos = 0;
    auto lineError = [&](const std::string& what) {
        fail(source, "line " + std::to_string(lineNo) + ": " + what);
    };

    while (pos < text.size()) {
        size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view line = text.substr(pos, end - pos);
        pos = end + 1;
        ++lineNo;
        if (const size_t hash = line.find('#'); hash != std::string_view::npos) line = line.substr(0, hash);
        splitFields(line, fields);
        if (fields.empty()) continue;

        if (fields[0] == "v") {
            if (fields.size() < 4) lineError("vertex needs three coordinates");
            Vec3f p;
            for (int i = 0; i < 3; ++i) {
                std::string_view t = fields[1 + i];
                if (!t.empty() && t[0] == '+') t.remove_prefix(1);
                double value = 0;
                const auto [ptr, ec] = std::from_chars(t.data(), t.data() + t.size(), value);
                if (t.empty() || ptr != t.data() + t.size() || ec == std::errc::invalid_argument)
                    lineError("bad coordinate '" + std::string(fields[1 + i]) + "'");
                p[i] = float(value);
                if (ec == std::errc::result_out_of_range || !std::isfinite(p[i]))
                    lineError("non-finite or out-of-range coordinate '" + std::string(fields[1 + i]) + "'");
            }
            mesh.positions.push_back(p);
        } else if (fields[0] == "f") {
            if (fields.size() < 4) lineError("face needs at least three vertices");
            polygon.clear();
            for (size_t i = 1; i < fields.size(); ++i) {
                // v, v/vt, v//vn or v/vt/vn: only the position index matters.
                const std::string_view t = fields[i];
                const std::string_view first = t.substr(0, t.find('/'));
                int64_t index = 0;
                const auto [ptr, ec] = std::from_chars(first.data(), first.data() + first.size(), index);
                if (first.empty() || ptr != first.data() + first.size() || ec != std::errc())
                    lineError("bad face vertex '" + std::string(t) + "'");
                const int64_t count = int64_t(mesh.positions.size());
                if (index == 0) lineError("vertex index 0 in face (OBJ indices start at 1)");
                if (index < 0) {
                    if (-index > count)
                        lineError("relative vertex index " + std::to_string(index) +
                                  " points before the first vertex");
                    index = count + index + 1;  // -1 is the last vertex defined so far
                } else if (index > count) {
                    if (index > int64_t(UINT32_MAX))
                        lineError("vertex index " + std::to_string(index) + " out of range");
                    forwardRefs.push_back({lineNo, index});
                }
                polygon.push_back(uint32_t(index - 1));
            }
            // Fan triangulation (v0, vi, vi+1): exact for triangles, fine for convex polygons.
            for (size_t i = 1; i + 1 < polygon.size(); ++i)
                mesh.triangles.push_back({polygon[0], polygon[i], polygon[i + 1]});
        }
        // vt, vn, vp, o, g, s, usemtl, mtllib, l, p and unknown records carry no surface geometry.
    }
    for (const ForwardRef& ref : forwardRefs) {
        if (ref.index > int64_t(mesh.positions.size())) {
            lineNo = ref.line;
            lineError("vertex index " + std::to_string(ref.index) + " out of range (the file has " +
                      std::to_string(mesh.positions.size()) + " vertices)");
        }
    }
    return mesh;
}

std::string serializeObj(const TriMesh& mesh) {
    std::string out = std::string("# written by ") + generatorString() + "\n";
    out.reserve(out.size() + mesh.positions.size() * 40 + mesh.triangles.size() * 24);
    char buf[64];
    for (const Vec3f& p : mesh.positions) {
        out += 'v';
        for (float x : p) {
            // Shortest representation that reads back to the same float.
            const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), x);
            out += ' ';
            out.append(buf, end);
        }
        out += '\n';
    }
    for (const Triangle& t : mesh.triangles) {
        out += 'f';
        for (uint32_t v : t) {
            const auto [end, ec] = std::to_chars(buf, buf + sizeof(buf), uint64_t(v) + 1);
            out += ' ';
            out.append(buf, end);
        }
        out += '\n';
    }
    return out;
}

}  // namespace zomefab::detail
