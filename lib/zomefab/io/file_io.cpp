// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/io/file_io.h"

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <iterator>
#include <sstream>

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

void writeOutputAtomic(const std::string& path, const std::function<void(std::ostream&)>& write) {
    if (path == "-") {
        write(std::cout);
        std::cout.flush();
        if (!std::cout) throw Error(ErrorCode::WriteFailed, "cannot write to stdout", "-");
        return;
    }
    const fs::path target(path);
    std::error_code ec;
    if (fs::is_directory(target, ec)) throw Error(ErrorCode::WriteFailed, "is a directory, not a file", path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
        throw Error(ErrorCode::WriteFailed, "directory does not exist: " + dir.string(), path);
    const fs::path temp = dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
    try {
        {
            std::ofstream out(temp, std::ios::binary | std::ios::trunc);
            if (!out)
                throw Error(ErrorCode::WriteFailed, std::string("cannot create: ") + std::strerror(errno),
                            path);
            write(out);
            out.flush();
            if (!out) throw Error(ErrorCode::WriteFailed, "write failed (disk full?)", path);
        }
        fs::rename(temp, target, ec);
        if (ec) throw Error(ErrorCode::WriteFailed, "cannot rename into place: " + ec.message(), path);
    } catch (...) {
        fs::remove(temp, ec);
        throw;
    }
}

StagedDirectory::StagedDirectory(const std::string& target, const std::string& markerFile)
    : mTarget(target), mMarker(markerFile) {
    fs::path t(target);
    while (!t.empty() && t.filename().empty()) t = t.parent_path();  // "out/" -> "out"
    if (t.empty()) throw Error(ErrorCode::WriteFailed, "empty output directory name", target);
    mTarget = t.string();
    const fs::path parent = t.has_parent_path() ? t.parent_path() : fs::path(".");
    std::error_code ec;
    if (!fs::is_directory(parent, ec))
        throw Error(ErrorCode::WriteFailed, "parent directory does not exist: " + parent.string(), target);
    if (fs::exists(t, ec) && !fs::is_directory(t, ec))
        throw Error(ErrorCode::WriteFailed, "exists and is not a directory", target);
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
    if (fs::exists(target, ec)) {
        const bool isEmpty = fs::is_empty(target, ec);
        if (!isEmpty && !fs::exists(target / mMarker, ec))
            throw Error(ErrorCode::WriteFailed,
                        "exists and is not an output of this tool (no " + mMarker + "); not replacing it",
                        mTarget);
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
