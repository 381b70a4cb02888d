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

namespace liveset::viewer {

namespace {

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

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
    const auto c0 = Clock::now();
    const SegmentOutcome cli = segment_image(s->image(), req);
    const double cli_ms = ms_since(c0);

    render::Framebuffer window(width, height);
    viewer.frame(window.id(), width, height, 1.0 / 60.0);  // the first picture (not timed)
    std::vector<double> frame_ms, step_counts;
    const auto v0 = Clock::now();
    viewer.set_segment_running(true);
    while (viewer.segment_running()) {
        const auto f0 = Clock::now();
        viewer.frame(window.id(), width, height, 1.0 / 60.0);
        frame_ms.push_back(ms_since(f0));
        step_counts.push_back(viewer.last_frame().segment_steps);
    }
    viewer.frame(window.id(), width, height, 1.0 / 60.0);  // the final picture
    const double viewer_ms = ms_since(v0);
    const int iterations = s->segment_status().iterations;
    const bool identical = iterations == cli.result.iterations && same_bits(s->field().phi(), cli.field->phi());
    const Summary f = summarise(frame_ms), st = summarise(step_counts);
    const nlohmann::json j = {{"cli_ms", cli_ms}, {"viewer_ms", viewer_ms}, {"ratio", viewer_ms / cli_ms},
                              {"cli_iterations", cli.result.iterations}, {"viewer_iterations", iterations},
                              {"identical_phi", identical}, {"frames", frame_ms.size()},
                              {"frame_ms_median", f.median}, {"frame_ms_worst", f.worst},
                              {"steps_per_frame_median", st.median}, {"triangles", s->mesher().triangle_count()}};
    if (o.json) {
        fmt::print("{}\n", j.dump());
    } else {
        fmt::print("liveset view --bench-mode segment ({}x{} window)\n", width, height);
        fmt::print("  CLI (segment_image)  {:9.1f} ms  {} iterations\n", cli_ms, cli.result.iterations);
        fmt::print("  viewer (Run)         {:9.1f} ms  {} iterations  {} frames  frame median {:.1f} ms, worst {:.1f} ms, "
                   "steps/frame median {:.0f}\n",
                   viewer_ms, iterations, frame_ms.size(), f.median, f.worst, st.median);
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

}  // namespace

// Each interaction: its events pushed, then one frame; the latency is that frame's wall time (the
// events are processed and everything they changed is drawn in it).
int run_interaction_bench(Viewer& viewer, const BenchOptions& o, int width, int height) {
    Session* s = viewer.session();
    if (!s || !s->has_surface()) throw cli::UsageError("--bench-mode interaction needs a surface: give --phi or --mask");
    render::Framebuffer window(width, height);
    const auto first = Clock::now();
    viewer.frame(window.id(), width, height, 1.0 / 60.0);
    const double full_first = ms_since(first);  // every pane, the 3D one at full quality
    const Rect r3 = viewer.pane_rect(Pane::kView3d), ra = viewer.pane_rect(Pane::kAxial);
    const double cx = r3.x + r3.w / 2.0, cy = r3.y + r3.h / 2.0;
    std::vector<double> draw3d;  // of the current interaction's frames: the 3D pane's draw
    const auto timed = [&](const std::vector<InputEvent>& events) {
        for (const InputEvent& e : events) viewer.push_event(e);
        const auto t0 = Clock::now();
        viewer.frame(window.id(), width, height, 1.0 / 60.0);
        draw3d.push_back(viewer.last_frame().draw_ms);
        return ms_since(t0);
    };
    using T = InputEvent::Type;
    nlohmann::json results = nlohmann::json::array();
    std::vector<double> still_ms;
    const auto report = [&](const char* name, const std::vector<double>& v) {
        const Summary m = summarise(v), d = summarise(draw3d);
        draw3d.clear();
        results.push_back({{"interaction", name}, {"samples", m.n}, {"median_ms", m.median}, {"worst_ms", m.worst},
                           {"draw3d_median_ms", d.median}});
        if (!o.json)
            fmt::print("  {:<24} median {:7.1f} ms   worst {:7.1f} ms   (3D pane draw median {:6.1f} ms; {} samples)\n", name,
                       m.median, m.worst, d.median, m.n);
    };
    if (!o.json)
        fmt::print("liveset view --bench-mode interaction: {}x{} window, {} triangles (coarse level of detail {}), "
                   "first frame (all panes, full quality) {:.1f} ms\n",
                   width, height, s->mesher().triangle_count(), viewer.budget().options().lod_min_triangles <= s->mesher().triangle_count() ? "on" : "off",
                   full_first);
    settle(viewer, window, width, height);
    draw3d.clear();
    const int n = std::max(o.frames, 1);
    std::vector<double> rotate;  // a drag: press, then one move per frame
    viewer.push_event(mouse(T::kPress, cx, cy));
    viewer.frame(window.id(), width, height, 1.0 / 60.0);
    draw3d.clear();
    for (int i = 0; i < n; ++i) rotate.push_back(timed({mouse(T::kMove, cx + 6.0 * (i + 1), cy + 2.0 * (i % 3))}));
    viewer.push_event(mouse(T::kRelease, cx + 6.0 * n, cy));
    viewer.frame(window.id(), width, height, 1.0 / 60.0);
    still_ms.push_back(settle(viewer, window, width, height));
    report("rotate (3D drag)", rotate);
    std::vector<double> wheel3d, scroll, click_slice, click_3d;
    for (int i = 0; i < n; ++i) {
        InputEvent w = mouse(T::kScroll, cx, cy);
        w.scroll = i % 2 ? 1.0 : -1.0;
        wheel3d.push_back(timed({w}));
    }
    still_ms.push_back(settle(viewer, window, width, height));
    report("zoom (3D wheel)", wheel3d);
    for (int i = 0; i < n; ++i) {
        InputEvent w = mouse(T::kScroll, ra.x + ra.w / 2.0, ra.y + ra.h / 2.0);
        w.scroll = i % 2 ? 1.0 : -1.0;
        scroll.push_back(timed({w}));
    }
    still_ms.push_back(settle(viewer, window, width, height));
    report("slice scroll (wheel)", scroll);
    viewer.set_tool(Tool::kCrosshair);
    for (int i = 0; i < n; ++i) {
        const double x = ra.x + ra.w * (0.35 + 0.3 * ((i * 7) % 10) / 10.0), y = ra.y + ra.h * (0.35 + 0.3 * ((i * 3) % 10) / 10.0);
        click_slice.push_back(timed({mouse(T::kPress, x, y), mouse(T::kRelease, x, y)}));
    }
    still_ms.push_back(settle(viewer, window, width, height));
    report("click (slice crosshair)", click_slice);
    for (int i = 0; i < n; ++i) {  // a pick on the surface (from whatever the pane shows)
        const double x = cx + r3.w * 0.1 * ((i % 5) - 2) / 2.0, y = cy + r3.h * 0.1 * ((i % 3) - 1);
        click_3d.push_back(timed({mouse(T::kPress, x, y), mouse(T::kRelease, x, y)}));
    }
    still_ms.push_back(settle(viewer, window, width, height));
    report("click (3D pick)", click_3d);
    const Summary st = summarise(still_ms);
    if (!o.json) fmt::print("  {:<22} median {:7.1f} ms   worst {:7.1f} ms   ({} samples, after {:.0f} ms without input)\n",
                            "full-quality redraw", st.median, st.worst, st.n, viewer.budget().options().still_ms);
    if (o.json)
        fmt::print("{}\n", nlohmann::json{{"width", width}, {"height", height}, {"triangles", s->mesher().triangle_count()},
                                          {"interactions", results}, {"full_redraw_median_ms", st.median},
                                          {"full_redraw_worst_ms", st.worst}}.dump());
    return 0;
}

}  // namespace liveset::viewer
