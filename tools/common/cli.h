// SPDX-License-Identifier: GPL-3.0-or-later
/// @file The conventions every zomefab tool shares: generated --help, --version, -v/-q, --threads,
/// --seed, --report, messages on stderr, exit codes from docs/cli.md, Ctrl-C as exit 5.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <functional>
#include <nlohmann/json.hpp>
#include <string>

#include "zomefab/core/run_context.h"
#include "zomefab/io/file_io.h"

namespace zomefab::cli {

struct CommonOptions {
    int verbosity = 0;       ///< -1 quiet (errors only), 0 normal, 1 verbose (-v), 2 debug (-vv)
    int threads = 0;         ///< 0 = all cores (TBB default)
    uint64_t seed = 1;       ///< seed for every random choice; same seed, same output
    std::string reportPath;  ///< --report FILE.json, empty = none
};

/// One command-line tool. Declare options on `app()`, then `return tool.run(argc, argv, body)`.
class Tool {
public:
    Tool(std::string name, std::string description);

    CLI::App& app() { return mApp; }
    const CommonOptions& common() const { return mCommon; }
    /// Context for library calls: log and progress go to stderr, Ctrl-C cancels.
    RunContext& context() { return *mContext; }
    const std::string& name() const { return mName; }

    /// Parses @p argv, applies --threads, runs @p body and maps errors to exit codes. @p body fills
    /// the report (written to --report FILE atomically, with warnings added) and returns an exit code.
    int run(int argc, char** argv, const std::function<int(nlohmann::json& report)>& body);

    /// Writes output @p path through @p write as part of this run's outputs: every file the run
    /// writes (and its --report) is renamed into place only when the whole run succeeded; a
    /// failure leaves none of them and touches no existing file. "-" writes stdout at once.
    void writeOutput(const std::string& path, const std::function<void(std::ostream&)>& write) {
        mOutputs.add(path, write);
    }
    /// writeOutput of @p json as writeJsonFile formats it.
    void writeJsonOutput(const std::string& path, const nlohmann::json& json);

    /// Adds `--in-format` / `--out-format`-style option that only accepts @p choices.
    CLI::Option* addFormatOption(const std::string& flag, std::string& target,
                                 const std::vector<std::string>& choices, const std::string& help);

private:
    std::string mName;
    CLI::App mApp;
    CommonOptions mCommon;
    std::unique_ptr<RunContext> mContext;
    StagedFiles mOutputs;
    bool mQuiet = false;
    int mVerboseCount = 0;
};

/// Prints a one-line summary to stderr unless -q.
void printInfo(const Tool& tool, const std::string& message);

/// Writes @p json (2-space indent) to @p path ("-" = stdout) atomically.
void writeJsonFile(const nlohmann::json& json, const std::string& path);

}  // namespace zomefab::cli
