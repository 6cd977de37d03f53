// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Shared helpers for the unit tests: data paths, scratch directories, small fixtures.
#pragma once

#include <doctest/doctest.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "zomefab/core/error.h"
#include "zomefab/core/tri_mesh.h"

namespace zomefab::test {

/// Absolute path of a file in the repository's data/ directory.
std::string dataPath(const std::string& name);

/// Absolute path of a built tool (build/tools/<name>).
std::string toolPath(const std::string& name);

/// A fresh empty directory under the system temp dir, removed when the object dies.
class ScratchDir {
public:
    explicit ScratchDir(const std::string& tag = "zomefab-test");
    ~ScratchDir();
    ScratchDir(const ScratchDir&) = delete;
    ScratchDir& operator=(const ScratchDir&) = delete;
    const std::filesystem::path& path() const { return mPath; }
    std::string file(const std::string& name) const { return (mPath / name).string(); }

private:
    std::filesystem::path mPath;
};

/// Runs @p command with `bash -o pipefail -c`; its exit code (−1 when it did not exit normally).
int runShell(const std::string& command);

/// Runs @p command through the shell (popen); its exit code (−1 when it did not exit normally),
/// with its stdout in @p out when given (add `2>&1` to the command for stderr too).
int runCapture(const std::string& command, std::string* out = nullptr);

/// What runMeasured saw of one process.
struct MeasuredRun {
    int exitCode = -1;       ///< -1 when it did not exit normally (a signal)
    int signal = 0;          ///< the signal that ended it, 0 when it exited
    long peakRssKb = 0;      ///< its maximum resident set (wait4's ru_maxrss)
    std::string stderrText;  ///< what it wrote to stderr
};

/// Runs @p argv (argv[0] a path, no shell) with stdout discarded, and reports its exit, its peak
/// memory and its stderr.
MeasuredRun runMeasured(const std::vector<std::string>& argv);

/// @p name is a command on PATH.
bool hasCommand(const std::string& name);

/// The whole file @p path as bytes (empty when it cannot be read).
std::string readFile(const std::string& path);

/// Writes @p bytes to @p path (test fixtures only).
void writeBytes(const std::string& path, const std::string& bytes);

/// The code of the zomefab::Error that @p f throws (a failed check when it throws none).
inline ErrorCode errorCodeOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.code();
    }
    FAIL("no zomefab::Error thrown");
    return ErrorCode::Internal;
}

/// An axis-aligned box [min, max] as 12 outward triangles on 8 shared vertices.
TriMesh makeBox(const Vec3d& min, const Vec3d& max);
/// Pointers to each of @p meshes (what costReport and PreviewInput take).
inline std::vector<const TriMesh*> pointersTo(const std::vector<TriMesh>& meshes) {
    std::vector<const TriMesh*> out;
    for (const TriMesh& m : meshes) out.push_back(&m);
    return out;
}
/// A closed, outward UV sphere (rings × segments quads split into triangles, poles fanned).
TriMesh makeSphere(const Vec3d& center, double radius, int rings = 32, int segments = 64);

}  // namespace zomefab::test
