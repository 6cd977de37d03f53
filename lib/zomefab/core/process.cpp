// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/process.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <thread>

#include "zomefab/core/error.h"

extern char** environ;

namespace zomefab {

namespace {

/// The exit status as the shell reports it.
int exitCodeOf(int status) {
    if (WIFEXITED(status)) return WEXITSTATUS(status);
    return 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

/// Waits for @p pid, polling @p context every 20 ms when there is one.
int waitFor(pid_t pid, const RunContext* context, const std::string& name) {
    int status = 0;
    for (;;) {
        const pid_t r = ::waitpid(pid, &status, context ? WNOHANG : 0);
        if (r == pid) return exitCodeOf(status);
        if (r < 0 && errno != EINTR)
            throw Error(ErrorCode::ProcessingFailed,
                        "lost the process '" + name + "': " + std::strerror(errno));
        if (context && context->isCancelled()) {
            ::kill(pid, SIGTERM);
            while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
            }
            context->throwIfCancelled();
        }
        if (context) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
}

}  // namespace

int runProcess(const std::vector<std::string>& args, const ProcessOptions& options) {
    if (args.empty()) throw Error(ErrorCode::Internal, "runProcess: no program given");
    std::vector<std::string> copy(args);
    std::vector<char*> argv;
    for (std::string& a : copy) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    if (!options.outputPath.empty()) {
        posix_spawn_file_actions_addopen(&actions, 1, options.outputPath.c_str(),
                                         O_WRONLY | O_CREAT | O_TRUNC, 0644);
        posix_spawn_file_actions_adddup2(&actions, 1, 2);
    }
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    pid_t pid = 0;
    const int spawned = options.searchPath
                            ? ::posix_spawnp(&pid, argv[0], &actions, nullptr, argv.data(), environ)
                            : ::posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    if (spawned != 0)
        throw Error(ErrorCode::ProcessingFailed, "cannot start '" + args[0] + "': " + std::strerror(spawned));
    return waitFor(pid, options.context, args[0]);
}

}  // namespace zomefab
