// SPDX-License-Identifier: GPL-3.0-or-later
// 3MF package writer: XML parts, and a small deterministic zip writer over zlib's raw deflate.
#include "zomefab/io/threemf.h"

#include <zlib.h>

#include <charconv>
#include <cstring>

#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"

namespace zomefab {

namespace {

template <class T>
void put(std::string& out, T value) {
    for (size_t i = 0; i < sizeof(T); ++i) out.push_back(char((uint64_t(value) >> (8 * i)) & 0xFF));  // little-endian
}

/// Raw deflate (no zlib header), as zip's method 8 expects.
std::string deflateRaw(const std::string& data) {
    z_stream z{};
    // Level 6 (zlib's default): about 5× smaller XML at ~30 MB/s here; windowBits −15 = raw.
    if (deflateInit2(&z, 6, Z_DEFLATED, -15, 8, Z_DEFAULT_STRATEGY) != Z_OK)
        throw Error(ErrorCode::Internal, "zlib: deflateInit2 failed");
    std::string out;
    out.resize(deflateBound(&z, uLong(data.size())));
    z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
    z.avail_in = uInt(data.size());
    z.next_out = reinterpret_cast<Bytef*>(out.data());
    z.avail_out = uInt(out.size());
    const int rc = deflate(&z, Z_FINISH);
    const size_t written = z.total_out;
    deflateEnd(&z);
    if (rc != Z_STREAM_END) throw Error(ErrorCode::Internal, "zlib: deflate did not finish");
    out.resize(written);
    return out;
}

void appendEscaped(std::string& out, const std::string& text) {
    for (char c : text) {
        switch (c) {
            case '&': out += "&amp;"; break;
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '"': out += "&quot;"; break;
            case '\'': out += "&apos;"; break;
            default: out.push_back(c);
        }
    }
}

/// Shortest decimal that reads back to the same float (std::to_chars): locale-independent.
void appendNumber(std::string& out, float v) {
    char buffer[32];
    const auto r = std::to_chars(buffer, buffer + sizeof(buffer), v == 0.0f ? 0.0f : v);
    out.append(buffer, r.ptr);
}
void appendNumber(std::string& out, double v) {
    char buffer[40];
    const auto r = std::to_chars(buffer, buffer + sizeof(buffer), v == 0.0 ? 0.0 : v);
    out.append(buffer, r.ptr);
}
void appendNumber(std::string& out, uint32_t v) {
    char buffer[16];
    const auto r = std::to_chars(buffer, buffer + sizeof(buffer), v);
    out.append(buffer, r.ptr);
}

std::string modelXml(const std::vector<ThreeMfObject>& objects, const std::string& generator) {
    std::string x;
    size_t estimate = 1024;
    for (const ThreeMfObject& o : objects)
        if (o.mesh) estimate += 60 * o.mesh->positions.size() + 50 * o.mesh->triangles.size();
    x.reserve(estimate);
    x += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
         "<model unit=\"millimeter\" xml:lang=\"en-US\" "
         "xmlns=\"http://schemas.microsoft.com/3dmanufacturing/core/2015/02\">\n"
         " <metadata name=\"Application\">";
    appendEscaped(x, generator);
    x += "</metadata>\n <resources>\n";
    for (size_t i = 0; i < objects.size(); ++i) {
        const TriMesh& m = *objects[i].mesh;
        x += "  <object id=\"";
        appendNumber(x, uint32_t(i + 1));
        x += "\" name=\"";
        appendEscaped(x, objects[i].name);
        x += "\" type=\"model\">\n   <mesh>\n    <vertices>\n";
        for (const Vec3f& p : m.positions) {
            x += "     <vertex x=\"";
            appendNumber(x, p[0]);
            x += "\" y=\"";
            appendNumber(x, p[1]);
            x += "\" z=\"";
            appendNumber(x, p[2]);
            x += "\"/>\n";
        }
        x += "    </vertices>\n    <triangles>\n";
        for (const Triangle& t : m.triangles) {
            x += "     <triangle v1=\"";
            appendNumber(x, t[0]);
            x += "\" v2=\"";
            appendNumber(x, t[1]);
            x += "\" v3=\"";
            appendNumber(x, t[2]);
            x += "\"/>\n";
        }
        x += "    </triangles>\n   </mesh>\n  </object>\n";
    }
    x += " </resources>\n <build>\n";
    for (size_t i = 0; i < objects.size(); ++i) {
        // 3MF multiplies row vectors: [x y z 1]·M, so M's rows are the columns of ours and the
        // translation is the last row: "m00 m01 m02 m10 m11 m12 m20 m21 m22 m30 m31 m32".
        const Transform4d& t = objects[i].placementMm;
        x += "  <item objectid=\"";
        appendNumber(x, uint32_t(i + 1));
        x += "\" transform=\"";
        for (int row = 0; row < 4; ++row)
            for (int col = 0; col < 3; ++col) {
                if (row > 0 || col > 0) x += ' ';
                appendNumber(x, row < 3 ? t.at(col, row) : t.at(col, 3));
            }
        x += "\"/>\n";
    }
    x += " </build>\n</model>\n";
    return x;
}

}  // namespace

std::string zipArchive(const std::vector<ZipEntry>& entries) {
    if (entries.size() > 0xFFFF) throw Error(ErrorCode::WriteFailed, "a zip archive holds at most 65535 entries");
    std::string out, central;
    const uint16_t time = 0, date = (0 << 9) | (1 << 5) | 1;  // 1980-01-01 00:00: reproducible bytes
    for (const ZipEntry& e : entries) {
        const uint32_t crc = uint32_t(crc32(crc32(0L, Z_NULL, 0), reinterpret_cast<const Bytef*>(e.data.data()),
                                            uInt(e.data.size())));
        std::string deflated = deflateRaw(e.data);
        const bool isDeflated = deflated.size() < e.data.size();
        const std::string& body = isDeflated ? deflated : e.data;
        if (e.data.size() >= 0xFFFFFFFFull || out.size() + body.size() + e.name.size() + 64 >= 0xFFFFFFFFull)
            throw Error(ErrorCode::WriteFailed, "the zip archive would exceed 4 GiB");
        const uint32_t offset = uint32_t(out.size());
        const uint16_t method = isDeflated ? 8 : 0;
        put<uint32_t>(out, 0x04034b50);  // local file header
        put<uint16_t>(out, 20);          // version needed: 2.0 (deflate)
        put<uint16_t>(out, 0);           // flags
        put<uint16_t>(out, method);
        put<uint16_t>(out, time);
        put<uint16_t>(out, date);
        put<uint32_t>(out, crc);
        put<uint32_t>(out, uint32_t(body.size()));
        put<uint32_t>(out, uint32_t(e.data.size()));
        put<uint16_t>(out, uint16_t(e.name.size()));
        put<uint16_t>(out, 0);  // extra field length
        out += e.name;
        out += body;

        put<uint32_t>(central, 0x02014b50);  // central directory header
        put<uint16_t>(central, 20);          // version made by: 2.0, MS-DOS attributes
        put<uint16_t>(central, 20);
        put<uint16_t>(central, 0);
        put<uint16_t>(central, method);
        put<uint16_t>(central, time);
        put<uint16_t>(central, date);
        put<uint32_t>(central, crc);
        put<uint32_t>(central, uint32_t(body.size()));
        put<uint32_t>(central, uint32_t(e.data.size()));
        put<uint16_t>(central, uint16_t(e.name.size()));
        put<uint16_t>(central, 0);  // extra
        put<uint16_t>(central, 0);  // comment
        put<uint16_t>(central, 0);  // disk number
        put<uint16_t>(central, 0);  // internal attributes
        put<uint32_t>(central, 0);  // external attributes
        put<uint32_t>(central, offset);
        central += e.name;
    }
    if (out.size() + central.size() + 22 >= 0xFFFFFFFFull)
        throw Error(ErrorCode::WriteFailed, "the zip archive would exceed 4 GiB");
    const uint32_t centralOffset = uint32_t(out.size());
    out += central;
    put<uint32_t>(out, 0x06054b50);  // end of central directory
    put<uint16_t>(out, 0);
    put<uint16_t>(out, 0);
    put<uint16_t>(out, uint16_t(entries.size()));
    put<uint16_t>(out, uint16_t(entries.size()));
    put<uint32_t>(out, uint32_t(central.size()));
    put<uint32_t>(out, centralOffset);
    put<uint16_t>(out, 0);  // comment length
    return out;
}

std::string threeMfBytes(const std::vector<ThreeMfObject>& objects, const std::string& generator) {
    for (size_t i = 0; i < objects.size(); ++i) {
        const TriMesh* m = objects[i].mesh;
        if (!m || m->triangles.empty())
            throw Error(ErrorCode::Usage, "3MF object " + std::to_string(i) + " ('" + objects[i].name + "') has no mesh");
        for (const Triangle& t : m->triangles)
            for (uint32_t v : t)
                if (v >= m->positions.size())
                    throw Error(ErrorCode::Usage, "3MF object '" + objects[i].name + "' has a vertex index out of range");
    }
    std::vector<ZipEntry> entries;
    entries.push_back({"[Content_Types].xml",
                       "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                       "<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">\n"
                       " <Default Extension=\"rels\" "
                       "ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>\n"
                       " <Default Extension=\"model\" "
                       "ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/>\n"
                       "</Types>\n"});
    entries.push_back({"_rels/.rels",
                       "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
                       "<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\n"
                       " <Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" "
                       "Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/>\n"
                       "</Relationships>\n"});
    entries.push_back({"3D/3dmodel.model", modelXml(objects, generator)});
    return zipArchive(entries);
}

void writeThreeMf(const std::vector<ThreeMfObject>& objects, const std::string& generator, const std::string& path) {
    const std::string bytes = threeMfBytes(objects, generator);
    writeOutputAtomic(path, [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); });
}

}  // namespace zomefab
