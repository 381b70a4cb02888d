// Headless (EGL) runs: scripts and benchmarks.
#include "headless_app.hpp"

#include <fmt/core.h>

#include "cli_common.hpp"
#include "liveset/render/headless_context.hpp"
#include "script_player.hpp"

namespace liveset::viewer {

namespace {

std::unique_ptr<render::HeadlessContext> make_context() {
    try {
        return std::make_unique<render::HeadlessContext>();
    } catch (const std::runtime_error& e) {
        throw cli::UsageError(e.what());
    }
}

}  // namespace

int run_headless(std::unique_ptr<Session> session, const std::string& image_name, const ViewerConfig& config,
                 const HeadlessOptions& options) {
    const auto context = make_context();
    ViewerConfig c = config;
    c.headless = true;
    Viewer viewer(std::move(session), image_name, c);
    viewer.set_window_size(options.width, options.height);
    if (options.maximised) viewer.set_maximised(options.maximised);
    if (options.bench) {
        BenchOptions b = *options.bench;
        b.renderer = render::describe_current_context() + " (EGL " + context->platform() + ")";
        if (b.mode == "segment") return run_segment_bench(viewer, b, options.width, options.height);
        if (b.mode == "interaction") return run_interaction_bench(viewer, b, options.width, options.height);
        return run_bench(viewer, b, options.width, options.height);
    }
    if (options.script) {
        ScriptPlayer player(*options.script);
        while (!player.done()) {
            player.advance(viewer);
            viewer.autosave().tick();  // no frames here: keep the crash copy and autosaves current
        }
    }
    viewer.request_quit("script done");
    return 0;
}

}  // namespace liveset::viewer
