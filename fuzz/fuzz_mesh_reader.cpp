// SPDX-License-Identifier: GPL-3.0-or-later
/// @file libFuzzer entry point for one mesh reader (chosen at compile time). A zomefab::Error is
/// the expected answer to bad input; anything else (crash, sanitizer report, other exception,
/// a broken invariant of the returned mesh) is a bug.
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#include "zomefab/core/error.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/mesh/mesh_check.h"

using namespace zomefab;

namespace {

void require(bool condition, const char* what) {
    if (!condition) {
        std::fprintf(stderr, "fuzz invariant broken: %s\n", what);
        std::abort();
    }
}

MeshFormat formatFor(std::string_view bytes) {
#if defined(ZOMEFAB_FUZZ_FORMAT_stl)
    (void)bytes;
    return MeshFormat::Stl;
#elif defined(ZOMEFAB_FUZZ_FORMAT_obj)
    (void)bytes;
    return MeshFormat::Obj;
#elif defined(ZOMEFAB_FUZZ_FORMAT_ply)
    (void)bytes;
    return MeshFormat::Ply;
#else
    return bytes.substr(0, 4) == "glTF" ? MeshFormat::Glb : MeshFormat::Gltf;
#endif
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    const std::string_view bytes(reinterpret_cast<const char*>(data), size);
    const MeshFormat format = formatFor(bytes);
    TriMesh mesh;
    try {
        mesh = parseMesh(bytes, format, "fuzz-input");  // no externalDir: glTF may not open files
    } catch (const Error&) {
        return 0;
    }
    // What every reader promises.
    require(!mesh.triangles.empty(), "a mesh without triangles was returned");
    for (const Triangle& t : mesh.triangles)
        for (uint32_t v : t) require(v < mesh.positions.size(), "triangle index out of range");
    for (const Vec3f& p : mesh.positions)
        require(std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]), "non-finite position");
    require(mesh.salientFaces.empty() || mesh.salientFaces.size() == mesh.triangles.size(), "salient flags");
    const mesh::MeshReport report = mesh::checkMesh(mesh);
    require(report.triangleCount == mesh.triangles.size(), "report triangle count");
    // What is written reads back with the same triangles.
    for (MeshFormat out : {MeshFormat::Stl, MeshFormat::Obj, MeshFormat::Ply}) {
        const TriMesh back = parseMesh(serializeMesh(mesh, out), out, "round-trip");
        require(back.triangles.size() == mesh.triangles.size(), "round trip changed the triangle count");
    }
    return 0;
}
