// SPDX-License-Identifier: GPL-3.0-or-later
/// @file assembly.html: the assembly guide as a page with pictures, self-contained (the pictures are
/// PNGs this project renders, inlined as data: URLs; no script, no network). One picture per frame
/// layer (the parts added in that layer in colour, what is built already in grey) and one per
/// mounting step (the piece in its preview colour, in place; pieces already on in grey; an arrow
/// along the push; the balls its pegs go into ringed). docs/report.md, "assembly.html".
#pragma once

#include <string>

#include "zomefab/report/assembly_guide.h"
#include "zomefab/report/preview_scene.h"

namespace zomefab::report {

/// The page of @p guide; @p scene gives the frame and the pieces in frame mm (as for the preview),
/// @p title names the object. Deterministic.
/// @throw Error(InvalidInput) when the scene has no frame or a step names a piece it does not hold.
std::string assemblyGuideHtml(const AssemblyGuide& guide, const PreviewInput& scene, const std::string& title,
                              const zome::PriceOptions& prices = {});

}  // namespace zomefab::report
