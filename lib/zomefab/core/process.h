// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The one way the library starts another program (the slicer, batch workers): posix_spawn
/// (safe in a process with TBB worker threads, unlike fork), no shell, stdin from /dev/null, and
/// a wait that polls the run's cancellation so an interrupted run ends its child too.
#pragma once

#include <string>
#include <vector>

#include "zomefab/core/run_context.h"

namespace zomefab {

struct ProcessOptions {
    /// Empty: the child shares this process's stdout and stderr. Otherwise both go to this file
    /// (created or truncated), e.g. a slicer's log.
    std::string outputPath;
    /// Look argv[0] up in PATH (posix_spawnp) unless it contains a slash.
    bool searchPath = true;
    /// Polled while the child runs; when cancelled the child gets SIGTERM, is waited for, and
    /// runProcess throws Error(Cancelled). Null: wait without polling.
    const RunContext* context = nullptr;
};

/// Runs @p argv (argv[0] the program) and waits for it. Returns its exit code, or 128 + the
/// signal number when a signal ended it (the shell's convention).
/// @throw Error(ProcessingFailed) when it cannot be started; Error(Cancelled) as above.
int runProcess(const std::vector<std::string>& argv, const ProcessOptions& options = {});

}  // namespace zomefab
