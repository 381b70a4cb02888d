// `liveset flow`: the mean-curvature-flow experiment (a box contracting under
// F = κ until it vanishes), with periodic band invariant checks and a short report.
#include <fmt/core.h>

#include <nlohmann/json.hpp>
#include <thread>

#include <tbb/global_control.h>

#include "cli_common.hpp"
#include "commands.hpp"
#include "liveset/levelset/curvature_flow.hpp"
#include "liveset/levelset/invariants.hpp"

namespace liveset::cli {

namespace {

struct FlowArgs {
    BoxFlowOptions box;
    int check_every = 100;
    bool json = false;
    bool quiet = false;
    std::string csv;
    bool full_band = false;
};

int run_flow(const FlowArgs& a, int threads, const char* title) {
    const auto guard = limit_threads(threads);
    SparseField field = make_box_field(a.box);
    const double v0 = enclosed_volume(field);
    int checks = 0;
    std::string first_problem;
    std::vector<std::pair<double, double>> volumes{{0.0, v0}};
    auto check = [&](const SparseField& f) {
        ++checks;
        const InvariantReport r = check_invariants(f);
        if (!r.ok() && first_problem.empty()) first_problem = r.summary();
    };
    check(field);
    const FlowHook hook = [&](const SparseField& f, const StepResult&, const FlowStepRecord& rec) {
        if (a.check_every > 0 && rec.step % a.check_every == 0) {
            check(f);
            volumes.emplace_back(rec.time, enclosed_volume(f));
        }
        return true;
    };
    // The incremental step (without sleeping: the full-band reference's bits, faster where few
    // points change layer per step, as here), or the reference itself.
    const StepMode mode = a.full_band ? StepMode::kFullBand : StepMode::kIncremental;
    const BoxFlowReport rep = run_curvature_flow(field, a.box.max_steps, {.cfl = a.box.cfl, .mode = mode}, hook);
    check(field);
    const double t_end = rep.steps.empty() ? 0.0 : rep.steps.back().time;
    volumes.emplace_back(t_end, enclosed_volume(field));
    bool monotone = true;
    for (std::size_t i = 1; i < volumes.size(); ++i) monotone = monotone && volumes[i].second <= volumes[i - 1].second;
    const int used_threads = threads > 0 ? threads
                                         : static_cast<int>(tbb::global_control::active_value(
                                               tbb::global_control::max_allowed_parallelism));

    if (!a.csv.empty()) {
        std::string csv = "step,time,dt,zero_layer,band,changed,ms\n";
        for (const auto& s : rep.steps)
            csv += fmt::format("{},{:.6f},{:.6f},{},{},{},{:.4f}\n", s.step, s.time, s.dt, s.zero_layer, s.band,
                               s.changed, s.ms);
        write_atomically(a.csv, csv);
    }
    if (a.json) {
        nlohmann::json j;
        j["experiment"] = "box_mean_curvature_flow";
        j["lattice"] = a.box.lattice;
        j["box"] = a.box.box;
        j["layers"] = a.box.layers;
        j["step"] = a.full_band ? "full_band" : "incremental";
        j["threads"] = used_threads;
        j["steps"] = rep.steps.size();
        j["vanished"] = rep.vanished;
        j["time"] = t_end;
        j["median_step_ms"] = rep.median_step_ms();
        j["total_ms"] = rep.total_ms;
        j["volume_start"] = v0;
        j["volume_monotone"] = monotone;
        j["invariant_checks"] = checks;
        j["invariants_ok"] = first_problem.empty();
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        fmt::print("{}: mean curvature flow (F = kappa) of a {}^3 box in a {}^3 lattice, {} layers\n", title,
                   a.box.box, a.box.lattice, a.box.layers);
        fmt::print("  steps        {} ({}, t = {:.1f})\n", rep.steps.size(),
                   rep.vanished ? "the box vanished" : "step limit reached", t_end);
        fmt::print("  step time    median {:.3f} ms, total {:.2f} s, {} thread(s)\n", rep.median_step_ms(),
                   rep.total_ms / 1000.0, used_threads);
        fmt::print("  volume       ");
        for (std::size_t i = 0; i < volumes.size(); i += std::max<std::size_t>(1, volumes.size() / 6))
            fmt::print("t={:.0f}: {:.0f}  ", volumes[i].first, volumes[i].second);
        fmt::print("end: {:.0f} ({})\n", volumes.back().second, monotone ? "shrinks monotonically" : "NOT monotone");
        fmt::print("  invariants   {} checks, {}\n", checks, first_problem.empty() ? "all held" : first_problem);
    }
    return first_problem.empty() && monotone ? 0 : 3;
}

void add_box_options(CLI::App& cmd, FlowArgs& a) {
    cmd.add_option("--lattice", a.box.lattice, "lattice edge length in points")->check(CLI::Range(4, 2048))->capture_default_str();
    cmd.add_option("--box", a.box.box, "box edge length in points")->check(CLI::Range(1, 2046))->capture_default_str();
    cmd.add_option("--steps", a.box.max_steps, "step limit")->check(CLI::Range(0, 10'000'000))->capture_default_str();
    cmd.add_option("--layers", a.box.layers, "sparse-field layers on each side of the zero layer")
        ->check(CLI::Range(1, SparseField::kMaxLayers))
        ->capture_default_str();
    cmd.add_option("--cfl", a.box.cfl, "largest |dphi| per step")
        ->check(finite_number() & CLI::Range(0.01, 0.5))
        ->capture_default_str();
    cmd.add_option("--check-every", a.check_every, "run the band invariant checker every K steps (0: only at the ends)")
        ->check(CLI::Range(0, 1'000'000))
        ->capture_default_str();
    cmd.add_flag("--json", a.json, "print the report as one JSON object");
    cmd.add_flag("--quiet,-q", a.quiet, "print nothing (exit status tells the outcome)");
    cmd.add_option("--csv", a.csv, "write per-step records (step,time,dt,zero_layer,band,changed,ms) to this file");
    cmd.add_flag("--full-band", a.full_band, "step with the full-band reference instead of the incremental step (the same bits)");
}

}  // namespace

void add_flow_commands(CLI::App& app, const int& threads) {
    static FlowArgs flow_args;
    auto* flow = app.add_subcommand("flow", "mean curvature flow of a box until it vanishes (the paper's Figure 3 scenario)");
    add_box_options(*flow, flow_args);
    flow->callback([&threads] {
        const int rc = run_flow(flow_args, threads, "liveset flow");
        if (rc != 0) throw std::runtime_error("the experiment failed its checks");
    });

}

}  // namespace liveset::cli
