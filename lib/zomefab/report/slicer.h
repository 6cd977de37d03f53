// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The real slicer as an alternative to the estimator: PrusaSlicer's command line run as a
/// subprocess on a temporary STL file, its G-code comments parsed for time and filament
/// (`--slicer prusa-slicer`). The only place in the library that starts a process; it writes
/// only inside its own temporary directory and removes it. Command line: docs/report.md.
#pragma once

#include <string>
#include <vector>

#include "zomefab/core/run_context.h"
#include "zomefab/core/tri_mesh.h"
#include "zomefab/report/print_estimate.h"

namespace zomefab::report {

struct SlicerOptions {
    std::string executable = "prusa-slicer";  ///< a name looked up in PATH, or a path
    std::string tempDir;                      ///< parent of the scratch directory; empty = system temp
};

/// True when @p executable can be run (a path that is executable, or found in PATH).
bool isSlicerAvailable(const std::string& executable = "prusa-slicer");

/// The PrusaSlicer arguments used for @p settings (profile of ../shared/docs/print-estimates.md,
/// a 1000 mm virtual bed so large parts are not refused; automatic supports when settings.supports),
/// without input and output.
std::vector<std::string> prusaSlicerArguments(const PrintSettings& settings, double bedMm = 1000.0);

/// Slices @p part with PrusaSlicer and reads `; estimated printing time (normal mode)` and
/// `; filament used [cm3]` from the G-code. @p label names the part in errors. Polls
/// @p context for cancellation while the slicer runs (the child is then killed).
/// @throw Error(ProcessingFailed) when the slicer is missing, fails (with its last message) or
///   prints no estimate; Error(Cancelled); Error(WriteFailed) when the scratch files cannot be written.
PrintEstimate sliceWithPrusaSlicer(const TriMesh& part, const PrintSettings& settings,
                                   const std::string& label, const SlicerOptions& options = {},
                                   RunContext& context = RunContext::silent());

/// Seconds from PrusaSlicer's time format ("1d 2h 3m 4s", "3m 4s", "59s"); negative when malformed.
double parseSlicerDuration(const std::string& text);

/// Millimetres of filament PrusaSlicer's G-code @p in extrudes as support (the moves after
/// ";TYPE:Support material" and ";TYPE:Support material interface"), with absolute (M82, G92 E
/// resets) or relative (M83) extrusion. Reads line by line.
double supportFilamentMm(std::istream& in);

}  // namespace zomefab::report
