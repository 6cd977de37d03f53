// SPDX-License-Identifier: GPL-3.0-or-later
/// @file viewer.html: the preview as a page that opens offline from the output folder. It inlines
/// three.js r111 (Debian's libjs-three, MIT licence: GLTFLoader, OrbitControls) and the scene as an
/// uncompressed GLB in base64, so it needs no network, no server and no Draco decoder
/// (docs/preview.md, "viewer.html").
#pragma once

#include <string>

#include "zomefab/report/preview_scene.h"

namespace zomefab::report {

/// The page: a WebGL view of @p glbBytes (a GLB without KHR_draco_mesh_compression, as
/// serializeGlb writes with PreviewOptions::isPieceDracoCompressed = false), titled @p title, with
/// a slider over the mounting steps (pieces whose node extras "step" is at most the slider's
/// value are shown; step 0 is the frame alone). Deterministic.
std::string viewerPage(const std::string& glbBytes, const std::string& title);

/// viewer.html of the preview scene of @p input: the scene built as buildPreviewScene with
/// @p options but uncompressed (the page has no Draco decoder), then viewerPage, written atomically
/// to @p path. The title names the object (the extras' "source" file name) when there is one.
/// @throw as buildPreviewScene and serializeGlb; Error(WriteFailed) naming the file.
void writeViewer(const PreviewInput& input, const PreviewOptions& options, const std::string& path);

}  // namespace zomefab::report
