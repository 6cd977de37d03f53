// SPDX-License-Identifier: GPL-3.0-or-later
/// @file GLB writer. The JSON and the binary container are written here; Draco only encodes (and,
/// for the accessor counts and bounds, decodes) mesh bitstreams. No tinygltf here: libdraco exports
/// its own copy of the tinygltf symbols (io/CMakeLists.txt), and draco::GltfEncoder would bring
/// that copy into play, so the Draco calls stay at the level of draco::Mesh.
#include "zomefab/io/glb_write.h"

#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/mesh.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/io/file_io.h"

namespace zomefab {

namespace {

// glTF 2.0 enumerations (§5).
constexpr int kFloat = 5126;
constexpr int kUnsignedShort = 5123;
constexpr int kUnsignedInt = 5125;
constexpr int kArrayBuffer = 34962;
constexpr int kElementArrayBuffer = 34963;
constexpr int kTriangles = 4;
constexpr const char* kDracoExtension = "KHR_draco_mesh_compression";

[[noreturn]] void invalid(const std::string& message) {
    throw Error(ErrorCode::InvalidInput, "GLB scene: " + message);
}

bool isFinite3(const Vec3f& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); }

std::string meshLabel(const GlbScene& scene, size_t m) {
    const std::string& name = scene.meshes[m].name;
    return "mesh " + std::to_string(m) + (name.empty() ? "" : " '" + name + "'");
}
std::string nodeLabel(const GlbScene& scene, size_t n) {
    const std::string& name = scene.nodes[n].name;
    return "node " + std::to_string(n) + (name.empty() ? "" : " '" + name + "'");
}

/// Everything serializeGlb relies on, checked up front so no half-built JSON is ever thrown away.
void validateScene(const GlbScene& scene, const GlbWriteOptions& options) {
    if (options.dracoPositionBits < 1 || options.dracoPositionBits > 30 || options.dracoNormalBits < 1 ||
        options.dracoNormalBits > 30 || options.dracoEncodingSpeed < 0 || options.dracoEncodingSpeed > 10 ||
        options.dracoDecodingSpeed < 0 || options.dracoDecodingSpeed > 10)
        throw Error(ErrorCode::Usage, "Draco options out of range (quantisation bits 1..30, speeds 0..10)");
    for (size_t i = 0; i < scene.materials.size(); ++i) {
        const GlbMaterial& m = scene.materials[i];
        for (double c : m.baseColor)
            if (!(c >= 0.0 && c <= 1.0))
                invalid("material " + std::to_string(i) + " has a colour outside [0, 1]");
        if (!(m.metallic >= 0.0 && m.metallic <= 1.0) || !(m.roughness >= 0.0 && m.roughness <= 1.0))
            invalid("material " + std::to_string(i) + " has metallic or roughness outside [0, 1]");
    }
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
        const GlbMesh& m = scene.meshes[i];
        const TriMesh& g = m.geometry;
        if (g.triangles.empty()) invalid(meshLabel(scene, i) + " has no triangles");
        if (g.positions.size() > std::numeric_limits<uint32_t>::max())
            invalid(meshLabel(scene, i) + " has more than 2^32 vertices");
        for (const Vec3f& p : g.positions)
            if (!isFinite3(p)) invalid(meshLabel(scene, i) + " has a non-finite position");
        for (const Triangle& t : g.triangles)
            for (uint32_t v : t)
                if (v >= g.positions.size())
                    invalid(meshLabel(scene, i) + " has vertex index " + std::to_string(v) + " but only " +
                            std::to_string(g.positions.size()) + " vertices");
        if (!m.normals.empty() && m.normals.size() != g.positions.size())
            invalid(meshLabel(scene, i) + " has " + std::to_string(m.normals.size()) + " normals for " +
                    std::to_string(g.positions.size()) + " vertices");
        for (const Vec3f& n : m.normals) {
            const double len = std::sqrt(double(n[0]) * n[0] + double(n[1]) * n[1] + double(n[2]) * n[2]);
            if (!isFinite3(n) || std::abs(len - 1.0) > 1e-3)
                invalid(meshLabel(scene, i) + " has a normal that is not unit length");
        }
        if (m.material < -1 || m.material >= int(scene.materials.size()))
            invalid(meshLabel(scene, i) + " refers to material " + std::to_string(m.material) +
                    ", which does not exist");
    }
    std::vector<int> parent(scene.nodes.size(), -1);
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        const GlbNode& n = scene.nodes[i];
        if (n.mesh < -1 || n.mesh >= int(scene.meshes.size()))
            invalid(nodeLabel(scene, i) + " refers to mesh " + std::to_string(n.mesh) +
                    ", which does not exist");
        for (double v : n.translation)
            if (!std::isfinite(v)) invalid(nodeLabel(scene, i) + " has a non-finite translation");
        for (double v : n.scale)
            if (!std::isfinite(v)) invalid(nodeLabel(scene, i) + " has a non-finite scale");
        double q2 = 0.0;
        for (double v : n.rotation) q2 += v * v;
        // glTF validators accept |q| within 0.0005 of 1 (ROTATION_NON_UNIT).
        if (!std::isfinite(q2) || std::abs(std::sqrt(q2) - 1.0) > 1e-6)
            invalid(nodeLabel(scene, i) + " has a rotation that is not a unit quaternion");
        for (int c : n.children) {
            if (c < 0 || c >= int(scene.nodes.size()))
                invalid(nodeLabel(scene, i) + " has child " + std::to_string(c) + ", which does not exist");
            if (parent[size_t(c)] != -1 || c == int(i))
                invalid(nodeLabel(scene, size_t(c)) + " has more than one parent");
            parent[size_t(c)] = int(i);
        }
    }
    // Every node must lie in a tree: walking up from any node reaches a root within nodes.size() steps.
    for (size_t i = 0; i < scene.nodes.size(); ++i) {
        int at = int(i);
        for (size_t steps = 0; at != -1; ++steps) {
            if (steps > scene.nodes.size()) invalid(nodeLabel(scene, i) + " lies in a cycle of children");
            at = parent[size_t(at)];
        }
    }
    std::vector<char> isRoot(scene.nodes.size(), 0);
    for (int r : scene.roots) {
        if (r < 0 || r >= int(scene.nodes.size()))
            invalid("root node " + std::to_string(r) + " does not exist");
        if (parent[size_t(r)] != -1) invalid(nodeLabel(scene, size_t(r)) + " is a root and a child");
        if (isRoot[size_t(r)]) invalid(nodeLabel(scene, size_t(r)) + " is listed twice as a root");
        isRoot[size_t(r)] = 1;
    }
}

/// The binary chunk under construction: every bufferView starts on a 4-byte boundary (glTF 2.0
/// §3.6.2.4, accessor alignment).
class BinaryBuilder {
public:
    /// Appends @p size bytes and returns the new bufferView's index in @p views.
    int addView(const void* data, size_t size, int target, nlohmann::json& views) {
        while (mBytes.size() % 4) mBytes.push_back('\0');
        const size_t offset = mBytes.size();
        mBytes.append(static_cast<const char*>(data), size);
        nlohmann::json view = {{"buffer", 0}, {"byteOffset", offset}, {"byteLength", size}};
        if (target) view["target"] = target;
        views.push_back(std::move(view));
        return int(views.size() - 1);
    }
    std::string& bytes() {
        while (mBytes.size() % 4) mBytes.push_back('\0');
        return mBytes;
    }

private:
    std::string mBytes;
};

/// min/max of float triples, as JSON arrays of the exact float values.
void addBounds(nlohmann::json& accessor, const std::vector<Vec3f>& values) {
    Vec3f lo = values.front(), hi = values.front();
    for (const Vec3f& v : values)
        for (int c = 0; c < 3; ++c) lo[c] = std::min(lo[c], v[c]), hi[c] = std::max(hi[c], v[c]);
    accessor["min"] = {double(lo[0]), double(lo[1]), double(lo[2])};
    accessor["max"] = {double(hi[0]), double(hi[1]), double(hi[2])};
}

nlohmann::json vec3Accessor(size_t count) {
    return {{"componentType", kFloat}, {"count", count}, {"type", "VEC3"}};
}

/// Writes an uncompressed primitive: positions, optional normals, indices (uint16 when they fit).
nlohmann::json writePlainPrimitive(const GlbMesh& mesh, BinaryBuilder& bin, nlohmann::json& views,
                                   nlohmann::json& accessors) {
    const TriMesh& g = mesh.geometry;
    nlohmann::json attributes;
    nlohmann::json position = vec3Accessor(g.positions.size());
    position["bufferView"] =
        bin.addView(g.positions.data(), g.positions.size() * sizeof(Vec3f), kArrayBuffer, views);
    addBounds(position, g.positions);
    accessors.push_back(std::move(position));
    attributes["POSITION"] = accessors.size() - 1;
    if (!mesh.normals.empty()) {
        nlohmann::json normal = vec3Accessor(mesh.normals.size());
        normal["bufferView"] =
            bin.addView(mesh.normals.data(), mesh.normals.size() * sizeof(Vec3f), kArrayBuffer, views);
        accessors.push_back(std::move(normal));
        attributes["NORMAL"] = accessors.size() - 1;
    }
    const size_t indexCount = g.triangles.size() * 3;
    nlohmann::json index = {{"count", indexCount}, {"type", "SCALAR"}};
    if (g.positions.size() <= 65535) {
        std::vector<uint16_t> idx;
        idx.reserve(indexCount);
        for (const Triangle& t : g.triangles)
            for (uint32_t v : t) idx.push_back(uint16_t(v));
        index["componentType"] = kUnsignedShort;
        index["bufferView"] =
            bin.addView(idx.data(), idx.size() * sizeof(uint16_t), kElementArrayBuffer, views);
    } else {
        index["componentType"] = kUnsignedInt;
        index["bufferView"] = bin.addView(g.triangles.data(), g.triangles.size() * sizeof(Triangle),
                                          kElementArrayBuffer, views);
    }
    accessors.push_back(std::move(index));
    return {{"attributes", std::move(attributes)}, {"indices", accessors.size() - 1}, {"mode", kTriangles}};
}

/// Encodes @p mesh with Draco, decodes it again, and writes the KHR_draco_mesh_compression
/// primitive whose accessors describe the decoded mesh (count, bounds) and have no bufferView.
nlohmann::json writeDracoPrimitive(const GlbMesh& mesh, const std::string& label,
                                   const GlbWriteOptions& options, BinaryBuilder& bin, nlohmann::json& views,
                                   nlohmann::json& accessors) {
    const TriMesh& g = mesh.geometry;
    draco::Mesh dm;
    dm.set_num_points(uint32_t(g.positions.size()));
    auto addAttribute = [&](draco::GeometryAttribute::Type type, const std::vector<Vec3f>& values) {
        draco::GeometryAttribute ga;
        ga.Init(type, nullptr, 3, draco::DT_FLOAT32, false, sizeof(float) * 3, 0);
        const int id = dm.AddAttribute(ga, true, uint32_t(values.size()));
        draco::PointAttribute* att = dm.attribute(id);
        for (size_t v = 0; v < values.size(); ++v)
            att->SetAttributeValue(draco::AttributeValueIndex(uint32_t(v)), values[v].data());
        return att->unique_id();
    };
    const uint32_t positionId = addAttribute(draco::GeometryAttribute::POSITION, g.positions);
    uint32_t normalId = 0;
    if (!mesh.normals.empty()) normalId = addAttribute(draco::GeometryAttribute::NORMAL, mesh.normals);
    dm.SetNumFaces(g.triangles.size());
    for (size_t f = 0; f < g.triangles.size(); ++f) {
        const Triangle& t = g.triangles[f];
        dm.SetFace(draco::FaceIndex(uint32_t(f)),
                   {draco::PointIndex(t[0]), draco::PointIndex(t[1]), draco::PointIndex(t[2])});
    }

    draco::Encoder encoder;
    encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, options.dracoPositionBits);
    encoder.SetAttributeQuantization(draco::GeometryAttribute::NORMAL, options.dracoNormalBits);
    encoder.SetSpeedOptions(options.dracoEncodingSpeed, options.dracoDecodingSpeed);
    encoder.SetEncodingMethod(draco::MESH_EDGEBREAKER_ENCODING);
    draco::EncoderBuffer encoded;
    const draco::Status status = encoder.EncodeMeshToBuffer(dm, &encoded);
    if (!status.ok())
        throw Error(ErrorCode::ProcessingFailed,
                    "Draco cannot encode " + label + ": " + status.error_msg_string());

    // Decode what we wrote: Draco may drop degenerate faces and unreferenced vertices and split
    // non-manifold ones, and quantisation moves positions, so counts and bounds come from here.
    draco::DecoderBuffer in;
    in.Init(encoded.data(), encoded.size());
    draco::Decoder decoder;
    auto decoded = decoder.DecodeMeshFromBuffer(&in);
    if (!decoded.ok())
        throw Error(ErrorCode::ProcessingFailed, "Draco cannot decode its own encoding of " + label + ": " +
                                                     decoded.status().error_msg_string());
    const std::unique_ptr<draco::Mesh> back = std::move(decoded).value();
    const draco::PointAttribute* pos = back->GetAttributeByUniqueId(positionId);
    if (!pos || back->num_points() == 0 || back->num_faces() == 0)
        throw Error(ErrorCode::ProcessingFailed,
                    "Draco dropped every triangle of " + label + " (degenerate mesh)");
    std::vector<Vec3f> decodedPositions(back->num_points());
    for (uint32_t p = 0; p < back->num_points(); ++p)
        pos->GetMappedValue(draco::PointIndex(p), decodedPositions[p].data());

    const int view = bin.addView(encoded.data(), encoded.size(), 0, views);
    nlohmann::json attributes, dracoAttributes;
    nlohmann::json position = vec3Accessor(back->num_points());
    addBounds(position, decodedPositions);
    accessors.push_back(std::move(position));
    attributes["POSITION"] = accessors.size() - 1;
    dracoAttributes["POSITION"] = positionId;
    if (!mesh.normals.empty()) {
        accessors.push_back(vec3Accessor(back->num_points()));
        attributes["NORMAL"] = accessors.size() - 1;
        dracoAttributes["NORMAL"] = normalId;
    }
    accessors.push_back({{"componentType", back->num_points() <= 65535 ? kUnsignedShort : kUnsignedInt},
                         {"count", size_t(back->num_faces()) * 3},
                         {"type", "SCALAR"}});
    return {{"attributes", std::move(attributes)},
            {"indices", accessors.size() - 1},
            {"mode", kTriangles},
            {"extensions",
             {{kDracoExtension, {{"bufferView", view}, {"attributes", std::move(dracoAttributes)}}}}}};
}

template <typename T>
void appendLe(std::string& out, T value) {
    char buf[sizeof(T)];
    std::memcpy(buf, &value, sizeof(T));  // little-endian hosts only (checked in mesh_io.cpp)
    out.append(buf, sizeof(T));
}

}  // namespace

std::string serializeGlb(const GlbScene& scene, const GlbWriteOptions& options) {
    validateScene(scene, options);

    nlohmann::json gltf;
    gltf["asset"] = {{"version", "2.0"}};
    if (!scene.generator.empty()) gltf["asset"]["generator"] = scene.generator;

    BinaryBuilder bin;
    nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
    nlohmann::json meshes = nlohmann::json::array();
    bool usesDraco = false;
    for (size_t m = 0; m < scene.meshes.size(); ++m) {
        const GlbMesh& mesh = scene.meshes[m];
        nlohmann::json primitive =
            mesh.isDracoCompressed
                ? writeDracoPrimitive(mesh, meshLabel(scene, m), options, bin, views, accessors)
                : writePlainPrimitive(mesh, bin, views, accessors);
        usesDraco = usesDraco || mesh.isDracoCompressed;
        if (mesh.material >= 0) primitive["material"] = mesh.material;
        nlohmann::json entry = {{"primitives", nlohmann::json::array({std::move(primitive)})}};
        if (!mesh.name.empty()) entry["name"] = mesh.name;
        meshes.push_back(std::move(entry));
    }

    nlohmann::json materials = nlohmann::json::array();
    for (const GlbMaterial& m : scene.materials) {
        nlohmann::json entry = {{"pbrMetallicRoughness",
                                 {{"baseColorFactor", m.baseColor},
                                  {"metallicFactor", m.metallic},
                                  {"roughnessFactor", m.roughness}}}};
        if (!m.name.empty()) entry["name"] = m.name;
        materials.push_back(std::move(entry));
    }

    nlohmann::json nodes = nlohmann::json::array();
    for (const GlbNode& n : scene.nodes) {
        nlohmann::json entry = nlohmann::json::object();
        if (!n.name.empty()) entry["name"] = n.name;
        if (n.mesh >= 0) entry["mesh"] = n.mesh;
        if (!n.children.empty()) entry["children"] = n.children;
        // Defaults are left out (glTF 2.0 §5.25): smaller files, and viewers treat them the same.
        if (n.translation != Vec3d{0.0, 0.0, 0.0}) entry["translation"] = n.translation;
        if (n.rotation != std::array<double, 4>{0.0, 0.0, 0.0, 1.0}) entry["rotation"] = n.rotation;
        if (n.scale != Vec3d{1.0, 1.0, 1.0}) entry["scale"] = n.scale;
        if (!n.extras.is_null()) entry["extras"] = n.extras;
        nodes.push_back(std::move(entry));
    }

    nlohmann::json sceneJson = {{"nodes", scene.roots}};
    if (!scene.sceneName.empty()) sceneJson["name"] = scene.sceneName;
    if (!scene.extras.is_null()) sceneJson["extras"] = scene.extras;
    gltf["scene"] = 0;
    gltf["scenes"] = nlohmann::json::array({std::move(sceneJson)});
    if (!nodes.empty()) gltf["nodes"] = std::move(nodes);
    if (!meshes.empty()) gltf["meshes"] = std::move(meshes);
    if (!materials.empty()) gltf["materials"] = std::move(materials);
    if (!accessors.empty()) gltf["accessors"] = std::move(accessors);
    if (!views.empty()) gltf["bufferViews"] = std::move(views);
    std::string& binary = bin.bytes();
    if (!binary.empty()) gltf["buffers"] = nlohmann::json::array({{{"byteLength", binary.size()}}});
    if (usesDraco) {
        gltf["extensionsUsed"] = {kDracoExtension};
        gltf["extensionsRequired"] = {kDracoExtension};  // no uncompressed fallback is stored
    }

    // GLB container (glTF 2.0 §4.4): 12-byte header, JSON chunk padded with spaces, BIN chunk.
    std::string json = gltf.dump();
    while (json.size() % 4) json += ' ';
    const uint64_t total = 12 + 8 + json.size() + (binary.empty() ? 0 : 8 + binary.size());
    if (total > std::numeric_limits<uint32_t>::max()) invalid("the GLB would exceed 4 GiB");
    std::string out;
    out.reserve(size_t(total));
    out += "glTF";
    appendLe<uint32_t>(out, 2);
    appendLe<uint32_t>(out, uint32_t(total));
    appendLe<uint32_t>(out, uint32_t(json.size()));
    out += "JSON";
    out += json;
    if (!binary.empty()) {
        appendLe<uint32_t>(out, uint32_t(binary.size()));
        out.append("BIN\0", 4);
        out += binary;
    }
    return out;
}

void writeGlb(const GlbScene& scene, const std::string& path, const GlbWriteOptions& options) {
    const std::string bytes = serializeGlb(scene, options);
    writeOutputAtomic(path,
                      [&](std::ostream& out) { out.write(bytes.data(), std::streamsize(bytes.size())); });
}

std::string base64Encode(const std::string& bytes) {
    static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (size_t i = 0; i < bytes.size(); i += 3) {
        // Three bytes make four 6-bit digits; a short last group is padded with '='.
        const size_t n = std::min<size_t>(3, bytes.size() - i);
        uint32_t group = uint32_t(uint8_t(bytes[i])) << 16;
        if (n > 1) group |= uint32_t(uint8_t(bytes[i + 1])) << 8;
        if (n > 2) group |= uint32_t(uint8_t(bytes[i + 2]));
        for (size_t k = 0; k < 4; ++k) out += k <= n ? kAlphabet[(group >> (18 - 6 * k)) & 63] : '=';
    }
    return out;
}

}  // namespace zomefab
