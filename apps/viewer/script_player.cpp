// Script playback: one bounded piece of work per advance().
#include "script_player.hpp"

#include <fmt/core.h>

#include <cmath>

#include "cli_common.hpp"
#include "image_commands.hpp"
#include "liveset/eval/perforations.hpp"
#include "liveset/io/image_io.hpp"

namespace liveset::viewer {

void ScriptPlayer::fail(const ScriptAction& a, const std::string& why) const {
    throw cli::UsageError(fmt::format("script {} entry {} (\"{}\"): {}", script_.path, a.entry, a.name, why));
}

void ScriptPlayer::check(Viewer& viewer, const ScriptAction& a, bool ok) const {
    if (!ok) fail(a, viewer.message());
}

void ScriptPlayer::finish_entry(Viewer& viewer) {
    if (viewer.session()) viewer.session()->end_action();
    ++next_;
    steps_done_ = 0;
}

// {"params": ...}: threshold parameters (µ or ε given: the window is no longer the seeds'; α given: no
// longer automatic) and swarm settings.
void ScriptPlayer::apply_params(Viewer& viewer, const ScriptAction& a) {
    Session* s = viewer.session();
    ThresholdParams p = s->params();
    bool auto_window = s->window_from_seeds();
    if (a.mu || a.epsilon) auto_window = false;
    if (a.auto_window) auto_window = *a.auto_window;
    bool auto_alpha = s->alpha_automatic() && !a.alpha;
    if (a.auto_alpha) auto_alpha = *a.auto_alpha;
    if (a.smooth_mm && auto_alpha) fail(a, "smooth_mm needs alpha: the automatic choice sets both");
    if (a.mu) p.mu = *a.mu;
    if (a.epsilon) p.epsilon = *a.epsilon;
    if (a.n) p.n = *a.n;
    if (a.alpha) p.alpha = *a.alpha;
    if (s->alpha_automatic() && !auto_alpha) p.smooth_mm = 0.0;  // a given α: no blur unless given, as `segment --alpha`
    if (a.smooth_mm) p.smooth_mm = *a.smooth_mm;
    check(viewer, a, viewer.apply_params(p, auto_window, auto_alpha));
    if (!a.repair_fields.empty()) check(viewer, a, viewer.apply_repair_options(apply_repair_fields(s->repair_options(), a.repair_fields)));
}

// {"camera": ...}: a named view, angles, zoom, pan, a new orbit centre.
void ScriptPlayer::move_camera(Viewer& viewer, const ScriptAction& a) {
    Session* s = viewer.session();
    render::OrbitCamera& c = viewer.camera();
    if (a.reset && s) c.frame(render::surface_bounds(s->mesher()));
    render::CameraPose pose = c.pose();
    if (a.view) render::OrbitCamera::named_pose(*a.view, pose);
    if (a.yaw) pose.yaw_deg = *a.yaw;
    if (a.pitch) pose.pitch_deg = *a.pitch;
    if (a.zoom) pose.zoom = *a.zoom;
    if (a.pan) pose.pan = *a.pan;
    if (a.center) {  // the orbit centre is the framed centre plus the pan
        const Vec3d w = s->lattice().to_world(*a.center);
        pose.pan = glm::dvec3(w.x, w.y, w.z) - (c.centre() - c.pose().pan);
    }
    c.set_pose(pose);
    viewer.camera_changed();
}

// {"screenshot": ...}: a pane or the window into a PNG, overlays hidden on request.
void ScriptPlayer::take_screenshot(Viewer& viewer, const ScriptAction& a) {
    const render::SceneStyle saved = viewer.scene_style;
    if (!a.overlays) viewer.scene_style.bounding_box = viewer.scene_style.cursor = false;
    const bool ok = viewer.save_screenshot(a.path, a.pane, a.width, a.height, a.supersample);
    viewer.scene_style = saved;
    viewer.camera_changed();
    check(viewer, a, ok);
}

// {"perforations": ...}: the truth's perforations of the current mask, printed; one may become the target.
void ScriptPlayer::report_perforations(Viewer& viewer, const ScriptAction& a) {
    Session* s = viewer.session();
    const Grid<std::uint8_t> labels = read_label_image(a.path);
    if (!labels.lattice().same_geometry(s->lattice(), 1e-3)) fail(a, fmt::format("{} does not overlay the image", a.path));
    Grid<std::uint8_t> truth(labels.lattice()), inner(labels.lattice());
    for (PointIndex i = 0; i < labels.size(); ++i) {
        truth[i] = labels[i] == a.label;
        inner[i] = labels[i] == a.inner_label;
    }
    const std::vector<Perforation> found = find_perforations(s->mask(), truth, inner);
    nlohmann::json list = nlohmann::json::array();
    for (std::size_t k = 0; k < found.size() && k < 20; ++k)
        list.push_back({{"voxels", found[k].voxels}, {"centroid", {found[k].centroid.x, found[k].centroid.y, found[k].centroid.z}}});
    fmt::print("{}\n", nlohmann::json{{"entry", a.entry}, {"perforations", found.size()}, {"largest", list}}.dump());
    std::fflush(stdout);
    if (a.rank) {
        if (*a.rank >= static_cast<int>(found.size())) fail(a, fmt::format("only {} perforations", found.size()));
        check(viewer, a, viewer.set_target(found[static_cast<std::size_t>(*a.rank)].centroid));
    }
}

// {"eval": ...}: Dice and topology of the current mask against a truth image, printed and logged.
void ScriptPlayer::report_eval(Viewer& viewer, const ScriptAction& a) {
    Session* s = viewer.session();
    Grid<std::uint8_t> truth = read_label_image(a.path);
    if (!truth.lattice().same_geometry(s->lattice(), 1e-3)) fail(a, fmt::format("{} does not overlay the image", a.path));
    for (std::uint8_t& v : truth.values()) v = a.label ? v == a.label : v != 0;
    const nlohmann::json report = cli::evaluation_report(s->mask(), truth);
    fmt::print("{}\n", nlohmann::json{{"entry", a.entry}, {"eval", report}}.dump());
    std::fflush(stdout);
    viewer.log().add("eval", {{"entry", a.entry}, {"dice", report["dice"]}, {"holes", report["holes"]}});
}

// A "display" entry; false (the viewer's message says why) when the window cannot be set.
bool apply_display(Viewer& viewer, const ScriptAction& a) {
    const nlohmann::json& v = a.display;
    if (v.contains("pane")) {
        const Pane pane = *pane_from_name(v["pane"].get<std::string>());
        std::optional<Vec3d> centre;
        if (v.contains("center")) centre = Vec3d{v["center"][0].get<double>(), v["center"][1].get<double>(), v["center"][2].get<double>()};
        viewer.set_slice_view(pane, v.value("zoom", 1.0), centre);
    }
    if (v.contains("window")) {
        const nlohmann::json& w = v["window"];
        const bool ok = w.is_array() ? viewer.set_display_window({w[0].get<double>(), w[1].get<double>()})
                                     : viewer.set_window_preset(w.get<std::string>());
        if (!ok) return false;
    }
    render::OverlayStyle style = viewer.slice_display().overlay;
    if (v.contains("label_opacity")) style.label_opacity = v["label_opacity"].get<float>();
    if (v.contains("roi")) style.roi = *render::roi_style_from_name(v["roi"].get<std::string>());
    style.preview = v.value("preview", style.preview);
    viewer.set_overlay_style(style, v.value("contour", viewer.slice_display().contour));
    return true;
}

void ScriptPlayer::advance(Viewer& viewer) {
    if (done()) return;
    const ScriptAction& a = script_.actions[next_];
    viewer.halt_run();  // a script entry uses the session: no background run meanwhile
    Session* s = viewer.session();
    if (!s) fail(a, "no image is open");
    using K = ScriptAction::Kind;
    switch (a.kind) {
        case K::kSeed: check(viewer, a, viewer.add_seed(a.point, a.radius)); break;
        case K::kRemoveSeed: check(viewer, a, viewer.remove_seed_at(a.point)); break;
        case K::kParams: apply_params(viewer, a); break;
        case K::kSegment: {
            if (steps_done_ == 0 && !s->has_surface()) fail(a, "no surface to evolve: place a seed first");
            viewer.segment_step();
            ++steps_done_;
            const SegmentStatus& st = s->segment_status();
            const bool stop = st.vanished || (a.until_converged && st.converged) || steps_done_ >= a.count;
            if (!stop) return;  // more steps on the next call
            break;
        }
        case K::kClick: {
            const Rect r = viewer.pane_rect(Pane::kView3d);
            if (a.x >= r.w || a.y >= r.h) fail(a, fmt::format("pixel ({}, {}) is outside the {}x{} 3D pane", a.x, a.y, r.w, r.h));
            if (!viewer.click_3d(a.x, a.y, true)) fail(a, fmt::format("no surface under pixel ({}, {})", a.x, a.y));
            break;
        }
        case K::kTarget: check(viewer, a, viewer.set_target(a.point)); break;
        case K::kClearTarget: viewer.clear_target(); break;
        case K::kTargetSurfaceNear: {
            const auto p = s->nearest_surface_point(a.point, a.radius);
            if (!p) fail(a, fmt::format("no surface within {} voxels", a.radius));
            check(viewer, a, viewer.set_target(*p));
            break;
        }
        case K::kSwarm: {
            if (!s->target()) fail(a, "no target: add a \"target\", \"target_surface_near\" or \"click\" entry first");
            viewer.swarm_step();
            if (++steps_done_ < a.count) return;
            break;
        }
        case K::kCamera: move_camera(viewer, a); break;
        case K::kCursor:
            viewer.set_cursor({static_cast<int>(std::lround(a.point.x)), static_cast<int>(std::lround(a.point.y)),
                               static_cast<int>(std::lround(a.point.z))});
            break;
        case K::kLayout: viewer.set_maximised(a.pane); break;
        case K::kTool: viewer.set_tool(a.tool); break;
        case K::kUndo: viewer.undo(a.count); break;
        case K::kRedo: viewer.redo(a.count); break;
        case K::kSaveMask: check(viewer, a, viewer.save_mask(a.path)); break;
        case K::kSavePhi: check(viewer, a, viewer.save_phi(a.path)); break;
        case K::kSaveMesh: check(viewer, a, viewer.save_mesh(a.path)); break;
        case K::kSaveWorkspace: check(viewer, a, viewer.save_workspace(a.path, true)); break;
        case K::kSaveSeeds: check(viewer, a, viewer.save_seeds(a.path)); break;
        case K::kLoadSeeds: check(viewer, a, viewer.load_seeds(a.path)); break;
        case K::kScreenshot: take_screenshot(viewer, a); break;
        case K::kPerforations: report_perforations(viewer, a); break;
        case K::kEval: report_eval(viewer, a); break;
        case K::kDisplay: check(viewer, a, apply_display(viewer, a)); break;
        case K::kFindHoles: {  // runs on the finder's thread: wait for it a little at a time
            if (steps_done_++ == 0) check(viewer, a, viewer.find_holes(a.hole_scan));
            viewer.poll_holes(true);
            if (viewer.holes_busy()) return;
            if (!viewer.hole_tool().error().empty()) fail(a, viewer.hole_tool().error());
            fmt::print("{}\n", nlohmann::json{{"entry", a.entry}, {"holes", hole_report(viewer.hole_tool())}}.dump());
            std::fflush(stdout);
            break;
        }
        case K::kSelectHole: check(viewer, a, viewer.select_hole(static_cast<std::size_t>(a.count))); break;
    }
    finish_entry(viewer);
}

}  // namespace liveset::viewer
