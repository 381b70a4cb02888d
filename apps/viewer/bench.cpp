// Frame-time benchmark scenarios.
#include "bench.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "liveset/render/framebuffer.hpp"
#include "liveset/session/repair_presets.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::viewer {

namespace {

struct Totals {
    double level_set = 0, agents = 0, mesh = 0, upload = 0, draw = 0, frame = 0;
    double fragments = 0, triangles = 0;
    int frames = 0;
};

// The top of the surface: the zero-layer point nearest the point above the surface's centre.
Vec3d default_target(const Session& s) {
    Vec3d lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
    double top_world = -1e300;
    for (PointIndex i : s.field().zero_layer()) {
        const Vec3d p = s.lattice().coord(i).cast<double>();
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], p[a]);
            hi[a] = std::max(hi[a], p[a]);
        }
        top_world = std::max(top_world, s.lattice().to_world(p).z);
    }
    const Vec3d centre = (lo + hi) * 0.5;
    // Highest point (world +z, superior) near the centre column.
    const Vec3d c_world = s.lattice().to_world(centre);
    const Vec3d above = s.lattice().to_index({c_world.x, c_world.y, top_world});
    const auto p = s.nearest_surface_point(above, 1e9);
    return p ? *p : centre;
}

}  // namespace

int run_bench(Viewer& viewer, const BenchOptions& o, int width, int height) {
    Session* s = viewer.session();
    if (!s || !s->has_surface()) throw cli::UsageError("--bench needs a surface: give --phi or --mask");
    using Clock = std::chrono::steady_clock;
    viewer.set_maximised(Pane::kView3d);
    render::Framebuffer window(width, height);
    const Vec3d target = o.target ? *o.target : default_target(*s);
    struct Scenario {
        const char* name;
        bool agents;
        double p;
    };
    const Scenario scenarios[] = {{"static", false, 0.0}, {"agents moving", true, 0.0}, {"repairing p=0.1", true, 0.1},
                                  {"repairing p=0.5", true, 0.5}};
    nlohmann::json results = nlohmann::json::array();
    if (!o.json)
        fmt::print("liveset view --bench: {} frames per scenario, 3D view {}x{}, {} triangles, renderer: {}\n", o.frames,
                   width - viewer.panel_rect().w, height, s->mesher().triangle_count(), o.renderer);
    for (const Scenario& sc : scenarios) {
        if (sc.agents) {
            RepairOptions ro = demo_repair_options();
            ro.swarm.agents = o.agents;
            ro.swarm.act_probability = sc.p;
            ro.swarm.edit_range = 0.0;  // as in the paper's timing: every agent may edit, wherever it is,
            ro.swarm.decision = EditDecision::kRandom;  // raising or lowering the surface at random
            viewer.apply_repair_options(ro);
            if (!viewer.set_target(target)) throw cli::UsageError("bench target: " + viewer.message());
        } else {
            s->clear_target();
        }
        Totals t;
        for (int f = -5; f < o.frames; ++f) {
            viewer.camera().rotate(1.0, 0.0);  // a new view every frame: the 3D pane is redrawn
            viewer.camera_changed();
            const auto t0 = Clock::now();
            if (sc.agents) viewer.swarm_step();  // accounted in this frame's statistics
            viewer.frame(window.id(), width, height, 1.0 / 60.0);
            const double ms = ms_since(t0);
            if (f < 0) continue;
            const FrameStats& st = viewer.last_frame();
            t.level_set += st.level_set_ms;
            t.agents += st.agents_ms;
            t.mesh += st.mesh_ms;
            t.upload += st.upload_ms;
            t.draw += st.draw_ms;
            t.frame += ms;
            t.fragments += static_cast<double>(st.fragments);
            t.triangles += static_cast<double>(st.triangles);
            ++t.frames;
        }
        const double n = std::max(t.frames, 1);
        // Put the surface back for the next scenario (the repair is one undoable action).
        s->end_action();
        if (sc.p > 0.0) viewer.undo();
        const nlohmann::json r = {{"scenario", sc.name}, {"frames", t.frames}, {"agents", sc.agents ? o.agents : 0}, {"p", sc.p},
                                  {"level_set_ms", t.level_set / n}, {"agents_ms", t.agents / n}, {"mesh_ms", t.mesh / n},
                                  {"upload_ms", t.upload / n}, {"draw_ms", t.draw / n}, {"frame_ms", t.frame / n},
                                  {"fps", 1000.0 * n / std::max(t.frame, 1e-9)}, {"fragments_per_frame", t.fragments / n},
                                  {"triangles", t.triangles / n}};
        results.push_back(r);
        if (!o.json)
            fmt::print("  {:<16} level set {:6.2f}  agents {:6.2f}  mesh {:6.2f}  upload {:6.2f}  draw {:7.2f}  frame {:7.2f} ms"
                       "  {:6.1f} FPS  {:6.1f} fragments/frame  {:.0f} triangles\n",
                       sc.name, t.level_set / n, t.agents / n, t.mesh / n, t.upload / n, t.draw / n, t.frame / n,
                       1000.0 * n / std::max(t.frame, 1e-9), t.fragments / n, t.triangles / n);
    }
    if (o.json)
        fmt::print("{}\n", nlohmann::json{{"width", width - viewer.panel_rect().w}, {"height", height},
                                          {"renderer", o.renderer}, {"target", {target.x, target.y, target.z}},
                                          {"scenarios", results}}.dump());
    return 0;
}

}  // namespace liveset::viewer
