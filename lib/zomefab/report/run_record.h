// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Everything one `zomefab run` made, in memory: each stage's result as the stage returned
/// it. The pipeline fills it (lib/zomefab/pipeline), this module turns it into report.json, cost.md
/// and the summary lines (run_report.h).
#pragma once

#include <string>
#include <vector>

#include "zomefab/core/fabrication.h"
#include "zomefab/core/transform.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/frame/frame.h"
#include "zomefab/mesh/mesh_check.h"
#include "zomefab/mesh/scale.h"
#include "zomefab/partition/partition_result.h"
#include "zomefab/pieces/pieces.h"
#include "zomefab/pieces/plates.h"
#include "zomefab/report/assembly_guide.h"
#include "zomefab/report/cost_report.h"
#include "zomefab/sdf/level_set.h"

namespace zomefab::report {

/// Seconds spent in one stage.
struct StageTiming {
    std::string stage;
    double seconds = 0;
};

struct RunRecord {
    std::string sourceName;        ///< the input file as given ("-" = stdin)
    Fabrication fabrication;       ///< what the run made
    mesh::MeshReport inputReport;  ///< checks of the input as read (file units)
    mesh::ScaledMesh scaled;       ///< the object in mm, z up, with transform_mm
    sdf::ObjectField field;        ///< "object" and "interior" level sets
    sdf::LevelSet shell;           ///< the hollow shell
    frame::FrameResult frame;      ///< the frame (structure in frame mm)
    Transform4d frameTransformMm;  ///< input coordinates → frame mm
    frame::FrameMetrics frameMetrics;
    TriMesh surfaceFrameMm;  ///< the scaled surface in the frame's coordinates
    partition::PartitionResult partition;
    pieces::Pieces pieces;              ///< printable pieces, in printer coordinates
    std::vector<pieces::Plate> plates;  ///< the pieces on printer beds, one print job each
    AssemblyGuide assembly;             ///< build order of the frame and the pieces' tenons
    CostReport cost;                    ///< Table 1: ZomeFab against the octree baseline
    std::vector<StageTiming> timings;   ///< in run order
    double totalSeconds = 0;
};

}  // namespace zomefab::report
