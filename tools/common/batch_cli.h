// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The `zomefab batch` and `zomefab bench` commands: their options and how they call the
/// batch module (lib/zomefab/batch, docs/batch.md).
#pragma once

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "cli.h"
#include "zomefab/batch/batch.h"

namespace zomefab::cli {

/// What workers inherit from this process: the seed, the thread limit, -q.
batch::WorkerCommand workerCommand(const Tool& tool);

struct BatchCli {
    std::string manifest, outDir;
    int index = -1;
    bool isMergeOnly = false;
    bool isCountOnly = false;  ///< print the number of entries on stdout (for job-array ranges)

    void addTo(CLI::App& app);
    /// Checks every entry's options as `zomefab run` would (exit 2 naming the entry), then runs one
    /// entry (--index), all of them, or only the merge; --count prints the number of entries. Exit 0 when
    /// every entry succeeded, else 3.
    int execute(Tool& tool, nlohmann::json& report) const;
};

struct BenchCli {
    std::string output = "-";
    batch::BenchOptions options;

    void addTo(CLI::App& app);
    int execute(Tool& tool, nlohmann::json& report) const;
};

}  // namespace zomefab::cli
