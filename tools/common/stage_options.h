// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Option declarations and parsers that several tools share (scaling, printer size, saliency),
/// so `zomefab run` and the stage tools spell and check them the same way.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "scale_options.h"
#include "zomefab/partition/partition.h"

namespace zomefab::cli {

/// "200x200x200" or "200,200,200" (mm). @throw Error(Usage) naming --printer-mm
Vec3d parsePrinterMm(const std::string& text);
/// "x,y,z,r" (mm). @throw Error(Usage) naming --salient
partition::SalientSphere parseSalientSphere(const std::string& text);
/// A JSON list of face indices, or {"salient_faces": [...]}, every index below @p faceCount.
/// @throw Error(InvalidInput) naming @p path
std::vector<uint32_t> readSalientFaceList(const std::string& path, size_t faceCount);

}  // namespace zomefab::cli
