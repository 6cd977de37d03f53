// SPDX-License-Identifier: GPL-3.0-or-later
#include "cli.h"

#include <sys/resource.h>
#include <sys/sysinfo.h>
#include <tbb/global_control.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <memory>
#include <new>

#include "zomefab/core/error.h"
#include "zomefab/core/version.h"
#include "zomefab/io/file_io.h"

namespace zomefab::cli {

namespace {

std::atomic<bool> gInterrupted{false};

/// SIGINT, SIGTERM and SIGHUP all cancel the run: the work stops at the next check, the staging
/// directory and any child process (PrusaSlicer, batch workers) go, and the tool exits 5.
extern "C" void onInterrupt(int signal) {
    gInterrupted.store(true);
    std::signal(signal, SIG_DFL);  // a second one kills at once
}

/// A seed is a decimal integer in [0, 2^64 − 1]: CLI11 would saturate a larger one silently.
CLI::Validator seedValidator() {
    return CLI::Validator(
        [](std::string& text) -> std::string {
            const std::string largest = "18446744073709551615";
            const bool isDigits = !text.empty() && std::all_of(text.begin(), text.end(),
                                                               [](char c) { return c >= '0' && c <= '9'; });
            std::string digits = text;
            digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size() - 1));
            if (!isDigits || digits.size() > largest.size() ||
                (digits.size() == largest.size() && digits > largest))
                return "the seed must be an integer from 0 to " + largest + ", got " + text;
            return {};
        },
        "0..2^64-1");
}

const char* levelPrefix(LogLevel level) {
    switch (level) {
        case LogLevel::Debug:
            return "debug: ";
        case LogLevel::Detail:
        case LogLevel::Info:
            return "";
        case LogLevel::Warning:
            return "warning: ";
    }
    return "";
}

/// A ceiling on the address space (RLIMIT_AS) at 90 % of the machine's memory and swap: an
/// allocation beyond it fails with std::bad_alloc, which run() reports as "out of memory" (exit 3),
/// where the kernel's OOM killer would end the run, or another process, without a word (seen once
/// at 700 mm and not reproduced, docs/benchmarks.md). The stages' own guards (--max-memory-gb)
/// refuse earlier with an estimate; this catches what they do not estimate. A lower limit the user
/// set stays. Not under AddressSanitizer or ThreadSanitizer, whose shadow memory reserves terabytes
/// of address space.
void limitAddressSpace() {
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define ZOMEFAB_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__) || defined(ZOMEFAB_SANITIZED)
    return;
#else
    struct sysinfo info {};
    if (sysinfo(&info) != 0) return;
    const double total = (double(info.totalram) + double(info.totalswap)) * double(info.mem_unit);
    const rlim_t ceiling = rlim_t(0.9 * total);
    struct rlimit limit {};
    if (getrlimit(RLIMIT_AS, &limit) != 0) return;
    // A soft limit at or under the ceiling stays; the hard limit, never under the soft, is then
    // above the ceiling too.
    if (limit.rlim_cur != RLIM_INFINITY && limit.rlim_cur <= ceiling) return;
    limit.rlim_cur = ceiling;
    setrlimit(RLIMIT_AS, &limit);
#endif
}

constexpr const char* kOutOfMemory =
    "out of memory (the limit is 90 % of the machine's memory and swap, or a lower ulimit -v): a coarser "
    "--voxel-mm or a smaller --height-mm needs less";

/// The tool's name for onTerminate, kept where no allocation is needed to read it.
char gToolName[64] = "zomefab";

/// std::terminate in a tool: one line and exit 3, not an abort. When memory runs out inside
/// OpenVDB, its tree destructors allocate while the std::bad_alloc unwinds, which ends here (seen
/// with the address-space ceiling above). Only write(2) and _exit: the heap may be exhausted. A
/// staging directory left behind is removed by the next run into the same place (docs/cli.md).
[[noreturn]] void onTerminate() {
    const char* what = "internal error (std::terminate)";
    if (const std::exception_ptr e = std::current_exception()) {
        try {
            std::rethrow_exception(e);
        } catch (const std::bad_alloc&) {
            what = kOutOfMemory;
        } catch (...) {
        }
    }
    for (const char* part : {static_cast<const char*>(gToolName), ": error: ", what, "\n"})
        if (::write(2, part, std::strlen(part)) < 0) break;
    ::_exit(3);
}

}  // namespace

Tool::Tool(std::string name, std::string description)
    : mName(std::move(name)), mApp(std::move(description), mName) {
    mApp.set_version_flag("--version", std::string(generatorString()));
    mApp.add_flag("-v,--verbose", mVerboseCount, "More messages on stderr (-vv for debug)");
    mApp.add_flag("-q,--quiet", mQuiet, "Only errors on stderr");
    mApp.add_option("--threads", mCommon.threads, "Worker threads (0 = all cores)")
        ->check(CLI::NonNegativeNumber)
        ->default_val(0);
    mApp.add_option("--seed", mCommon.seed, "Random seed; same seed and input give the same output")
        ->check(seedValidator())
        ->default_val(1);
    mApp.add_option("--report", mCommon.reportPath, "Also write a JSON report to this file");
    mApp.get_formatter()->column_width(34);
}

CLI::Option* Tool::addFormatOption(const std::string& flag, std::string& target,
                                   const std::vector<std::string>& choices, const std::string& help) {
    return mApp.add_option(flag, target, help)->check(CLI::IsMember(choices, CLI::ignore_case));
}

int Tool::run(int argc, char** argv, const std::function<int(nlohmann::json&)>& body) {
    try {
        mApp.parse(argc, argv);
    } catch (const CLI::CallForHelp& e) {
        return mApp.exit(e);
    } catch (const CLI::CallForAllHelp& e) {
        return mApp.exit(e);
    } catch (const CLI::CallForVersion& e) {
        return mApp.exit(e);
    } catch (const CLI::ParseError& e) {
        std::cerr << mName << ": error: " << e.what() << " (see --help)\n";
        return 1;
    }
    mCommon.verbosity = mQuiet ? -1 : mVerboseCount;
    const int verbosity = mCommon.verbosity;
    const std::string toolName = mName;
    auto log = [toolName, verbosity](LogLevel level, const std::string& msg) {
        if (level == LogLevel::Debug && verbosity < 2) return;
        if (level == LogLevel::Detail && verbosity < 1) return;  // stage internals: -v
        if (level != LogLevel::Debug && verbosity < 0) return;   // -q: errors only
        std::cerr << toolName << ": " << levelPrefix(level) << msg << '\n';
    };
    auto stageClock = std::make_shared<Stopwatch>();
    auto lastPrint = std::make_shared<double>(-1.0);
    auto lastStage = std::make_shared<std::string>();
    auto lastFraction = std::make_shared<double>(-1.0);
    auto progress = [toolName, verbosity, stageClock, lastPrint, lastStage, lastFraction](
                        const std::string& stage, double fraction) {
        if (verbosity < 0) return;
        const double now = stageClock->seconds();
        const bool isNewStage = stage != *lastStage;
        // At most two lines a second per stage, plus the start and end of each stage (once: a stage
        // and the pipeline around it may both report its end).
        if (!isNewStage && fraction < 1.0 && now - *lastPrint < 0.5) return;
        if (!isNewStage && fraction >= 1.0 && *lastFraction >= 1.0) return;
        *lastStage = stage;
        *lastPrint = now;
        *lastFraction = fraction;
        std::fprintf(stderr, "%s: [%s] %3d%% %.1f s\n", toolName.c_str(), stage.c_str(),
                     int(fraction * 100.0 + 0.5), now);
    };
    mContext = std::make_unique<RunContext>(log, progress, &gInterrupted);
    for (int signal : {SIGINT, SIGTERM, SIGHUP}) std::signal(signal, onInterrupt);
    std::snprintf(gToolName, sizeof gToolName, "%s", mName.c_str());
    std::set_terminate(onTerminate);
    limitAddressSpace();

    std::unique_ptr<tbb::global_control> threadLimit;
    if (mCommon.threads > 0)
        threadLimit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                            size_t(mCommon.threads));

    try {
        // A --report that cannot be written fails now, before any other output exists.
        if (!mCommon.reportPath.empty()) checkOutputPath(mCommon.reportPath);
        nlohmann::json report;
        const int code = body(report);
        if (!mCommon.reportPath.empty()) {
            report["tool"] = mName;
            report["generator"] = generatorString();
            report["warnings"] = mContext->warnings();
            writeJsonOutput(mCommon.reportPath, report);
        }
        mOutputs.commit();
        return code;
    } catch (const Error& e) {
        std::cerr << mName << ": error: " << e.what() << '\n';
        return exitCodeFor(e.code());
    } catch (const std::bad_alloc&) {
        std::cerr << mName << ": error: " << kOutOfMemory << '\n';
        return 3;
    } catch (const std::exception& e) {
        std::cerr << mName << ": error: internal: " << e.what() << '\n';
        return 3;
    }
}

void printInfo(const Tool& tool, const std::string& message) {
    if (tool.common().verbosity >= 0) std::cerr << tool.name() << ": " << message << '\n';
}

namespace {

/// The tools' JSON files: 2-space indent, a final newline.
void writeJsonText(std::ostream& out, const nlohmann::json& json) { out << json.dump(2) << '\n'; }

}  // namespace

void Tool::writeJsonOutput(const std::string& path, const nlohmann::json& json) {
    mOutputs.add(path, [&](std::ostream& out) { writeJsonText(out, json); });
}

void writeJsonFile(const nlohmann::json& json, const std::string& path) {
    writeOutputAtomic(path, [&](std::ostream& out) { writeJsonText(out, json); });
}

}  // namespace zomefab::cli
