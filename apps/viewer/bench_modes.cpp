// `liveset view --headless --bench --bench-mode segment | interaction`: the in-viewer
// segmentation against the CLI's (segment_image, as `liveset segment`) in the same run, and the
// latency of interactions (rotate, zoom, slice scroll, clicks) with the loaded surface.
#include <fmt/core.h>

#include <algorithm>
#include <bit>
#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "bench.hpp"
#include "cli_common.hpp"
#include "liveset/render/framebuffer.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::viewer {

namespace {

using Clock = std::chrono::steady_clock;

struct Summary {
    double median = 0, worst = 0;
    std::size_t n = 0;
};

Summary summarise(std::vector<double> v) {
    Summary s;
    if (v.empty()) return s;
    std::sort(v.begin(), v.end());
    s.n = v.size();
    s.median = v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
    s.worst = v.back();
    return s;
}

bool same_bits(const Grid<float>& a, const Grid<float>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (std::bit_cast<std::uint32_t>(a.values()[i]) != std::bit_cast<std::uint32_t>(b.values()[i])) return false;
    return true;
}

}  // namespace

// The CLI's segmentation (segment_image with the session's seeds, ROI and parameters), then the
// same in the viewer (Run, frames until it stops), timed; φ compared bit for bit.
int run_segment_bench(Viewer& viewer, const BenchOptions& o, int width, int height) {
    Session* s = viewer.session();
    if (!s || s->seeds().empty()) throw cli::UsageError("--bench-mode segment needs --seed");
    if (s->segment_status().iterations > 0) throw cli::UsageError("--bench-mode segment starts from the seeds: no --mask or --phi");
    SegmentRequest req;
    req.seeds = s->seeds();
    req.roi = s->roi();
    req.mu = s->params().mu;
    req.epsilon = s->params().epsilon;
    req.n = s->params().n;
    req.alpha = s->params().alpha;
    req.smooth_mm = s->params().smooth_mm;  // the session's blur, automatic or given
    req.loop.step = s->options().segmentation.step;  // `view --step` as `segment --step` (default: sleeping, the thin-front rule on)
    req.coarse_start = s->options().coarse_start;  // `view --coarse-start` as `segment --coarse-start` (same bits)
    const auto c0 = Clock::now();
    const SegmentOutcome cli = segment_image(s->image(), req);
    const double cli_ms = ms_since(c0);

    render::Framebuffer window(width, height);
    viewer.frame(window.id(), width, height, 1.0 / 60.0);  // the first picture (not timed)
    std::vector<double> frame_ms, step_counts;
    double level_set = 0, mesh = 0, upload = 0, draw = 0;  // summed over the run's frames
    FrameStats worst;  // the slowest frame's parts
    double worst_ms = -1.0;
    const auto v0 = Clock::now();
    viewer.set_segment_running(true);
    while (viewer.segment_running()) {
        if (!viewer.needs_frame()) {  // a background run: the render thread waits for its next hand-over
            viewer.wait_for_frame(1000.0);
            continue;
        }
        const auto f0 = Clock::now();
        viewer.frame(window.id(), width, height, 1.0 / 60.0);
        frame_ms.push_back(ms_since(f0));
        const FrameStats& fs = viewer.last_frame();
        if (frame_ms.back() > worst_ms) {
            worst_ms = frame_ms.back();
            worst = fs;
        }
        step_counts.push_back(fs.segment_steps);
        level_set += fs.level_set_ms;
        mesh += fs.mesh_ms;
        upload += fs.upload_ms;
        draw += fs.draw_ms;
    }
    viewer.frame(window.id(), width, height, 1.0 / 60.0);  // the final picture
    const double viewer_ms = ms_since(v0);
    const int iterations = s->segment_status().iterations, coarse_iterations = s->segment_status().coarse_iterations;
    const int cli_coarse = cli.coarse ? cli.coarse->result.iterations : 0;
    const bool identical = iterations == cli.result.iterations && coarse_iterations == cli_coarse && same_bits(s->field().phi(), cli.field->phi());
    const Summary f = summarise(frame_ms), st = summarise(step_counts);
    const nlohmann::json j = {{"cli_ms", cli_ms}, {"viewer_ms", viewer_ms}, {"ratio", viewer_ms / cli_ms},
                              {"cli_iterations", cli.result.iterations}, {"viewer_iterations", iterations},
                              {"cli_coarse_iterations", cli_coarse}, {"viewer_coarse_iterations", coarse_iterations},
                              {"identical_phi", identical}, {"frames", frame_ms.size()},
                              {"frame_ms_median", f.median}, {"frame_ms_worst", f.worst},
                              {"steps_per_frame_median", st.median}, {"triangles", s->mesher().triangle_count()},
                              {"level_set_ms", level_set}, {"mesh_ms", mesh}, {"upload_ms", upload}, {"draw3d_ms", draw},
                              {"worst_frame", {{"ms", worst_ms}, {"wait_ms", worst.wait_ms}, {"mesh_ms", worst.mesh_ms},
                                               {"upload_ms", worst.upload_ms}, {"draw3d_ms", worst.draw_ms}}}};
    if (o.json) {
        fmt::print("{}\n", j.dump());
    } else {
        fmt::print("liveset view --bench-mode segment ({}x{} window)\n", width, height);
        fmt::print("  CLI (segment_image)  {:9.1f} ms  {} + {} coarse iterations ({} step{})\n", cli_ms, cli.result.iterations, cli_coarse,
                   step_name(req.loop.step), req.loop.step.thin_fronts ? ", thin fronts" : "");
        fmt::print("  viewer (Run)         {:9.1f} ms  {} + {} coarse iterations  {} frames  frame median {:.1f} ms, worst {:.1f} ms, "
                   "steps/frame median {:.0f}\n",
                   viewer_ms, iterations, coarse_iterations, frame_ms.size(), f.median, f.worst, st.median);
        fmt::print("  viewer time in: level set (steps) {:.1f} s, meshing {:.1f} s, upload {:.1f} s, 3D draws {:.1f} s, "
                   "the rest (slice panes, panel, history) {:.1f} s\n",
                   level_set / 1e3, mesh / 1e3, upload / 1e3, draw / 1e3, (viewer_ms - level_set - mesh - upload - draw) / 1e3);
        fmt::print("  worst frame          {:9.1f} ms: waiting for the run's step {:.1f}, meshing {:.1f}, upload {:.1f}, 3D draw {:.1f}\n",
                   worst_ms, worst.wait_ms, worst.mesh_ms, worst.upload_ms, worst.draw_ms);
        fmt::print("  viewer / CLI         {:9.3f}   φ identical bit for bit: {}\n", viewer_ms / cli_ms, identical ? "yes" : "NO");
    }
    return identical ? 0 : 1;
}

namespace {

// Frames until the 3D pane is back at full quality (the level of detail's "still" wait); returns
// the cost of the frame that redrew it.
double settle(Viewer& viewer, const render::Framebuffer& window, int width, int height) {
    std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(viewer.budget().options().still_ms + 20.0));
    double last = 0.0;
    for (int i = 0; i < 8 && (viewer.needs_frame() || viewer.view3d_coarse()); ++i) {
        const auto t0 = Clock::now();
        viewer.frame(window.id(), width, height, 1.0 / 60.0);
        last = std::max(last, ms_since(t0));
    }
    return last;
}

InputEvent mouse(InputEvent::Type type, double x, double y, int button = 0) {
    InputEvent e;
    e.type = type;
    e.x = x;
    e.y = y;
    e.button = button;
    return e;
}

// The events of sample i of each interaction (the drag's press comes before its first sample).
std::vector<InputEvent> interaction_events(int kind, int i, const Rect& r3, const Rect& ra) {
    using T = InputEvent::Type;
    const double cx = r3.x + r3.w / 2.0, cy = r3.y + r3.h / 2.0;
    InputEvent wheel = mouse(T::kScroll, kind == 1 ? cx : ra.x + ra.w / 2.0, kind == 1 ? cy : ra.y + ra.h / 2.0);
    wheel.scroll = i % 2 ? 1.0 : -1.0;
    switch (kind) {
        case 0:  // rotate: one move of a held left drag per frame
            return {mouse(T::kMove, cx + 6.0 * (i + 1), cy + 2.0 * (i % 3))};
        case 1:  // zoom: a wheel step over the 3D pane
        case 2:  // slice scroll: a wheel step over the axial pane
            return {wheel};
        case 3: {  // crosshair click in the axial pane
            const double x = ra.x + ra.w * (0.35 + 0.03 * ((i * 7) % 10)), y = ra.y + ra.h * (0.35 + 0.03 * ((i * 3) % 10));
            return {mouse(T::kPress, x, y), mouse(T::kRelease, x, y)};
        }
        default: {  // a pick on the surface (from whatever the pane shows)
            const double x = cx + r3.w * 0.05 * ((i % 5) - 2), y = cy + r3.h * 0.1 * ((i % 3) - 1);
            return {mouse(T::kPress, x, y), mouse(T::kRelease, x, y)};
        }
    }
}

}  // namespace

// Each interaction: its events pushed, then one frame; the latency is that frame's wall time (the
// events are processed and everything they changed is drawn in it). After each kind, the viewer
// settles (full quality once still), timed apart.
int run_interaction_bench(Viewer& viewer, const BenchOptions& o, int width, int height) {
    Session* s = viewer.session();
    if (!s || !s->has_surface()) throw cli::UsageError("--bench-mode interaction needs a surface: give --phi or --mask");
    render::Framebuffer window(width, height);
    const auto frame = [&] {
        const auto t0 = Clock::now();
        viewer.frame(window.id(), width, height, 1.0 / 60.0);
        return ms_since(t0);
    };
    const double first = frame();  // every pane, the 3D one at full quality
    settle(viewer, window, width, height);
    const Rect r3 = viewer.pane_rect(Pane::kView3d), ra = viewer.pane_rect(Pane::kAxial);
    if (!o.json)
        fmt::print("liveset view --bench-mode interaction: {}x{} window, {} triangles (coarse level of detail: {} triangles), "
                   "first frame (all panes, full quality) {:.1f} ms\n",
                   width, height, s->mesher().triangle_count(), viewer.coarse_triangles(), first);
    static constexpr const char* kNames[] = {"rotate (3D drag)", "zoom (3D wheel)", "slice scroll (wheel)",
                                             "click (slice crosshair)", "click (3D pick)"};
    nlohmann::json results = nlohmann::json::array();
    std::vector<double> still_ms;
    viewer.set_tool(Tool::kCrosshair);
    for (int kind = 0; kind < 5; ++kind) {
        std::vector<double> ms, draw3d;
        if (kind == 0) {
            viewer.push_event(mouse(InputEvent::Type::kPress, r3.x + r3.w / 2.0, r3.y + r3.h / 2.0));
            frame();
        }
        for (int i = 0; i < std::max(o.frames, 1); ++i) {
            for (const InputEvent& e : interaction_events(kind, i, r3, ra)) viewer.push_event(e);
            ms.push_back(frame());
            draw3d.push_back(viewer.last_frame().draw_ms);
        }
        if (kind == 0) {
            viewer.push_event(mouse(InputEvent::Type::kRelease, r3.x + r3.w / 2.0, r3.y + r3.h / 2.0));
            frame();
        }
        still_ms.push_back(settle(viewer, window, width, height));
        const Summary m = summarise(ms), d = summarise(draw3d);
        results.push_back({{"interaction", kNames[kind]}, {"samples", m.n}, {"median_ms", m.median}, {"worst_ms", m.worst},
                           {"draw3d_median_ms", d.median}});
        if (!o.json)
            fmt::print("  {:<24} median {:7.1f} ms   worst {:7.1f} ms   (3D pane draw median {:6.1f} ms; {} samples)\n",
                       kNames[kind], m.median, m.worst, d.median, m.n);
    }
    const Summary st = summarise(still_ms);
    if (o.json)
        fmt::print("{}\n", nlohmann::json{{"width", width}, {"height", height}, {"triangles", s->mesher().triangle_count()},
                                          {"coarse_triangles", viewer.coarse_triangles()}, {"interactions", results},
                                          {"first_frame_ms", first}, {"full_redraw_median_ms", st.median},
                                          {"full_redraw_worst_ms", st.worst}}.dump());
    else
        fmt::print("  {:<24} median {:7.1f} ms   worst {:7.1f} ms   ({} samples, {:.0f} ms after the last input)\n",
                   "full-quality redraw", st.median, st.worst, st.n, viewer.budget().options().still_ms);
    return 0;
}

}  // namespace liveset::viewer
