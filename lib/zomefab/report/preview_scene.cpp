// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/preview_scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/vec.h"
#include "zomefab/core/version.h"
#include "zomefab/zome/holes.h"
#include "zomefab/zome/parts.h"

namespace zomefab::report {

namespace {

/// @p mesh with its vertices in the order the triangles first use them, bit-identical ones merged:
/// what reading its STL back gives, so an uncompressed scene has the same bytes whether its pieces
/// come from memory (`zomefab run`) or from the files (`zf-preview`). Draco orders vertices itself.
TriMesh inTriangleOrder(const TriMesh& mesh) {
    TriMesh soup;
    soup.positions.reserve(mesh.triangles.size() * 3);
    soup.triangles.reserve(mesh.triangles.size());
    for (const Triangle& t : mesh.triangles) {
        const uint32_t first = uint32_t(soup.positions.size());
        for (const uint32_t v : t) soup.positions.push_back(mesh.positions[v]);
        soup.triangles.push_back({first, first + 1, first + 2});
    }
    weldIdenticalVertices(soup);
    return soup;
}

using Mat3 = std::array<Vec3d, 3>;  // columns

/// sRGB component (0..1) to the linear value glTF's baseColorFactor expects (glTF 2.0 §3.9.2).
double srgbToLinear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

GlbMaterial material(const std::string& name, double r, double g, double b, double roughness = 0.5) {
    GlbMaterial m;
    m.name = name;
    m.baseColor = {srgbToLinear(r), srgbToLinear(g), srgbToLinear(b), 1.0};
    m.roughness = roughness;
    return m;
}

GlbMaterial pieceMaterial(size_t i, const std::string& name) {
    const std::array<double, 3> c = pieceColorSrgb(i);
    return material(name, c[0], c[1], c[2], 0.7);
}

/// Rotation matrix (columns) to a unit quaternion (x, y, z, w) (Shepperd's method).
std::array<double, 4> quaternionFromColumns(const Mat3& m) {
    // m[c][r]: column c, row r.
    const double m00 = m[0][0], m11 = m[1][1], m22 = m[2][2];
    const double trace = m00 + m11 + m22;
    std::array<double, 4> q{};
    if (trace > 0.0) {
        const double s = 2.0 * std::sqrt(1.0 + trace);
        q = {(m[1][2] - m[2][1]) / s, (m[2][0] - m[0][2]) / s, (m[0][1] - m[1][0]) / s, 0.25 * s};
    } else if (m00 > m11 && m00 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m00 - m11 - m22);
        q = {0.25 * s, (m[1][0] + m[0][1]) / s, (m[2][0] + m[0][2]) / s, (m[1][2] - m[2][1]) / s};
    } else if (m11 > m22) {
        const double s = 2.0 * std::sqrt(1.0 + m11 - m00 - m22);
        q = {(m[1][0] + m[0][1]) / s, 0.25 * s, (m[2][1] + m[1][2]) / s, (m[2][0] - m[0][2]) / s};
    } else {
        const double s = 2.0 * std::sqrt(1.0 + m22 - m00 - m11);
        q = {(m[2][0] + m[0][2]) / s, (m[2][1] + m[1][2]) / s, 0.25 * s, (m[0][1] - m[1][0]) / s};
    }
    const double n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
    for (double& c : q) c /= n;
    if (q[3] < 0.0)
        for (double& c : q) c = -c;  // one sign for determinism
    return q;
}

/// Icosphere of radius @p r: smooth normals, 20·4^levels triangles, outward.
GlbMesh sphereMesh(double r, int levels) {
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3d> p = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
    for (Vec3d& v : p) v = normalized(v);
    std::vector<Triangle> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                               {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                               {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                               {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
    for (int level = 0; level < levels; ++level) {
        std::map<std::pair<uint32_t, uint32_t>, uint32_t> mid;
        auto midpoint = [&](uint32_t a, uint32_t b) {
            const auto key = std::minmax(a, b);
            const auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            const Vec3d m = normalized({p[a][0] + p[b][0], p[a][1] + p[b][1], p[a][2] + p[b][2]});
            p.push_back(m);
            mid.emplace(key, uint32_t(p.size() - 1));
            return uint32_t(p.size() - 1);
        };
        std::vector<Triangle> next;
        next.reserve(f.size() * 4);
        for (const Triangle& tri : f) {
            const uint32_t a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]),
                           c = midpoint(tri[2], tri[0]);
            next.push_back({tri[0], a, c});
            next.push_back({tri[1], b, a});
            next.push_back({tri[2], c, b});
            next.push_back({a, b, c});
        }
        f.swap(next);
    }
    GlbMesh mesh;
    mesh.name = "ball";
    for (const Vec3d& v : p) {
        mesh.geometry.positions.push_back({float(r * v[0]), float(r * v[1]), float(r * v[2])});
        mesh.normals.push_back({float(v[0]), float(v[1]), float(v[2])});
    }
    mesh.geometry.triangles = std::move(f);
    return mesh;
}

/// Prism of @p section (counter-clockwise, mm) from z = 0 to z = @p lengthMm, flat-shaded (each
/// face has its own vertices).
GlbMesh prismMesh(const std::string& name, const std::vector<std::array<double, 2>>& section,
                  double lengthMm) {
    GlbMesh mesh;
    mesh.name = name;
    TriMesh& g = mesh.geometry;
    const size_t n = section.size();
    auto add = [&](double x, double y, double z, const Vec3d& normal) {
        g.positions.push_back({float(x), float(y), float(z)});
        mesh.normals.push_back({float(normal[0]), float(normal[1]), float(normal[2])});
        return uint32_t(g.positions.size() - 1);
    };
    for (size_t i = 0; i < n; ++i) {
        const auto& a = section[i];
        const auto& b = section[(i + 1) % n];
        const Vec3d normal = normalized({b[1] - a[1], a[0] - b[0], 0.0});  // outward for CCW
        const uint32_t a0 = add(a[0], a[1], 0.0, normal), b0 = add(b[0], b[1], 0.0, normal);
        const uint32_t b1 = add(b[0], b[1], lengthMm, normal), a1 = add(a[0], a[1], lengthMm, normal);
        g.triangles.push_back({a0, b0, b1});
        g.triangles.push_back({a0, b1, a1});
    }
    const uint32_t bottom = uint32_t(g.positions.size());
    for (const auto& s : section) add(s[0], s[1], 0.0, {0, 0, -1});
    const uint32_t top = uint32_t(g.positions.size());
    for (const auto& s : section) add(s[0], s[1], lengthMm, {0, 0, 1});
    for (uint32_t i = 1; i + 1 < n; ++i) {
        g.triangles.push_back({bottom, bottom + i + 1, bottom + i});
        g.triangles.push_back({top, top + i, top + i + 1});
    }
    return mesh;
}

}  // namespace

std::array<double, 3> pieceColorSrgb(size_t i) {
    // Hues spaced by the golden angle, so neighbours in the list differ strongly.
    const double hue = std::fmod(double(i) * 0.6180339887498949, 1.0) * 6.0;
    const double s = 0.45, v = 0.95;
    const int sector = int(hue) % 6;
    const double f = hue - std::floor(hue);
    const double p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
    const std::array<std::array<double, 3>, 6> rgb = {
        {{v, t, p}, {q, v, p}, {p, v, t}, {p, q, v}, {t, p, v}, {v, p, q}}};
    return rgb[size_t(sector)];
}

std::array<double, 3> strutColorSrgb(zome::Color color) {
    switch (color) {
        case zome::Color::Blue:
            return {0.05, 0.33, 0.75};
        case zome::Color::Yellow:
            return {1.0, 0.80, 0.05};
        case zome::Color::Red:
            return {0.85, 0.10, 0.10};
    }
    return {0.5, 0.5, 0.5};
}

GlbScene buildPreviewScene(const PreviewInput& input, const PreviewOptions& options) {
    if (!input.pieceNames.empty() && input.pieceNames.size() != input.pieces.size())
        throw Error(ErrorCode::Usage, "preview: " + std::to_string(input.pieceNames.size()) +
                                          " piece names for " + std::to_string(input.pieces.size()) +
                                          " pieces");
    if (!input.pieceTransforms.empty() && input.pieceTransforms.size() != input.pieces.size())
        throw Error(ErrorCode::Usage, "preview: " + std::to_string(input.pieceTransforms.size()) +
                                          " piece transforms for " + std::to_string(input.pieces.size()) +
                                          " pieces");
    if (options.sphereSubdivisions < 0 || options.sphereSubdivisions > 5)
        throw Error(ErrorCode::Usage, "preview: sphere subdivisions must be 0..5");
    GlbScene scene;
    scene.generator = options.generator.empty() ? generatorString() : options.generator;
    scene.sceneName = "zomefab preview";

    // Root: glTF is metres and y up (glTF 2.0 §3.4); the model is millimetres and z up.
    GlbNode root;
    root.name = "zomefab";
    root.rotation = {-std::sqrt(0.5), 0.0, 0.0, std::sqrt(0.5)};  // −90° about x: z → y
    root.scale = {0.001, 0.001, 0.001};
    scene.nodes.push_back(root);
    scene.roots = {0};
    auto addGroup = [&](const std::string& name) {
        GlbNode g;
        g.name = name;
        scene.nodes.push_back(g);
        scene.nodes[0].children.push_back(int(scene.nodes.size() - 1));
        return int(scene.nodes.size() - 1);
    };

    nlohmann::json pieceNames = nlohmann::json::array();
    if (!input.pieces.empty()) {
        const int group = addGroup("pieces");
        for (size_t i = 0; i < input.pieces.size(); ++i) {
            const std::string name = input.pieceNames.empty() ? "piece-" + formatNumbers("%02.0f", double(i))
                                                              : input.pieceNames[i];
            if (!input.pieces[i] || input.pieces[i]->triangles.empty())
                throw Error(ErrorCode::Usage, "preview: " + name + " is empty");
            scene.materials.push_back(pieceMaterial(i, name));
            GlbMesh mesh;
            mesh.name = name;
            mesh.geometry =
                options.isPieceDracoCompressed ? *input.pieces[i] : inTriangleOrder(*input.pieces[i]);
            mesh.geometry.salientFaces.clear();
            if (!input.pieceTransforms.empty()) transformInPlace(mesh.geometry, input.pieceTransforms[i]);
            mesh.material = int(scene.materials.size() - 1);
            mesh.isDracoCompressed = options.isPieceDracoCompressed;
            scene.meshes.push_back(std::move(mesh));
            GlbNode node;
            node.name = name;
            node.mesh = int(scene.meshes.size() - 1);
            if (i < input.pieceExtras.size()) node.extras = input.pieceExtras[i];
            scene.nodes.push_back(node);
            scene.nodes[size_t(group)].children.push_back(int(scene.nodes.size() - 1));
            pieceNames.push_back(name);
        }
    }

    nlohmann::json extras = {
        {"format", "zomefab.preview"},
        {"version", 1},
        {"length_unit", "mm"},
        {"up_axis", "z"},
        {"root_node", "zomefab: rotation -90 deg about x (z up to glTF y up), scale 0.001 (mm to m)"},
        {"pieces", pieceNames}};
    if (input.frame) {
        const zome::Structure& frame = *input.frame;
        const zome::ZomeScale& scale = frame.scale();
        scene.materials.push_back(material("ball", 0.93, 0.93, 0.90, 0.35));
        const int ballMaterial = int(scene.materials.size() - 1);
        // Zometool's colours, sRGB.
        const std::array<std::array<double, 3>, 3> strutRgb = {{strutColorSrgb(zome::Color::Blue),
                                                                strutColorSrgb(zome::Color::Yellow),
                                                                strutColorSrgb(zome::Color::Red)}};
        std::array<int, zome::kColorCount> strutMaterial{-1, -1, -1};  // created on first use

        const std::vector<zome::BallId> balls = frame.ballIds();
        if (!balls.empty()) {
            GlbMesh sphere = sphereMesh(scale.ballRadiusMm(), options.sphereSubdivisions);
            sphere.material = ballMaterial;
            scene.meshes.push_back(std::move(sphere));
            const int sphereMesh = int(scene.meshes.size() - 1);
            const int group = addGroup("balls");
            for (zome::BallId id : balls) {
                GlbNode node;
                node.name = "ball-" + std::to_string(id);
                node.mesh = sphereMesh;
                node.translation = frame.ball(id).positionMm;
                scene.nodes.push_back(node);
                scene.nodes[size_t(group)].children.push_back(int(scene.nodes.size() - 1));
            }
        }

        const std::vector<zome::StrutId> struts = frame.strutIds();
        if (!struts.empty()) {
            // One prism per colour and size, created on first use (in strut id order).
            std::array<std::array<int, zome::kSizeCount>, zome::kColorCount> prism{};
            for (auto& row : prism) row.fill(-1);
            const int group = addGroup("struts");
            for (zome::StrutId id : struts) {
                const zome::Strut& s = frame.strut(id);
                int& mesh = prism[size_t(s.color)][s.size];
                if (mesh < 0) {
                    // Ball surface to ball surface, as the collision proxy (zome/structure.h).
                    const double lengthMm = scale.strutLengthMm(s.color, s.size) - scale.ballDiameterMm;
                    if (!(lengthMm > 0.0))
                        throw Error(ErrorCode::Usage, "preview: the ball (" +
                                                          std::to_string(scale.ballDiameterMm) +
                                                          " mm) is wider than a " +
                                                          zome::partName(s.color, s.size) + " strut is long");
                    GlbMesh prismMeshValue = prismMesh("strut-" + zome::partName(s.color, s.size),
                                                       zome::holeSectionMm(s.color), lengthMm);
                    int& colour = strutMaterial[size_t(s.color)];
                    if (colour < 0) {
                        const auto& rgb = strutRgb[size_t(s.color)];
                        scene.materials.push_back(material(std::string("strut-") + zome::colorName(s.color),
                                                           rgb[0], rgb[1], rgb[2]));
                        colour = int(scene.materials.size() - 1);
                    }
                    prismMeshValue.material = colour;
                    scene.meshes.push_back(std::move(prismMeshValue));
                    mesh = int(scene.meshes.size() - 1);
                }
                const Vec3d d = zome::holeDirection(s.holeA);
                const Vec3d& u = zome::holeSectionAxis(s.holeA);
                GlbNode node;
                node.name = "strut-" + std::to_string(id);
                node.mesh = mesh;
                node.translation = s.startMm;
                node.rotation = quaternionFromColumns({u, cross(d, u), d});
                node.extras = {{"part", zome::partName(s.color, s.size)},
                               {"balls", {s.a, s.b}},
                               {"holes", {int(s.holeA), int(s.holeB)}}};
                scene.nodes.push_back(node);
                scene.nodes[size_t(group)].children.push_back(int(scene.nodes.size() - 1));
            }
        }
        extras["parts"] = zome::partsListToJson(zome::partsList(frame));
        extras["balls"] = frame.ballCount();
        extras["struts"] = frame.strutCount();
    }
    if (input.extras.is_object()) {
        for (auto it = input.extras.begin(); it != input.extras.end(); ++it)
            if (!extras.contains(it.key())) extras[it.key()] = it.value();
    } else if (!input.extras.is_null()) {
        extras["user"] = input.extras;
    }
    scene.extras = std::move(extras);
    return scene;
}

void writePreview(const PreviewInput& input, const std::string& path, const PreviewOptions& options) {
    writeGlb(buildPreviewScene(input, options), path, options.glb);
}

}  // namespace zomefab::report
