// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/io/mesh_io.h"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "zomefab/core/error.h"
#include "zomefab/io/detail/mesh_formats.h"
#include "zomefab/io/file_io.h"

#if !defined(__BYTE_ORDER__) || __BYTE_ORDER__ != __ORDER_LITTLE_ENDIAN__
#error "zomefab's binary mesh readers and writers assume a little-endian host"
#endif

namespace zomefab {

namespace {

std::string lower(std::string s) {
    std::transform(s.begin(), s.end(), s.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return s;
}

std::optional<MeshFormat> formatFromLowerName(const std::string& name) {
    if (name == "stl") return MeshFormat::Stl;
    if (name == "obj") return MeshFormat::Obj;
    if (name == "ply") return MeshFormat::Ply;
    if (name == "gltf") return MeshFormat::Gltf;
    if (name == "glb") return MeshFormat::Glb;
    return std::nullopt;
}

}  // namespace

MeshFormat meshFormatFromName(const std::string& name, const std::string& sourceName) {
    if (auto format = formatFromLowerName(lower(name))) return *format;
    throw Error(ErrorCode::Usage, "unknown mesh format '" + name + "' (expected stl, obj, ply, gltf or glb)",
                sourceName);
}

MeshFormat meshFormatFromPath(const std::string& path) {
    const std::string ext = fileExtension(path);
    if (auto format = formatFromLowerName(ext)) return *format;
    throw Error(
        ErrorCode::InvalidInput,
        (ext.empty() ? std::string("no file extension") : "unknown mesh file extension '." + ext + "'") +
            " (expected .stl, .obj, .ply, .gltf or .glb, or give the format explicitly)",
        path);
}

const char* meshFormatName(MeshFormat format) {
    switch (format) {
        case MeshFormat::Stl:
            return "stl";
        case MeshFormat::Obj:
            return "obj";
        case MeshFormat::Ply:
            return "ply";
        case MeshFormat::Gltf:
            return "gltf";
        case MeshFormat::Glb:
            return "glb";
    }
    return "?";
}

TriMesh parseMesh(std::string_view bytes, MeshFormat format, const std::string& sourceName,
                  const MeshReadOptions& options) {
    if (bytes.empty()) throw Error(ErrorCode::InvalidInput, "empty file", sourceName);
    TriMesh mesh;
    switch (format) {
        case MeshFormat::Stl:
            mesh = detail::parseStl(bytes, sourceName, options.weldVertices);
            break;
        case MeshFormat::Obj:
            mesh = detail::parseObj(bytes, sourceName);
            break;
        case MeshFormat::Ply:
            mesh = detail::parsePly(bytes, sourceName);
            break;
        case MeshFormat::Gltf:
            mesh = detail::parseGltf(bytes, false, sourceName, options);
            break;
        case MeshFormat::Glb:
            mesh = detail::parseGltf(bytes, true, sourceName, options);
            break;
    }
    if (mesh.triangles.empty())
        throw Error(ErrorCode::InvalidInput,
                    std::string("no triangles in this ") + meshFormatName(format) + " file", sourceName);
    return mesh;
}

TriMesh readMesh(const std::string& path, const MeshReadOptions& options) {
    if (path == "-" && !options.format)
        throw Error(ErrorCode::Usage, "reading a mesh from stdin needs its format (--in-format)", "-");
    // Read first, so a missing file or a directory is reported as such, whatever its extension.
    const std::string bytes = readInputBytes(path);
    const MeshFormat format = options.format ? *options.format : meshFormatFromPath(path);
    MeshReadOptions parseOptions = options;
    if (!parseOptions.externalDir) {
        const std::filesystem::path parent = std::filesystem::path(path).parent_path();
        parseOptions.externalDir = (path == "-" || parent.empty()) ? std::string(".") : parent.string();
    }
    return parseMesh(bytes, format, path, parseOptions);
}

std::string serializeMesh(const TriMesh& mesh, MeshFormat format) {
    for (const Triangle& t : mesh.triangles)
        for (uint32_t v : t)
            if (v >= mesh.positions.size())
                throw Error(ErrorCode::Internal, "cannot write a mesh whose triangle refers to vertex " +
                                                     std::to_string(v) + " of " +
                                                     std::to_string(mesh.positions.size()));
    switch (format) {
        case MeshFormat::Stl:
            return detail::serializeStl(mesh);
        case MeshFormat::Obj:
            return detail::serializeObj(mesh);
        case MeshFormat::Ply:
            return detail::serializePly(mesh);
        case MeshFormat::Gltf:
        case MeshFormat::Glb:
            break;
    }
    throw Error(ErrorCode::Usage, std::string("cannot write meshes as ") + meshFormatName(format) +
                                      " (mesh outputs are stl, obj or ply)");
}

void writeMesh(const TriMesh& mesh, const std::string& path, const MeshWriteOptions& options) {
    if (path == "-" && !options.format)
        throw Error(ErrorCode::Usage, "writing a mesh to stdout needs its format (--out-format)", "-");
    MeshFormat format;
    if (options.format) {
        format = *options.format;
    } else {
        const std::string ext = fileExtension(path);
        const auto fromExt = formatFromLowerName(ext);
        if (!fromExt)
            throw Error(ErrorCode::Usage,
                        "unknown mesh output extension '." + ext + "' (expected .stl, .obj or .ply)", path);
        format = *fromExt;
    }
    std::string bytes;
    try {
        bytes = serializeMesh(mesh, format);
    } catch (const Error& e) {
        throw e.withFile(path);
    }
    writeOutputAtomic(path,
                      [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); });
}


}  // namespace zomefab
