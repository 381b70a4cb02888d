// liveset command-line entry point: global options, subcommand dispatch, and error reporting
// (one line on stderr and a non-zero exit status; never a crash).
#include <fmt/core.h>

#include <CLI/CLI.hpp>

#include <cstdio>
#include <exception>
#include <new>

#include "cli_common.hpp"
#include "commands.hpp"
#include "liveset/io/image_io.hpp"
#include "view_command.hpp"

int main(int argc, char** argv) {
    CLI::App app{"liveset: real-time interactive level-set segmentation of 3D medical images"};
    app.set_version_flag("--version", std::string("liveset ") + LIVESET_VERSION);
    app.require_subcommand(1);
    int threads = 0;
    app.add_option("--threads", threads, "worker threads (0 = all cores)")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    liveset::cli::add_flow_commands(app, threads);
    liveset::cli::add_segment_commands(app, threads);
    liveset::cli::add_eval_commands(app, threads);
    liveset::cli::add_repair_command(app, threads);
    liveset::cli::add_holes_command(app, threads);
    liveset::cli::add_bench_commands(app, threads);
    // The headless commands link no viewer code: the demo gets its live window from here.
    liveset::cli::add_demo_command(app, threads, {liveset::cli::viewer_display_available, liveset::cli::open_demo_viewer});
    liveset::cli::add_view_command(app, threads);
    liveset::cli::add_batch_command(app);

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
        // One line, as every other bad input (CLI11's own would add a second, "Run with --help").
        fmt::print(stderr, "liveset: error: {} (see --help)\n", e.what());
        return e.get_exit_code();
    } catch (const liveset::cli::UsageError& e) {
        fmt::print(stderr, "liveset: error: {}\n", e.what());
        return 1;
    } catch (const std::bad_alloc&) {
        fmt::print(stderr, "liveset: error: out of memory\n");
        return 1;
    } catch (const liveset::ImageIoError& e) {
        fmt::print(stderr, "liveset: error: {}\n", e.what());
        return 2;
    } catch (const std::exception& e) {
        fmt::print(stderr, "liveset: error: {}\n", e.what());
        return 1;
    }
    return 0;
}
