// Shared pieces of the apps: validators for CLI11 options, the user-facing error type, the
// thread-count control every subcommand honours, and atomic text output.
#pragma once

#include <CLI/CLI.hpp>

#include <memory>
#include <stdexcept>
#include <string>

namespace liveset::cli {

// An error the user caused (bad values, missing files): printed as one line, exit status 1.
struct UsageError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// CLI11 validator rejecting NaN and infinities (CLI::Range lets NaN through).
CLI::Validator finite_number();

// Limits TBB to `threads` workers for the lifetime of the returned object (0 = all cores).
std::shared_ptr<void> limit_threads(int threads);

// Writes `text` to `path` through the atomic file writer (liveset/base/atomic_file.hpp), so readers
// never see a half-written file. Throws UsageError when the file cannot be written.
void write_atomically(const std::string& path, const std::string& text);

}  // namespace liveset::cli
