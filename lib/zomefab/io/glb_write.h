// SPDX-License-Identifier: GPL-3.0-or-later
/// @file A generic writer of binary glTF 2.0 (GLB) scenes: meshes shared by many nodes (instancing
/// by reference), metallic-roughness materials, node TRS transforms, `extras`, and optional Draco
/// compression of a mesh (KHR_draco_mesh_compression). The container and the glTF JSON are written
/// here with nlohmann-json; Draco (linked PRIVATE to zomefab_io) only encodes the mesh bitstreams.
/// The scene knows nothing of Zometool: lib/zomefab/report/preview_scene.h builds the preview.
/// Layout, units and validation: docs/preview.md.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/tri_mesh.h"

namespace zomefab {

/// A glTF metallic-roughness material (`pbrMetallicRoughness`), opaque and single-sided.
struct GlbMaterial {
    std::string name;
    std::array<double, 4> baseColor{1.0, 1.0, 1.0, 1.0};  ///< linear RGBA, each in [0, 1]
    double metallic = 0.0;                                ///< [0, 1]
    double roughness = 0.6;                               ///< [0, 1]
};

/// One mesh = one indexed triangle primitive. Several nodes may refer to the same mesh.
struct GlbMesh {
    std::string name;
    TriMesh geometry;  ///< positions in the scene's length unit, outward triangles
    /// Empty (viewers then compute flat normals, glTF 2.0 §3.7.2.1) or one unit normal per vertex.
    std::vector<Vec3f> normals;
    int material = -1;  ///< index into GlbScene::materials; -1 = glTF's default material
    /// Store the primitive as a Draco bitstream (KHR_draco_mesh_compression): positions quantised
    /// to GlbWriteOptions::dracoPositionBits, vertex order and count chosen by Draco.
    bool isDracoCompressed = false;
};

/// A node: an optional mesh, children, and a local transform T·R·S (glTF 2.0 §3.5.3).
struct GlbNode {
    std::string name;
    int mesh = -1;              ///< index into GlbScene::meshes, -1 = none
    std::vector<int> children;  ///< node indices
    Vec3d translation{0.0, 0.0, 0.0};
    std::array<double, 4> rotation{0.0, 0.0, 0.0, 1.0};  ///< unit quaternion (x, y, z, w)
    Vec3d scale{1.0, 1.0, 1.0};
    nlohmann::json extras;  ///< null = no `extras`
};

/// One scene: the nodes listed in @c roots and everything below them.
struct GlbScene {
    std::vector<GlbMaterial> materials;
    std::vector<GlbMesh> meshes;
    std::vector<GlbNode> nodes;
    std::vector<int> roots;  ///< root node indices of scenes[0]
    std::string sceneName;
    nlohmann::json extras;  ///< scenes[0].extras; null = none
    std::string generator;  ///< asset.generator, e.g. "zomefab 0.1.0"
};

/// Draco settings for meshes with GlbMesh::isDracoCompressed.
struct GlbWriteOptions {
    /// Position quantisation (bits per coordinate over the mesh's bounding box): 14 bits keep a
    /// 200 mm piece within 0.012 mm, well below a 0.2 mm print layer. Draco allows 1..30.
    int dracoPositionBits = 14;
    int dracoNormalBits = 10;  ///< normal quantisation (octahedral), 1..30
    /// Draco speed options 0 (smallest file, slowest) .. 10 (fastest); 3 = draco_encoder's `-cl 7`.
    int dracoEncodingSpeed = 3;
    int dracoDecodingSpeed = 3;
};

/// The GLB bytes of @p scene: header, JSON chunk, BIN chunk. Deterministic: the same scene and
/// options give the same bytes. Every compressed mesh is decoded again in memory, so its
/// accessors carry the counts and the min/max of what a viewer will actually decode.
/// @throw Error(InvalidInput) for an inconsistent scene (an index out of range, a node with two
///   parents or in a cycle, an empty mesh, non-finite numbers, a normals array of the wrong size,
///   more than 2^32 bytes) naming the mesh or node; Error(ProcessingFailed) when Draco fails.
std::string serializeGlb(const GlbScene& scene, const GlbWriteOptions& options = {});

/// @p bytes in base64 (RFC 4648, with padding), e.g. to inline a GLB in a web page.
std::string base64Encode(const std::string& bytes);

/// serializeGlb() written atomically to @p path ("-" = stdout).
/// @throw as serializeGlb(), Error(WriteFailed) naming the file.
void writeGlb(const GlbScene& scene, const std::string& path, const GlbWriteOptions& options = {});

}  // namespace zomefab
