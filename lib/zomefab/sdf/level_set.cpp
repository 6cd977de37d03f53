// SPDX-License-Identifier: GPL-3.0-or-later
// The LevelSet handle and .vdb stream I/O with zomefab's metadata (docs/sdf.md, "Metadata").
#include <openvdb/io/Stream.h>
#include <openvdb/tools/Interpolation.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/sdf/level_set_grid.h"
#include "zomefab/sdf/vdb_check.h"
#include "zomefab/sdf/vdb_file.h"

namespace zomefab::sdf {

namespace {

/// OpenVDB's registries (grid types, maps, metadata) must be initialised once before any I/O.
void ensureOpenVdbInitialized() {
    static const bool initialized = [] {
        openvdb::initialize();
        return true;
    }();
    (void)initialized;
}

// Grid metadata keys; docs/sdf.md lists them.
constexpr const char* kUnitsKey = "units";
constexpr const char* kVoxelKey = "voxel_size_mm";
constexpr const char* kExteriorKey = "exterior_band_mm";
constexpr const char* kInteriorKey = "interior_band_mm";
constexpr const char* kShellKey = "shell_mm";
constexpr const char* kSourceKey = "source_file";
constexpr const char* kGeneratorKey = "generator";
constexpr const char* kTransformKey = "transform_mm";

/// Our row-major column-vector matrix as OpenVDB's row-vector Mat4d (translation in the last row),
/// so openvdb::math::Mat4d::transform() applies it directly.
openvdb::math::Mat4d toVdbMatrix(const Transform4d& t) {
    openvdb::math::Mat4d m;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m(c, r) = t.at(r, c);
    return m;
}

Transform4d fromVdbMatrix(const openvdb::math::Mat4d& m) {
    Transform4d t;
    for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) t.m[size_t(r * 4 + c)] = m(c, r);
    return t;
}

void writeInfoMetadata(openvdb::FloatGrid& grid, const LevelSetInfo& info) {
    grid.insertMeta(kUnitsKey, openvdb::StringMetadata("mm"));
    grid.insertMeta(kVoxelKey, openvdb::DoubleMetadata(info.voxelMm));
    grid.insertMeta(kExteriorKey, openvdb::DoubleMetadata(info.exteriorBandMm));
    grid.insertMeta(kInteriorKey, openvdb::DoubleMetadata(info.interiorBandMm));
    grid.insertMeta(kShellKey, openvdb::DoubleMetadata(info.shellMm));
    grid.insertMeta(kSourceKey, openvdb::StringMetadata(info.sourceFile));
    grid.insertMeta(kGeneratorKey, openvdb::StringMetadata(info.generator));
    grid.insertMeta(kTransformKey, openvdb::Mat4DMetadata(toVdbMatrix(info.transformMm)));
}

template <typename MetaT, typename ValueT>
bool readMeta(const openvdb::GridBase& grid, const char* key, ValueT& value) {
    const auto meta = grid.getMetadata<MetaT>(key);
    if (!meta) return false;
    value = meta->value();
    return true;
}

LevelSet levelSetFromGrid(openvdb::FloatGrid::Ptr grid, const std::string& sourceName, RunContext& context) {
    const std::string gridName = grid->getName().empty() ? "(unnamed)" : grid->getName();
    const openvdb::math::Transform& xform = grid->transform();
    const bool isUniformScale = xform.isLinear() && xform.hasUniformScale() &&
                                (xform.mapType() == openvdb::math::UniformScaleMap::mapType() ||
                                 xform.mapType() == openvdb::math::UniformScaleTranslateMap::mapType());
    if (!isUniformScale) {
        throw Error(ErrorCode::InvalidInput,
                    "grid '" + gridName + "' has a " + xform.mapType() +
                        " transform; only uniform voxels without rotation are supported",
                    sourceName);
    }
    // Blosc-compressed voxel values are only seen once decompressed: a NaN or infinite distance
    // would poison every stage after this one.
    for (auto it = grid->tree().cbeginValueAll(); it; ++it) {
        if (!std::isfinite(*it))
            throw Error(ErrorCode::InvalidInput, "grid '" + gridName + "' holds a non-finite distance value",
                        sourceName);
    }
    LevelSetInfo info;
    info.name = grid->getName();
    info.voxelMm = xform.voxelSize()[0];
    std::string units;
    if (readMeta<openvdb::StringMetadata>(*grid, kUnitsKey, units)) {
        if (units != "mm") {
            throw Error(ErrorCode::InvalidInput,
                        "grid '" + gridName + "' is in '" + units + "', zomefab needs millimetres",
                        sourceName);
        }
    } else {
        context.warn(sourceName + ": grid '" + gridName +
                     "' has no units metadata; taking its world units as millimetres");
    }
    const double halfWidthMm = kHalfWidthVoxels * info.voxelMm;
    const double background = grid->background();
    info.exteriorBandMm = std::max(0.0, background - halfWidthMm);
    info.interiorBandMm = info.exteriorBandMm;
    readMeta<openvdb::DoubleMetadata>(*grid, kExteriorKey, info.exteriorBandMm);
    readMeta<openvdb::DoubleMetadata>(*grid, kInteriorKey, info.interiorBandMm);
    readMeta<openvdb::DoubleMetadata>(*grid, kShellKey, info.shellMm);
    readMeta<openvdb::StringMetadata>(*grid, kSourceKey, info.sourceFile);
    readMeta<openvdb::StringMetadata>(*grid, kGeneratorKey, info.generator);
    openvdb::math::Mat4d m;
    if (readMeta<openvdb::Mat4DMetadata>(*grid, kTransformKey, m)) info.transformMm = fromVdbMatrix(m);
    if (!std::isfinite(info.exteriorBandMm) || info.exteriorBandMm < 0 || std::isnan(info.interiorBandMm) ||
        info.interiorBandMm < 0 || !std::isfinite(info.shellMm) || info.shellMm < 0) {
        throw Error(ErrorCode::InvalidInput, "grid '" + gridName + "' has invalid band metadata", sourceName);
    }
    return detail::LevelSetAccess::wrap(std::move(grid), std::move(info));
}

}  // namespace

// ---- LevelSet ------------------------------------------------------------------------------

LevelSet::LevelSet() = default;

LevelSet detail::LevelSetAccess::wrap(openvdb::FloatGrid::Ptr grid, LevelSetInfo info) {
    LevelSet levelSet;
    auto impl = std::make_shared<LevelSet::Impl>();
    impl->grid = std::move(grid);
    levelSet.mImpl = std::move(impl);
    levelSet.mInfo = std::move(info);
    return levelSet;
}

const openvdb::FloatGrid::Ptr& detail::LevelSetAccess::grid(const LevelSet& levelSet) {
    if (!levelSet.mImpl) throw Error(ErrorCode::Internal, "empty level set");
    return levelSet.mImpl->grid;
}

openvdb::FloatGrid::ConstPtr levelSetGrid(const LevelSet& levelSet) {
    return detail::LevelSetAccess::grid(levelSet);
}

LevelSet wrapLevelSetGrid(openvdb::FloatGrid::Ptr grid, LevelSetInfo info) {
    if (!grid) throw Error(ErrorCode::Internal, "wrapLevelSetGrid: null grid");
    grid->setName(info.name);
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    return detail::LevelSetAccess::wrap(std::move(grid), std::move(info));
}

size_t LevelSet::activeVoxelCount() const { return mImpl ? size_t(mImpl->grid->activeVoxelCount()) : 0; }

size_t LevelSet::memoryBytes() const { return mImpl ? size_t(mImpl->grid->memUsage()) : 0; }

Box3d LevelSet::activeBoundsMm() const {
    Box3d box;
    if (!mImpl || mImpl->grid->activeVoxelCount() == 0) return box;
    const openvdb::CoordBBox bbox = mImpl->grid->evalActiveVoxelBoundingBox();
    const openvdb::Vec3d a = mImpl->grid->indexToWorld(bbox.min());
    const openvdb::Vec3d b = mImpl->grid->indexToWorld(bbox.max());
    box.expand({a[0], a[1], a[2]});
    box.expand({b[0], b[1], b[2]});
    return box;
}

double LevelSet::valueMm(const Vec3d& p) const {
    const auto& grid = detail::LevelSetAccess::grid(*this);
    const openvdb::Vec3d index = grid->worldToIndex(openvdb::Vec3d(p[0], p[1], p[2]));
    return openvdb::tools::BoxSampler::sample(grid->tree(), index);
}

double LevelSet::insideVolumeMm3() const {
    if (!mImpl) return 0;
    const openvdb::FloatTree& tree = mImpl->grid->tree();
    openvdb::Index64 count = 0;
    for (auto it = tree.cbeginValueAll(); it; ++it) {
        if (*it < 0) count += it.getVoxelCount();
    }
    const double voxel = mInfo.voxelMm > 0 ? mInfo.voxelMm : mImpl->grid->voxelSize()[0];
    return double(count) * voxel * voxel * voxel;
}

// ---- .vdb streams --------------------------------------------------------------------------

std::string serializeVdb(const std::vector<LevelSet>& levelSets) {
    ensureOpenVdbInitialized();
    openvdb::GridPtrVec grids;
    std::set<std::string> names;
    for (const LevelSet& levelSet : levelSets) {
        if (levelSet.empty()) throw Error(ErrorCode::Internal, "writeVdb: empty level set");
        if (!names.insert(levelSet.info().name).second)
            throw Error(ErrorCode::Internal, "writeVdb: two grids named '" + levelSet.info().name + "'");
        // A shallow copy shares the tree but has its own metadata, so writing never touches the
        // (shared, immutable) source grid.
        openvdb::FloatGrid::Ptr grid = detail::LevelSetAccess::grid(levelSet)->copy();
        grid->setName(levelSet.info().name);
        grid->setGridClass(openvdb::GRID_LEVEL_SET);
        writeInfoMetadata(*grid, levelSet.info());
        grids.push_back(grid);
    }
    std::ostringstream buffer;
    try {
        openvdb::io::Stream stream(buffer);
        stream.setCompression(openvdb::io::COMPRESS_BLOSC | openvdb::io::COMPRESS_ACTIVE_MASK);
        // The checksum entry, filled in by sealVdbStream once the bytes are known.
        openvdb::MetaMap fileMeta;
        fileMeta.insertMeta(detail::kVdbChecksumKey,
                            openvdb::StringMetadata(detail::kVdbChecksumPlaceholder));
        stream.write(grids, fileMeta);
    } catch (const openvdb::Exception& e) {
        throw Error(ErrorCode::WriteFailed, std::string("cannot serialize the grids: ") + e.what());
    }
    std::string bytes = std::move(buffer).str();
    detail::sealVdbStream(bytes);
    return bytes;
}

void writeVdb(const std::vector<LevelSet>& levelSets, std::ostream& out) {
    const std::string bytes = serializeVdb(levelSets);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    if (!out) throw Error(ErrorCode::WriteFailed, "cannot write the .vdb stream");
}

std::vector<LevelSet> parseVdb(std::string_view bytes, const std::string& sourceName, RunContext& context) {
    ensureOpenVdbInitialized();
    if (bytes.empty())
        throw Error(ErrorCode::InvalidInput, "empty input, expected a .vdb stream", sourceName);
    // Every size checked (and zomefab's checksum) before OpenVDB trusts them.
    detail::VdbCheck checked = detail::checkVdbStream(bytes, sourceName);
    const double budget = memoryBudgetBytes(0);
    if (double(checked.treeBytes) > budget) {
        throw Error(
            ErrorCode::ProcessingFailed,
            formatNumbers("its grids would need about %.1f GB of memory, more than the %.1f GB budget "
                          "(75 %% of this machine's)",
                          double(checked.treeBytes) / 1e9, budget / 1e9),
            sourceName);
    }
    openvdb::GridPtrVecPtr grids;
    try {
        std::istringstream in{std::move(checked.sanitized)};
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        grids = stream.getGrids();
    } catch (const std::exception& e) {
        // (checkVdbStream has already refused what is not a .vdb stream at all.)
        throw Error(ErrorCode::InvalidInput, std::string("cannot read the .vdb stream: ") + e.what(),
                    sourceName);
    }
    std::vector<LevelSet> result;
    std::string others;
    if (grids) {
        for (const openvdb::GridBase::Ptr& base : *grids) {
            auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
            if (grid && grid->getGridClass() == openvdb::GRID_LEVEL_SET) {
                result.push_back(levelSetFromGrid(grid, sourceName, context));
            } else {
                others += (others.empty() ? "" : ", ") +
                          ("'" + base->getName() + "' (" + base->valueType() + " " +
                           openvdb::GridBase::gridClassToString(base->getGridClass()) + ")");
            }
        }
    }
    if (result.empty()) {
        throw Error(ErrorCode::InvalidInput,
                    "no float level-set grid in the .vdb stream" +
                        (others.empty() ? std::string() : "; found " + others),
                    sourceName);
    }
    return result;
}

const LevelSet& findLevelSet(const std::vector<LevelSet>& levelSets, const std::string& name,
                             const std::string& sourceName) {
    std::string names;
    for (const LevelSet& levelSet : levelSets) {
        if (name.empty() || levelSet.info().name == name) return levelSet;
        names += (names.empty() ? "'" : ", '") + levelSet.info().name + "'";
    }
    throw Error(ErrorCode::InvalidInput,
                "no level set named '" + name + "' (the file has " + (names.empty() ? "none" : names) + ")",
                sourceName);
}

}  // namespace zomefab::sdf
