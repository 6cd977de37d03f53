// SPDX-License-Identifier: GPL-3.0-or-later
/// @file Typed error thrown by every zomefab library function. The library never prints or exits.
#pragma once

#include <stdexcept>
#include <string>

namespace zomefab {

/// What went wrong; each code maps to one documented exit code of the tools (docs/cli.md).
enum class ErrorCode {
    Usage,             ///< bad option value (exit 1)
    InvalidInput,      ///< unreadable or invalid input file (exit 2)
    ProcessingFailed,  ///< the input is valid but a stage cannot succeed, e.g. no frame fits (exit 3)
    WriteFailed,       ///< an output cannot be written (exit 4)
    Cancelled,         ///< interrupted by the user (exit 5)
    Internal,          ///< a bug: an invariant did not hold (exit 3)
};

/// The exit code the command-line tools use for @p code (docs/cli.md).
int exitCodeFor(ErrorCode code);

/// The one exception type of the library. `what()` is a one-line message that starts with the file
/// name when there is one: "bunny.stl: truncated binary STL: ...".
class Error : public std::runtime_error {
public:
    Error(ErrorCode code, const std::string& message, const std::string& file = {});

    ErrorCode code() const { return mCode; }
    const std::string& file() const { return mFile; }
    /// The message without the file prefix.
    const std::string& message() const { return mMessage; }

    /// The same error attributed to @p file (keeps an existing file name).
    Error withFile(const std::string& file) const;

private:
    ErrorCode mCode;
    std::string mFile;
    std::string mMessage;
};

}  // namespace zomefab
