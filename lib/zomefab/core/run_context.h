// SPDX-License-Identifier: GPL-3.0-or-later
/// @file What a stage gets besides its input and options: a log sink, progress, cancellation and
/// the warnings it raised. Not a state bag: stages keep no state in it.
#pragma once

#include <atomic>
#include <chrono>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

namespace zomefab {

/// Debug: for developers (-vv). Detail: how a stage went, its internal numbers (energies, schedule
/// steps, merges; -v). Info: what the user follows by default (progress, results). Warning: what the
/// user should act on.
enum class LogLevel { Debug, Detail, Info, Warning };

class RunContext {
public:
    using LogSink = std::function<void(LogLevel, const std::string&)>;
    /// stage name, fraction done in [0, 1]
    using ProgressSink = std::function<void(const std::string&, double)>;

    RunContext() = default;
    RunContext(LogSink log, ProgressSink progress, const std::atomic<bool>* cancelFlag = nullptr)
        : mLog(std::move(log)), mProgress(std::move(progress)), mCancelFlag(cancelFlag) {}

    void debug(const std::string& msg) const { emit(LogLevel::Debug, msg); }
    void detail(const std::string& msg) const { emit(LogLevel::Detail, msg); }
    void info(const std::string& msg) const { emit(LogLevel::Info, msg); }
    /// Logs a warning and records it, so reports can list everything that was adjusted or skipped.
    void warn(const std::string& msg) const;
    std::vector<std::string> warnings() const;

    /// Reports progress of @p stage; thread-safe, cheap when no sink is set.
    void progress(const std::string& stage, double fraction) const;

    bool isCancelled() const { return mCancelFlag && mCancelFlag->load(std::memory_order_relaxed); }
    /// @throw Error(ErrorCode::Cancelled) when the user interrupted the run.
    void throwIfCancelled() const;

    /// A context that drops all messages: for tests and library callers that do not care.
    static RunContext& silent();

private:
    void emit(LogLevel level, const std::string& msg) const;

    LogSink mLog;
    ProgressSink mProgress;
    const std::atomic<bool>* mCancelFlag = nullptr;
    mutable std::mutex mMutex;
    mutable std::vector<std::string> mWarnings;
};

/// Wall-clock stopwatch in seconds.
class Stopwatch {
public:
    Stopwatch() : mStart(std::chrono::steady_clock::now()) {}
    double seconds() const {
        return std::chrono::duration<double>(std::chrono::steady_clock::now() - mStart).count();
    }

private:
    std::chrono::steady_clock::time_point mStart;
};

/// Peak resident set size of this process in bytes (Linux /proc), 0 when unknown.
size_t peakRssBytes();

}  // namespace zomefab
