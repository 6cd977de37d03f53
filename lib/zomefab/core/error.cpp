// SPDX-License-Identifier: GPL-3.0-or-later
#include "zomefab/core/error.h"

namespace zomefab {

int exitCodeFor(ErrorCode code) {
    switch (code) {
    case ErrorCode::Usage: return 1;
    case ErrorCode::InvalidInput: return 2;
    case ErrorCode::ProcessingFailed: return 3;
    case ErrorCode::WriteFailed: return 4;
    case ErrorCode::Cancelled: return 5;
    case ErrorCode::Internal: return 3;
    }
    return 3;
}

namespace {
std::string joinFileAndMessage(const std::string& file, const std::string& message) {
    return file.empty() ? message : file + ": " + message;
}
}  // namespace

Error::Error(ErrorCode code, const std::string& message, const std::string& file)
    : std::runtime_error(joinFileAndMessage(file, message)), mCode(code), mFile(file),
      mMessage(message) {}

Error Error::withFile(const std::string& file) const {
    return mFile.empty() ? Error(mCode, mMessage, file) : *this;
}

}  // namespace zomefab
