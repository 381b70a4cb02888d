// The `liveset` subcommands: each registers itself on the app. They link no viewer code; the demo's
// live window is handed in by main.cpp (DemoWindow).
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <memory>

#include "liveset/grid/vec3.hpp"
#include "liveset/session/session.hpp"

namespace liveset::cli {

// The demo's live window: the viewer on a prepared session with the swarm aimed at `target`.
// Empty members: no window (the demo then only writes its outputs).
struct DemoWindow {
    std::function<bool()> available;                                   // a display to open it on
    std::function<int(std::unique_ptr<Session>, Vec3d target)> open;  // runs it; the exit status
};

void add_flow_commands(CLI::App& app, const int& threads);
void add_bench_commands(CLI::App& app, const int& threads);
void add_segment_commands(CLI::App& app, const int& threads);
void add_eval_commands(CLI::App& app, const int& threads);
void add_demo_command(CLI::App& app, const int& threads, DemoWindow window = {});
void add_repair_command(CLI::App& app, const int& threads);
void add_holes_command(CLI::App& app, const int& threads);
void add_soak_command(CLI::App* bench, const int& threads);  // `bench soak`
void add_batch_command(CLI::App& app);  // runs python3 -m liveset.batch (python/)

}  // namespace liveset::cli
