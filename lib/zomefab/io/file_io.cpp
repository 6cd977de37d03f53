// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/io/file_io.h"

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>
#include <vector>

#include "zomefab/core/error.h"

namespace fs = std::filesystem;

namespace zomefab {

std::string readInputBytes(const std::string& path) {
    if (path == "-") {
        std::ostringstream buffer;
        buffer << std::cin.rdbuf();
        return buffer.str();
    }
    std::error_code ec;
    const fs::file_status status = fs::status(path, ec);
    if (ec || !fs::exists(status)) throw Error(ErrorCode::InvalidInput, "no such file", path);
    if (fs::is_directory(status)) throw Error(ErrorCode::InvalidInput, "is a directory, not a file", path);
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(ErrorCode::InvalidInput, std::string("cannot open: ") + std::strerror(errno), path);
    std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (in.bad()) throw Error(ErrorCode::InvalidInput, "read error", path);
    return bytes;
}

void checkOutputPath(const std::string& path) {
    if (path == "-") return;
    const fs::path target(path);
    std::error_code ec;
    if (fs::is_directory(target, ec)) throw Error(ErrorCode::WriteFailed, "is a directory, not a file", path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
        throw Error(ErrorCode::WriteFailed, "directory does not exist: " + dir.string(), path);
    const fs::file_status status = fs::symlink_status(target, ec);
    if (fs::exists(status) && !fs::is_regular_file(status))
        throw Error(ErrorCode::WriteFailed,
                    "exists and is not a regular file (a device, FIFO, socket or link): it is not replaced",
                    path);
    if (::access(dir.c_str(), W_OK) != 0)
        throw Error(ErrorCode::WriteFailed, "directory is not writable: " + dir.string(), path);
}

StagedFiles::~StagedFiles() {
    std::error_code ec;
    for (const auto& [temp, target] : mStaged) fs::remove(temp, ec);
}

void StagedFiles::add(const std::string& path, const std::function<void(std::ostream&)>& write) {
    if (path == "-") {
        write(std::cout);
        std::cout.flush();
        if (!std::cout) throw Error(ErrorCode::WriteFailed, "cannot write to stdout", "-");
        return;
    }
    checkOutputPath(path);
    const fs::path target(path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    const fs::path temp = dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
    for (const auto& staged : mStaged)
        if (staged.second == path)
            throw Error(ErrorCode::Usage, "the same file is named as two outputs", path);
    mStaged.emplace_back(temp.string(), path);  // removed by the destructor unless committed
    std::ofstream out(temp, std::ios::binary | std::ios::trunc);
    if (!out)
        throw Error(ErrorCode::WriteFailed, std::string("cannot create: ") + std::strerror(errno), path);
    write(out);
    out.flush();
    if (!out) throw Error(ErrorCode::WriteFailed, "write failed (disk full?)", path);
}

void StagedFiles::commit() {
    std::error_code ec;
    for (const auto& [temp, target] : mStaged) {
        fs::rename(temp, target, ec);
        if (ec) throw Error(ErrorCode::WriteFailed, "cannot rename into place: " + ec.message(), target);
    }
    mStaged.clear();
}

void writeOutputAtomic(const std::string& path, const std::function<void(std::ostream&)>& write) {
    StagedFiles files;
    files.add(path, write);
    files.commit();
}

namespace {

/// Removes the staging directories ".NAME.tmpPID" next to @p target whose process has ended (a
/// run killed by a signal it could not catch).
void removeStaleStaging(const fs::path& parent, const std::string& name) {
    const std::string prefix = "." + name + ".tmp";
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(parent, ec)) {
        const std::string n = entry.path().filename().string();
        if (n.compare(0, prefix.size(), prefix) != 0 || n.size() == prefix.size()) continue;
        const std::string digits = n.substr(prefix.size());
        if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; })) continue;
        const long pid = std::strtol(digits.c_str(), nullptr, 10);
        if (pid <= 0 || (::kill(pid_t(pid), 0) == 0 || errno != ESRCH)) continue;  // alive, or not ours
        std::error_code rm;
        fs::remove_all(entry.path(), rm);
    }
}

/// Why @p target may not be replaced, or empty: everything in it must be listed in its manifest.
std::string replaceRefusal(const fs::path& target) {
    std::error_code ec;
    if (fs::is_empty(target, ec)) return {};
    const fs::path manifest = target / kOutputManifestFile;
    std::ifstream in(manifest);
    if (!in) return std::string("is not an output of zomefab (no ") + kOutputManifestFile + ")";
    std::vector<std::string> listed{kOutputManifestFile};
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) listed.push_back(line);
    for (const auto& entry : fs::directory_iterator(target, ec)) {
        const std::string n = entry.path().filename().string();
        if (std::find(listed.begin(), listed.end(), n) == listed.end())
            return "holds " + n + ", which zomefab did not write";
    }
    return {};
}

}  // namespace

std::string checkOutputDirectory(const std::string& target) {
    fs::path t(target);
    while (!t.empty() && t.filename().empty()) t = t.parent_path();  // "out/" -> "out"
    if (t.empty()) throw Error(ErrorCode::WriteFailed, "empty output directory name", target);
    const fs::path parent = t.has_parent_path() ? t.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(parent, ec))
        throw Error(ErrorCode::WriteFailed, "parent directory does not exist: " + parent.string(), target);
    if (fs::exists(t, ec) && !fs::is_directory(t, ec))
        throw Error(ErrorCode::WriteFailed, "exists and is not a directory", target);
    if (::access(parent.c_str(), W_OK) != 0)
        throw Error(ErrorCode::WriteFailed, "parent directory is not writable: " + parent.string(), target);
    return t.string();
}

StagedDirectory::StagedDirectory(const std::string& target) : mTarget(checkOutputDirectory(target)) {
    const fs::path t(mTarget);
    const fs::path parent = t.has_parent_path() ? t.parent_path() : fs::path(".");
    std::error_code ec;
    removeStaleStaging(parent, t.filename().string());
    mStaging = (parent / ("." + t.filename().string() + ".tmp" + std::to_string(::getpid()))).string();
    fs::remove_all(mStaging, ec);
    if (!fs::create_directory(mStaging, ec))
        throw Error(ErrorCode::WriteFailed, "cannot create a staging directory: " + ec.message(), target);
}

StagedDirectory::~StagedDirectory() {
    if (mCommitted) return;
    std::error_code ec;
    fs::remove_all(mStaging, ec);
}

void StagedDirectory::commitAs(const std::string& target) {
    mTarget = target;
    commit();
}

void StagedDirectory::commit() {
    std::error_code ec;
    const fs::path target(mTarget);
    {
        // The manifest: what this output holds, so a later run knows what it may replace.
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(mStaging, ec))
            if (entry.path().filename() != kOutputManifestFile)
                names.push_back(entry.path().filename().string());
        std::sort(names.begin(), names.end());
        std::ofstream out(fs::path(mStaging) / kOutputManifestFile);
        for (const std::string& n : names) out << n << '\n';
        if (!out) throw Error(ErrorCode::WriteFailed, "cannot write the output manifest", mTarget);
    }
    if (fs::is_symlink(target, ec) || (fs::exists(target, ec) && !fs::is_directory(target, ec)))
        throw Error(ErrorCode::WriteFailed, "exists and is not a directory; not replacing it", mTarget);
    if (fs::exists(target, ec)) {
        const std::string refusal = replaceRefusal(target);
        if (!refusal.empty()) throw Error(ErrorCode::WriteFailed, refusal + "; not replacing it", mTarget);
        const fs::path old = target.string() + ".old" + std::to_string(::getpid());
        fs::rename(target, old, ec);
        if (ec)
            throw Error(ErrorCode::WriteFailed, "cannot move the old output aside: " + ec.message(), mTarget);
        fs::rename(mStaging, target, ec);
        if (ec) {
            fs::rename(old, target);  // put the old output back
            throw Error(ErrorCode::WriteFailed, "cannot move the output into place: " + ec.message(),
                        mTarget);
        }
        fs::remove_all(old, ec);
    } else {
        fs::rename(mStaging, target, ec);
        if (ec)
            throw Error(ErrorCode::WriteFailed, "cannot move the output into place: " + ec.message(),
                        mTarget);
    }
    mCommitted = true;
}

std::string fileExtension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

}  // namespace zomefab
