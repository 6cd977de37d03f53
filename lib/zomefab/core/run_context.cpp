// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/run_context.h"

#include <fstream>
#include <string>

#include "zomefab/core/error.h"

namespace zomefab {

void RunContext::emit(LogLevel level, const std::string& msg) const {
    if (!mLog) return;
    std::lock_guard<std::mutex> lock(mMutex);
    mLog(level, msg);
}

void RunContext::warn(const std::string& msg) const {
    {
        std::lock_guard<std::mutex> lock(mMutex);
        mWarnings.push_back(msg);
    }
    emit(LogLevel::Warning, msg);
}

std::vector<std::string> RunContext::warnings() const {
    std::lock_guard<std::mutex> lock(mMutex);
    return mWarnings;
}

void RunContext::progress(const std::string& stage, double fraction) const {
    if (!mProgress) return;
    std::lock_guard<std::mutex> lock(mMutex);
    mProgress(stage, fraction);
}

void RunContext::throwIfCancelled() const {
    if (isCancelled()) throw Error(ErrorCode::Cancelled, "interrupted");
}

RunContext& RunContext::silent() {
    // Each thread gets its own silent context so the recorded warnings do not leak between tests.
    thread_local RunContext context;
    return context;
}

size_t peakRssBytes() {
    std::ifstream status("/proc/self/status");
    std::string line;
    while (std::getline(status, line)) {
        if (line.rfind("VmHWM:", 0) == 0) return size_t(std::stoull(line.substr(6))) * 1024;
    }
    return 0;
}

}  // namespace zomefab
