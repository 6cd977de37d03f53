// SPDX-License-Identifier: GPL-3.0-or-later
/// @file zomefab: the whole pipeline in one process (`zomefab run`), docs/cli.md and README.md.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <iostream>
#include <set>
#include <sstream>
#include <thread>

#include "common/cli.h"
#include "common/stage_options.h"
#include "zomefab/core/error.h"
#include "zomefab/core/format.h"
#include "zomefab/core/version.h"
#include "zomefab/io/file_io.h"
#include "zomefab/io/mesh_io.h"
#include "zomefab/pipeline/pipeline.h"
#include "zomefab/zome/parts.h"

using namespace zomefab;
namespace fs = std::filesystem;
using nlohmann::json;

extern char** environ;

namespace {

/// Runs this executable again with @p args (no shell), stdin closed, stderr shared; returns its
/// exit code (128 + signal when it was killed). @throw Error(ProcessingFailed) if it cannot start.
int runSelf(const std::vector<std::string>& args) {
    std::vector<std::string> argv{"/proc/self/exe"};
    argv.insert(argv.end(), args.begin(), args.end());
    std::vector<char*> cargs;
    for (std::string& a : argv) cargs.push_back(a.data());
    cargs.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    pid_t pid = 0;
    const int rc = posix_spawn(&pid, "/proc/self/exe", &actions, nullptr, cargs.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) throw Error(ErrorCode::ProcessingFailed, std::string("cannot start a worker: ") + std::strerror(rc));
    int status = 0;
    while (waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) throw Error(ErrorCode::ProcessingFailed, "lost a worker process");
    }
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

json readJsonFile(const std::string& path) {
    json j = json::parse(readInputBytes(path), nullptr, false);
    if (j.is_discarded()) throw Error(ErrorCode::InvalidInput, "invalid JSON", path);
    return j;
}

struct RunCommand {
    std::string input, outDir, inFormat, printer = "200x200x200", salientFile, slicer = "estimator";
    std::vector<std::string> salientSpheres;
    cli::ScaleCli scale;
    pipeline::RunOptions options;

    void addTo(cli::Tool& tool, CLI::App& run) {
        run.add_option("mesh", input, "Closed mesh (.stl .obj .ply .gltf .glb); - reads stdin")->required();
        run.add_option("-o,--output", outDir, "Output directory (created; a previous zomefab output is replaced)")
            ->required();
        scale.addTo(run);
        tool.addFormatOption("--in-format", inFormat, {"stl", "obj", "ply", "gltf", "glb"}, "Input format (for -)");
        run.add_flag("--repair", options.validate.repair, "Close small holes of an open mesh");
        run.add_option("--voxel-mm", options.field.voxelMm,
                       formatNumbers("Voxel of the object and shell level sets (at most %.2f for the tenon pegs)",
                                     pieces::maxVoxelForPegsMm(options.pieces.tenons)))
            ->capture_default_str();
        run.add_option("--shell-mm", options.shell.shellMm, "Shell wall thickness (paper: dMin = 16 mm)")
            ->capture_default_str();
        run.add_option("--chains", options.frame.chains, "Annealing chains run in parallel; the best is kept")
            ->capture_default_str()
            ->check(CLI::Range(1, 4096));
        run.add_option("--iterations", options.frame.anneal.maxIterations,
                       "Annealing iterations per chain (0 = until T < T_end)")
            ->capture_default_str();
        run.add_option("--printer-mm", printer, "Printer build volume WxDxH in mm")->capture_default_str();
        run.add_option("--salient", salientSpheres,
                       "Keep the surface within a sphere whole: x,y,z,r in the scaled object's mm (repeatable)");
        run.add_option("--salient-faces", salientFile, "JSON list of salient face indices of the input mesh");
        report::CostOptions& cost = options.cost;
        run.add_option("--slicer", slicer,
                       "Print times and filament from: estimator (built in) or prusa-slicer (runs it on every part)")
            ->capture_default_str()
            ->check(CLI::IsMember({"estimator", "prusa-slicer"}));
        run.add_option("--filament-mm", cost.filament.diameterMm, "Filament diameter")->capture_default_str();
        run.add_option("--filament-g-per-cm3", cost.filament.densityGPerCm3, "Filament density")->capture_default_str();
        run.add_option("--filament-usd-per-m", cost.filament.usdPerM, "Filament price per metre")->capture_default_str();
        run.add_option("--strut-usd", cost.prices.strutUsd, "Price of one Zometool strut")->capture_default_str();
        run.add_option("--ball-usd", cost.prices.ballUsd, "Price of one Zometool ball")->capture_default_str();
    }

    int execute(cli::Tool& tool, nlohmann::json& report) {
        options.scale = scale.resolve();
        options.partition.printerMm = cli::parsePrinterMm(printer);
        for (const std::string& s : salientSpheres) options.partition.salientSpheres.push_back(cli::parseSalientSphere(s));
        options.frame.seed = tool.common().seed;
        if (slicer == "prusa-slicer") options.cost.source = report::EstimateSource::PrusaSlicer;
        pipeline::checkRunOptions(options);

        MeshReadOptions readOptions;
        if (!inFormat.empty()) readOptions.format = meshFormatFromName(inFormat);
        const TriMesh mesh = readMesh(input, readOptions);
        if (!salientFile.empty())
            options.partition.salientFaceIndices = cli::readSalientFaceList(salientFile, mesh.triangleCount());

        RunContext& context = tool.context();
        const pipeline::RunResult result = pipeline::runPipeline(mesh, input, options, context);
        report = pipeline::runReportJson(result, options, context);
        const std::vector<std::string> files = pipeline::writeRunOutputs(result, options, report, outDir);

        for (const std::string& line : pipeline::runSummaryLines(result)) cli::printInfo(tool, line);
        cli::printInfo(tool, "done in " + std::to_string(int(result.totalSeconds + 0.5)) + " s");
        std::string list;
        for (const std::string& f : files) list += (list.empty() ? "" : ", ") + f;
        cli::printInfo(tool, "wrote " + outDir + ": " + list);
        return 0;
    }
};

/// One entry of a batch manifest (docs/batch.md): a mesh, a name for its output directory, and the
/// `zomefab run` options as {"height-mm": 400, "up": "y", "salient": ["0,0,300,40"], "repair": true}.
struct BatchEntry {
    std::string name;
    std::string mesh;
    std::vector<std::string> runArgs;
};

std::vector<BatchEntry> readManifest(const std::string& path) {
    const json manifest = readJsonFile(path);
    auto fail = [&](const std::string& what) { throw Error(ErrorCode::InvalidInput, what, path); };
    if (!manifest.is_object() || manifest.value("format", "") != "zomefab.batch")
        fail("not a batch manifest (expected \"format\": \"zomefab.batch\")");
    if (manifest.value("version", 0) != 1) fail("unsupported manifest version (expected 1)");
    const json defaults = manifest.value("defaults", json::object());
    if (!defaults.is_object()) fail("\"defaults\" must be an object of run options");
    if (!manifest.contains("entries") || !manifest["entries"].is_array() || manifest["entries"].empty())
        fail("\"entries\" must be a non-empty list");
    const fs::path base = fs::path(path).parent_path();
    std::vector<BatchEntry> entries;
    std::set<std::string> names;
    for (size_t i = 0; i < manifest["entries"].size(); ++i) {
        const json& e = manifest["entries"][i];
        const std::string where = "entry " + std::to_string(i);
        if (!e.is_object() || !e.contains("mesh") || !e["mesh"].is_string()) fail(where + ": needs \"mesh\"");
        BatchEntry entry;
        const fs::path mesh(e["mesh"].get<std::string>());
        entry.mesh = (mesh.is_absolute() || base.empty()) ? mesh.string() : (base / mesh).string();
        entry.name = e.value("name", mesh.stem().string());
        if (entry.name.empty() || entry.name.find('/') != std::string::npos || entry.name[0] == '.')
            fail(where + ": \"name\" must be a plain directory name");
        if (!names.insert(entry.name).second) fail(where + ": duplicate name \"" + entry.name + "\"");
        json options = defaults;
        if (e.contains("options")) {
            if (!e["options"].is_object()) fail(where + ": \"options\" must be an object");
            options.update(e["options"]);
        }
        for (const auto& [key, value] : options.items()) {
            const std::string flag = "--" + key;
            if (value.is_boolean()) {
                if (value.get<bool>()) entry.runArgs.push_back(flag);
            } else if (value.is_array()) {
                for (const json& v : value) entry.runArgs.insert(entry.runArgs.end(), {flag, v.is_string() ? v.get<std::string>() : v.dump()});
            } else if (value.is_string() || value.is_number()) {
                entry.runArgs.insert(entry.runArgs.end(), {flag, value.is_string() ? value.get<std::string>() : value.dump()});
            } else {
                fail(where + ": option \"" + key + "\" must be a string, number, boolean or list");
            }
        }
        entries.push_back(std::move(entry));
    }
    return entries;
}

/// The summary row of one entry, from its run's report.json (or the failure).
json entrySummary(const BatchEntry& entry, int exitCode, double seconds, const std::string& outDir) {
    json row{{"name", entry.name}, {"mesh", entry.mesh}, {"exit_code", exitCode}, {"seconds", seconds}};
    row["status"] = exitCode == 0 ? "ok" : "failed";
    const std::string reportPath = outDir + "/" + entry.name + "/report.json";
    if (exitCode == 0 && fs::exists(reportPath)) {
        const json report = readJsonFile(reportPath);
        row["peak_rss_bytes"] = report.value("peak_rss_bytes", 0);
        row["balls"] = report["frame"].value("balls", 0);
        row["struts"] = report["frame"].value("struts", 0);
        row["pieces"] = report["partition"].value("pieces", 0);
        if (report.contains("cost") && report["cost"].contains("material_saved_hollow_percent"))
            row["material_saved_percent"] = report["cost"]["material_saved_hollow_percent"];
    }
    return row;
}

std::string summaryTable(const json& rows) {
    std::ostringstream out;
    out << "| input | status | seconds | peak MB | balls | struts | pieces | material saved |\n"
        << "|---|---|---:|---:|---:|---:|---:|---:|\n";
    for (const json& r : rows) {
        char line[512];
        const std::string saved = r.contains("material_saved_percent")
                                      ? std::to_string(int(r["material_saved_percent"].get<double>() + 0.5)) + "%"
                                      : "–";
        std::snprintf(line, sizeof line, "| %s | %s | %.1f | %.0f | %d | %d | %d | %s |\n",
                      r["name"].get<std::string>().c_str(), r["status"].get<std::string>().c_str(),
                      r["seconds"].get<double>(), r.value("peak_rss_bytes", 0.0) / 1048576.0, r.value("balls", 0),
                      r.value("struts", 0), r.value("pieces", 0), saved.c_str());
        out << line;
    }
    return out.str();
}

struct BatchCommand {
    std::string manifest, outDir;
    int index = -1;
    bool merge = false;

    void addTo(CLI::App& batch) {
        batch.add_option("manifest", manifest, "Batch manifest (docs/batch.md)")->required();
        batch.add_option("-o,--output", outDir, "Directory for one output directory per entry and the summary")
            ->required();
        batch.add_option("--index", index, "Run entry I alone (for Slurm job arrays or GNU parallel)")
            ->check(CLI::NonNegativeNumber);
        batch.add_flag("--merge", merge, "Only join the per-entry summaries already in the output directory");
    }

    /// Runs entry @p i in a worker process and writes DIR/<name>.summary.json.
    json runEntry(cli::Tool& tool, const std::vector<BatchEntry>& entries, size_t i) {
        const BatchEntry& entry = entries[i];
        std::vector<std::string> args{"run", entry.mesh, "-o", outDir + "/" + entry.name};
        args.insert(args.end(), entry.runArgs.begin(), entry.runArgs.end());
        args.insert(args.end(), {"--seed", std::to_string(tool.common().seed)});
        if (tool.common().threads > 0) args.insert(args.end(), {"--threads", std::to_string(tool.common().threads)});
        if (tool.common().verbosity < 0) args.push_back("-q");
        cli::printInfo(tool, "[" + std::to_string(i + 1) + "/" + std::to_string(entries.size()) + "] " + entry.name);
        Stopwatch clock;
        const int code = runSelf(args);
        const json row = entrySummary(entry, code, clock.seconds(), outDir);
        writeOutputAtomic(outDir + "/" + entry.name + ".summary.json",
                          [&](std::ostream& out) { out << row.dump(2) << '\n'; });
        if (code != 0) tool.context().warn(entry.name + ": failed with exit code " + std::to_string(code));
        return row;
    }

    json mergeSummaries(const std::vector<BatchEntry>& entries) {
        json rows = json::array();
        for (const BatchEntry& entry : entries) {
            const std::string path = outDir + "/" + entry.name + ".summary.json";
            if (fs::exists(path)) {
                rows.push_back(readJsonFile(path));
            } else {
                rows.push_back({{"name", entry.name}, {"mesh", entry.mesh}, {"status", "missing"}, {"seconds", 0.0}});
            }
        }
        const json summary{{"format", "zomefab.batch-summary"}, {"version", 1}, {"generator", generatorString()},
                           {"entries", rows}};
        writeOutputAtomic(outDir + "/summary.json", [&](std::ostream& out) { out << summary.dump(2) << '\n'; });
        const std::string table = summaryTable(rows);
        writeOutputAtomic(outDir + "/summary.md", [&](std::ostream& out) { out << table; });
        return summary;
    }

    int execute(cli::Tool& tool, json& report) {
        const std::vector<BatchEntry> entries = readManifest(manifest);
        std::error_code ec;
        fs::create_directories(outDir, ec);
        if (!fs::is_directory(outDir)) throw Error(ErrorCode::WriteFailed, "cannot create the directory", outDir);
        if (index >= 0) {
            if (size_t(index) >= entries.size())
                throw Error(ErrorCode::Usage, "--index " + std::to_string(index) + " is past the last entry (" +
                                                  std::to_string(entries.size() - 1) + ")");
            report = runEntry(tool, entries, size_t(index));
            return report["exit_code"] == 0 ? 0 : 3;
        }
        if (!merge) {
            for (size_t i = 0; i < entries.size(); ++i) {
                tool.context().throwIfCancelled();
                if (runEntry(tool, entries, i)["exit_code"] == 5) throw Error(ErrorCode::Cancelled, "interrupted");
            }
        }
        report = mergeSummaries(entries);
        std::cerr << summaryTable(report["entries"]);
        size_t failed = 0;
        for (const json& r : report["entries"]) failed += r["status"] != "ok";
        cli::printInfo(tool, std::to_string(entries.size() - failed) + " of " + std::to_string(entries.size()) +
                                 " inputs succeeded; summary in " + outDir + "/summary.md");
        return failed == 0 ? 0 : 3;
    }
};

/// `zomefab bench`: the whole pipeline on bundled meshes at several sizes, one worker process per
/// case (so peak memory is per case); per-stage seconds and peak RSS as JSON (docs/benchmarks.md).
struct BenchCommand {
    std::string output = "-";
    std::vector<std::string> meshes{"bunny_cgal_75k.stl"};
    std::vector<double> heightsMm{300, 400, 800};
    std::string up = "y";
    std::string dataDir = "data";
    std::vector<std::string> extra;

    void addTo(CLI::App& bench) {
        bench.add_option("-o,--output", output, "Benchmark JSON (- = stdout)")->capture_default_str();
        bench.add_option("--mesh", meshes, "Meshes under --data-dir to run (repeatable)")->capture_default_str();
        bench.add_option("--height-mm", heightsMm, "Object heights to run each mesh at (repeatable)")
            ->capture_default_str();
        bench.add_option("--up", up, "Up axis of the meshes")->capture_default_str();
        bench.add_option("--data-dir", dataDir, "Where the meshes are")->capture_default_str();
        bench.add_option("--run-arg", extra, "Extra option passed to every `zomefab run` (repeatable)");
    }

    int execute(cli::Tool& tool, json& report) {
        const fs::path scratch = fs::temp_directory_path() / ("zomefab-bench-" + std::to_string(::getpid()));
        fs::create_directories(scratch);
        json cases = json::array();
        int failures = 0;
        for (const std::string& mesh : meshes) {
            for (const double height : heightsMm) {
                char heightText[32];
                std::snprintf(heightText, sizeof heightText, "%g", height);
                const std::string out = (scratch / (fs::path(mesh).stem().string() + "-" + heightText)).string();
                std::vector<std::string> args{"run", (fs::path(dataDir) / mesh).string(), "-o", out, "--up", up,
                                              "--height-mm", heightText, "-q",
                                              "--seed", std::to_string(tool.common().seed)};
                if (tool.common().threads > 0) args.insert(args.end(), {"--threads", std::to_string(tool.common().threads)});
                args.insert(args.end(), extra.begin(), extra.end());
                cli::printInfo(tool, "bench: " + mesh + " at " + heightText + " mm");
                Stopwatch clock;
                const int code = runSelf(args);
                json row{{"mesh", mesh}, {"height_mm", height}, {"exit_code", code}, {"wall_seconds", clock.seconds()}};
                if (code == 0) {
                    const json runReport = readJsonFile(out + "/report.json");
                    for (const char* key : {"timings", "peak_rss_bytes", "level_sets", "frame", "partition", "pieces", "cost"})
                        if (runReport.contains(key)) row[key] = runReport[key];
                } else {
                    ++failures;
                }
                cases.push_back(row);
            }
        }
        std::error_code ec;
        fs::remove_all(scratch, ec);
        report = {{"format", "zomefab.bench"}, {"version", 1}, {"generator", generatorString()},
                  {"threads", tool.common().threads}, {"hardware_concurrency", std::thread::hardware_concurrency()},
                  {"cases", cases}};
        writeOutputAtomic(output, [&](std::ostream& o) { o << report.dump(2) << '\n'; });
        return failures == 0 ? 0 : 3;
    }
};

}  // namespace

int main(int argc, char** argv) {
    cli::Tool tool("zomefab", "Turn a closed mesh into a Zometool frame and printable shell pieces.");
    CLI::App& app = tool.app();
    app.require_subcommand(1);
    RunCommand runCommand;
    CLI::App* run = app.add_subcommand("run", "Run every stage on one mesh and write the outputs into a directory");
    run->fallthrough();
    runCommand.addTo(tool, *run);

    BatchCommand batchCommand;
    CLI::App* batch = app.add_subcommand("batch", "Run many inputs from a manifest, one worker process each");
    batch->fallthrough();
    batchCommand.addTo(*batch);

    BenchCommand benchCommand;
    CLI::App* bench = app.add_subcommand("bench", "Time every stage on bundled meshes at several sizes; JSON out");
    bench->fallthrough();
    benchCommand.addTo(*bench);

    return tool.run(argc, argv, [&](nlohmann::json& report) {
        if (bench->parsed()) return benchCommand.execute(tool, report);
        if (run->parsed()) return runCommand.execute(tool, report);
        if (batch->parsed()) return batchCommand.execute(tool, report);
        throw Error(ErrorCode::Usage, "no command given (see --help)");
    });
}
