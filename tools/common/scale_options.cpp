// SPDX-License-Identifier: GPL-3.0-or-later
#include "scale_options.h"

namespace zomefab::cli {

void ScaleCli::addTo(CLI::App& app) {
    auto* height = app.add_option("--height-mm", options.heightMm,
                                  "Scale uniformly so the extent along the up axis is this many mm");
    app.add_option("--scale", options.scale, "Alternative: multiply file units by this to get mm")->excludes(height);
    app.add_option("--up", up, "The input's up axis; y-up meshes are rotated to z up")
        ->check(CLI::IsMember({"z", "y"}, CLI::ignore_case))
        ->default_val("z");
}

mesh::ScaleOptions ScaleCli::resolve() const {
    mesh::ScaleOptions resolved = options;
    resolved.up = (up == "y" || up == "Y") ? mesh::UpAxis::Y : mesh::UpAxis::Z;
    mesh::checkScaleOptions(resolved);
    return resolved;
}

}  // namespace zomefab::cli
