// SPDX-License-Identifier: GPL-3.0-or-later
/// @file 3MF (3D Manufacturing Format, core specification 1.2) writer: one OPC zip package holding
/// [Content_Types].xml, _rels/.rels and 3D/3dmodel.model with one mesh object and one build item
/// per part, unit millimetre. The zip is written here (deflate through zlib, CRC-32, no zip64), with
/// fixed timestamps, so equal inputs give equal bytes. docs/io.md, "3MF".
#pragma once

#include <string>
#include <vector>

#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab {

/// One part of the package.
struct ThreeMfObject {
    std::string name;              ///< the object's name attribute (XML-escaped on output)
    const TriMesh* mesh = nullptr; ///< millimetres; not owned
    /// Where the build item places the object: an affine transform (rotation part and translation).
    Transform4d placementMm;
};

/// The bytes of a .3mf package with @p objects (in order; object ids 1..n). @p generator goes into
/// the model's Application metadata.
/// @throw Error(Usage) for an object without a mesh, an empty mesh or a triangle index out of range;
///        Error(WriteFailed) when the package would exceed 4 GiB (no zip64).
std::string threeMfBytes(const std::vector<ThreeMfObject>& objects, const std::string& generator);

/// Writes threeMfBytes() to @p path atomically (writeOutputAtomic). @throw as threeMfBytes, and
/// Error(WriteFailed) naming the file.
void writeThreeMf(const std::vector<ThreeMfObject>& objects, const std::string& generator, const std::string& path);

/// One stored or deflated entry of a zip archive.
struct ZipEntry {
    std::string name;
    std::string data;
};

/// A zip archive of @p entries (deflated when that is smaller, else stored), timestamps 1980-01-01.
/// @throw Error(WriteFailed) past 4 GiB or 65535 entries.
std::string zipArchive(const std::vector<ZipEntry>& entries);

}  // namespace zomefab
