// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/batch/batch.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <thread>

#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/process.h"
#include "zomefab/core/version.h"
#include "zomefab/io/file_io.h"
#include "zomefab/report/run_report.h"

namespace zomefab::batch {

using nlohmann::json;
namespace fs = std::filesystem;

namespace {

json readJsonFile(const std::string& path) {
    json j = json::parse(readInputBytes(path), nullptr, false);
    if (j.is_discarded()) throw Error(ErrorCode::InvalidInput, "invalid JSON", path);
    return j;
}

/// The `zomefab run` arguments of one entry's merged options.
std::vector<std::string> runArguments(const json& options, const std::string& where,
                                      const std::string& path) {
    std::vector<std::string> args;
    for (const auto& [key, value] : options.items()) {
        const std::string flag = "--" + key;
        if (value.is_boolean()) {
            if (value.get<bool>()) args.push_back(flag);
        } else if (value.is_array()) {
            for (const json& v : value)
                args.insert(args.end(), {flag, v.is_string() ? v.get<std::string>() : v.dump()});
        } else if (value.is_string() || value.is_number()) {
            args.insert(args.end(), {flag, value.is_string() ? value.get<std::string>() : value.dump()});
        } else {
            throw Error(ErrorCode::InvalidInput,
                        where + ": option \"" + key + "\" must be a string, number, boolean or list", path);
        }
    }
    return args;
}

BatchEntry readEntry(const json& e, size_t index, const json& defaults, const fs::path& base,
                     const std::string& path) {
    const std::string where = "entry " + std::to_string(index);
    auto fail = [&](const std::string& what) {
        throw Error(ErrorCode::InvalidInput, where + ": " + what, path);
    };
    if (!e.is_object() || !e.contains("mesh") || !e["mesh"].is_string()) fail("needs \"mesh\"");
    BatchEntry entry;
    const fs::path mesh(e["mesh"].get<std::string>());
    entry.mesh = (mesh.is_absolute() || base.empty()) ? mesh.string() : (base / mesh).string();
    entry.name = e.value("name", mesh.stem().string());
    if (entry.name.empty() || entry.name.find('/') != std::string::npos || entry.name[0] == '.')
        fail("\"name\" must be a plain directory name");
    json options = defaults;
    if (e.contains("options")) {
        if (!e["options"].is_object()) fail("\"options\" must be an object");
        options.update(e["options"]);
    }
    entry.runArgs = runArguments(options, where, path);
    return entry;
}

/// The summary row of one entry, from its run's report.json (or the failure).
json entrySummary(const BatchEntry& entry, int exitCode, double seconds, const std::string& outDir) {
    json row{{"name", entry.name}, {"mesh", entry.mesh}, {"exit_code", exitCode}, {"seconds", seconds}};
    row["status"] = exitCode == 0 ? "ok" : "failed";
    const std::string reportPath = outDir + "/" + entry.name + "/report.json";
    if (exitCode == 0 && fs::exists(reportPath)) {
        const report::RunSummary s = report::runSummaryFromJson(readJsonFile(reportPath));
        row["peak_rss_bytes"] = s.peakRssBytes;
        row["balls"] = s.balls;
        row["struts"] = s.struts;
        row["pieces"] = s.pieces;
        if (s.hasMaterialSaved) row["material_saved_percent"] = s.materialSavedPercent;
    }
    return row;
}

}  // namespace

std::vector<BatchEntry> readManifest(const std::string& path) {
    return parseManifest(readInputBytes(path), path);
}

namespace {

std::vector<BatchEntry> manifestFromJson(const json& manifest, const std::string& path) {
    auto fail = [&](const std::string& what) { throw Error(ErrorCode::InvalidInput, what, path); };
    if (!manifest.is_object() || manifest.value("format", "") != kManifestFormatName)
        fail("not a batch manifest (expected \"format\": \"zomefab.batch\")");
    if (!manifest.contains("version") || manifest["version"] != 1)
        fail("unsupported manifest version (expected 1)");
    const json defaults = manifest.contains("defaults") ? manifest["defaults"] : json::object();
    if (!defaults.is_object()) fail("\"defaults\" must be an object of run options");
    if (!manifest.contains("entries") || !manifest["entries"].is_array() || manifest["entries"].empty())
        fail("\"entries\" must be a non-empty list");
    const fs::path base = fs::path(path).parent_path();
    std::vector<BatchEntry> entries;
    std::set<std::string> names;
    for (size_t i = 0; i < manifest["entries"].size(); ++i) {
        entries.push_back(readEntry(manifest["entries"][i], i, defaults, base, path));
        if (!names.insert(entries.back().name).second)
            fail("entry " + std::to_string(i) + ": duplicate name \"" + entries.back().name + "\"");
    }
    return entries;
}

}  // namespace

std::vector<BatchEntry> parseManifest(std::string_view bytes, const std::string& path) {
    const json manifest = json::parse(bytes, nullptr, false);
    if (manifest.is_discarded()) throw Error(ErrorCode::InvalidInput, "invalid JSON", path);
    try {
        return manifestFromJson(manifest, path);
    } catch (const json::exception& e) {
        // A member of the wrong type ("format": 5, found by fuzz_manifest).
        throw Error(ErrorCode::InvalidInput, std::string("malformed manifest: ") + e.what(), path);
    }
}

json runEntry(const WorkerCommand& command, const std::vector<BatchEntry>& entries, size_t index,
              const std::string& outDir, RunContext& context) {
    const BatchEntry& entry = entries[index];
    std::vector<std::string> args{command.executable, "run", entry.mesh, "-o", outDir + "/" + entry.name};
    args.insert(args.end(), entry.runArgs.begin(), entry.runArgs.end());
    args.insert(args.end(), command.sharedArgs.begin(), command.sharedArgs.end());
    context.info("[" + std::to_string(index + 1) + "/" + std::to_string(entries.size()) + "] " + entry.name);
    Stopwatch clock;
    ProcessOptions process;
    process.searchPath = false;
    process.context = &context;
    const int code = runProcess(args, process);
    const json row = entrySummary(entry, code, clock.seconds(), outDir);
    writeOutputAtomic(outDir + "/" + entry.name + ".summary.json",
                      [&](std::ostream& out) { out << row.dump(2) << '\n'; });
    if (code != 0) context.warn(entry.name + ": failed with exit code " + std::to_string(code));
    return row;
}

std::string summaryTable(const json& rows) {
    std::ostringstream out;
    out << "| input | status | seconds | peak MB | balls | struts | pieces | material saved |\n"
        << "|---|---|---:|---:|---:|---:|---:|---:|\n";
    for (const json& r : rows) {
        const std::string saved =
            r.contains("material_saved_percent")
                ? std::to_string(int(r["material_saved_percent"].get<double>() + 0.5)) + "%"
                : "–";
        out << "| " << r["name"].get<std::string>() << " | " << r["status"].get<std::string>() << " | "
            << formatNumbers("%.1f", r["seconds"].get<double>()) << " | "
            << formatNumbers("%.0f", r.value("peak_rss_bytes", 0.0) / 1048576.0) << " | "
            << r.value("balls", 0) << " | " << r.value("struts", 0) << " | " << r.value("pieces", 0) << " | "
            << saved << " |\n";
    }
    return out.str();
}

json mergeSummaries(const std::vector<BatchEntry>& entries, const std::string& outDir) {
    json rows = json::array();
    for (const BatchEntry& entry : entries) {
        const std::string path = outDir + "/" + entry.name + ".summary.json";
        if (fs::exists(path))
            rows.push_back(readJsonFile(path));
        else
            rows.push_back(
                {{"name", entry.name}, {"mesh", entry.mesh}, {"status", "missing"}, {"seconds", 0.0}});
    }
    const json summary{
        {"format", kSummaryFormatName}, {"version", 1}, {"generator", generatorString()}, {"entries", rows}};
    writeOutputAtomic(outDir + "/summary.json", [&](std::ostream& out) { out << summary.dump(2) << '\n'; });
    const std::string table = summaryTable(rows);
    writeOutputAtomic(outDir + "/summary.md", [&](std::ostream& out) { out << table; });
    return summary;
}

json runBench(const WorkerCommand& command, const BenchOptions& options, RunContext& context) {
    const fs::path scratch = fs::temp_directory_path() / ("zomefab-bench-" + std::to_string(::getpid()));
    fs::create_directories(scratch);
    json cases = json::array();
    for (const std::string& mesh : options.meshes) {
        for (const double height : options.heightsMm) {
            const std::string heightText = formatNumber(height);
            const std::string out = (scratch / (fs::path(mesh).stem().string() + "-" + heightText)).string();
            std::vector<std::string> args{command.executable,
                                          "run",
                                          (fs::path(options.dataDir) / mesh).string(),
                                          "-o",
                                          out,
                                          "--up",
                                          options.up,
                                          "--height-mm",
                                          heightText,
                                          "-q"};
            args.insert(args.end(), command.sharedArgs.begin(), command.sharedArgs.end());
            args.insert(args.end(), options.extraArgs.begin(), options.extraArgs.end());
            context.info("bench: " + mesh + " at " + heightText + " mm");
            Stopwatch clock;
            ProcessOptions process;
            process.searchPath = false;
            process.context = &context;
            const int code = runProcess(args, process);
            json row{{"mesh", mesh},
                     {"height_mm", height},
                     {"exit_code", code},
                     {"wall_seconds", clock.seconds()}};
            if (code == 0) {
                const json runReport = readJsonFile(out + "/report.json");
                for (const char* key :
                     {"timings", "peak_rss_bytes", "level_sets", "frame", "partition", "pieces", "cost"})
                    if (runReport.contains(key)) row[key] = runReport[key];
            }
            cases.push_back(row);
        }
    }
    std::error_code ec;
    fs::remove_all(scratch, ec);
    return {{"format", "zomefab.bench"},
            {"version", 1},
            {"generator", generatorString()},
            {"hardware_concurrency", std::thread::hardware_concurrency()},
            {"cases", cases}};
}

}  // namespace zomefab::batch
