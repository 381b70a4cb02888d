// `liveset bench fig3`: the paper's Figure 3 (the experiment is liveset/experiments/figure3.hpp):
// runs it, writes the cumulative seconds per step as CSV and a gnuplot PNG, and prints a summary
// table.
#include <fmt/core.h>
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <tbb/global_control.h>

#include "cli_common.hpp"
#include "commands.hpp"
#include "liveset/base/atomic_file.hpp"
#include "liveset/experiments/figure3.hpp"

extern char** environ;

namespace liveset::cli {

namespace {

namespace fs = std::filesystem;

struct Fig3Args {
    std::string out = "fig3-out";
    Figure3Options experiment;
    bool no_plot = false;
};

void validate(const Fig3Args& a) {
    try {
        a.experiment.validate();
    } catch (const std::invalid_argument& e) {
        // The option names are the fields' with dashes: "--steps must be in [1, 1000000], got 0".
        std::string why = e.what();
        if (why.rfind("verify_every", 0) == 0) why.replace(0, 12, "verify-every");
        if (const auto at = why.find(" in sizes"); at != std::string::npos) why.replace(at, 9, " in --sizes");
        throw UsageError(why.rfind("fragment", 0) == 0 ? why : "--" + why);
    }
    if (a.out.empty()) throw UsageError("--out must not be empty");
}

// Creates the output directory and proves it writable before the (long) run.
void prepare_output_dir(const fs::path& dir) {
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir))
        throw UsageError(fmt::format("cannot create output directory {}{}", dir.string(), ec ? ": " + ec.message() : ""));
    const fs::path probe = dir / ".liveset-write-probe";
    write_atomically(probe.string(), "");
    fs::remove(probe, ec);
}

bool gnuplot_on_path() {
    const char* path = std::getenv("PATH");
    if (!path) return false;
    std::string p(path);
    std::size_t start = 0;
    while (start <= p.size()) {
        const std::size_t end = std::min(p.find(':', start), p.size());
        const fs::path dir = end > start ? fs::path(p.substr(start, end - start)) : fs::path(".");
        if (::access((dir / "gnuplot").c_str(), X_OK) == 0) return true;
        start = end + 1;
    }
    return false;
}

// A gnuplot single-quoted string literal ('' stands for one quote).
std::string gp_quote(const std::string& s) {
    std::string r = "'";
    for (char c : s) r += c == '\'' ? std::string("''") : std::string(1, c);
    return r + "'";
}

std::string plot_script(const Figure3Options& a, std::size_t columns, int threads) {
    std::string s;
    s += "# Figure 3 (Feltell & Bai): regenerate with `gnuplot fig3.gp` in this directory.\n";
    s += "if (!exists(\"outfile\")) outfile = 'fig3.png'\n";
    s += "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {\n"
         "    set terminal pngcairo size 1100,750 noenhanced font 'sans,11'\n"
         "} else {\n"
         "    set terminal png size 1100,750 noenhanced\n"
         "}\n";
    s += "set output outfile\n";
    s += "set datafile separator ','\n";
    s += fmt::format(
        "set title \"Cumulative time to find and repolygonise affected mesh fragments\\n"
        "{0}x{0}x{0} lattice, {1}x{1}x{1} box under mean curvature flow, {2} time steps, {3} thread(s)\"\n",
        a.lattice, a.box, a.steps, threads);
    s += "set xlabel 'time step'\n";
    s += "set ylabel 'cumulative time (s)'\n";
    s += "set yrange [0:*]\n";
    s += "set grid\n";
    s += "set key outside right top\n";
    s += fmt::format("set xrange [0:{}]\n", a.steps);
    s += fmt::format("plot for [i=2:{}] 'fig3.csv' using 1:i with lines lw 2 title columnheader(i)\n", columns + 1);
    return s;
}

void run_gnuplot(const fs::path& dir) {
    const fs::path abs = fs::absolute(dir);
    const fs::path log = abs / "fig3.gp.log";
    AtomicFile png(abs / "fig3.png");  // gnuplot draws into its temporary
    const std::string cd = "cd " + gp_quote(abs.string()) + "; outfile = " + gp_quote(png.temp_path().filename().string());
    const std::string script = (abs / "fig3.gp").string();
    std::vector<std::string> args{"gnuplot", "-e", cd, script};
    std::vector<char*> argv;
    for (auto& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t fa;
    posix_spawn_file_actions_init(&fa);
    posix_spawn_file_actions_addopen(&fa, 0, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 1, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addopen(&fa, 2, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    pid_t pid = 0;
    const int err = posix_spawnp(&pid, "gnuplot", &fa, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&fa);
    if (err != 0) throw UsageError(fmt::format("cannot run gnuplot: {}", std::strerror(err)));
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0)
        if (errno != EINTR) throw UsageError("waiting for gnuplot failed");
    std::string first_line;
    {
        std::ifstream in(log);
        std::string line;
        while (std::getline(in, line))
            if (line.find_first_not_of(" \t^") != std::string::npos) {
                first_line = line;
                break;
            }
    }
    std::error_code ec;
    fs::remove(log, ec);
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !fs::exists(png.temp_path()))
        throw UsageError("gnuplot failed to draw fig3.png" + (first_line.empty() ? std::string() : ": " + first_line));
    try {
        png.commit();
    } catch (const std::runtime_error& e) {
        throw UsageError("cannot write " + (abs / "fig3.png").string() + ": " + e.what());
    }
}

// The summary table: each column's time, and how many times cheaper than the naive scan and the
// band-only single fragment.
void print_figure3(const Figure3Options& a, const Figure3Result& r, int threads) {
    const Figure3Column* naive = nullptr;
    for (const Figure3Column& c : r.columns)
        if (c.naive) naive = &c;  // the largest whole-lattice size
    const Figure3Column& band = r.columns.back();
    fmt::print("liveset bench fig3: {0}^3 lattice, {1}^3 box, {2} steps of mean curvature flow, {3} thread(s)\n", a.lattice,
               a.box, a.steps, threads);
    if (r.flow_steps < a.steps)
        fmt::print("  level set    the box vanished after step {}; steps {}..{} have no changed points\n", r.flow_steps,
                   r.flow_steps + 1, a.steps);
    else
        fmt::print("  level set    {} steps, the box did not vanish\n", r.flow_steps);
    fmt::print("  level set    {:.2f} s in total (not timed below); mean |X| = {:.0f} changed points per step\n", r.level_set_s,
               static_cast<double>(r.changed_sum) / a.steps);
    fmt::print("  mesh checks  {} passed: every merged mesh equals marching_cubes_band of the current phi\n", r.checks);
    fmt::print("  {:<10} {:>9} {:>10} {:>10} {:>11} {:>11} {:>14} {:>8} {:>12} {:>12}\n", "column", "fragments", "total s",
               "ms/step", "naive/this", "band/this", "rebuilt/step", "max", "V-only/step", "cells/step");
    for (const Figure3Column& c : r.columns) {
        const std::string frags = c.naive ? "1 (scan)" : std::to_string(c.fragments);
        const std::string vs_naive = naive ? fmt::format("{:.1f}x", naive->total_s / c.total_s) : "-";
        fmt::print("  {:<10} {:>9} {:>10.4f} {:>10.4f} {:>11} {:>10.2f}x {:>14.1f} {:>8} {:>12.1f} {:>12.0f}\n", c.name, frags,
                   c.total_s, 1000.0 * c.total_s / a.steps, vs_naive, band.total_s / c.total_s,
                   static_cast<double>(c.rebuilt_sum) / a.steps, c.rebuilt_max,
                   static_cast<double>(c.vertices_only_sum) / a.steps, static_cast<double>(c.cells_sum) / a.steps);
    }
    fmt::print("  (naive/this, band/this: how many times cheaper than the naive whole-lattice scan and the band-only "
               "single fragment; V-only: of the fragments rebuilt, those whose triangles stayed and only the vertices "
               "were recomputed)\n");
}

void run_fig3(const Fig3Args& a, int threads) {
    validate(a);
    const auto guard = limit_threads(threads);
    const int used_threads = threads > 0 ? threads
                                         : static_cast<int>(tbb::global_control::active_value(
                                               tbb::global_control::max_allowed_parallelism));
    const fs::path dir(a.out);
    if (!a.no_plot && !gnuplot_on_path()) throw UsageError("gnuplot not found on PATH (install gnuplot or pass --no-plot)");
    prepare_output_dir(dir);
    const Figure3Options& e = a.experiment;
    const Figure3Result r = run_figure3(e);

    std::string csv = "step";
    for (const Figure3Column& c : r.columns) csv += "," + c.name;
    csv += "\n";
    for (int s = 0; s < e.steps; ++s) {
        csv += std::to_string(s + 1);
        for (const Figure3Column& c : r.columns) csv += fmt::format(",{:.9f}", c.cumulative[static_cast<std::size_t>(s)]);
        csv += "\n";
    }
    write_atomically((dir / "fig3.csv").string(), csv);
    if (!a.no_plot) {
        write_atomically((dir / "fig3.gp").string(), plot_script(e, r.columns.size(), used_threads));
        run_gnuplot(dir);
    }
    print_figure3(e, r, used_threads);
    fmt::print("  wrote {}{}\n", (dir / "fig3.csv").string(), a.no_plot ? "" : ", " + (dir / "fig3.png").string());
}

}  // namespace

void add_bench_commands(CLI::App& app, const int& threads) {
    auto* bench = app.add_subcommand("bench", "benchmark experiments from the paper");
    bench->require_subcommand(1);

    static Fig3Args fig3_args;
    auto* fig3 = bench->add_subcommand(
        "fig3", "the paper's Figure 3: cumulative re-meshing time per fragment size during mean curvature flow of a box");
    fig3->add_option("--out", fig3_args.out, "output directory (fig3.csv, fig3.png, fig3.gp)")->capture_default_str();
    fig3->add_option("--steps", fig3_args.experiment.steps, "level-set time steps")->capture_default_str();
    fig3->add_option("--lattice", fig3_args.experiment.lattice, "lattice edge length in points")->capture_default_str();
    fig3->add_option("--box", fig3_args.experiment.box, "box edge length in points")->capture_default_str();
    fig3->add_option("--sizes", fig3_args.experiment.sizes,
                     "fragment sizes in cells, comma separated (>= 3; a size covering the lattice is the naive "
                     "whole-lattice scan)")
        ->delimiter(',')
        ->capture_default_str();
    fig3->add_option("--verify-every", fig3_args.experiment.verify_every,
                     "compare every mesher with marching_cubes_band every K steps (0: only at the start and the end)")
        ->capture_default_str();
    fig3->add_flag("--no-plot", fig3_args.no_plot, "write only the CSV (no gnuplot needed)");
    fig3->callback([&threads] { run_fig3(fig3_args, threads); });
    add_soak_command(bench, threads);
}

}  // namespace liveset::cli
