// `liveset bench fig3`: the paper's Figure 3. A box contracts under mean curvature flow; after
// every level-set step each fragment size re-meshes from the SAME changed points X, and only
// "find and re-polygonise the affected fragments" (FragmentMesher::update) is timed, so the
// level-set cost is excluded and the sizes are compared on identical input. Writes the cumulative
// seconds per step as CSV and a gnuplot PNG, and prints a summary table.
//
// Columns: x<S> for each fragment size S (cells per fragment edge). A size whose single fragment
// covers the whole lattice (S >= lattice - 1 cells) is the paper's naive method: every cell of the
// lattice is scanned every step (CellPolygoniser::polygonise_box into one reused mesh, with none
// of the incremental mesher's bookkeeping; O(volume)), whether or not
// anything changed. x<L>_band (L = lattice points per edge) is the same whole-lattice fragment
// updated band-driven (FragmentMesher::update, O(surface)).
//
// After the box vanishes (zero layer empty) the level set stops; the remaining steps have no
// changed points (incremental columns pay only the empty update) while the naive column keeps
// scanning the lattice, as a renderer re-meshing every frame would.
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
#include "liveset/levelset/curvature_flow.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"

extern char** environ;

namespace liveset::cli {

namespace {

namespace fs = std::filesystem;

struct Fig3Args {
    std::string out = "fig3-out";
    int steps = 1500;
    int lattice = 100;
    int box = 50;
    int verify_every = 250;
    bool no_plot = false;
    std::vector<int> sizes{3, 5, 10, 20, 25, 50, 100};
};

struct Column {
    std::string name;
    bool naive = false;  // whole-lattice scan every step
    FragmentMesher mesher;
    std::vector<double> cumulative;  // seconds after each step
    double total_s = 0.0;
    std::size_t rebuilt_sum = 0, rebuilt_max = 0;
    std::size_t cells_sum = 0;
    // The naive column: one polygoniser scanning every cell into one reused mesh (the paper's
    // whole-lattice marching cubes; no incremental bookkeeping such as the mesher's sign bits).
    CellPolygoniser scan;
    Mesh scan_mesh;
};

void naive_scan(Column& c, const Grid<float>& phi) {
    const Vec3i d = phi.dims();
    c.scan_mesh.clear();
    c.scan.polygonise_box(phi, {0, 0, 0}, {d.x - 1, d.y - 1, d.z - 1}, c.scan_mesh);
}

void validate(const Fig3Args& a) {
    if (a.steps < 1 || a.steps > 1'000'000) throw UsageError(fmt::format("--steps must be in [1, 1000000], got {}", a.steps));
    if (a.lattice < 4 || a.lattice > 1024)
        throw UsageError(fmt::format("--lattice must be in [4, 1024], got {}", a.lattice));
    if (a.box < 1 || a.box > a.lattice - 2)
        throw UsageError(fmt::format("--box must be in [1, lattice - 2 = {}], got {}", a.lattice - 2, a.box));
    if (a.verify_every < 0) throw UsageError(fmt::format("--verify-every must not be negative, got {}", a.verify_every));
    if (a.sizes.empty()) throw UsageError("--sizes needs at least one fragment size");
    std::set<int> seen;
    for (int s : a.sizes) {
        if (s < 3 || s > 1'000'000)
            throw UsageError(fmt::format("fragment sizes must be in [3, 1000000] (3 is the smallest workable size), got {}", s));
        if (!seen.insert(s).second) throw UsageError(fmt::format("fragment size {} given twice in --sizes", s));
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

std::string plot_script(const Fig3Args& a, const std::vector<Column>& cols, int threads) {
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
    s += fmt::format("plot for [i=2:{}] 'fig3.csv' using 1:i with lines lw 2 title columnheader(i)\n", cols.size() + 1);
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

void verify(int step, const Grid<float>& phi, std::span<const PointIndex> zero_layer, const std::vector<Column>& cols) {
    const Mesh ref = marching_cubes_band(phi, zero_layer);
    const auto ref_tris = canonical_triangles(ref);
    for (const Column& c : cols) {
        const Mesh m = c.naive ? c.scan_mesh : c.mesher.merged();
        if (m.triangle_count() != ref.triangle_count())
            throw std::runtime_error(fmt::format(
                "figure 3 check failed at step {}: {} mesh has {} triangles, marching_cubes_band has {}", step, c.name,
                m.triangle_count(), ref.triangle_count()));
        if (canonical_triangles(m) != ref_tris)
            throw std::runtime_error(fmt::format(
                "figure 3 check failed at step {}: {} mesh differs from marching_cubes_band ({} triangles each)", step,
                c.name, m.triangle_count()));
    }
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

    BoxFlowOptions box;
    box.lattice = a.lattice;
    box.box = a.box;
    box.max_steps = a.steps;
    SparseField field = make_box_field(box);
    const Lattice& lattice = field.lattice();
    const int cells = a.lattice - 1;

    std::vector<Column> cols;
    for (int s : a.sizes) {
        Column c{fmt::format("x{}", s), s >= cells, FragmentMesher(lattice, std::min(s, cells)), {}, 0.0, 0, 0, 0, {}, {}};
        cols.push_back(std::move(c));
    }
    cols.push_back(Column{fmt::format("x{}_band", a.lattice), false, FragmentMesher(lattice, cells), {}, 0.0, 0, 0, 0, {}, {}});
    for (Column& c : cols) {
        if (c.naive)
            naive_scan(c, field.phi());
        else
            c.mesher.full_rebuild(field.phi(), field.zero_layer());
        c.cumulative.reserve(static_cast<std::size_t>(a.steps));
    }
    verify(0, field.phi(), field.zero_layer(), cols);

    using clock = std::chrono::steady_clock;
    int checks = 1;
    std::size_t changed_sum = 0;
    const auto mesh_step = [&](int step, std::span<const PointIndex> changed) {
        const Grid<float>& phi = field.phi();
        changed_sum += changed.size();
        const std::size_t n = cols.size();
        for (std::size_t k = 0; k < n; ++k) {  // rotate the order so no size always runs first
            Column& c = cols[(k + static_cast<std::size_t>(step)) % n];
            std::size_t rebuilt = 1;
            const auto t0 = clock::now();
            if (c.naive)
                naive_scan(c, phi);
            else
                rebuilt = c.mesher.update(phi, changed).size();
            const auto t1 = clock::now();
            c.total_s += std::chrono::duration<double>(t1 - t0).count();
            c.cumulative.push_back(c.total_s);
            c.rebuilt_sum += rebuilt;
            c.rebuilt_max = std::max(c.rebuilt_max, rebuilt);
            c.cells_sum += c.naive ? static_cast<std::size_t>(cells) * cells * cells : c.mesher.last_stats().cells_visited;
        }
        if ((a.verify_every > 0 && step % a.verify_every == 0) || step == a.steps) {
            verify(step, phi, field.zero_layer(), cols);
            ++checks;
        }
    };

    const FlowHook hook = [&](const SparseField&, const StepResult& r, const FlowStepRecord& rec) {
        mesh_step(rec.step, r.changed.points);
        return true;
    };
    const BoxFlowReport rep = run_curvature_flow(field, a.steps, box.cfl, hook);
    const int flow_steps = static_cast<int>(rep.steps.size());
    for (int s = flow_steps + 1; s <= a.steps; ++s) mesh_step(s, {});

    // CSV and plot.
    std::string csv = "step";
    for (const Column& c : cols) csv += "," + c.name;
    csv += "\n";
    for (int s = 0; s < a.steps; ++s) {
        csv += std::to_string(s + 1);
        for (const Column& c : cols) csv += fmt::format(",{:.9f}", c.cumulative[static_cast<std::size_t>(s)]);
        csv += "\n";
    }
    write_atomically((dir / "fig3.csv").string(), csv);
    if (!a.no_plot) {
        write_atomically((dir / "fig3.gp").string(), plot_script(a, cols, used_threads));
        run_gnuplot(dir);
    }

    // Summary table.
    const Column* naive = nullptr;
    for (const Column& c : cols)
        if (c.naive) naive = &c;  // the largest whole-lattice size
    const Column& band = cols.back();
    fmt::print("liveset bench fig3: {0}^3 lattice, {1}^3 box, {2} steps of mean curvature flow, {3} thread(s)\n", a.lattice,
               a.box, a.steps, used_threads);
    if (flow_steps < a.steps)
        fmt::print("  level set    the box vanished after step {}; steps {}..{} have no changed points\n", flow_steps,
                   flow_steps + 1, a.steps);
    else
        fmt::print("  level set    {} steps, the box did not vanish\n", flow_steps);
    fmt::print("  level set    {:.2f} s in total (not timed below); mean |X| = {:.0f} changed points per step\n",
               [&] {
                   double ms = 0;
                   for (const FlowStepRecord& r : rep.steps) ms += r.ms;
                   return ms / 1000.0;
               }(),
               static_cast<double>(changed_sum) / a.steps);
    fmt::print("  mesh checks  {} passed: every merged mesh equals marching_cubes_band of the current phi\n", checks);
    fmt::print("  {:<10} {:>9} {:>10} {:>10} {:>11} {:>11} {:>14} {:>8} {:>12}\n", "column", "fragments", "total s",
               "ms/step", "naive/this", "band/this", "rebuilt/step", "max", "cells/step");
    for (const Column& c : cols) {
        const std::string frags = c.naive ? "1 (scan)" : std::to_string(c.mesher.fragment_count());
        const std::string vs_naive = naive ? fmt::format("{:.1f}x", naive->total_s / c.total_s) : "-";
        fmt::print("  {:<10} {:>9} {:>10.4f} {:>10.4f} {:>11} {:>10.2f}x {:>14.1f} {:>8} {:>12.0f}\n", c.name, frags,
                   c.total_s, 1000.0 * c.total_s / a.steps, vs_naive, band.total_s / c.total_s,
                   static_cast<double>(c.rebuilt_sum) / a.steps, c.rebuilt_max,
                   static_cast<double>(c.cells_sum) / a.steps);
    }
    fmt::print("  (naive/this, band/this: how many times cheaper than the naive whole-lattice scan and the band-only "
               "single fragment)\n");
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
    fig3->add_option("--steps", fig3_args.steps, "level-set time steps")->capture_default_str();
    fig3->add_option("--lattice", fig3_args.lattice, "lattice edge length in points")->capture_default_str();
    fig3->add_option("--box", fig3_args.box, "box edge length in points")->capture_default_str();
    fig3->add_option("--sizes", fig3_args.sizes,
                     "fragment sizes in cells, comma separated (>= 3; a size covering the lattice is the naive "
                     "whole-lattice scan)")
        ->delimiter(',')
        ->capture_default_str();
    fig3->add_option("--verify-every", fig3_args.verify_every,
                     "compare every mesher with marching_cubes_band every K steps (0: only at the start and the end)")
        ->capture_default_str();
    fig3->add_flag("--no-plot", fig3_args.no_plot, "write only the CSV (no gnuplot needed)");
    fig3->callback([&threads] { run_fig3(fig3_args, threads); });
    add_soak_command(bench, threads);
}

}  // namespace liveset::cli
