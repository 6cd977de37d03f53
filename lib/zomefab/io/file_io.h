// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Whole-file input and crash-safe output. "-" means stdin / stdout everywhere.
#pragma once

#include <functional>
#include <ostream>
#include <string>

namespace zomefab {

/// Reads all bytes of @p path ("-" = stdin).
/// @throw Error(InvalidInput) naming the file when it does not exist, is a directory or unreadable.
std::string readInputBytes(const std::string& path);

/// Writes @p path through @p write, first into a temporary sibling, then renamed into place, so a
/// failure never leaves a partial file. "-" writes to stdout directly (binary-safe).
/// @throw Error(WriteFailed) naming the file; whatever @p write throws is rethrown after cleanup.
void writeOutputAtomic(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Lower-case extension of @p path without the dot ("mesh.STL" -> "stl"), empty when none.
std::string fileExtension(const std::string& path);

}  // namespace zomefab
