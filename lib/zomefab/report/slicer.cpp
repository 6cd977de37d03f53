// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/report/slicer.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/process.h"
#include "zomefab/io/mesh_io.h"

namespace zomefab::report {

namespace fs = std::filesystem;

namespace {

/// The filament diameter the slicer is told (mm): the paper's 2.85 mm PLA. Only the volumes
/// PrusaSlicer reports are used, so it sets no cost; it converts the support's length to mm³.
constexpr double kSlicerFilamentMm = 2.85;

/// Removes the scratch directory however the slicing ends.
struct ScratchDir {
    fs::path path;
    ~ScratchDir() {
        std::error_code ec;
        if (!path.empty()) fs::remove_all(path, ec);
    }
};

std::string lastLine(const fs::path& log) {
    std::ifstream in(log);
    std::string line, last;
    while (std::getline(in, line)) {
        while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
        if (!line.empty()) last = line;
    }
    return last.empty() ? "no message" : last;
}

/// The value after "= " of the last line starting with @p prefix in @p text, or empty.
std::string commentValue(const std::string& text, const std::string& prefix) {
    size_t at = std::string::npos, from = 0;
    while ((from = text.find(prefix, from)) != std::string::npos) {
        if (from == 0 || text[from - 1] == '\n') at = from;
        from += prefix.size();
    }
    if (at == std::string::npos) return {};
    const size_t eq = text.find("= ", at);
    const size_t end = text.find('\n', at);
    if (eq == std::string::npos || (end != std::string::npos && eq > end)) return {};
    return text.substr(eq + 2, end == std::string::npos ? std::string::npos : end - eq - 2);
}

}  // namespace

bool isSlicerAvailable(const std::string& executable) {
    if (executable.empty()) return false;
    if (executable.find('/') != std::string::npos) return ::access(executable.c_str(), X_OK) == 0;
    const char* path = std::getenv("PATH");
    if (!path) return false;
    std::stringstream dirs(path);
    std::string dir;
    while (std::getline(dirs, dir, ':')) {
        if (dir.empty()) dir = ".";
        const std::string candidate = dir + "/" + executable;
        struct stat st {};
        if (::stat(candidate.c_str(), &st) == 0 && S_ISREG(st.st_mode) &&
            ::access(candidate.c_str(), X_OK) == 0)
            return true;
    }
    return false;
}

std::vector<std::string> prusaSlicerArguments(const PrintSettings& s, double bedMm) {
    const std::string bed = formatNumber(bedMm, 10);
    // PrusaSlicer refuses the "triangles" pattern at 100 % ("not supposed to work at 100%
    // density"); its solid infill is rectilinear.
    const bool isSolid = s.infillPercent >= 100.0;
    std::vector<std::string> args = {"--loglevel",
                                     "1",
                                     "--export-gcode",
                                     "--layer-height",
                                     formatNumber(s.layerHeightMm, 10),
                                     "--first-layer-height",
                                     formatNumber(s.firstLayerHeightMm, 10),
                                     "--nozzle-diameter",
                                     formatNumber(s.nozzleMm, 10),
                                     "--filament-diameter",
                                     formatNumber(kSlicerFilamentMm, 10),
                                     "--filament-density",
                                     "1.24",
                                     "--fill-density",
                                     formatNumber(std::min(100.0, s.infillPercent), 10) + "%",
                                     "--fill-pattern",
                                     isSolid ? "rectilinear" : "triangles",
                                     "--perimeters",
                                     std::to_string(s.perimeters),
                                     "--top-solid-layers",
                                     std::to_string(s.topLayers),
                                     "--bottom-solid-layers",
                                     std::to_string(s.bottomLayers),
                                     "--gcode-flavor",
                                     "marlin2",
                                     "--machine-limits-usage",
                                     "time_estimate_only",
                                     "--bed-shape",
                                     "0x0," + bed + "x0," + bed + "x" + bed + ",0x" + bed,
                                     "--max-print-height",
                                     bed};
    if (s.supports) {
        args.insert(args.end(), {"--support-material", "--support-material-auto"});
        if (std::abs(s.overhangDeg - pieces::kOverhangDeg) > 1e-9)
            args.insert(args.end(), {"--support-material-threshold", formatNumber(90.0 - s.overhangDeg, 10)});
    }
    // PrusaSlicer's automatic width is 1.125 × nozzle; anything else is passed explicitly.
    if (std::abs(s.extrusionWidthMm - 1.125 * s.nozzleMm) > 1e-9) {
        args.push_back("--extrusion-width");
        args.push_back(formatNumber(s.extrusionWidthMm, 10));
    }
    return args;
}

double parseSlicerDuration(const std::string& text) {
    std::istringstream in(text);
    std::string token;
    double seconds = 0.0;
    bool any = false;
    while (in >> token) {
        if (token.size() < 2) return -1.0;
        const char unit = token.back();
        const std::string number = token.substr(0, token.size() - 1);
        char* end = nullptr;
        const double v = std::strtod(number.c_str(), &end);
        if (end != number.c_str() + number.size() || !(v >= 0.0)) return -1.0;
        switch (unit) {
            case 'd':
                seconds += v * 86400.0;
                break;
            case 'h':
                seconds += v * 3600.0;
                break;
            case 'm':
                seconds += v * 60.0;
                break;
            case 's':
                seconds += v;
                break;
            default:
                return -1.0;
        }
        any = true;
    }
    return any ? seconds : -1.0;
}

double supportFilamentMm(std::istream& in) {
    double e = 0.0, support = 0.0;
    bool isRelative = false, isSupport = false;
    // The E word of a move or a G92 line; NaN when it has none.
    auto eWord = [](const std::string& line) {
        for (size_t at = line.find(' '); at != std::string::npos; at = line.find(' ', at + 1))
            if (at + 1 < line.size() && line[at + 1] == 'E')
                return std::strtod(line.c_str() + at + 2, nullptr);
        return std::nan("");
    };
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind(";TYPE:", 0) == 0) {
            isSupport = line.rfind(";TYPE:Support material", 0) == 0;
        } else if (line.rfind("M83", 0) == 0) {
            isRelative = true;
        } else if (line.rfind("M82", 0) == 0) {
            isRelative = false;
        } else if (line.rfind("G92", 0) == 0) {
            const double v = eWord(line);
            if (!std::isnan(v)) e = v;
        } else if (line.rfind("G1 ", 0) == 0 || line.rfind("G0 ", 0) == 0) {
            const double v = eWord(line.substr(0, line.find(';')));
            if (std::isnan(v)) continue;
            const double delta = isRelative ? v : v - e;
            if (!isRelative) e = v;
            if (isSupport) support += delta;
        }
    }
    return std::max(0.0, support);
}

PrintEstimate sliceWithPrusaSlicer(const TriMesh& part, const PrintSettings& settings,
                                   const std::string& label, const SlicerOptions& options,
                                   RunContext& context) {
    settings.validate();
    if (!isSlicerAvailable(options.executable))
        throw Error(ErrorCode::ProcessingFailed,
                    "slicer '" + options.executable + "' not found (Debian package prusa-slicer)");
    if (part.triangles.empty()) throw Error(ErrorCode::ProcessingFailed, label + ": nothing to slice");

    std::error_code ec;
    const fs::path parent = options.tempDir.empty() ? fs::temp_directory_path(ec) : fs::path(options.tempDir);
    std::string pattern = (parent / "zomefab-slice-XXXXXX").string();
    if (!::mkdtemp(pattern.data()))
        throw Error(ErrorCode::WriteFailed,
                    std::string("cannot create a scratch directory: ") + std::strerror(errno),
                    parent.string());
    ScratchDir scratch{fs::path(pattern)};
    const fs::path stl = scratch.path / "part.stl", gcode = scratch.path / "part.gcode",
                   log = scratch.path / "slicer.log";
    writeMesh(part, stl.string());

    const Box3d box = boundingBox(part);
    const Vec3d size = box.size();
    const double bedMm = std::max(1000.0, 2.0 * std::max({size[0], size[1], size[2]}));
    std::vector<std::string> args = {options.executable};
    for (std::string& a : prusaSlicerArguments(settings, bedMm)) args.push_back(std::move(a));
    args.insert(args.end(), {"-o", gcode.string(), stl.string()});
    ProcessOptions process;
    process.outputPath = log.string();
    process.context = &context;
    const int exitCode = runProcess(args, process);
    if (exitCode != 0)
        throw Error(ErrorCode::ProcessingFailed,
                    options.executable + " failed on " + label + ": " + lastLine(log));

    // The estimates are comments near the end of the G-code, before the configuration block.
    std::ifstream in(gcode, std::ios::binary | std::ios::ate);
    if (!in) throw Error(ErrorCode::ProcessingFailed, options.executable + " wrote no G-code for " + label);
    const std::streamoff length = in.tellg();
    const std::streamoff tail = std::min<std::streamoff>(length, 1 << 20);
    std::string text(size_t(tail), '\0');
    in.seekg(length - tail);
    in.read(text.data(), tail);

    const double seconds = parseSlicerDuration(commentValue(text, "; estimated printing time (normal mode)"));
    const std::string cm3 = commentValue(text, "; filament used [cm3]");
    char* end = nullptr;
    const double filamentCm3 = std::strtod(cm3.c_str(), &end);
    if (seconds < 0.0 || cm3.empty() || end == cm3.c_str() || !(filamentCm3 >= 0.0))
        throw Error(ErrorCode::ProcessingFailed,
                    options.executable + " printed no time or filament estimate for " + label);
    PrintEstimate e;
    e.seconds = seconds;
    e.filamentMm3 = filamentCm3 * 1000.0;
    e.parts = 1;
    if (settings.supports) {
        std::ifstream all(gcode, std::ios::binary);
        // The filament's section times the length.
        const double area = 0.25 * 3.14159265358979323846 * kSlicerFilamentMm * kSlicerFilamentMm;
        e.supportMm3 = std::min(e.filamentMm3, supportFilamentMm(all) * area);
    }
    return e;
}

}  // namespace zomefab::report
