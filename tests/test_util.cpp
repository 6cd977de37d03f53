// SPDX-License-Identifier: GPL-3.0-or-later
#include "test_util.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace zomefab::test {

std::string dataPath(const std::string& name) { return std::string(ZOMEFAB_DATA_DIR) + "/" + name; }

std::string toolPath(const std::string& name) { return std::string(ZOMEFAB_TOOLS_DIR) + "/" + name; }

ScratchDir::ScratchDir(const std::string& tag) {
    static std::atomic<int> counter{0};
    mPath = std::filesystem::temp_directory_path() /
            (tag + "-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
    std::filesystem::remove_all(mPath);
    std::filesystem::create_directories(mPath);
}

ScratchDir::~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(mPath, ec);
}

int runShell(const std::string& command) {
    std::string quoted = "'";
    for (char c : command) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
    quoted += "'";
    const int status = std::system(("bash -o pipefail -c " + quoted).c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int runCapture(const std::string& command, std::string* out) {
    FILE* pipe = ::popen(command.c_str(), "r");
    if (!pipe) return -1;
    std::string text;
    char buf[65536];
    while (size_t n = std::fread(buf, 1, sizeof buf, pipe)) text.append(buf, n);
    const int status = ::pclose(pipe);
    if (out) *out = std::move(text);
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

MeasuredRun runMeasured(const std::vector<std::string>& argv) {
    MeasuredRun run;
    char errPath[] = "/tmp/zomefab-test-stderr-XXXXXX";
    const int errFd = ::mkstemp(errPath);
    if (errFd < 0 || argv.empty()) return run;
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int devNull = ::open("/dev/null", O_WRONLY);
        ::dup2(devNull, 1);
        ::dup2(errFd, 2);
        std::vector<char*> args;
        for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
        args.push_back(nullptr);
        ::execv(args[0], args.data());
        ::_exit(127);
    }
    int status = 0;
    struct rusage usage {};
    if (pid > 0 && ::wait4(pid, &status, 0, &usage) == pid) {
        run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        run.signal = WIFSIGNALED(status) ? WTERMSIG(status) : 0;
        run.peakRssKb = usage.ru_maxrss;
    }
    ::close(errFd);
    run.stderrText = readFile(errPath);
    ::unlink(errPath);
    return run;
}

bool hasCommand(const std::string& name) {
    return std::system(("command -v " + name + " > /dev/null 2>&1").c_str()) == 0;
}

std::string readFile(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& path, const std::string& bytes) {
    std::ofstream out(path, std::ios::binary);
    out << bytes;
    if (!out) throw std::runtime_error("cannot write test fixture " + path);
}

TriMesh makeBox(const Vec3d& a, const Vec3d& b) {
    TriMesh m;
    for (int i = 0; i < 8; ++i)
        m.positions.push_back(
            {float(i & 1 ? b[0] : a[0]), float(i & 2 ? b[1] : a[1]), float(i & 4 ? b[2] : a[2])});
    // Each face as two counter-clockwise triangles seen from outside.
    const uint32_t faces[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                  {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : faces) {
        m.triangles.push_back({f[0], f[1], f[2]});
        m.triangles.push_back({f[0], f[2], f[3]});
    }
    return m;
}

TriMesh makeSphere(const Vec3d& c, double r, int rings, int segments) {
    TriMesh m;
    const double pi = std::acos(-1.0);
    m.positions.push_back({float(c[0]), float(c[1]), float(c[2] + r)});  // north pole
    for (int i = 1; i < rings; ++i) {
        const double theta = pi * i / rings;
        for (int j = 0; j < segments; ++j) {
            const double phi = 2 * pi * j / segments;
            m.positions.push_back({float(c[0] + r * std::sin(theta) * std::cos(phi)),
                                   float(c[1] + r * std::sin(theta) * std::sin(phi)),
                                   float(c[2] + r * std::cos(theta))});
        }
    }
    m.positions.push_back({float(c[0]), float(c[1]), float(c[2] - r)});  // south pole
    const uint32_t south = uint32_t(m.positions.size() - 1);
    auto ring = [&](int i, int j) { return uint32_t(1 + (i - 1) * segments + (j % segments)); };
    for (int j = 0; j < segments; ++j) m.triangles.push_back({0, ring(1, j), ring(1, j + 1)});
    for (int i = 1; i < rings - 1; ++i)
        for (int j = 0; j < segments; ++j) {
            m.triangles.push_back({ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)});
            m.triangles.push_back({ring(i, j), ring(i + 1, j + 1), ring(i, j + 1)});
        }
    for (int j = 0; j < segments; ++j)
        m.triangles.push_back({south, ring(rings - 1, j + 1), ring(rings - 1, j)});
    return m;
}

}  // namespace zomefab::test
