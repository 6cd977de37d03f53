// SPDX-License-Identifier: GPL-3.0-or-later
/// @file glTF 2.0 / GLB reader over Debian's shared libtinygltf. The only translation unit of
/// zomefab that includes tiny_gltf.h (see io/CMakeLists.txt for why: libdraco exports its own copy
/// of the tinygltf symbols).
#include <dlfcn.h>
#include <tiny_gltf.h>

#include <array>
#include <climits>
#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "zomefab/io/detail/mesh_formats.h"

namespace zomefab::detail {

namespace {

using Matrix4 = std::array<double, 16>;  // column-major, as glTF stores it

Matrix4 identity4() { return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}; }

Matrix4 multiply(const Matrix4& a, const Matrix4& b) {
    Matrix4 r{};
    for (int col = 0; col < 4; ++col)
        for (int row = 0; row < 4; ++row) {
            double s = 0;
            for (int k = 0; k < 4; ++k) s += a[k * 4 + row] * b[col * 4 + k];
            r[col * 4 + row] = s;
        }
    return r;
}

/// Determinant of the upper-left 3x3 block: negative for a mirroring transform.
double linearDeterminant(const Matrix4& m) {
    return m[0] * (m[5] * m[10] - m[9] * m[6]) - m[4] * (m[1] * m[10] - m[9] * m[2]) +
           m[8] * (m[1] * m[6] - m[5] * m[2]);
}

/// A node's local transform: `matrix`, or T * R * S from translation, rotation (x, y, z, w) and scale.
Matrix4 localTransform(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) {
        Matrix4 m;
        std::copy(node.matrix.begin(), node.matrix.end(), m.begin());
        return m;
    }
    Matrix4 t = identity4();
    if (node.translation.size() == 3)
        for (int i = 0; i < 3; ++i) t[12 + i] = node.translation[i];
    Matrix4 r = identity4();
    if (node.rotation.size() == 4) {
        double x = node.rotation[0], y = node.rotation[1], z = node.rotation[2], w = node.rotation[3];
        const double n = std::sqrt(x * x + y * y + z * z + w * w);
        if (n > 0) x /= n, y /= n, z /= n, w /= n;
        r = {1 - 2 * (y * y + z * z),
             2 * (x * y + z * w),
             2 * (x * z - y * w),
             0,
             2 * (x * y - z * w),
             1 - 2 * (x * x + z * z),
             2 * (y * z + x * w),
             0,
             2 * (x * z + y * w),
             2 * (y * z - x * w),
             1 - 2 * (x * x + y * y),
             0,
             0,
             0,
             0,
             1};
    }
    Matrix4 s = identity4();
    if (node.scale.size() == 3)
        for (int i = 0; i < 3; ++i) s[i * 5] = node.scale[i];
    return multiply(t, multiply(r, s));
}

/// Filesystem access for external buffer URIs: only below MeshReadOptions::externalDir.
struct FsPolicy {
    bool allowed = false;
};

bool fsFileExists(const std::string& path, void* user) {
    if (!static_cast<FsPolicy*>(user)->allowed) return false;
    std::ifstream in(path, std::ios::binary);
    return bool(in);
}
std::string fsExpandPath(const std::string& path, void*) { return path; }  // no ~ or $VAR expansion
bool fsReadWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* user) {
    if (!static_cast<FsPolicy*>(user)->allowed) {
        if (err) *err += "external files are not allowed here";
        return false;
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) {
        if (err) *err += "cannot open " + path;
        return false;
    }
    out->assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
    return true;
}
bool fsWriteWholeFile(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err) *err += "zomefab never writes through the glTF reader";
    return false;
}

/// Only geometry matters: images are neither decoded nor checked.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
               void*) {
    return true;
}

std::string oneLine(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == '\r' || s.back() == ' ')) s.pop_back();
    for (char& c : s)
        if (c == '\n' || c == '\r') c = ';';
    return s;
}

/// How many times over node instancing may repeat the vertices a file stores, and a floor below
/// which any repetition is fine (a small part repeated many times is a real scene).
constexpr uint64_t kMaxInstancing = 16;
constexpr uint64_t kInstancingSlackVertices = 1u << 20;

class GltfMeshBuilder {
public:
    GltfMeshBuilder(const tinygltf::Model& model, const std::string& source)
        : mModel(model), mSource(source) {}

    TriMesh build() {
        for (const std::string& ext : mModel.extensionsRequired)
            if (ext == "KHR_draco_mesh_compression" || ext == "EXT_meshopt_compression")
                fail(mSource, "glTF uses " + ext + ", which zomefab cannot read; export it uncompressed");
        // Nodes may use one mesh many times; a small file must not expand without bound.
        uint64_t stored = 0;
        for (size_t i = 0; i < mModel.meshes.size(); ++i) stored += storedVertices(int(i));
        mVertexLimit = std::max(kMaxInstancing * stored, kInstancingSlackVertices);
        if (!mModel.scenes.empty()) {
            const int s = (mModel.defaultScene >= 0 && size_t(mModel.defaultScene) < mModel.scenes.size())
                              ? mModel.defaultScene
                              : 0;
            for (int node : mModel.scenes[size_t(s)].nodes) addNode(node, identity4(), 0);
        } else if (!mModel.nodes.empty()) {
            // No scene: every root node (one that is nobody's child).
            std::vector<char> isChild(mModel.nodes.size(), 0);
            for (const tinygltf::Node& n : mModel.nodes)
                for (int c : n.children)
                    if (c >= 0 && size_t(c) < isChild.size()) isChild[size_t(c)] = 1;
            for (size_t i = 0; i < mModel.nodes.size(); ++i)
                if (!isChild[i]) addNode(int(i), identity4(), 0);
        } else {
            for (size_t i = 0; i < mModel.meshes.size(); ++i) addMesh(int(i), identity4());
        }
        return std::move(mMesh);
    }

private:
    void addNode(int index, const Matrix4& parent, int depth) {
        if (depth > 256) fail(mSource, "glTF node hierarchy is deeper than 256 levels");
        if (index < 0 || size_t(index) >= mModel.nodes.size())
            fail(mSource, "glTF refers to node " + std::to_string(index) + ", which does not exist");
        mVisited.resize(mModel.nodes.size(), 0);
        if (mVisited[size_t(index)])
            fail(mSource, "glTF node " + std::to_string(index) + " appears twice in the scene (not a tree)");
        mVisited[size_t(index)] = 1;
        const tinygltf::Node& node = mModel.nodes[size_t(index)];
        const Matrix4 world = multiply(parent, localTransform(node));
        if (node.mesh >= 0) addMesh(node.mesh, world);
        for (int child : node.children) addNode(child, world, depth + 1);
    }

    /// Vertices the POSITION accessors of mesh @p index announce (readAccessor checks them later).
    uint64_t storedVertices(int index) const {
        uint64_t count = 0;
        if (index < 0 || size_t(index) >= mModel.meshes.size()) return 0;
        for (const tinygltf::Primitive& prim : mModel.meshes[size_t(index)].primitives) {
            const auto position = prim.attributes.find("POSITION");
            if (position != prim.attributes.end() && position->second >= 0 &&
                size_t(position->second) < mModel.accessors.size())
                count += std::min<uint64_t>(mModel.accessors[size_t(position->second)].count, UINT32_MAX);
        }
        return count;
    }

    void addMesh(int index, const Matrix4& world) {
        if (index < 0 || size_t(index) >= mModel.meshes.size())
            fail(mSource, "glTF refers to mesh " + std::to_string(index) + ", which does not exist");
        if (mMesh.positions.size() + storedVertices(index) > mVertexLimit)
            fail(mSource, "glTF nodes use its meshes so often that they would expand to more than " +
                              std::to_string(mVertexLimit) + " vertices (zomefab takes up to " +
                              std::to_string(kMaxInstancing) +
                              " times the vertices the file stores); flatten the scene in the exporter");
        const tinygltf::Mesh& mesh = mModel.meshes[size_t(index)];
        // A mirroring transform reverses the winding (glTF 2.0 spec, "Transformations").
        const bool mirrored = linearDeterminant(world) < 0;
        for (size_t p = 0; p < mesh.primitives.size(); ++p) {
            const tinygltf::Primitive& prim = mesh.primitives[p];
            if (prim.mode != TINYGLTF_MODE_TRIANGLES && prim.mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
                prim.mode != TINYGLTF_MODE_TRIANGLE_FAN)
                continue;  // points and lines have no surface
            const std::string what = "mesh " + std::to_string(index) + " primitive " + std::to_string(p);
            const auto position = prim.attributes.find("POSITION");
            if (position == prim.attributes.end())
                fail(mSource, "glTF " + what + " has no POSITION attribute");
            const std::vector<double> xyz =
                readAccessor(position->second, TINYGLTF_TYPE_VEC3, what + " POSITION");
            const size_t vertexCount = xyz.size() / 3;
            const uint32_t base = uint32_t(mMesh.positions.size());
            if (uint64_t(base) + vertexCount > UINT32_MAX) fail(mSource, "glTF has more than 2^32 vertices");
            for (size_t v = 0; v < vertexCount; ++v) {
                Vec3f q;
                for (int r = 0; r < 3; ++r)
                    q[r] = float(world[r] * xyz[3 * v] + world[4 + r] * xyz[3 * v + 1] +
                                 world[8 + r] * xyz[3 * v + 2] + world[12 + r]);
                if (!isFinite(q))
                    fail(mSource, "glTF " + what + " has a non-finite position (NaN or infinity)");
                mMesh.positions.push_back(q);
            }
            std::vector<double> indices;
            if (prim.indices >= 0) {
                indices = readAccessor(prim.indices, TINYGLTF_TYPE_SCALAR, what + " indices");
            } else {
                indices.resize(vertexCount);
                for (size_t v = 0; v < vertexCount; ++v) indices[v] = double(v);
            }
            for (double i : indices)
                if (!(i >= 0 && i < double(vertexCount)))
                    fail(mSource, "glTF " + what + " has vertex index " + std::to_string(int64_t(i)) +
                                      " but only " + std::to_string(vertexCount) + " vertices");
            auto add = [&](size_t a, size_t b, size_t c) {
                Triangle t{base + uint32_t(indices[a]), base + uint32_t(indices[b]),
                           base + uint32_t(indices[c])};
                if (mirrored) std::swap(t[1], t[2]);
                mMesh.triangles.push_back(t);
            };
            const size_t n = indices.size();
            if (prim.mode == TINYGLTF_MODE_TRIANGLES) {
                if (n % 3 != 0)
                    fail(mSource,
                         "glTF " + what + " has " + std::to_string(n) + " indices, not a multiple of 3");
                for (size_t i = 0; i + 2 < n; i += 3) add(i, i + 1, i + 2);
            } else if (prim.mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
                for (size_t i = 0; i + 2 < n; ++i) {
                    if (indices[i] == indices[i + 1] || indices[i + 1] == indices[i + 2] ||
                        indices[i] == indices[i + 2])
                        continue;  // repeated indices join strips; they are not geometry
                    if (i % 2 == 0)
                        add(i, i + 1, i + 2);
                    else
                        add(i + 1, i, i + 2);
                }
            } else {
                for (size_t i = 1; i + 1 < n; ++i) add(0, i, i + 1);
            }
        }
    }

    /// The accessor's values as doubles (count x components), integers normalised when the
    /// accessor says so. Every offset is bounds-checked: the file may be hostile.
    std::vector<double> readAccessor(int index, int expectedType, const std::string& what) {
        if (index < 0 || size_t(index) >= mModel.accessors.size())
            fail(mSource,
                 "glTF " + what + " refers to accessor " + std::to_string(index) + ", which does not exist");
        const tinygltf::Accessor& acc = mModel.accessors[size_t(index)];
        if (acc.type != expectedType)
            fail(mSource, "glTF " + what + " accessor has the wrong type (" + std::to_string(acc.type) + ")");
        const int componentSize = tinygltf::GetComponentSizeInBytes(uint32_t(acc.componentType));
        const int components = tinygltf::GetNumComponentsInType(uint32_t(acc.type));
        if (componentSize <= 0 || components <= 0 || acc.componentType == TINYGLTF_COMPONENT_TYPE_DOUBLE)
            fail(mSource, "glTF " + what + " accessor has an invalid component type");
        if (expectedType == TINYGLTF_TYPE_SCALAR &&
            acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
            acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
            acc.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
            fail(mSource, "glTF " + what + " must be unsigned integers");
        const size_t elementBytes = size_t(componentSize) * size_t(components);
        const size_t count = acc.count;
        if (count > (size_t(1) << 32)) fail(mSource, "glTF " + what + " accessor is too large");

        std::vector<double> values;
        if (acc.bufferView >= 0) {
            const char* data = viewRange(acc.bufferView, acc.byteOffset, count, elementBytes, what);
            const size_t stride = strideOf(acc.bufferView, elementBytes, what);
            values.resize(count * size_t(components));
            for (size_t i = 0; i < count; ++i)
                for (int c = 0; c < components; ++c)
                    values[i * size_t(components) + size_t(c)] =
                        component(data + i * stride + size_t(c) * size_t(componentSize), acc.componentType,
                                  acc.normalized);
        } else {
            // Without a bufferView the values start as zeros and only sparse entries are set;
            // cap the count so a tiny hostile file cannot demand gigabytes of zeros.
            const size_t sparse = acc.sparse.isSparse && acc.sparse.count > 0 ? size_t(acc.sparse.count) : 0;
            if (count > 1024 + 64 * sparse)
                fail(mSource, "glTF " + what + " accessor has no bufferView and no data for its " +
                                  std::to_string(count) + " elements");
            values.assign(count * size_t(components), 0.0);
        }
        if (acc.sparse.isSparse) {
            const auto& sp = acc.sparse;
            if (sp.count <= 0 || size_t(sp.count) > count || sp.indices.byteOffset < 0 ||
                sp.values.byteOffset < 0)
                fail(mSource, "glTF " + what + " has an invalid sparse accessor");
            const int indexSize = tinygltf::GetComponentSizeInBytes(uint32_t(sp.indices.componentType));
            if (sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE &&
                sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT &&
                sp.indices.componentType != TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT)
                fail(mSource, "glTF " + what + " has invalid sparse indices");
            const char* idx = viewRange(sp.indices.bufferView, size_t(sp.indices.byteOffset),
                                        size_t(sp.count), size_t(indexSize), what + " sparse indices");
            const char* val = viewRange(sp.values.bufferView, size_t(sp.values.byteOffset), size_t(sp.count),
                                        elementBytes, what + " sparse values");
            for (size_t k = 0; k < size_t(sp.count); ++k) {
                const double target = component(idx + k * size_t(indexSize), sp.indices.componentType, false);
                if (!(target < double(count)))
                    fail(mSource, "glTF " + what + " has a sparse index out of range");
                for (int c = 0; c < components; ++c)
                    values[size_t(target) * size_t(components) + size_t(c)] =
                        component(val + k * elementBytes + size_t(c) * size_t(componentSize),
                                  acc.componentType, acc.normalized);
            }
        }
        return values;
    }

    size_t strideOf(int view, size_t elementBytes, const std::string& what) const {
        const size_t stride = mModel.bufferViews[size_t(view)].byteStride;
        if (stride == 0) return elementBytes;
        if (stride < elementBytes)
            fail(mSource, "glTF " + what + " has a byteStride smaller than an element");
        return stride;
    }

    /// Start of @p count elements of @p elementBytes at @p offset in bufferView @p view (strided
    /// when the view says so), after checking that they lie inside the view and its buffer.
    const char* viewRange(int view, size_t offset, size_t count, size_t elementBytes,
                          const std::string& what) const {
        if (view < 0 || size_t(view) >= mModel.bufferViews.size())
            fail(mSource,
                 "glTF " + what + " refers to bufferView " + std::to_string(view) + ", which does not exist");
        const tinygltf::BufferView& bv = mModel.bufferViews[size_t(view)];
        if (bv.buffer < 0 || size_t(bv.buffer) >= mModel.buffers.size())
            fail(mSource, "glTF " + what + " refers to a buffer that does not exist");
        const std::vector<unsigned char>& buffer = mModel.buffers[size_t(bv.buffer)].data;
        if (bv.byteOffset > buffer.size() || bv.byteLength > buffer.size() - bv.byteOffset)
            fail(mSource,
                 "glTF " + what + ": bufferView " + std::to_string(view) + " lies outside its buffer");
        const size_t stride = strideOf(view, elementBytes, what);
        if (count > 0) {
            if (offset > bv.byteLength || bv.byteLength - offset < elementBytes ||
                (count - 1) > (bv.byteLength - offset - elementBytes) / stride)
                fail(mSource, "glTF " + what + " reads past the end of bufferView " + std::to_string(view));
        }
        return reinterpret_cast<const char*>(buffer.data()) + bv.byteOffset + offset;
    }

    static double component(const char* p, int type, bool normalized) {
        switch (type) {
            case TINYGLTF_COMPONENT_TYPE_BYTE: {
                const double v = loadScalar<int8_t>(p, false);
                return normalized ? std::max(v / 127.0, -1.0) : v;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: {
                const double v = loadScalar<uint8_t>(p, false);
                return normalized ? v / 255.0 : v;
            }
            case TINYGLTF_COMPONENT_TYPE_SHORT: {
                const double v = loadScalar<int16_t>(p, false);
                return normalized ? std::max(v / 32767.0, -1.0) : v;
            }
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: {
                const double v = loadScalar<uint16_t>(p, false);
                return normalized ? v / 65535.0 : v;
            }
            case TINYGLTF_COMPONENT_TYPE_INT:
                return loadScalar<int32_t>(p, false);
            case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT:
                return loadScalar<uint32_t>(p, false);
            case TINYGLTF_COMPONENT_TYPE_FLOAT:
                return loadScalar<float>(p, false);
            default:
                return 0;
        }
    }

    const tinygltf::Model& mModel;
    const std::string& mSource;
    TriMesh mMesh;
    std::vector<char> mVisited;
    uint64_t mVertexLimit = 0;  ///< what node instancing may expand the stored vertices to
};

/// Libdraco exports an older, layout-incompatible copy of the tinygltf symbols. When it precedes
/// libtinygltf in the executable's DT_NEEDED list, the dynamic linker binds our calls to Draco's
/// copy and the heap is corrupted (seen as "free(): invalid pointer"). Say so instead of crashing.
void requireRealTinyGltf() {
    static const bool ok = [] {
        Dl_info info{};
        if (!dladdr(reinterpret_cast<void*>(&tinygltf::FileExists), &info) || !info.dli_fname) return true;
        return std::string(info.dli_fname).find("draco") == std::string::npos;
    }();
    if (!ok)
        throw Error(ErrorCode::Internal,
                    "tinygltf symbols resolve to libdraco: link libtinygltf before libdraco "
                    "(see lib/zomefab/io/CMakeLists.txt)");
}

}  // namespace

TriMesh parseGltf(std::string_view bytes, bool isBinary, const std::string& source,
                  const MeshReadOptions& options) {
    requireRealTinyGltf();
    if (bytes.size() > UINT_MAX) fail(source, "glTF file larger than 4 GiB");
    tinygltf::TinyGLTF loader;
    FsPolicy policy{options.externalDir.has_value()};
    loader.SetFsCallbacks({&fsFileExists, &fsExpandPath, &fsReadWholeFile, &fsWriteWholeFile, &policy});
    loader.SetImageLoader(&skipImage, nullptr);
    tinygltf::Model model;
    std::string err, warn;
    const std::string baseDir = options.externalDir.value_or("");
    const bool ok =
        isBinary
            ? loader.LoadBinaryFromMemory(&model, &err, &warn,
                                          reinterpret_cast<const unsigned char*>(bytes.data()),
                                          unsigned(bytes.size()), baseDir)
            : loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(), unsigned(bytes.size()), baseDir);
    if (!ok)
        fail(source,
             std::string(isBinary ? "GLB" : "glTF") + " parse error: " + oneLine(err.empty() ? warn : err));
    TriMesh mesh = GltfMeshBuilder(model, source).build();
    if (options.weldVertices) weldIdenticalVertices(mesh);
    return mesh;
}

}  // namespace zomefab::detail
