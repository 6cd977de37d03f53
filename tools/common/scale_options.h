// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The scaling options of every tool that reads a mesh in file units.
#pragma once

#include <CLI/CLI.hpp>
#include <string>

#include "zomefab/mesh/scale.h"

namespace zomefab::cli {

/// --height-mm / --scale / --up, as every tool that reads a mesh in file units takes them.
struct ScaleCli {
    mesh::ScaleOptions options;
    std::string up = "z";

    void addTo(CLI::App& app);
    /// The options with --up applied. @throw Error(Usage) for a bad height or scale.
    mesh::ScaleOptions resolve() const;
};

}  // namespace zomefab::cli
