// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The `preview.glb` scene: printed pieces (Draco-compressed, one node and colour each), the
/// Zometool balls (one white sphere mesh instanced by every ball node) and struts (one prism mesh
/// per colour and size with the real cross-section, instanced), under a root node that turns the
/// model's millimetres and z-up into glTF's metres and y-up. Layout: docs/preview.md.
#pragma once

#include <array>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/io/glb_write.h"
#include "zomefab/zome/structure.h"

namespace zomefab::report {

/// What the preview shows. Everything in the model's millimetres, z up.
struct PreviewInput {
    std::vector<const TriMesh*> pieces;   ///< closed piece meshes (not owned)
    std::vector<std::string> pieceNames;  ///< node names, one per piece; empty = "piece-00", ...
    /// Empty (the pieces already sit where they belong in the frame's mm), or one transform per
    /// piece taking it there, e.g. printer → frame mm: affineInverse(frameToGridMm) ·
    /// affineInverse(piece.gridToPrintMm) for pieces in their print orientation.
    std::vector<Transform4d> pieceTransforms;
    /// Empty, or one object per piece for its node's extras (the mounting step, so a viewer can
    /// play the installation plan: docs/preview.md).
    std::vector<nlohmann::json> pieceExtras;
    const zome::Structure* frame = nullptr;  ///< the Zometool frame; null = pieces only
    /// Merged into scenes[0].extras next to the parts list (e.g. the run's summary); null = none.
    nlohmann::json extras;
};

struct PreviewOptions {
    int sphereSubdivisions = 2;          ///< icosphere levels of the ball mesh: 2 = 320 triangles
    bool isPieceDracoCompressed = true;  ///< KHR_draco_mesh_compression on the pieces
    GlbWriteOptions glb;                 ///< Draco quantisation and speed
    std::string generator;               ///< asset.generator; empty = "zomefab <version>"
};

/// The colour of piece @p index in the preview (and the guide's pictures), sRGB in [0, 1]: hues
/// spaced by the golden angle at saturation 0.45, value 0.95.
std::array<double, 3> pieceColorSrgb(size_t index);
/// The colour of a strut of @p color, sRGB in [0, 1].
std::array<double, 3> strutColorSrgb(zome::Color color);

/// Builds the scene. Node names: "piece-NN" (or pieceNames), "ball-<id>", "strut-<id>" with the
/// frame's ids; group nodes "zomefab" (root), "pieces", "balls", "struts".
/// @throw Error(Usage) when pieceNames or pieceTransforms has the wrong size, a piece is empty, or the
/// frame's ball is
///   at least as wide as its shortest strut is long.
GlbScene buildPreviewScene(const PreviewInput& input, const PreviewOptions& options = {});

/// buildPreviewScene() then writeGlb(), atomically. @throw as both.
void writePreview(const PreviewInput& input, const std::string& path, const PreviewOptions& options = {});

}  // namespace zomefab::report
