// `liveset view` argument handling and dispatch.
#include "view_command.hpp"

#include <fmt/core.h>
#include <fmt/ranges.h>

#include <filesystem>
#include <string>
#include <vector>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "headless_app.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/session/repair_presets.hpp"
#include "seed_file.hpp"
#include "view_params.hpp"
#include "window_app.hpp"
#include "workspace.hpp"

namespace liveset::cli {

namespace {

struct ViewArgs : ThresholdArgs {
    std::string image, mask, phi, roi, script, log_events, size = "1280x720", layout = "four";
    std::string workspace, seeds_file;
    bool n_given = false, alpha_given = false;
    bool step_given = false, thin_fronts_given = false;  // --step; --thin-fronts or --no-thin-fronts
    std::vector<std::string> seeds;
    double seed_radius = 2.0;
    bool headless = false, bench = false, json = false;
    int bench_frames = 100;
    std::string bench_mode = "frames";
    std::size_t bench_agents = 200;
    std::string bench_target;
    int fragment_size = 16;
    bool recover = false, no_autosave = false;
    double autosave_every = 120.0;
    std::string recovery_dir;
    std::string window_from = "model";  // µ, ε from the seeds: the tissue model or the seeds' statistics
    std::string coarse_start = "auto";  // --coarse-start, as `segment`'s (coarse_start.hpp)
    bool bias_correct = true;           // N4 first, as `segment` (also for images opened from the panel)
    bool bias_given = false;            // --bias-correct or --no-bias-correct on the command line
    std::optional<bool> workspace_bias; // a continued workspace's: its image corrected again, or not
    bool coarse_start_given = false;            // --coarse-start
    std::optional<StepOptions> workspace_step;  // a continued workspace's step (continued_step)
    std::optional<CoarseStart> workspace_coarse_start;  // and its coarse start (likewise)
    std::string workspace_step_note;            // how it differs from the saved one, as asked
    std::string workspace_warning;      // the workspace was refused, or its ROI is not the one it was saved with
    bool image_corrected = false;       // set by load_session: the session's image is N4-corrected
    bool image_oriented = true;         // set by load_session: its header gave an orientation (saved masks say so too)
    bool roi_by_default = false;        // set by load_session: no --roi, and the automatic brain mask found
    // set by load_session: --seed and --seeds, each with how it was given, less those the ROI left out
    std::vector<std::pair<SeedBall, std::string>> start_seeds;
};

void parse_size(const std::string& text, int& w, int& h) {
    const auto x = text.find('x');
    try {
        if (x == std::string::npos) throw std::invalid_argument(text);
        std::size_t used = 0;
        w = std::stoi(text.substr(0, x), &used);
        if (used != x) throw std::invalid_argument(text);
        h = std::stoi(text.substr(x + 1), &used);
        if (used != text.size() - x - 1) throw std::invalid_argument(text);
    } catch (const std::exception&) {
        throw UsageError(fmt::format("--size {}: expected WIDTHxHEIGHT, e.g. 1280x720", text));
    }
    if (w < 320 || h < 240 || w > 8192 || h > 8192) throw UsageError(fmt::format("--size {}: from 320x240 to 8192x8192", text));
}

// The session options of the command line: for its image and for images opened from the panel.
SessionOptions session_options(const ViewArgs& a) {
    SessionOptions so;
    so.fragment_size = a.fragment_size;
    so.window.estimate = a.window_from == "seeds" ? WindowSource::kSeeds : WindowSource::kModel;
    so.repair = demo_repair_options();
    so.segmentation.step = step_options(a);  // as `liveset segment` (same bits)
    so.coarse_start = parse_coarse_start(a.coarse_start);  // likewise: the run from seeds starts coarse on a fine grid
    so.alpha_automatic = !a.alpha_given;     // chosen once there is a window (choose_start_params says how)
    if (a.alpha_given && a.alpha) so.params.alpha = *a.alpha;
    if (a.alpha_given && a.smooth_mm) so.params.smooth_mm = *a.smooth_mm;
    return so;
}

// --seed and --seeds against the ROI, as `segment` fits them (fit_seeds_to_roi): seeds wholly
// outside it left out with a warning each, every one outside a ROI asked for an error, and the
// default ROI given up (the image opened as with --roi none) when more than half are outside.
void fit_start_seeds(ViewArgs& a, const Lattice& lattice, std::optional<Roi>& roi, PreparedImage& prepared) {
    std::vector<std::pair<SeedBall, std::string>> given;
    for (const std::string& text : a.seeds) given.emplace_back(parse_seed_voxel(text, a.seed_radius), "--seed " + text);
    if (!a.seeds_file.empty())
        for (const SeedBall& b : read_seed_file(a.seeds_file, a.seed_radius)) given.emplace_back(b, "in " + a.seeds_file + " " + format_seed(b));
    std::vector<SeedBall> balls;
    for (const auto& [b, given_as] : given) {
        check_seed_inside(b, lattice, given_as);
        balls.push_back(b);
    }
    const SeedFit fit = fit_seeds_to_roi(roi, prepared, balls, nullptr, "--roi none");
    for (const std::string& w : fit.warnings) fmt::print(stderr, "liveset: warning: {}\n", w);
    if (fit.default_dropped) {
        a.roi_by_default = false;
        a.roi = "none";
    }
    a.start_seeds.clear();
    std::size_t k = 0;  // the kept balls, in order, are a subsequence of the given ones
    for (auto& entry : given)
        if (k < balls.size() && entry.first.center == balls[k].center && entry.first.radius == balls[k].radius) {
            a.start_seeds.push_back(std::move(entry));
            ++k;
        }
}

std::unique_ptr<Session> load_session(ViewArgs& a) {
    Scan scan = read_scan(a.image);
    scan.print_note(a.image);
    Grid<float>& image = scan.image;
    const ImageHeader& header = scan.header;
    a.image_oriented = header.orientation_known;
    // A level set to continue (--mask, --phi) may come from another tool: no default ROI to clip it.
    if (a.roi.empty() && (!a.mask.empty() || !a.phi.empty())) a.roi = "none";
    BrainLookup lookup;
    lookup.options = brain_mask_options(header);
    std::optional<Roi> r = load_roi(a.roi, image, "--roi", &lookup);  // a mask file, "auto", "none" or the default, as `segment`
    if (a.roi.empty()) {  // the default's choice, kept as such (workspaces, a second load)
        a.roi_by_default = r.has_value();
        a.roi = r ? "auto" : "none";
    }
    // N4 first, as `segment`: skipped with a warning where it cannot run, unless asked for (or a
    // continued workspace's image was corrected: then it must be again).
    const BiasCorrection mode = bias_mode(a.workspace_bias.value_or(a.bias_correct), a.bias_given || a.workspace_bias);
    PreparedImage prepared;
    try {
        prepared = prepare_image(image, r, mode, nullptr, &lookup, scan.no_data_mask());
    } catch (const std::invalid_argument& e) {
        throw UsageError(fmt::format("{}: {}", a.image, e.what()));
    }
    for (const std::string& w : prepared.warnings()) fmt::print(stderr, "liveset: warning: {}\n", w);
    fit_start_seeds(a, image.lattice(), r, prepared);
    if (r && r->brain_mask)
        fmt::print(stderr, "liveset: note: {}: brain mask of {} voxels ({})\n",
                   a.roi_by_default ? "the front stays in the automatic brain mask by default (--roi none: the whole image)" : "--roi auto",
                   r->brain_mask->mask_voxels, brain_mask_summary(*r->brain_mask));
    SessionOptions so = session_options(a);
    if (a.workspace_step) so.segmentation.step = *a.workspace_step;
    if (a.workspace_coarse_start) so.coarse_start = *a.workspace_coarse_start;
    so.model_region_is_brain = prepared.fit_is_brain(r);
    so.model_region_grey_brighter = prepared.grey_brighter;
    so.brain_mask = lookup.options;
    std::optional<Grid<std::uint8_t>> roi;
    if (r) roi = std::move(r->mask);
    a.image_corrected = prepared.bias.has_value();
    so.model_region = std::move(prepared.fit_region);  // as `segment`: the automatic brain mask (none with a ROI)
    try {
        return std::make_unique<Session>(std::move(image), so, std::move(roi));
    } catch (const std::invalid_argument& e) {
        throw UsageError(fmt::format("{}: {}", a.image, e.what()));
    }
}

// --mask / --phi, then --seed and --seeds (load_session fitted them to the ROI).
void load_inputs(Session& s, const ViewArgs& a) {
    const Lattice& lattice = s.lattice();
    if (!a.mask.empty()) {
        s.load_mask(load_mask_like(a.mask, lattice, "--mask"));
        if (!s.has_surface()) throw UsageError(fmt::format("--mask {} holds no surface (empty or full)", a.mask));
    } else if (!a.phi.empty()) {
        const Grid<float> phi = read_image(a.phi);
        if (!phi.lattice().same_geometry(lattice, 1e-3))
            throw UsageError(fmt::format("--phi {} ({}) does not overlay the image ({})", a.phi, phi.lattice().describe(), lattice.describe()));
        s.load_phi(phi);
        if (!s.has_surface()) throw UsageError(fmt::format("--phi {} holds no surface (no sign change)", a.phi));
    }
    for (const auto& [b, given_as] : a.start_seeds) {  // fitted to the ROI by load_session
        try {
            s.add_seed(b);
        } catch (const std::invalid_argument& e) {
            throw UsageError(fmt::format("seed {}: {}{}", given_as, e.what(), a.roi_by_default ? kDefaultRoiHint : ""));
        }
    }
    s.end_action();
}

// A workspace that cannot be continued: one line on stderr, and the status line and event log.
void refuse_workspace(ViewArgs& a, const std::exception& e) {
    fmt::print(stderr, "liveset: error: {}; the viewer opens without it\n", e.what());
    a.workspace_warning = fmt::format("{}; opened without it", e.what());
}

// The step a continued workspace takes (a.workspace_step) and its coarse start
// (a.workspace_coarse_start): the ones it was saved with (an older file records only that the rule
// was off: its --step and --coarse-start are the command line's), but for what --step,
// --thin-fronts, --no-thin-fronts or --coarse-start ask, which a.workspace_step_note says (from
// there it does not step as one run would; printed once the workspace is continued).
void continue_workspace_step(ViewArgs& a, const viewer::Workspace& ws) {
    ThresholdArgs t = a;
    std::vector<std::string> asked;
    if (ws.step && !a.step_given) t.step = *ws.step;
    if (ws.step && t.step != *ws.step) asked.push_back(fmt::format("--step {} (saved with --step {})", t.step, *ws.step));
    if (ws.thin_fronts && !a.thin_fronts_given) t.thin_fronts = *ws.thin_fronts;
    if (ws.thin_fronts && t.thin_fronts != *ws.thin_fronts)
        asked.push_back(t.thin_fronts ? "--thin-fronts (saved without)" : "--no-thin-fronts (saved with --thin-fronts)");
    CoarseStart coarse = parse_coarse_start(a.coarse_start);
    if (ws.coarse_start && !a.coarse_start_given) coarse = *ws.coarse_start;
    if (ws.coarse_start && coarse != *ws.coarse_start)
        asked.push_back(fmt::format("--coarse-start {} (saved with --coarse-start {})", to_string(coarse), to_string(*ws.coarse_start)));
    a.workspace_step_note.clear();
    if (!asked.empty())
        a.workspace_step_note =
            fmt::format("workspace {} continues with {} as asked: from here it steps unlike one run", a.workspace, fmt::join(asked, " and "));
    a.workspace_step = step_options(t);
    a.workspace_coarse_start = coarse;
}

// --workspace W: read and check it; on any problem one line on stderr and the viewer opens
// without it. Fills in the image and the ROI from it when the command line gives none.
std::optional<viewer::Workspace> read_workspace_arg(ViewArgs& a) {
    if (a.workspace.empty()) return std::nullopt;
    try {
        viewer::Workspace ws = viewer::read_workspace(a.workspace);
        if (a.image.empty() && !std::filesystem::exists(ws.image))
            throw std::runtime_error(fmt::format("workspace {}: its image {} is gone", a.workspace, ws.image));
        if (a.bias_given && a.bias_correct != ws.bias_corrected)
            throw std::runtime_error(fmt::format("workspace {} was saved {} bias correction; drop {}", a.workspace,
                                                 ws.bias_corrected ? "with" : "without", a.bias_correct ? "--bias-correct" : "--no-bias-correct"));
        if (a.image.empty()) a.image = ws.image;
        if (a.roi.empty()) a.roi = ws.roi;
        a.workspace_bias = ws.bias_corrected;
        continue_workspace_step(a, ws);
        return ws;
    } catch (const std::runtime_error& e) {
        refuse_workspace(a, e);
        return std::nullopt;
    }
}

// The session of the command line: the image, the workspace continued (when it fits the image),
// the level set and seeds given, the start parameters; `note` says where the parameters came from.
std::unique_ptr<Session> open_session(ViewArgs& a, std::optional<viewer::Workspace>& ws, std::string& note) {
    std::unique_ptr<Session> s = load_session(a);
    if (ws) {
        try {
            viewer::check_workspace_image(*ws, a.workspace, s->image(), s->roi(), a.roi);
            viewer::apply_workspace(*s, *ws);
            a.workspace_warning = viewer::workspace_roi_warning(*ws, a.workspace, *s, a.roi);
            if (!a.workspace_warning.empty()) fmt::print(stderr, "liveset: warning: {}\n", a.workspace_warning);
            if (!a.workspace_step_note.empty()) fmt::print(stderr, "liveset: note: {}\n", a.workspace_step_note);
        } catch (const std::exception& e) {
            refuse_workspace(a, e);
            ws.reset();
            a.workspace_bias.reset();  // the command line's settings again
            a.workspace_step.reset();
            a.workspace_coarse_start.reset();
            s = load_session(a);
        }
    }
    load_inputs(*s, a);
    viewer::StartParams sp;
    sp.args = &a;
    sp.n_given = a.n_given;
    sp.alpha_given = a.alpha_given;
    sp.level_set_loaded = !a.mask.empty() || !a.phi.empty();
    if (ws) sp.workspace = a.workspace;
    note = viewer::choose_start_params(*s, sp);
    if (!note.empty()) fmt::print(stderr, "liveset: note: {}\n", note);
    return s;
}

int run_view(ViewArgs& a, int threads) {
    const auto guard = limit_threads(threads);
    check_threshold_args(a);
    std::optional<viewer::Workspace> ws = read_workspace_arg(a);
    int width = 1280, height = 720;
    parse_size(a.size, width, height);
    std::optional<viewer::Pane> maximised;
    if (a.layout != "four") {
        maximised = viewer::pane_from_name(a.layout);
        if (!maximised) throw UsageError("--layout must be four, 3d, axial, sagittal or coronal");
    }
    if (!a.log_events.empty()) check_output_path(a.log_events, OutputKind::kText, "--log-events");
    if (a.bench && !a.headless) throw UsageError("--bench runs headless: add --headless");
    if (a.headless && a.image.empty()) throw UsageError("--headless needs an IMAGE");
    if (a.headless && a.script.empty() && !a.bench) throw UsageError("--headless needs --script or --bench");
    if (!a.mask.empty() && !a.phi.empty()) throw UsageError("give --mask or --phi, not both");
    if (a.recover && (a.no_autosave || (a.headless && a.recovery_dir.empty())))
        throw UsageError("--recover needs autosave (a --recovery-dir, or a window without --no-autosave)");
    if (a.recover && a.image.empty()) throw UsageError("--recover needs an IMAGE");
    if (a.image.empty() && (!a.mask.empty() || !a.phi.empty() || !a.seeds.empty() || !a.roi.empty() || !a.script.empty() || !a.seeds_file.empty()))
        throw UsageError("--mask, --phi, --roi, --seed, --seeds and --script need an IMAGE");

    std::unique_ptr<Session> session;
    std::string note;
    const bool roi_none = a.roi == "none";  // as asked (open_session records the default's choice in a.roi)
    if (!a.image.empty()) session = open_session(a, ws, note);
    std::optional<viewer::Script> script;
    if (!a.script.empty()) script = viewer::parse_script(a.script, session->lattice());
    viewer::ViewerConfig config;
    config.log_events = a.log_events;
    config.session = session_options(a);  // images opened from the panel start as the command line's
    config.image_path = a.image;
    config.roi_path = a.roi;
    config.roi_by_default = a.roi_by_default;
    config.roi_none = roi_none;
    config.bias_correct = a.bias_correct;
    config.image_corrected = a.image_corrected;
    config.image_oriented = a.image_oriented;
    config.params_note = note;
    config.open_warning = a.workspace_warning;
    config.workspace_path = a.workspace;
    if (ws) config.workspace_view = ws->view;
    // Windows autosave by default; headless runs (scripts, tests) only into an explicit --recovery-dir.
    if (!a.no_autosave) config.autosave.dir = !a.recovery_dir.empty() ? std::filesystem::path(a.recovery_dir)
                                                : (a.headless ? std::filesystem::path() : viewer::default_recovery_dir());
    config.autosave.interval_seconds = a.autosave_every;
    config.autosave.recover = a.recover;
    config.autosave.step_given = a.step_given;
    config.autosave.thin_fronts_given = a.thin_fronts_given;
    config.autosave.coarse_start_given = a.coarse_start_given;
    const std::string name = a.image.empty() ? std::string() : std::filesystem::path(a.image).filename().string();

    if (a.headless) {
        viewer::HeadlessOptions ho;
        ho.width = width;
        ho.height = height;
        ho.maximised = maximised;
        ho.script = script ? &*script : nullptr;
        if (a.bench) {
            viewer::BenchOptions bo;
            bo.frames = a.bench_frames;
            bo.mode = a.bench_mode;
            bo.agents = a.bench_agents;
            bo.json = a.json;
            if (!a.bench_target.empty()) {
                const SeedBall t = parse_seed_voxel(a.bench_target, 1.0);
                check_seed_inside(t, session->lattice(), "--bench-target");
                bo.target = t.center;
            }
            ho.bench = bo;
        }
        return viewer::run_headless(std::move(session), name, config, ho);
    }
    if (!viewer::display_available()) throw UsageError("no display to open a window on (DISPLAY is not set); use --headless --script");
    viewer::WindowOptions wo;
    wo.width = width;
    wo.height = height;
    wo.title = name.empty() ? "liveset" : "liveset - " + name;
    wo.maximised = maximised;
    wo.script = script ? &*script : nullptr;
    return viewer::run_window(std::move(session), name, config, wo);
}

}  // namespace

bool viewer_display_available() { return viewer::display_available(); }

int open_demo_viewer(std::unique_ptr<Session> session, Vec3d target) {
    viewer::ViewerConfig config;
    config.session.repair = demo_repair_options();
    viewer::WindowOptions wo;
    wo.title = "liveset demo - phantom repair (Ctrl+Q quits)";
    return viewer::run_window(std::move(session), "phantom", config, wo, [target](viewer::Viewer& v) {
        render::CameraPose superior;
        render::OrbitCamera::named_pose("superior", superior);
        v.camera().set_pose(superior);
        v.camera_changed();
        v.set_tool(viewer::Tool::kTarget);
        if (v.set_target(target)) v.set_swarm_running(true);
    });
}

void add_view_command(CLI::App& app, const int& threads) {
    static ViewArgs va;
    auto* v = app.add_subcommand("view", "interactive 3D viewer: segment, repair with agent swarms, undo, save (window or --headless)");
    v->add_option("image", va.image, "image to open (NIfTI, MetaImage, NRRD, MINC, DICOM folder)");
    v->add_option("--mask", va.mask, "start from this segmentation mask (non-zero inside)");
    v->add_option("--phi", va.phi, "start from this level set (< 0 inside)");
    v->add_option("--roi", va.roi, "region-of-interest mask the front may not leave; 'auto': a brain mask computed from the T1; 'none': the whole image. "
                    "Default, as segment: the automatic brain mask when the image is a full head, else none");
    v->add_option("--seed", va.seeds, "seed I,J,K[:R] (voxels); repeatable");
    v->add_option("--coarse-start", va.coarse_start, fmt::format("a run from the seeds first converges on 2x2x2-voxel blocks, one iteration a step, then refines from there, as `segment`: auto (where every voxel side is at most {} mm), on or off", kCoarseStartMaxSpacing))->check(CLI::IsMember({"auto", "on", "off"}))->capture_default_str();
    v->add_option("--window-from", va.window_from, "estimate the window from the tissue model (the seeds pick the class) or from the seeds' statistics, as `segment`")->check(CLI::IsMember({"model", "seeds"}))->capture_default_str();
    auto* bias = v->add_flag("--bias-correct,!--no-bias-correct", va.bias_correct, "correct the intensity non-uniformity first (N4), as `segment`. Default: on, skipped with a warning where it cannot run (asked for: an error); a continued workspace keeps its own setting");
    v->add_option("--seeds", va.seeds_file, "seed file: one I,J,K[:R] per line (the --seed format; the panel saves them)");
    v->add_option("--workspace", va.workspace, "continue a saved workspace (image, ROI, phi, seeds, parameters, step and coarse start, swarm, camera); the panel saves it; --step, --thin-fronts, --no-thin-fronts or --coarse-start override what it saved, with a note");
    add_threshold_options(*v, va);  // as `liveset segment`: --mu, --epsilon, --mu-raw, --epsilon-raw, --n, --alpha
    v->get_option("--alpha")->description("curvature weight in [0,1), per millimetre (default: automatic, as `segment` chooses it for the window and re-chosen as seeds move it - said in the start note; or the workspace's)");
    v->add_option("--seed-radius", va.seed_radius, "default seed radius, voxels")->check(CLI::PositiveNumber)->capture_default_str();
    v->add_flag("--headless", va.headless, "no window: render with EGL into an offscreen framebuffer (needs --script or --bench)");
    v->add_option("--script", va.script, "replay a session: JSON list of actions (see README)");
    v->add_option("--size", va.size, "window (or offscreen) size WIDTHxHEIGHT")->capture_default_str();
    v->add_option("--layout", va.layout, "four | 3d | axial | sagittal | coronal (one pane maximised)")->capture_default_str();
    v->add_option("--log-events", va.log_events, "write user actions as JSON lines to this file (rewritten atomically)");
    v->add_option("--fragment-size", va.fragment_size, "cells per mesh fragment edge (one GPU buffer each)")
        ->check(CLI::Range(2, 512))
        ->capture_default_str();
    v->add_flag("--bench", va.bench, "headless frame-time breakdown: static, agents moving, repairing at p = 0.1 and 0.5");
    v->add_option("--bench-mode", va.bench_mode, "frames: the paper's four scenarios; segment: the in-viewer segmentation (Run) against the CLI's; interaction: rotate, zoom, scroll and click latency")
        ->check(CLI::IsMember({"frames", "segment", "interaction"}))->capture_default_str();
    v->add_option("--bench-frames", va.bench_frames, "measured frames per scenario")->check(CLI::Range(1, 100000))->capture_default_str();
    v->add_option("--bench-agents", va.bench_agents, "agents in the swarm scenarios")->check(CLI::Range(1, 100000))->capture_default_str();
    v->add_option("--bench-target", va.bench_target, "swarm target I,J,K (default: the top of the surface)");
    v->add_flag("--json", va.json, "benchmark results as one JSON object");
    v->add_option("--autosave-every", va.autosave_every, "seconds between autosaves of unsaved work (0: at every change)")
        ->check(CLI::Range(0.0, 86400.0))
        ->capture_default_str();
    v->add_option("--recovery-dir", va.recovery_dir,
                  "folder of the recovery files (default $XDG_STATE_HOME/liveset/recovery or ~/.local/state/liveset/recovery; "
                  "headless runs autosave only when it is given)");
    v->add_flag("--no-autosave", va.no_autosave, "no autosave, no recovery offer");
    v->add_flag("--recover", va.recover, "restore the image's recovery file (unsaved work of an earlier run) without asking");
    v->callback([&threads, v, bias] {
        va.n_given = v->count("--n") > 0;
        va.alpha_given = v->count("--alpha") > 0;
        va.bias_given = bias->count() > 0;
        va.step_given = v->count("--step") > 0;
        va.thin_fronts_given = v->count("--thin-fronts") > 0;
        va.coarse_start_given = v->count("--coarse-start") > 0;
        const int rc = run_view(va, threads);
        if (rc != 0) std::exit(rc);
    });
}

}  // namespace liveset::cli
