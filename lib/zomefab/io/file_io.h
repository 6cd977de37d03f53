// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Whole-file input and crash-safe output. "-" means stdin / stdout everywhere.
#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <utility>
#include <vector>

namespace zomefab {

/// Reads all bytes of @p path ("-" = stdin).
/// @throw Error(InvalidInput) naming the file when it does not exist, is a directory or unreadable.
std::string readInputBytes(const std::string& path);

/// Writes @p path through @p write, first into a temporary sibling, then renamed into place, so a
/// failure never leaves a partial file. "-" writes to stdout directly (binary-safe).
/// @throw Error(WriteFailed) naming the file; whatever @p write throws is rethrown after cleanup.
void writeOutputAtomic(const std::string& path, const std::function<void(std::ostream&)>& write);

/// Several output files written as one (a tool's main output, its --report, its --colored-ply):
/// add() writes each into a temporary sibling, commit() renames them all into place. Without
/// commit() (an error, Ctrl-C) the temporaries are removed and no existing file was touched, so a
/// run that fails leaves none of its outputs. "-" writes stdout at once.
class StagedFiles {
public:
    StagedFiles() = default;
    ~StagedFiles();
    StagedFiles(const StagedFiles&) = delete;
    StagedFiles& operator=(const StagedFiles&) = delete;

    /// Writes @p path's bytes through @p write into its temporary. @throw Error(WriteFailed) naming
    /// the file (checkOutputPath's refusals included); whatever @p write throws is rethrown.
    void add(const std::string& path, const std::function<void(std::ostream&)>& write);
    /// Renames every temporary into place. @throw Error(WriteFailed)
    void commit();

private:
    std::vector<std::pair<std::string, std::string>> mStaged;  ///< temporary, target
};

/// What writeOutputAtomic would refuse, checked before any work: @p path is a directory, its
/// directory does not exist or is not writable, or it exists and is not a regular file (a device,
/// FIFO, socket or symbolic link is never replaced). "-" passes. @throw Error(WriteFailed) naming it.
void checkOutputPath(const std::string& path);

/// What StagedDirectory would refuse, checked before any work: an empty name, a parent directory
/// that does not exist or is not writable, a target that exists and is not a directory. Returns the
/// target without trailing slashes. @throw Error(WriteFailed) naming it.
std::string checkOutputDirectory(const std::string& target);

/// The file every output directory zomefab writes carries: one name per line of what it wrote.
inline constexpr const char* kOutputManifestFile = ".zomefab-output";

/// An output directory built in a temporary sibling and moved into place by commit(), so a run that
/// fails (or is interrupted) leaves no half-written directory. Without commit() the staging
/// directory is removed. commit() writes kOutputManifestFile, the list of what it holds, and
/// replaces an existing target only when it is empty or holds nothing but what its own manifest
/// lists (a previous zomefab output); anything else is refused, never deleted. Staging
/// directories left by a killed run (".NAME.tmpPID" whose process is gone) are removed.
class StagedDirectory {
public:
    /// @throw Error(WriteFailed) when the parent directory does not exist or is not writable.
    explicit StagedDirectory(const std::string& target);
    ~StagedDirectory();
    StagedDirectory(const StagedDirectory&) = delete;
    StagedDirectory& operator=(const StagedDirectory&) = delete;

    /// Where to write now (the staging directory).
    const std::string& path() const { return mStaging; }
    /// path()/@p name
    std::string file(const std::string& name) const { return mStaging + "/" + name; }
    /// Moves the staging directory to the target. @throw Error(WriteFailed)
    void commit();
    /// Moves it to @p target instead (a sibling of the target: the same rules for what it may
    /// replace), e.g. OUT.failed for an output that failed its checks. @throw Error(WriteFailed)
    void commitAs(const std::string& target);

private:
    std::string mTarget;
    std::string mStaging;
    bool mCommitted = false;
};

/// Lower-case extension of @p path without the dot ("mesh.STL" -> "stl"), empty when none.
std::string fileExtension(const std::string& path);

}  // namespace zomefab
