// Shared pieces of the CLI: validators for CLI11 options, the user-facing error type, and the
// thread-count control every subcommand honours.
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

// Writes `text` to `path` through a temporary file in the same directory and a rename, so readers
// never see a half-written file. Throws UsageError when the file cannot be written.
void write_atomically(const std::string& path, const std::string& text);

// Each subcommand registers itself on the app.
void add_flow_commands(CLI::App& app, const int& threads);
void add_bench_commands(CLI::App& app, const int& threads);
void add_segment_commands(CLI::App& app, const int& threads);
void add_eval_commands(CLI::App& app, const int& threads);
void add_demo_command(CLI::App& app, const int& threads);
void add_repair_command(CLI::App& app, const int& threads);
void add_soak_command(CLI::App* bench, const int& threads);  // `bench soak`
void add_batch_command(CLI::App& app);  // runs python3 -m liveset.batch (python/)

}  // namespace liveset::cli
