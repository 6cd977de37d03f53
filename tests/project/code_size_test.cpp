// SPDX-License-Identifier: GPL-3.0-or-later
// The code stays in pieces one can read and test alone: no function in lib/ over 150 lines, no
// source file over 600, no tool's source over 120 (docs/architecture.md, "Rules of thumb").
#include <doctest/doctest.h>

#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include "test_util.h"

namespace fs = std::filesystem;

namespace {

/// @p source without comments and with every string or character literal emptied (newlines kept).
std::string stripped(const std::string& source) {
    std::string out;
    out.reserve(source.size());
    for (size_t i = 0; i < source.size();) {
        if (source.compare(i, 2, "//") == 0) {
            while (i < source.size() && source[i] != '\n') ++i;
        } else if (source.compare(i, 2, "/*") == 0) {
            const size_t end = source.find("*/", i + 2);
            for (size_t k = i; k < std::min(end, source.size()); ++k)
                if (source[k] == '\n') out += '\n';
            i = end == std::string::npos ? source.size() : end + 2;
        } else if (source.compare(i, 2, "R\"") == 0) {
            const size_t open = source.find('(', i);
            const std::string close = ")" + source.substr(i + 2, open - i - 2) + "\"";
            const size_t end = source.find(close, open);
            for (size_t k = i; k < std::min(end, source.size()); ++k)
                if (source[k] == '\n') out += '\n';
            out += "\"\"";
            i = end == std::string::npos ? source.size() : end + close.size();
        } else if (source[i] == '"' || source[i] == '\'') {
            const char quote = source[i++];
            while (i < source.size() && source[i] != quote) i += source[i] == '\\' ? 2 : 1;
            out += quote;
            out += quote;
            ++i;
        } else {
            out += source[i++];
        }
    }
    return out;
}

struct Function {
    size_t firstLine = 0, lines = 0;
};

/// The outermost function bodies of @p code (stripped): a brace after a parameter list (and
/// qualifiers), not after a control statement; lambdas count as part of their function.
std::vector<Function> functionBodies(const std::string& code) {
    static const std::regex afterParameters(
        R"(\)\s*(const|noexcept|override|final|mutable|\s|->\s*[\w:<>&*, ]+)*$)");
    static const std::regex control(R"(\b(if|for|while|switch|catch)\s*\(.*\)\s*$)");
    static const std::regex lambda(R"(\]\s*\([^()]*\)\s*(mutable)?\s*(->[^{]*)?$)");
    struct Open {
        size_t line;
        bool isFunction;
    };
    std::vector<Open> open;
    std::vector<Function> out;
    size_t line = 1;
    for (size_t i = 0; i < code.size(); ++i) {
        if (code[i] == '\n') {
            ++line;
        } else if (code[i] == '{') {
            const size_t from = i > 300 ? i - 300 : 0;
            std::string before = code.substr(from, i - from);
            for (char& c : before)
                if (c == '\n') c = ' ';
            const std::string statement = before.substr(
                before.find_last_of(";{}") == std::string::npos ? 0 : before.find_last_of(";{}") + 1);
            const bool isFunction = std::regex_search(before, afterParameters) &&
                                    !std::regex_search(statement, control) &&
                                    !std::regex_search(before, lambda);
            bool isInsideFunction = false;
            for (const Open& o : open) isInsideFunction = isInsideFunction || o.isFunction;
            open.push_back({line, isFunction && !isInsideFunction});
        } else if (code[i] == '}' && !open.empty()) {
            const Open o = open.back();
            open.pop_back();
            if (o.isFunction) out.push_back({o.line, line - o.line + 1});
        }
    }
    return out;
}

fs::path sourceRoot() { return fs::path(zomefab::test::dataPath("")).parent_path().parent_path(); }

std::vector<fs::path> sources(const fs::path& dir) {
    std::vector<fs::path> files;
    for (const fs::directory_entry& e : fs::recursive_directory_iterator(dir))
        if (e.is_regular_file() && (e.path().extension() == ".cpp" || e.path().extension() == ".h"))
            files.push_back(e.path());
    std::sort(files.begin(), files.end());
    return files;
}

size_t lineCount(const std::string& text) { return size_t(std::count(text.begin(), text.end(), '\n')); }

}  // namespace

TEST_CASE("code size: the checker finds functions and skips control blocks and lambdas") {
    const std::string code =
        "int f(int a) {\n  if (a) {\n    return 1;\n  }\n  auto g = [](int x) {\n return x; };\n"
        "  return g(a);\n}\nstruct S {\n  void m() const {\n  }\n};\n";
    const std::vector<Function> f = functionBodies(stripped(code));
    REQUIRE(f.size() == 2);
    CHECK(f[0].firstLine == 1);
    CHECK(f[0].lines == 8);
    CHECK(f[1].firstLine == 10);
    CHECK(stripped("a = \"{\"; // {\n") == "a = \"\"; \n");
}

TEST_CASE("code size: no function in lib/ over 150 lines, no file over 600") {
    const fs::path root = sourceRoot();
    REQUIRE(fs::is_directory(root / "lib"));
    size_t files = 0;
    for (const fs::path& file : sources(root / "lib")) {
        const std::string text = zomefab::test::readFile(file.string());
        const std::string where = fs::relative(file, root).string();
        INFO(where);
        CHECK(lineCount(text) <= 600);
        for (const Function& f : functionBodies(stripped(text))) {
            const std::string at = where + ":" + std::to_string(f.firstLine);
            INFO(at);
            CHECK(f.lines <= 150);
        }
        ++files;
    }
    CHECK(files > 50);
}

TEST_CASE("code size: every tool's source is a thin main (at most 120 lines)") {
    const fs::path root = sourceRoot();
    for (const fs::directory_entry& e : fs::directory_iterator(root / "tools")) {
        if (e.path().extension() != ".cpp") continue;
        INFO(e.path().filename().string());
        CHECK(lineCount(zomefab::test::readFile(e.path().string())) <= 120);
    }
}
