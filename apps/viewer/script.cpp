// Script parsing and validation: every problem is one line naming the entry.
#include "script.hpp"

#include <fmt/core.h>

#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "liveset/session/repair_presets.hpp"

namespace liveset::viewer {

namespace {

using nlohmann::json;

class EntryError {
public:
    EntryError(const std::string& script, std::size_t entry, std::string name) : script_(script), entry_(entry), name_(std::move(name)) {}
    [[noreturn]] void fail(const std::string& why) const {
        if (name_.empty()) throw cli::UsageError(fmt::format("script {} entry {}: {}", script_, entry_, why));
        throw cli::UsageError(fmt::format("script {} entry {} (\"{}\"): {}", script_, entry_, name_, why));
    }

private:
    const std::string& script_;
    std::size_t entry_;
    std::string name_;
};

double number(const json& v, const EntryError& err, const char* what) {
    if (!v.is_number()) err.fail(fmt::format("{} must be a number", what));
    const double d = v.get<double>();
    if (!std::isfinite(d)) err.fail(fmt::format("{} must be finite", what));
    return d;
}

int whole(const json& v, const EntryError& err, const char* what, int lo, int hi) {
    if (!v.is_number_integer()) err.fail(fmt::format("{} must be a whole number", what));
    const auto i = v.get<long long>();
    if (i < lo || i > hi) err.fail(fmt::format("{} must be in [{}, {}]", what, lo, hi));
    return static_cast<int>(i);
}

Vec3d point(const json& v, const EntryError& err, const Lattice& lattice, const char* what) {
    if (!v.is_array() || v.size() != 3) err.fail(fmt::format("{} must be [i, j, k] (voxel indices)", what));
    const Vec3d p{number(v[0], err, what), number(v[1], err, what), number(v[2], err, what)};
    if (!lattice.contains(p)) err.fail(fmt::format("{} ({}, {}, {}) lies outside the {} image", what, p.x, p.y, p.z, lattice.describe()));
    return p;
}

std::string text(const json& v, const EntryError& err, const char* what) {
    if (!v.is_string() || v.get<std::string>().empty()) err.fail(fmt::format("{} must be a non-empty string", what));
    return v.get<std::string>();
}

void only_keys(const json& obj, const std::set<std::string>& allowed, const EntryError& err) {
    for (auto it = obj.begin(); it != obj.end(); ++it)
        if (!allowed.count(it.key())) err.fail(fmt::format("unknown key \"{}\"", it.key()));
}

void output_path(const std::string& path, cli::OutputKind kind, const EntryError& err) {
    try {
        cli::check_output_path(path, kind, "the output");
    } catch (const std::exception& e) {
        err.fail(e.what());
    }
}

const std::set<std::string> kRepairKeys = {"preset", "agents", "p", "radius", "amount", "seed", "expand_sigmas",
                                           "contract_sigmas", "edit_range", "sample_depth", "decision"};

void parse_params(const json& p, ScriptAction& a, const EntryError& err) {
    if (!p.is_object()) err.fail("expected an object of parameters");
    std::set<std::string> allowed = {"mu", "epsilon", "n", "alpha", "smooth_mm", "auto_window", "auto_alpha"};
    allowed.insert(kRepairKeys.begin(), kRepairKeys.end());
    only_keys(p, allowed, err);
    if (p.contains("mu")) a.mu = number(p["mu"], err, "mu");
    if (p.contains("epsilon")) a.epsilon = number(p["epsilon"], err, "epsilon");
    if (p.contains("n")) a.n = number(p["n"], err, "n");
    if (p.contains("alpha")) a.alpha = number(p["alpha"], err, "alpha");
    if (p.contains("smooth_mm")) a.smooth_mm = number(p["smooth_mm"], err, "smooth_mm");
    if (p.contains("auto_window")) {
        if (!p["auto_window"].is_boolean()) err.fail("auto_window must be true or false");
        a.auto_window = p["auto_window"].get<bool>();
    }
    if (p.contains("auto_alpha")) {
        if (!p["auto_alpha"].is_boolean()) err.fail("auto_alpha must be true or false");
        a.auto_alpha = p["auto_alpha"].get<bool>();
        if (*a.auto_alpha && (a.alpha || a.smooth_mm)) err.fail("give alpha (or smooth_mm) or \"auto_alpha\": true, not both");
    }
    a.repair_fields = json::object();
    for (const std::string& k : kRepairKeys)
        if (p.contains(k)) a.repair_fields[k] = p[k];
    if (a.repair_fields.contains("preset") && a.repair_fields["preset"] != "demo") err.fail("the only preset is \"demo\"");
    if (a.repair_fields.contains("agents")) whole(a.repair_fields["agents"], err, "agents", 1, 1'000'000);
    if (a.repair_fields.contains("seed")) whole(a.repair_fields["seed"], err, "seed", 0, 2'000'000'000);
    for (const char* k : {"p", "radius", "amount", "expand_sigmas", "contract_sigmas", "edit_range", "sample_depth"})
        if (a.repair_fields.contains(k)) number(a.repair_fields[k], err, k);
    if (a.repair_fields.contains("decision")) {
        const json& d = a.repair_fields["decision"];
        const std::optional<EditDecision> rule = d.is_string() ? edit_decision_named(d.get<std::string>()) : std::nullopt;
        if (!rule || *rule == EditDecision::kSheet) err.fail("decision must be \"intensity\", \"random\" or \"cut\"");
    }
    // Check the values now, on top of the defaults: a bad value fails before anything runs.
    try {
        validate(apply_repair_fields(RepairOptions{}, a.repair_fields));
        ThresholdParams t;
        if (a.epsilon) t.epsilon = *a.epsilon;
        if (a.mu) t.mu = *a.mu;
        if (a.n) t.n = *a.n;
        if (a.alpha) t.alpha = *a.alpha;
        if (a.smooth_mm) t.smooth_mm = *a.smooth_mm;
        validate(t);
    } catch (const std::invalid_argument& e) {
        err.fail(e.what());
    }
}

// {"seed": ...} / {"remove_seed": ...}: a seed to add or remove, [i, j, k] with an optional radius.
void parse_seed_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice& lattice) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name, "radius"}, err);
    a.kind = name == "seed" ? K::kSeed : K::kRemoveSeed;
    a.point = point(v, err, lattice, "the seed");
    if (e.contains("radius")) a.radius = number(e["radius"], err, "radius");
    if (a.radius <= 0) err.fail("radius must be positive");
}

// {"params": ...}: new threshold or swarm parameters.
void parse_params_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kParams;
    parse_params(v, a, err);
}

// {"segment": ...}: a number of segmentation steps, or "converge".
void parse_segment_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name, "max"}, err);
    a.kind = K::kSegment;
    if (v.is_string() && v == "converge") {
        a.until_converged = true;
        a.count = e.contains("max") ? whole(e["max"], err, "max", 1, 10'000'000) : 2000;
    } else {
        if (!v.is_number_integer()) err.fail("expected a number of steps or \"converge\"");
        a.count = whole(v, err, "the number of steps", 1, 10'000'000);
    }
}

// {"click": ...}: a click at pixel [x, y] of the 3D pane.
void parse_click_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kClick;
    if (!v.is_array() || v.size() != 2) err.fail("expected [x, y] (pixels of the 3D pane)");
    a.x = number(v[0], err, "x");
    a.y = number(v[1], err, "y");
    if (a.x < 0 || a.y < 0) err.fail("pixel coordinates must not be negative");
}

// {"target": ...} / {"cursor": ...}: the swarm target or the cursor at a voxel.
void parse_point_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice& lattice) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = name == "target" ? K::kTarget : K::kCursor;
    a.point = point(v, err, lattice, "the point");
}

// {"target_surface_near": ...}: the target on the surface nearest a voxel.
void parse_target_near_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice& lattice) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name, "radius"}, err);
    a.kind = K::kTargetSurfaceNear;
    a.point = point(v, err, lattice, "the point");
    a.radius = e.contains("radius") ? number(e["radius"], err, "radius") : 20.0;
    if (a.radius <= 0) err.fail("radius must be positive");
}

// {"swarm": ...} / {"undo": ...} / {"redo": ...}: swarm steps, undos or redos: a count.
void parse_counted_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = name == "swarm" ? K::kSwarm : (name == "undo" ? K::kUndo : K::kRedo);
    a.count = whole(v, err, name == "swarm" ? "the number of steps" : "the count", 1, 10'000'000);
}

// {"camera": ...}: a named view, yaw, pitch, zoom, pan, centre or reset.
void parse_camera_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice& lattice) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kCamera;
    if (!v.is_object()) err.fail("expected an object such as {\"view\": \"superior\"}");
    only_keys(v, {"view", "yaw", "pitch", "zoom", "pan", "center", "reset"}, err);
    if (v.contains("center")) a.center = point(v["center"], err, lattice, "center");
    if (v.contains("view")) {
        a.view = text(v["view"], err, "view");
        render::CameraPose pose;
        if (!render::OrbitCamera::named_pose(*a.view, pose))
            err.fail("view must be superior, inferior, anterior, posterior, left, right or default");
    }
    if (v.contains("yaw")) a.yaw = number(v["yaw"], err, "yaw");
    if (v.contains("pitch")) a.pitch = number(v["pitch"], err, "pitch");
    if (v.contains("zoom")) a.zoom = number(v["zoom"], err, "zoom");
    if (a.zoom && *a.zoom <= 0) err.fail("zoom must be positive");
    if (v.contains("pan")) {
        const json& p = v["pan"];
        if (!p.is_array() || p.size() != 3) err.fail("pan must be [x, y, z] in mm");
        a.pan = glm::dvec3(number(p[0], err, "pan"), number(p[1], err, "pan"), number(p[2], err, "pan"));
    }
    if (v.contains("reset")) {
        if (!v["reset"].is_boolean()) err.fail("reset must be true or false");
        a.reset = v["reset"].get<bool>();
    }
}

// {"layout": ...}: four panes or one maximised.
void parse_layout_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kLayout;
    const std::string l = text(v, err, "layout");
    if (l != "four") {
        a.pane = pane_from_name(l);
        if (!a.pane) err.fail("layout must be four, 3d, axial, sagittal or coronal");
    }
}

// {"tool": ...}: the mouse tool.
void parse_tool_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kTool;
    const std::string t = text(v, err, "tool");
    if (t == "crosshair") a.tool = Tool::kCrosshair;
    else if (t == "seed") a.tool = Tool::kSeed;
    else if (t == "target") a.tool = Tool::kTarget;
    else err.fail("tool must be crosshair, seed or target");
}

// {"save_mask": ...} / {"save_phi": ...} / {"save_mesh": ...}: a mask, φ or mesh written to a path.
void parse_save_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = name == "save_mask" ? K::kSaveMask : (name == "save_phi" ? K::kSavePhi : K::kSaveMesh);
    a.path = text(v, err, "the path");
    output_path(a.path, name == "save_mesh" ? cli::OutputKind::kMesh : cli::OutputKind::kImage, err);
}

// {"save_workspace": ...} / {"save_seeds": ...} / {"load_seeds": ...}: the workspace or the seeds.
void parse_file_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    using K = ScriptAction::Kind;
    only_keys(e, {a.name}, err);
    a.kind = a.name == "save_workspace" ? K::kSaveWorkspace : (a.name == "save_seeds" ? K::kSaveSeeds : K::kLoadSeeds);
    a.path = text(e[a.name], err, "the path");
    if (a.kind != K::kLoadSeeds) output_path(a.path, cli::OutputKind::kText, err);
}

// {"screenshot": ...}: a PNG of a pane or of the window.
void parse_screenshot_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name, "pane", "size", "supersample", "overlays"}, err);
    if (e.contains("overlays")) {
        if (!e["overlays"].is_boolean()) err.fail("overlays must be true or false");
        a.overlays = e["overlays"].get<bool>();
    }
    a.kind = K::kScreenshot;
    a.path = text(v, err, "the path");
    if (a.path.size() < 4 || a.path.substr(a.path.size() - 4) != ".png") err.fail("screenshots are .png files");
    output_path(a.path, cli::OutputKind::kText, err);
    a.pane = Pane::kView3d;
    if (e.contains("pane")) {
        const std::string p = text(e["pane"], err, "pane");
        a.pane = p == "window" ? std::nullopt : pane_from_name(p);
        if (p != "window" && !a.pane) err.fail("pane must be 3d, axial, sagittal, coronal or window");
    }
    if (e.contains("size")) {
        const json& s = e["size"];
        if (!s.is_array() || s.size() != 2) err.fail("size must be [width, height]");
        a.width = whole(s[0], err, "width", 16, 8192);
        a.height = whole(s[1], err, "height", 16, 8192);
    }
    if (e.contains("supersample")) a.supersample = whole(e["supersample"], err, "supersample", 1, 4);
}

// {"eval": ...}: Dice and topology against a truth image.
void parse_eval_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kEval;
    if (!v.is_object() || !v.contains("truth")) err.fail("expected {\"truth\": path}");
    only_keys(v, {"truth", "label"}, err);
    a.path = text(v["truth"], err, "truth");
    if (v.contains("label")) a.label = whole(v["label"], err, "label", 1, 255);
}

// {"clear_target": ...}: the swarm stops and forgets its target.
void parse_clear_target_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kClearTarget;
    if (v != true) err.fail("expected true");
}

// {"perforations": ...}: the truth's perforations (optionally one as the target).
void parse_perforations_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const std::string& name = a.name;
    const json& v = e[name];
    using K = ScriptAction::Kind;
    only_keys(e, {name}, err);
    a.kind = K::kPerforations;
    if (!v.is_object() || !v.contains("labels")) err.fail("expected {\"labels\": path, \"truth_label\": 2, \"inner_label\": 3}");
    only_keys(v, {"labels", "truth_label", "inner_label", "target"}, err);
    a.path = text(v["labels"], err, "labels");
    a.label = v.contains("truth_label") ? whole(v["truth_label"], err, "truth_label", 1, 255) : 2;
    a.inner_label = v.contains("inner_label") ? whole(v["inner_label"], err, "inner_label", 1, 255) : 3;
    if (a.label == a.inner_label) err.fail("truth_label and inner_label must differ");
    if (v.contains("target")) a.rank = whole(v["target"], err, "target", 0, 1'000'000);
}

// {"display": ...}: a slice pane's zoom, the window/level, the overlay.
void parse_display_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice& lattice) {
    const json& v = e[a.name];
    only_keys(e, {a.name}, err);
    a.kind = ScriptAction::Kind::kDisplay;
    if (!v.is_object()) err.fail("expected an object such as {\"window\": \"auto\", \"label_opacity\": 0.5}");
    only_keys(v, {"pane", "zoom", "center", "window", "label_opacity", "roi", "preview", "contour"}, err);
    if (v.contains("zoom") || v.contains("center")) {
        if (!v.contains("pane")) err.fail("zoom and center need a \"pane\"");
        const auto pane = pane_from_name(text(v["pane"], err, "pane"));
        if (!pane || *pane == Pane::kView3d) err.fail("pane must be axial, sagittal or coronal");
        if (v.contains("zoom") && !(number(v["zoom"], err, "zoom") > 0)) err.fail("zoom must be positive");
        if (v.contains("center")) point(v["center"], err, lattice, "center");
    }
    if (v.contains("window")) {
        const json& w = v["window"];
        if (w.is_array()) {
            if (w.size() != 2 || !(number(w[0], err, "window") < number(w[1], err, "window")))
                err.fail("window must be [low, high] with low < high, or auto, minmax or narrow");
        } else if (const std::string p = text(w, err, "window"); p != "auto" && p != "minmax" && p != "narrow") {
            err.fail("window must be auto, minmax, narrow or [low, high]");
        }
    }
    if (v.contains("label_opacity")) {
        const double o = number(v["label_opacity"], err, "label_opacity");
        if (o < 0 || o > 1) err.fail("label_opacity must be in [0, 1]");
    }
    if (v.contains("roi") && !render::roi_style_from_name(text(v["roi"], err, "roi"))) err.fail("roi must be off, outline or tint");
    for (const char* k : {"preview", "contour"})
        if (v.contains(k) && !v[k].is_boolean()) err.fail(fmt::format("{} must be true or false", k));
    a.display = v;
}

// {"find_holes": {...}} / {"select_hole": rank}: the hole finder and a candidate of its list.
void parse_holes_entry(const json& e, ScriptAction& a, const EntryError& err, const Lattice&) {
    const json& v = e[a.name];
    only_keys(e, {a.name}, err);
    if (a.name == "select_hole") {
        a.kind = ScriptAction::Kind::kSelectHole;
        a.count = whole(v, err, "the rank", 1, 1'000'000'000);
        return;
    }
    a.kind = ScriptAction::Kind::kFindHoles;
    if (!v.is_object()) err.fail("expected an object such as {\"min_voxels\": 10}");
    only_keys(v, {"min_voxels", "min_sheet_share", "sheet_band"}, err);
    HoleScanOptions& o = a.hole_scan;
    if (v.contains("min_voxels")) o.min_voxels = static_cast<std::size_t>(whole(v["min_voxels"], err, "min_voxels", 1, 2'000'000'000));
    if (v.contains("min_sheet_share")) o.min_sheet_share = number(v["min_sheet_share"], err, "min_sheet_share");
    if (v.contains("sheet_band")) {
        const json& b = v["sheet_band"];
        if (!b.is_array() || b.size() != 2) err.fail("sheet_band must be [low, high] (raw intensities)");
        o.sheet_lower = number(b[0], err, "sheet_band");
        o.sheet_upper = number(b[1], err, "sheet_band");
    }
    try {
        o.validate();
    } catch (const std::invalid_argument& ex) {
        err.fail(ex.what());
    }
}

using EntryParser = void (*)(const json&, ScriptAction&, const EntryError&, const Lattice&);

// Every action a script entry can name, with its parser.
const std::map<std::string, EntryParser>& entry_parsers() {
    static const std::map<std::string, EntryParser> parsers = {
        {"seed", parse_seed_entry},
        {"remove_seed", parse_seed_entry},
        {"params", parse_params_entry},
        {"segment", parse_segment_entry},
        {"click", parse_click_entry},
        {"target", parse_point_entry},
        {"cursor", parse_point_entry},
        {"target_surface_near", parse_target_near_entry},
        {"swarm", parse_counted_entry},
        {"undo", parse_counted_entry},
        {"redo", parse_counted_entry},
        {"camera", parse_camera_entry},
        {"layout", parse_layout_entry},
        {"tool", parse_tool_entry},
        {"save_mask", parse_save_entry},
        {"save_phi", parse_save_entry},
        {"save_mesh", parse_save_entry},
        {"save_workspace", parse_file_entry},
        {"save_seeds", parse_file_entry},
        {"load_seeds", parse_file_entry},
        {"screenshot", parse_screenshot_entry},
        {"eval", parse_eval_entry},
        {"clear_target", parse_clear_target_entry},
        {"perforations", parse_perforations_entry},
        {"display", parse_display_entry},
        {"find_holes", parse_holes_entry},
        {"select_hole", parse_holes_entry},
    };
    return parsers;
}

ScriptAction parse_entry(const json& e, std::size_t entry, const std::string& path, const Lattice& lattice) {
    const EntryError bare(path, entry, "");
    if (!e.is_object() || e.empty()) bare.fail("expected an object such as {\"segment\": 100}");
    const auto& parsers = entry_parsers();
    std::string name;
    for (auto it = e.begin(); it != e.end(); ++it)
        if (parsers.count(it.key())) {
            if (!name.empty()) bare.fail(fmt::format("two actions (\"{}\" and \"{}\") in one entry", name, it.key()));
            name = it.key();
        }
    if (name.empty()) bare.fail(fmt::format("no action (unknown key \"{}\")", e.begin().key()));
    const EntryError err(path, entry, name);
    ScriptAction a;
    a.entry = entry;
    a.name = name;
    parsers.at(name)(e, a, err, lattice);
    return a;
}

}  // namespace

RepairOptions apply_repair_fields(RepairOptions o, const nlohmann::json& f) {
    if (f.contains("preset")) {
        const int steps = o.steps;
        o = demo_repair_options();
        o.steps = steps;
    }
    if (f.contains("agents")) o.swarm.agents = f["agents"].get<std::size_t>();
    if (f.contains("p")) o.swarm.act_probability = f["p"].get<double>();
    if (f.contains("radius")) o.swarm.edit_radius = f["radius"].get<double>();
    if (f.contains("amount")) o.swarm.edit_amount = f["amount"].get<double>();
    if (f.contains("seed")) o.swarm.seed = f["seed"].get<std::uint64_t>();
    if (f.contains("expand_sigmas")) o.swarm.expand_sigmas = f["expand_sigmas"].get<double>();
    if (f.contains("contract_sigmas")) o.swarm.contract_sigmas = f["contract_sigmas"].get<double>();
    if (f.contains("edit_range")) o.swarm.edit_range = f["edit_range"].get<double>();
    if (f.contains("sample_depth")) o.swarm.sample_depth = f["sample_depth"].get<double>();
    if (f.contains("decision")) {
        o.swarm.decision = edit_decision_named(f["decision"].get<std::string>()).value();  // parse_params checked it
        // A cut needs a brush: 3 voxels unless the script gives one.
        if (o.swarm.decision == EditDecision::kCut && !f.contains("edit_range") && !(o.swarm.edit_range > 0)) o.swarm.edit_range = 3.0;
    }
    return o;
}

Script parse_script_text(const std::string& text, const std::string& path, const Lattice& lattice) {
    json doc;
    try {
        doc = json::parse(text);
    } catch (const json::exception& e) {
        // parse_error, or out_of_range for a number beyond a double ("1e999"); nlohmann's message
        // names the byte position or the number: enough to find the typo.
        throw cli::UsageError(fmt::format("script {} is not valid JSON: {}", path, e.what()));
    }
    if (!doc.is_array()) throw cli::UsageError(fmt::format("script {} must be a JSON list of actions", path));
    Script s;
    s.path = path;
    for (std::size_t i = 0; i < doc.size(); ++i) s.actions.push_back(parse_entry(doc[i], i + 1, path, lattice));
    return s;
}

Script parse_script(const std::string& path, const Lattice& lattice) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw cli::UsageError(fmt::format("cannot read script {}", path));
    std::stringstream ss;
    ss << in.rdbuf();
    return parse_script_text(ss.str(), path, lattice);
}

}  // namespace liveset::viewer
