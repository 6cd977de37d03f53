// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The GLB writer: container layout, accessors and bounds, instancing, Draco primitives
/// decoded back (in process and with the draco_decoder tool), the Khronos glTF-Validator (run
/// through node when it is installed), and reading glTF and writing a Draco GLB in one process.
#include "zomefab/io/glb_write.h"

#include <doctest/doctest.h>
#include <draco/compression/decode.h>
#include <draco/mesh/mesh.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "glb_test_util.h"
#include "io_test_util.h"
#include "test_util.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"

using namespace zomefab;
using namespace zomefab::test;

namespace {

/// A sphere (Draco) and a box (plain, with normals, shown by three nodes) under a scaled root.
GlbScene testScene() {
    GlbScene s;
    s.generator = "zomefab test";
    s.materials = {{"red", {0.8, 0.05, 0.05, 1.0}, 0.0, 0.5}, {"white", {0.9, 0.9, 0.9, 1.0}, 0.0, 0.3}};
    GlbMesh sphere;
    sphere.name = "sphere";
    sphere.geometry = makeSphere({0, 0, 0}, 25, 24, 48);
    sphere.material = 0;
    sphere.isDracoCompressed = true;
    GlbMesh box;
    box.name = "box";
    // Flat-shaded box: 4 vertices per face with the face normal.
    const TriMesh b = makeBox({-5, -5, -5}, {5, 5, 5});
    for (const Triangle& t : b.triangles) {
        const Vec3f &p = b.positions[t[0]], &q = b.positions[t[1]], &r = b.positions[t[2]];
        const double ux = q[0] - p[0], uy = q[1] - p[1], uz = q[2] - p[2], vx = r[0] - p[0], vy = r[1] - p[1],
                     vz = r[2] - p[2];
        double n[3] = {uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx};
        const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
        const uint32_t base = uint32_t(box.geometry.positions.size());
        for (uint32_t v : t) {
            box.geometry.positions.push_back(b.positions[v]);
            box.normals.push_back({float(n[0] / len), float(n[1] / len), float(n[2] / len)});
        }
        box.geometry.triangles.push_back({base, base + 1, base + 2});
    }
    box.material = 1;
    s.meshes = {sphere, box};
    GlbNode root;
    root.name = "root";
    root.scale = {0.001, 0.001, 0.001};
    root.rotation = {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};
    root.children = {1, 2, 3, 4};
    GlbNode sphereNode;
    sphereNode.name = "sphere-0";
    sphereNode.mesh = 0;
    s.nodes = {root, sphereNode};
    for (int i = 0; i < 3; ++i) {
        GlbNode n;
        n.name = "box-" + std::to_string(i);
        n.mesh = 1;
        n.translation = {40.0 * (i + 1), 0.0, 0.0};
        n.extras = {{"index", i}};
        s.nodes.push_back(n);
    }
    s.roots = {0};
    s.sceneName = "test";
    s.extras = {{"parts", {{"balls", 3}}}};
    return s;
}

}  // namespace

TEST_CASE("glb_write: container, accessors, bounds and instancing of a plain mesh") {
    const GlbScene scene = testScene();
    const Glb g = parseGlb(serializeGlb(scene));
    const nlohmann::json& j = g.json;
    CHECK(j["asset"]["version"] == "2.0");
    CHECK(j["asset"]["generator"] == "zomefab test");
    CHECK(j["scene"] == 0);
    CHECK(j["scenes"][0]["nodes"] == nlohmann::json::array({0}));
    CHECK(j["scenes"][0]["extras"]["parts"]["balls"] == 3);
    CHECK(j["buffers"][0]["byteLength"] == g.bin.size());
    // Three nodes share mesh 1; defaults (rotation, scale) are left out.
    for (int i = 2; i <= 4; ++i) {
        CHECK(j["nodes"][size_t(i)]["mesh"] == 1);
        CHECK(!j["nodes"][size_t(i)].contains("rotation"));
        CHECK(j["nodes"][size_t(i)]["extras"]["index"] == i - 2);
    }
    CHECK(j["nodes"][0]["scale"] == nlohmann::json::array({0.001, 0.001, 0.001}));

    const nlohmann::json& prim = j["meshes"][1]["primitives"][0];
    CHECK(prim["mode"] == 4);
    CHECK(prim["material"] == 1);
    const nlohmann::json& pos = j["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
    CHECK(pos["count"] == 36);
    CHECK(pos["min"] == nlohmann::json::array({-5.0, -5.0, -5.0}));
    CHECK(pos["max"] == nlohmann::json::array({5.0, 5.0, 5.0}));
    const std::string positions = viewBytes(g, pos["bufferView"]);
    REQUIRE(positions.size() == 36 * 12);
    CHECK(std::memcmp(positions.data(), scene.meshes[1].geometry.positions.data(), positions.size()) == 0);
    const nlohmann::json& idx = j["accessors"][prim["indices"].get<size_t>()];
    CHECK(idx["componentType"] == 5123);  // uint16: fewer than 65536 vertices
    CHECK(idx["count"] == 36);
    const std::string indices = viewBytes(g, idx["bufferView"]);
    uint16_t third = 0;
    std::memcpy(&third, indices.data() + 4, 2);
    CHECK(third == 2);
    CHECK(j["bufferViews"][idx["bufferView"].get<size_t>()]["target"] == 34963);
}

TEST_CASE("glb_write: Draco primitives decode to the mesh, within the quantisation step") {
    const GlbScene scene = testScene();
    const Glb g = parseGlb(serializeGlb(scene));
    const nlohmann::json& j = g.json;
    CHECK(j["extensionsUsed"] == nlohmann::json::array({"KHR_draco_mesh_compression"}));
    CHECK(j["extensionsRequired"] == nlohmann::json::array({"KHR_draco_mesh_compression"}));
    const nlohmann::json& prim = j["meshes"][0]["primitives"][0];
    const nlohmann::json& ext = prim["extensions"]["KHR_draco_mesh_compression"];
    const nlohmann::json& pos = j["accessors"][prim["attributes"]["POSITION"].get<size_t>()];
    CHECK(!pos.contains("bufferView"));  // the data lives in the Draco bitstream
    const std::string bytes = viewBytes(g, ext["bufferView"]);
    draco::DecoderBuffer in;
    in.Init(bytes.data(), bytes.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&in);
    REQUIRE(decoded.ok());
    const std::unique_ptr<draco::Mesh> mesh = std::move(decoded).value();
    const TriMesh& original = scene.meshes[0].geometry;
    CHECK(mesh->num_faces() == original.triangles.size());
    CHECK(pos["count"] == mesh->num_points());
    CHECK(j["accessors"][prim["indices"].get<size_t>()]["count"] == 3 * original.triangles.size());
    const draco::PointAttribute* att =
        mesh->GetAttributeByUniqueId(ext["attributes"]["POSITION"].get<uint32_t>());
    REQUIRE(att != nullptr);
    // 14 bits over a 50 mm box: every decoded point lies within 0.004 mm of an input vertex.
    const double step = 50.0 / ((1 << 14) - 1);
    double worst = 0.0;
    for (uint32_t p = 0; p < mesh->num_points(); ++p) {
        float v[3];
        att->GetMappedValue(draco::PointIndex(p), v);
        double best = 1e9;
        for (const Vec3f& q : original.positions)
            best = std::min(best, std::hypot(double(v[0]) - q[0], double(v[1]) - q[1], double(v[2]) - q[2]));
        worst = std::max(worst, best);
        for (int c = 0; c < 3; ++c) {
            CHECK(v[c] >= pos["min"][size_t(c)].get<double>());
            CHECK(v[c] <= pos["max"][size_t(c)].get<double>());
        }
    }
    CHECK(worst <= step);
    // The volume survives: decoded faces keep the outward winding.
    double volume = 0.0;
    for (draco::FaceIndex f(0); f < mesh->num_faces(); ++f) {
        float a[3], b[3], c[3];
        att->GetMappedValue(mesh->face(f)[0], a);
        att->GetMappedValue(mesh->face(f)[1], b);
        att->GetMappedValue(mesh->face(f)[2], c);
        volume += (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
                   a[2] * (b[0] * c[1] - b[1] * c[0])) /
                  6.0;
    }
    CHECK(volume == doctest::Approx(signedVolume(original)).epsilon(1e-3));
}

TEST_CASE("glb_write: reading glTF and writing a Draco GLB in one process") {
    // The shipped combination: zomefab_io links libtinygltf before libdraco (io/CMakeLists.txt).
    const TriMesh tetra = readMesh(std::string(ZOMEFAB_CLI_FIXTURES) + "/tetra.glb");
    REQUIRE(tetra.triangles.size() == 4);
    GlbScene scene;
    GlbMesh compressed;
    compressed.geometry = makeSphere({0, 0, 0}, 10, 12, 24);
    compressed.isDracoCompressed = true;
    GlbMesh plain;
    plain.geometry = tetra;
    scene.meshes = {compressed, plain};
    scene.nodes.resize(2);
    scene.nodes[0].mesh = 0;
    scene.nodes[1].mesh = 1;
    scene.roots = {0, 1};
    ScratchDir dir("zomefab-glb");
    writeGlb(scene, dir.file("both.glb"));
    // The reader still works after Draco ran. It cannot read Draco primitives: tinygltf 2.7 stops
    // at their accessors (which have no bufferView), so the message names the file, not Draco.
    requireError([&] { readMesh(dir.file("both.glb")); }, ErrorCode::InvalidInput, {"both.glb"});
    scene.meshes[0].isDracoCompressed = false;
    writeGlb(scene, dir.file("plain.glb"));
    const TriMesh back = readMesh(dir.file("plain.glb"));
    CHECK(back.triangles.size() == compressed.geometry.triangles.size() + 4);
    CHECK(std::abs(signedVolume(back) - signedVolume(compressed.geometry) - signedVolume(tetra)) < 1e-3);
}

TEST_CASE("glb_write: the same scene gives the same bytes") {
    CHECK(serializeGlb(testScene()) == serializeGlb(testScene()));
}

TEST_CASE("glb_write: inconsistent scenes are refused, naming the mesh or node") {
    auto refuse = [](GlbScene s, std::initializer_list<std::string> parts) {
        requireError([&] { serializeGlb(s); }, ErrorCode::InvalidInput, parts);
    };
    GlbScene s = testScene();
    s.nodes[2].mesh = 7;
    refuse(s, {"node 2 'box-0'", "mesh 7"});
    s = testScene();
    s.nodes[3].children = {0};
    refuse(s, {"node 0 'root'", "cycle"});
    s = testScene();
    s.nodes[1].children = {1};
    refuse(s, {"more than one parent"});
    s = testScene();
    s.meshes[1].material = 5;
    refuse(s, {"mesh 1 'box'", "material 5"});
    s = testScene();
    s.meshes[1].geometry.triangles.push_back({0, 1, 99});
    refuse(s, {"mesh 1 'box'", "vertex index 99"});
    s = testScene();
    s.meshes[0].geometry.triangles.clear();
    refuse(s, {"mesh 0 'sphere'", "no triangles"});
    s = testScene();
    s.meshes[1].normals.pop_back();
    refuse(s, {"normals for"});
    s = testScene();
    s.nodes[2].rotation = {0, 0, 0, 2};
    refuse(s, {"unit quaternion"});
    s = testScene();
    s.meshes[0].geometry.positions[3][1] = std::nanf("");
    refuse(s, {"non-finite position"});
    s = testScene();
    s.roots = {0, 2};
    refuse(s, {"a root and a child"});
    s = testScene();
    GlbWriteOptions bad;
    bad.dracoPositionBits = 31;
    requireError([&] { serializeGlb(s, bad); }, ErrorCode::Usage, {"Draco options"});
}

TEST_CASE("glb_write: draco_decoder decodes every compressed primitive") {
    if (!hasCommand("draco_decoder")) {
        MESSAGE("draco_decoder is not installed (Debian package draco): skipped");
        return;
    }
    const Glb g = parseGlb(serializeGlb(testScene()));
    const nlohmann::json& prim = g.json["meshes"][0]["primitives"][0];
    ScratchDir dir("zomefab-drc");
    writeBytes(dir.file("sphere.drc"),
               viewBytes(g, prim["extensions"]["KHR_draco_mesh_compression"]["bufferView"]));
    const auto [vertices, faces] = dracoDecodeCounts(dir.file("sphere.drc"), dir.file("sphere.obj"));
    REQUIRE(vertices > 0);
    CHECK(vertices ==
          g.json["accessors"][prim["attributes"]["POSITION"].get<size_t>()]["count"].get<size_t>());
    CHECK(3 * faces == g.json["accessors"][prim["indices"].get<size_t>()]["count"].get<size_t>());
}

TEST_CASE("glb_write: the Khronos glTF-Validator finds no errors and no warnings") {
    if (!hasCommand("node")) {
        MESSAGE("node is not installed: the Khronos glTF-Validator check is skipped");
        return;
    }
    ScratchDir dir("zomefab-validate");
    writeGlb(testScene(), dir.file("scene.glb"));
    const nlohmann::json report = khronosValidate(dir.file("scene.glb"));
    INFO("validator: " << report.dump());
    CHECK(report["errors"] == 0);
    CHECK(report["warnings"] == 0);
}
