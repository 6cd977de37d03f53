// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The openvdb::FloatGrid behind a LevelSet, and RunContext as an OpenVDB interrupter. For
/// stages that run OpenVDB operations themselves (CSG of pieces, tenons); everything else should
/// include the light zomefab/sdf/level_set.h.
#pragma once

#include <openvdb/openvdb.h>
#include <openvdb/util/NullInterrupter.h>

#include <atomic>
#include <string>

#include "zomefab/core/run_context.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::sdf {

struct LevelSet::Impl {
    openvdb::FloatGrid::Ptr grid;  ///< never modified once wrapped
};

namespace detail {
struct LevelSetAccess {
    static LevelSet wrap(openvdb::FloatGrid::Ptr grid, LevelSetInfo info);
    static const openvdb::FloatGrid::Ptr& grid(const LevelSet& levelSet);
};
}  // namespace detail

/// The grid behind @p levelSet: world units mm, class GRID_LEVEL_SET. Shared, so treat it as
/// read-only (deepCopy() it before an operation that modifies or consumes its input).
/// @throw Error(Internal) for an empty level set.
openvdb::FloatGrid::ConstPtr levelSetGrid(const LevelSet& levelSet);

/// Wraps @p grid (shared; do not modify it afterwards). Sets the grid's name and class from
/// @p info. @throw Error(Internal) for a null grid.
LevelSet wrapLevelSetGrid(openvdb::FloatGrid::Ptr grid, LevelSetInfo info);

/// The closed, outward triangle mesh of {φ = @p options.isoMm} of @p grid: OpenVDB's VolumeToMesh
/// (dual contouring) with @p options.adaptivity, full resolution wherever @p fullResolution is
/// active (may be null), the adaptivity scaled by @p adaptivityWeight's value at each voxel where it
/// is given (may be null; background 1), every polygon reversed (OpenVDB winds clockwise seen from outside,
/// zomefab counter-clockwise), quads split along their shorter diagonal, and closed components
/// under options.minComponentVolumeMm3 dropped (specks where the surface grazes a voxel).
/// Deterministic: OpenVDB's output order for a given grid, each polygon pool's quads then its
/// triangles. The one mesher of the library (levelSetToMesh, the pieces stage).
TriMesh meshFloatGrid(const openvdb::FloatGrid& grid, const LevelSetToMeshOptions& options,
                      const openvdb::BoolTree::Ptr& fullResolution = nullptr,
                      const openvdb::FloatGrid::ConstPtr& adaptivityWeight = nullptr);

/// Passes OpenVDB's progress to RunContext::progress(stage, percent / 100) and asks it whether to
/// stop. OpenVDB operations return early (with a partial or empty result) when interrupted, so
/// call RunContext::throwIfCancelled() right after each of them.
class VdbInterrupter final : public openvdb::util::NullInterrupter {
public:
    VdbInterrupter(const RunContext& context, std::string stage)
        : mContext(context), mStage(std::move(stage)) {}
    void start(const char* = nullptr) override { mContext.progress(mStage, 0.0); }
    void end() override { mContext.progress(mStage, 1.0); }
    /// Thread-safe. OpenVDB calls this from every worker, very often: only a change of percent
    /// reaches RunContext::progress (which locks), the cancel check is an atomic load.
    bool wasInterrupted(int percent = -1) override {
        if (percent >= 0 && percent != mLastPercent.load(std::memory_order_relaxed) &&
            mLastPercent.exchange(percent) != percent) {
            mContext.progress(mStage, percent / 100.0);
        }
        return mContext.isCancelled();
    }

private:
    const RunContext& mContext;
    std::string mStage;
    std::atomic<int> mLastPercent{-1};
};

}  // namespace zomefab::sdf
