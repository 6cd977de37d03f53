// SPDX-License-Identifier: GPL-3.0-or-later
/// @file glTF/GLB input, built in the test: node transforms through the hierarchy, several
/// primitives, strips and fans, sparse accessors, welding of seam-split vertices, external buffers.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <string>
#include <vector>

#include "io_test_util.h"
#include "test_util.h"
#include "zomefab/io/mesh_io.h"

#ifdef ZOMEFAB_TEST_WITH_DRACO
#include <draco/core/decoder_buffer.h>
#endif

using namespace zomefab;
using namespace zomefab::test;

namespace {

std::string base64(const std::string& in) {
    static const char* t = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    size_t i = 0;
    for (; i + 2 < in.size(); i += 3) {
        const uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8) | uint8_t(in[i + 2]);
        for (int k = 3; k >= 0; --k) out += t[(v >> (6 * k)) & 63];
    }
    if (i + 1 == in.size()) {
        const uint32_t v = uint8_t(in[i]) << 16;
        out += t[(v >> 18) & 63], out += t[(v >> 12) & 63], out += "==";
    } else if (i + 2 == in.size()) {
        const uint32_t v = (uint8_t(in[i]) << 16) | (uint8_t(in[i + 1]) << 8);
        out += t[(v >> 18) & 63], out += t[(v >> 12) & 63], out += t[(v >> 6) & 63], out += '=';
    }
    return out;
}

template <typename T>
void put(std::string& s, T v) {
    s.append(reinterpret_cast<const char*>(&v), sizeof(T));
}

/// A GLB container: 12-byte header, JSON chunk, BIN chunk, each padded to 4 bytes.
[[maybe_unused]] std::string glb(std::string json, std::string bin) {
    while (json.size() % 4) json += ' ';
    while (bin.size() % 4) bin += '\0';
    std::string s = "glTF";
    put<uint32_t>(s, 2);
    put<uint32_t>(s, uint32_t(12 + 8 + json.size() + 8 + bin.size()));
    put<uint32_t>(s, uint32_t(json.size()));
    s += "JSON";
    s += json;
    put<uint32_t>(s, uint32_t(bin.size()));
    s += std::string("BIN\0", 4);
    s += bin;
    return s;
}

/// Unit tetrahedron: 4 float positions then 12 uint16 indices (48 + 24 bytes).
std::string tetraBuffer() {
    std::string b;
    for (float x : {0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f, 0.f, 0.f, 0.f, 1.f}) put<float>(b, x);
    for (uint16_t i : {0, 2, 1, 0, 1, 3, 1, 2, 3, 2, 0, 3}) put<uint16_t>(b, i);
    return b;
}

const char* kTetraViews = R"("bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},
                                    {"buffer":0,"byteOffset":48,"byteLength":24}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"},
                   {"bufferView":1,"componentType":5123,"count":12,"type":"SCALAR"}])";

/// A glTF scene of the tetrahedron mesh instanced by @p nodes (JSON array text), buffer embedded
/// as a data: URI.
std::string tetraGltf(const std::string& nodes, const std::string& sceneNodes) {
    const std::string bin = tetraBuffer();
    return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":)" + sceneNodes + R"(}],"nodes":)" +
           nodes +
           R"(,"meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
      "buffers":[{"byteLength":)" +
           std::to_string(bin.size()) + R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin) +
           R"("}],)" + kTetraViews + "}";
}

[[maybe_unused]] Box3d boxOf(const TriMesh& m) { return boundingBox(m); }

}  // namespace

#if !defined(ZOMEFAB_TEST_WITH_DRACO) || ZOMEFAB_TEST_WITH_DRACO == 1
TEST_CASE("gltf: GLB and glTF of the same tetrahedron read alike") {
    const std::string json = R"({"asset":{"version":"2.0"},"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1,"mode":4}]}],
      "buffers":[{"byteLength":72}],)" +
                             std::string(kTetraViews) + "}";
    const TriMesh fromGlb = parseMesh(glb(json, tetraBuffer()), MeshFormat::Glb, "t.glb");
    const TriMesh fromGltf = parseMesh(tetraGltf("[{\"mesh\":0}]", "[0]"), MeshFormat::Gltf, "t.gltf");
    CHECK(fromGlb.triangleCount() == 4);
    CHECK(fromGlb.vertexCount() == 4);
    CHECK(signedVolume(fromGlb) == doctest::Approx(1.0 / 6.0));
    CHECK(sameGeometry(fromGlb, fromGltf));
}

TEST_CASE("gltf: node transforms are applied through the hierarchy (TRS, matrix, mirror)") {
    // Node 0: translate (10, 0, 0), child node 1: uniform scale 2 with the mesh -> x in [10, 12].
    // Node 2: rotation 90 deg about z then the mesh -> (1,0,0) maps to (0,1,0).
    // Node 3: column-major matrix translating by (0, 0, 5) with scale 3.
    // Node 4: mirror x (scale -1): the winding must be reversed so the volume stays positive.
    const std::string nodes = R"([{"translation":[10,0,0],"children":[1]},
        {"scale":[2,2,2],"mesh":0},
        {"rotation":[0,0,0.7071067811865476,0.7071067811865476],"mesh":0},
        {"matrix":[3,0,0,0, 0,3,0,0, 0,0,3,0, 0,0,5,1],"mesh":0},
        {"scale":[-1,1,1],"translation":[-20,0,0],"mesh":0}])";
    MeshReadOptions noWeld;
    noWeld.weldVertices = false;
    const TriMesh m = parseMesh(tetraGltf(nodes, "[0,2,3,4]"), MeshFormat::Gltf, "scene.gltf", noWeld);
    REQUIRE(m.vertexCount() == 16);
    REQUIRE(m.triangleCount() == 16);
    auto vertex = [&](int instance, int corner) { return m.positions[size_t(instance * 4 + corner)]; };
    CHECK(vertex(0, 1)[0] == doctest::Approx(12.0));  // 10 + 2 * 1
    CHECK(vertex(0, 3)[2] == doctest::Approx(2.0));
    CHECK(vertex(1, 1)[0] == doctest::Approx(0.0).epsilon(1e-6));
    CHECK(vertex(1, 1)[1] == doctest::Approx(1.0));
    CHECK(vertex(2, 0)[2] == doctest::Approx(5.0));
    CHECK(vertex(2, 3)[2] == doctest::Approx(8.0));
    CHECK(vertex(3, 1)[0] == doctest::Approx(-21.0));
    // Every instance is outward: 8/6 + 1/6 + 27/6 + 1/6.
    CHECK(signedVolume(m) == doctest::Approx((8.0 + 1.0 + 27.0 + 1.0) / 6.0));

    // Only the scene's nodes count: node 2 alone.
    const TriMesh one = parseMesh(tetraGltf(nodes, "[2]"), MeshFormat::Gltf, "scene.gltf");
    CHECK(one.triangleCount() == 4);
}

TEST_CASE("gltf: several primitives, non-indexed, strips, fans, sparse; points and lines skipped") {
    // Buffer: 4 tetra positions (48 bytes), then a 4-vertex quad strip/fan square (48 bytes),
    // then sparse data: one uint8 index (padded to 4) and one replacement VEC3.
    std::string bin = tetraBuffer().substr(0, 48);
    for (float x : {0.f, 0.f, 5.f, 1.f, 0.f, 5.f, 0.f, 1.f, 5.f, 1.f, 1.f, 5.f}) put<float>(bin, x);
    bin += std::string("\x01\0\0\0", 4);
    for (float x : {7.f, 7.f, 7.f}) put<float>(bin, x);
    const std::string json = R"({"asset":{"version":"2.0"},"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[
          {"attributes":{"POSITION":0},"mode":4},
          {"attributes":{"POSITION":1},"mode":5},
          {"attributes":{"POSITION":1},"mode":6},
          {"attributes":{"POSITION":1},"mode":0},
          {"attributes":{"POSITION":1},"mode":1},
          {"attributes":{"POSITION":2},"mode":4}]}],
      "buffers":[{"byteLength":112}],
      "bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":48},
                     {"buffer":0,"byteOffset":96,"byteLength":4},{"buffer":0,"byteOffset":100,"byteLength":12}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"},
                   {"bufferView":1,"componentType":5126,"count":4,"type":"VEC3"},
                   {"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",
                    "sparse":{"count":1,"indices":{"bufferView":2,"componentType":5121},
                              "values":{"bufferView":3}}}]})";
    MeshReadOptions noWeld;
    noWeld.weldVertices = false;
    const TriMesh m = parseMesh(glb(json, bin), MeshFormat::Glb, "prims.glb", noWeld);
    // 1 (triangles) + 2 (strip) + 2 (fan) + 1 (sparse) triangles; points and lines add none.
    CHECK(m.triangleCount() == 6);
    CHECK(m.triangles[1] == Triangle{3, 4, 5});  // strip: (0,1,2), then (2,1,3) keeps the winding
    CHECK(m.triangles[2] == Triangle{5, 4, 6});
    CHECK(m.triangles[3] == Triangle{7, 8, 9});  // fan: (0,1,2), (0,2,3)
    CHECK(m.triangles[4] == Triangle{7, 9, 10});
    CHECK(m.positions[size_t(m.triangles[5][1])] == Vec3f{7, 7, 7});  // sparse replacement of element 1
}

TEST_CASE("gltf: seam-split vertices are welded (a flat-shaded cube has 24 vertices in glTF)") {
    const TriMesh box = makeBox({0, 0, 0}, {1, 1, 1});
    std::string bin;
    for (const Triangle& t : box.triangles)  // 36 corners, no sharing at all
        for (uint32_t v : t)
            for (float x : box.positions[v]) put<float>(bin, x);
    const std::string json =
        R"({"asset":{"version":"2.0"},"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],
      "buffers":[{"byteLength":432}],"bufferViews":[{"buffer":0,"byteLength":432}],
      "accessors":[{"bufferView":0,"componentType":5126,"count":36,"type":"VEC3"}]})";
    const TriMesh welded = parseMesh(glb(json, bin), MeshFormat::Glb, "cube.glb");
    CHECK(welded.vertexCount() == 8);
    CHECK(welded.triangleCount() == 12);
    CHECK(signedVolume(welded) == doctest::Approx(1.0));
    MeshReadOptions noWeld;
    noWeld.weldVertices = false;
    CHECK(parseMesh(glb(json, bin), MeshFormat::Glb, "cube.glb", noWeld).vertexCount() == 36);
}

TEST_CASE("gltf: external buffers load next to the file, and not at all from memory") {
    ScratchDir dir;
    writeBytes(dir.file("tetra.bin"), tetraBuffer());
    const std::string json = R"({"asset":{"version":"2.0"},"nodes":[{"mesh":0,"translation":[0,0,1]}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
      "buffers":[{"byteLength":72,"uri":"tetra.bin"}],)" +
                             std::string(kTetraViews) + "}";
    writeBytes(dir.file("tetra.gltf"), json);
    const TriMesh m = readMesh(dir.file("tetra.gltf"));
    CHECK(m.triangleCount() == 4);
    CHECK(boxOf(m).min[2] == doctest::Approx(1.0));
    requireError([&] { parseMesh(json, MeshFormat::Gltf, "mem.gltf"); }, ErrorCode::InvalidInput,
                 {"mem.gltf: glTF parse error"});
}

TEST_CASE("gltf: malformed input is rejected with one-line errors") {
    requireError([] { parseMesh("{not json", MeshFormat::Gltf, "bad.gltf"); }, ErrorCode::InvalidInput,
                 {"bad.gltf: glTF parse error"});
    requireError([] { parseMesh("glTF\x02", MeshFormat::Glb, "bad.glb"); }, ErrorCode::InvalidInput,
                 {"bad.glb: GLB parse error"});
    // Indices past the vertex count.
    std::string bin = tetraBuffer();
    bin[48] = 9;
    const std::string json = R"({"asset":{"version":"2.0"},"nodes":[{"mesh":0}],
      "meshes":[{"primitives":[{"attributes":{"POSITION":0},"indices":1}]}],
      "buffers":[{"byteLength":72}],)" +
                             std::string(kTetraViews) + "}";
    requireError([&] { parseMesh(glb(json, bin), MeshFormat::Glb, "idx.glb"); }, ErrorCode::InvalidInput,
                 {"idx.glb: glTF mesh 0 primitive 0 has vertex index 9 but only 4 vertices"});
    // An accessor reading past its bufferView.
    std::string longer = json;
    longer.replace(longer.find("\"count\":4"), 9, "\"count\":5");
    requireError([&] { parseMesh(glb(longer, tetraBuffer()), MeshFormat::Glb, "past.glb"); },
                 ErrorCode::InvalidInput,
                 {"past.glb: glTF mesh 0 primitive 0 POSITION reads past the end of bufferView 0"});
    // Only points: no triangles.
    std::string points = json;
    points.replace(points.find("\"indices\":1"), 11, "\"mode\":0");
    requireError([&] { parseMesh(glb(points, tetraBuffer()), MeshFormat::Glb, "pts.glb"); },
                 ErrorCode::InvalidInput, {"pts.glb: no triangles"});
    // Draco-compressed geometry is not readable here.
    std::string draco = json;
    draco.replace(draco.find("\"asset\""), 7,
                  R"("extensionsRequired":["KHR_draco_mesh_compression"],"asset")");
    requireError([&] { parseMesh(glb(draco, tetraBuffer()), MeshFormat::Glb, "draco.glb"); },
                 ErrorCode::InvalidInput, {"draco.glb: glTF uses KHR_draco_mesh_compression"});
    // A node that is its own child.
    requireError(
        [&] { parseMesh(tetraGltf(R"([{"mesh":0,"children":[0]}])", "[0]"), MeshFormat::Gltf, "loop.gltf"); },
        ErrorCode::InvalidInput, {"loop.gltf: glTF node 0 appears twice"});
}

#endif

#ifdef ZOMEFAB_TEST_WITH_DRACO
TEST_CASE("gltf: with libdraco linked too, the reader works or refuses clearly, never crashes") {
    // A call into libdraco, so the linker (Debian's gcc passes --as-needed) really links it.
    draco::DecoderBuffer buffer;
    buffer.Init("x", 1);
    CHECK(buffer.remaining_size() == 1);
    const std::string gltf = tetraGltf("[{\"mesh\":0}]", "[0]");
#if ZOMEFAB_TEST_WITH_DRACO == 1  // libtinygltf first on the link line
    CHECK(parseMesh(gltf, MeshFormat::Gltf, "t.gltf").triangleCount() == 4);
#else  // libdraco first: its tinygltf copy would win
    requireError([&] { parseMesh(gltf, MeshFormat::Gltf, "t.gltf"); }, ErrorCode::Internal,
                 {"link libtinygltf before libdraco"});
#endif
}
#endif

#if !defined(ZOMEFAB_TEST_WITH_DRACO) || ZOMEFAB_TEST_WITH_DRACO == 1
TEST_CASE("gltf: node instancing may not expand a small file without bound") {
    // One mesh of 4095 unindexed vertices (1365 triangles), used by 300 nodes: 1.2 M vertices, more
    // than 16 times what the file stores and more than the 1 M floor.
    std::string bin;
    for (int v = 0; v < 4095; ++v)
        for (float x : {float(v % 7), float(v % 11), float(v % 13)}) put<float>(bin, x);
    auto scene = [&](int instances) {
        std::string nodes = "[", sceneNodes = "[";
        for (int i = 0; i < instances; ++i) {
            nodes += std::string(i ? "," : "") + R"({"mesh":0,"translation":[)" + std::to_string(20 * i) +
                     ",0,0]}";
            sceneNodes += (i ? "," : "") + std::to_string(i);
        }
        return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":)" + sceneNodes +
               R"(]}],"nodes":)" + nodes +
               R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],"buffers":[{"byteLength":)" +
               std::to_string(bin.size()) + R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin) +
               R"("}],"bufferViews":[{"buffer":0,"byteLength":)" + std::to_string(bin.size()) +
               R"(}],"accessors":[{"bufferView":0,"componentType":5126,"count":4095,"type":"VEC3"}]})";
    };
    MeshReadOptions noWeld;
    noWeld.weldVertices = false;
    CHECK(parseMesh(scene(16), MeshFormat::Gltf, "few.gltf", noWeld).vertexCount() == 16 * 4095);
    try {
        parseMesh(scene(300), MeshFormat::Gltf, "many.gltf", noWeld);
        FAIL("no error");
    } catch (const Error& e) {
        CHECK(e.code() == ErrorCode::InvalidInput);
        CHECK(std::string(e.what()).find("many.gltf: glTF nodes use its meshes so often") == 0);
    }
}
#endif
