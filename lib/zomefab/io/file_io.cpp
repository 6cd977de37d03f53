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
    if (fs::is_directory(status))
        throw Error(ErrorCode::InvalidInput, "is a directory, not a file", path);
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
    if (fs::is_directory(target, ec))
        throw Error(ErrorCode::WriteFailed, "is a directory, not a file", path);
    const fs::path dir = target.has_parent_path() ? target.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
        throw Error(ErrorCode::WriteFailed, "directory does not exist: " + dir.string(), path);
    const fs::path temp = dir / ("." + target.filename().string() + ".tmp" + std::to_string(::getpid()));
    try {
        {
            std::ofstream out(temp, std::ios::binary | std::ios::trunc);
            if (!out) throw Error(ErrorCode::WriteFailed, std::string("cannot create: ") + std::strerror(errno), path);
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

std::string fileExtension(const std::string& path) {
    std::string ext = fs::path(path).extension().string();
    if (!ext.empty() && ext[0] == '.') ext.erase(0, 1);
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    return ext;
}

}  // namespace zomefab
