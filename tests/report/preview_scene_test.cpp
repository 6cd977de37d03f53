// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The preview scene: strut cross-sections and their orientation on the ball, instancing,
/// node names, transforms that put every strut between its balls' surfaces, extras.
#include "zomefab/report/preview_scene.h"

#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "report_test_util.h"
#include "test_util.h"
#include "zomefab/core/error.h"
#include "zomefab/zome/holes.h"
#include "zomefab/zome/parts.h"

using namespace zomefab;
using namespace zomefab::report;
using namespace zomefab::test;

namespace {

double polygonArea(const std::vector<std::array<double, 2>>& p) {
    double s = 0.0;
    for (size_t i = 0; i < p.size(); ++i) {
        const auto &a = p[i], &b = p[(i + 1) % p.size()];
        s += a[0] * b[1] - a[1] * b[0];
    }
    return 0.5 * s;
}

/// Rotates @p v by the unit quaternion @p q (x, y, z, w).
Vec3d rotate(const std::array<double, 4>& q, const Vec3d& v) {
    const Vec3d u{q[0], q[1], q[2]};
    const double w = q[3];
    const Vec3d t{2 * (u[1] * v[2] - u[2] * v[1]), 2 * (u[2] * v[0] - u[0] * v[2]),
                  2 * (u[0] * v[1] - u[1] * v[0])};
    return {v[0] + w * t[0] + (u[1] * t[2] - u[2] * t[1]), v[1] + w * t[1] + (u[2] * t[0] - u[0] * t[2]),
            v[2] + w * t[2] + (u[0] * t[1] - u[1] * t[0])};
}

/// The JSON chunk of a GLB.
nlohmann::json glbJson(const std::string& glb) {
    REQUIRE(glb.size() >= 20);
    REQUIRE(glb.compare(0, 4, "glTF") == 0);
    uint32_t length = 0, jsonLength = 0;
    std::memcpy(&length, glb.data() + 8, 4);
    std::memcpy(&jsonLength, glb.data() + 12, 4);
    CHECK(length == glb.size());
    CHECK(glb.compare(16, 4, "JSON") == 0);
    return nlohmann::json::parse(glb.substr(20, jsonLength));
}

const GlbNode* findNode(const GlbScene& s, const std::string& name) {
    for (const GlbNode& n : s.nodes)
        if (n.name == name) return &n;
    return nullptr;
}

}  // namespace

TEST_CASE("preview_scene: strut cross-sections have the Zome model's sizes") {
    const auto blue = zome::holeSectionMm(zome::Color::Blue);
    CHECK(blue.size() == 4);
    CHECK(polygonArea(blue) == doctest::Approx(5.46 * 3.38));
    const auto yellow = zome::holeSectionMm(zome::Color::Yellow);
    CHECK(yellow.size() == 3);
    const double edge = std::hypot(yellow[1][0] - yellow[0][0], yellow[1][1] - yellow[0][1]);
    CHECK(edge == doctest::Approx(5.46));  // the blue rectangle's long side
    const auto red = zome::holeSectionMm(zome::Color::Red);
    CHECK(red.size() == 5);
    CHECK(std::hypot(red[0][0], red[0][1]) == doctest::Approx(2.87));
    for (const auto& s : {blue, yellow, red}) CHECK(polygonArea(s) > 0.0);  // counter-clockwise
}

TEST_CASE("preview_scene: pieces, one instanced ball mesh, one mesh per strut kind") {
    const zome::Structure frame = colourFrame();
    PreviewInput input;
    const std::vector<TriMesh> meshes{makeBox({-30, -30, -30}, {0, 0, 0}),
                                      makeSphere({80, 0, 0}, 20, 12, 24)};
    input.pieces = test::pointersTo(meshes);
    input.pieceNames = {"piece-00", "piece-01"};
    input.frame = &frame;
    input.extras = {{"run", "test"}, {"format", "must not override"}};
    const GlbScene scene = buildPreviewScene(input);

    // Meshes: 2 pieces (Draco) + ball + B0, Y0, R0, B1.
    REQUIRE(scene.meshes.size() == 7);
    CHECK(scene.meshes[0].isDracoCompressed);
    CHECK(scene.meshes[1].isDracoCompressed);
    CHECK(scene.meshes[0].material != scene.meshes[1].material);
    std::map<int, int> uses;
    for (const GlbNode& n : scene.nodes)
        if (n.mesh >= 0) ++uses[n.mesh];
    const int ballMesh = findNode(scene, "ball-0")->mesh;
    CHECK(uses[ballMesh] == 5);
    CHECK(scene.meshes[size_t(ballMesh)].geometry.triangles.size() == 320);
    CHECK(isClosedOriented(scene.meshes[size_t(ballMesh)].geometry));

    // Root: mm → m and z up → y up.
    REQUIRE(scene.roots.size() == 1);
    const GlbNode& root = scene.nodes[size_t(scene.roots[0])];
    CHECK(root.name == "zomefab");
    CHECK(root.scale[0] == 0.001);
    const Vec3d up = rotate(root.rotation, {0, 0, 1});
    CHECK(up[1] == doctest::Approx(1.0));

    // Every strut prism runs from ball surface to ball surface, along its hole, cross-section
    // aligned with zome::holeSectionAxis().
    for (zome::StrutId id : frame.strutIds()) {
        const zome::Strut& s = frame.strut(id);
        const GlbNode* node = findNode(scene, "strut-" + std::to_string(id));
        REQUIRE(node != nullptr);
        const GlbMesh& mesh = scene.meshes[size_t(node->mesh)];
        CHECK(mesh.name == "strut-" + zome::partName(s.color, s.size));
        CHECK(isClosedOriented(weldedByPosition(mesh.geometry)));  // flat-shaded: split vertices
        const double length = boundingBox(mesh.geometry).max[2];
        const Vec3d tip = rotate(node->rotation, {0, 0, length});
        for (int k = 0; k < 3; ++k) {
            CHECK(node->translation[size_t(k)] == doctest::Approx(s.startMm[size_t(k)]));
            CHECK(node->translation[size_t(k)] + tip[size_t(k)] ==
                  doctest::Approx(s.endMm[size_t(k)]).epsilon(1e-6));  // float mesh
        }
        const Vec3d x = rotate(node->rotation, {1, 0, 0}), u = zome::holeSectionAxis(s.holeA);
        CHECK(x[0] * u[0] + x[1] * u[1] + x[2] * u[2] == doctest::Approx(1.0));
        CHECK(node->extras["part"] == zome::partName(s.color, s.size));
    }

    CHECK(scene.extras["parts"]["struts"]["B0"] == 1);
    CHECK(scene.extras["parts"]["struts"]["R0"] == 1);
    CHECK(scene.extras["parts"]["balls"] == 5);
    CHECK(scene.extras["length_unit"] == "mm");
    CHECK(scene.extras["run"] == "test");
    CHECK(scene.extras["format"] == "zomefab.preview");
    CHECK(scene.extras["pieces"] == nlohmann::json::array({"piece-00", "piece-01"}));

    const std::string glb = serializeGlb(scene);
    const nlohmann::json j = glbJson(glb);
    CHECK(j["extensionsRequired"] == nlohmann::json::array({"KHR_draco_mesh_compression"}));
    CHECK(j["nodes"].size() == scene.nodes.size());
    CHECK(j["scenes"][0]["extras"]["parts"]["strut_total"] == 4);
    CHECK(serializeGlb(buildPreviewScene(input)) == glb);  // deterministic
}

TEST_CASE("preview_scene: frame only, pieces only, and bad input") {
    const zome::Structure frame = colourFrame();
    PreviewInput frameOnly;
    frameOnly.frame = &frame;
    const GlbScene a = buildPreviewScene(frameOnly);
    CHECK(findNode(a, "pieces") == nullptr);
    CHECK(findNode(a, "balls") != nullptr);
    CHECK(a.meshes.size() == 5);

    PreviewInput piecesOnly;
    const TriMesh box = makeBox({0, 0, 0}, {1, 1, 1});
    piecesOnly.pieces = {&box};
    const GlbScene b = buildPreviewScene(piecesOnly);
    CHECK(findNode(b, "piece-00") != nullptr);
    CHECK(!b.extras.contains("parts"));

    // Per-piece transforms put print-oriented pieces back into the frame.
    piecesOnly.pieceTransforms = {Transform4d::scaleTranslate(1.0, {10, 20, 30})};
    const Box3d moved = boundingBox(buildPreviewScene(piecesOnly).meshes[0].geometry);
    CHECK(moved.min[0] == 10.0);
    CHECK(moved.max[2] == 31.0);
    piecesOnly.pieceTransforms.push_back(Transform4d::identity());
    CHECK_THROWS_AS(buildPreviewScene(piecesOnly), Error);
    piecesOnly.pieceTransforms.clear();

    piecesOnly.pieceNames = {"a", "b"};
    CHECK_THROWS_AS(buildPreviewScene(piecesOnly), Error);
    PreviewInput empty;
    const TriMesh nothing;
    empty.pieces = {&nothing};
    CHECK_THROWS_AS(buildPreviewScene(empty), Error);
}
