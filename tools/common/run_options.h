// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The options of `zomefab run`: every stage's group from stage_options.h, so a batch
/// manifest (docs/batch.md) can set any option of any stage, and checkRunArguments() can refuse a
/// bad manifest before a worker starts.
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "cli.h"
#include "stage_options.h"
#include "zomefab/pipeline/pipeline.h"

namespace zomefab::cli {

struct RunCli {
    std::string input;
    std::string outDir;
    std::string inFormat;
    ScaleCli scale;
    ValidateCli validate;
    FabricationCli fabrication;
    FieldCli field;
    FrameCli frame;
    PartitionCli partition;
    PiecesCli pieces;
    CostCli cost;
    PreviewCli preview;

    void addTo(CLI::App& run);
    /// Every option parsed and checked, --seed filled in; the salient faces (which need the mesh)
    /// are read by partition.resolveSalientFaces. @throw Error(Usage)
    pipeline::RunOptions resolve(uint64_t seed) const;
};

/// Parses @p args as the options of `zomefab run MESH -o DIR` and checks their values, as a run
/// would before reading its input. @throw Error(Usage) with the parser's message.
void checkRunArguments(const std::vector<std::string>& args);

}  // namespace zomefab::cli
