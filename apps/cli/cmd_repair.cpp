// `liveset repair`: headless agent-swarm repair of a segmentation where the user points (paper §4),
// for scripts, tests and the demo. Each step: swarm move -> edits -> local level-set update ->
// incremental mesh; one JSON line per step in --log.
#include <fmt/core.h>

#include <algorithm>

#include <chrono>

#include <cmath>
#include <ctime>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "finder_repair.hpp"
#include "image_commands.hpp"
#include "liveset/session/hole_scan.hpp"
#include "liveset/session/session.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/window.hpp"
#include "liveset/swarm/repair.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::cli {

namespace {

struct RepairArgs {
    std::string input, image, roi;
    std::vector<std::string> targets, targets_mm;
    RepairOptions options;
    std::string out_phi, out_mask, out_mesh, log;
    std::string decision = "intensity";
    std::optional<double> sheet_lower, sheet_upper;  // the sheet's band (raw); from the tissue model when absent
    std::size_t find_holes = 0;  // --find-holes N: the finder's N largest holes are the targets, one round each
    int round_steps = 1000;      // --round-steps (with --find-holes)
    std::size_t min_hole = 50;   // --min-hole (with --find-holes)
    bool p_given = false, decision_given = false, steps_given = false, share_given = false, range_given = false;
    bool json = false, quiet = false;
};

// "I,J,K[@STEP]" -> target (coordinates parsed like a seed).
RepairTarget parse_target(const std::string& text, const Lattice& lattice, bool mm) {
    std::string coords = text;
    int step = 0;
    if (const auto at = text.find('@'); at != std::string::npos) {
        coords = text.substr(0, at);
        const std::string s = text.substr(at + 1);
        try {
            std::size_t used = 0;
            step = std::stoi(s, &used);
            if (used != s.size() || step < 0) throw std::invalid_argument(s);
        } catch (const std::exception&) {
            throw UsageError(fmt::format("bad target '{}': the step after '@' must be a non-negative integer", text));
        }
    }
    if (coords.find(':') != std::string::npos) throw UsageError(fmt::format("bad target '{}': targets take no radius", text));
    const SeedBall b = mm ? parse_seed_mm(coords, lattice, 1.0) : parse_seed_voxel(coords, 1.0);
    if (!lattice.contains(b.center)) throw UsageError(fmt::format("target {} lies outside the image", text));
    return {b.center, step};
}

constexpr double kVerdictRadius = kHoleVerdictRadius;  // the finder's verdict counts hole voxels this close to a target

// The sheet's band for the finder's verdicts and --decision sheet: given (its mean the band's
// middle), or the tissue model's (model_sheet_band; nullopt when it cannot be told).
std::optional<SheetBand> sheet_band(const RepairArgs& a, const Grid<float>& image, const Grid<std::uint8_t>& mask,
                                    const Grid<std::uint8_t>* roi, const BrainMaskOptions& brain) {
    if (a.sheet_lower) return SheetBand{*a.sheet_lower, *a.sheet_upper, 0.5 * (*a.sheet_lower + *a.sheet_upper)};
    return model_sheet_band(image, mask, roi, brain);
}

// Bad targets, before anything runs or is written: outside the ROI, or with no surface within the
// brush (the edit range; the spawn radius without one) — one line each.
void check_targets(const std::vector<RepairTarget>& targets, const SparseField& field, const Grid<std::uint8_t>* roi,
                   const RepairOptions& o) {
    const Lattice& lat = field.lattice();
    const double reach = o.swarm.edit_range > 0 ? o.swarm.edit_range : o.spawn_radius;
    for (const RepairTarget& t : targets) {
        const Vec3i c{static_cast<int>(std::lround(t.position.x)), static_cast<int>(std::lround(t.position.y)),
                      static_cast<int>(std::lround(t.position.z))};
        const std::string at = fmt::format("{},{},{}", t.position.x, t.position.y, t.position.z);
        if (roi && !(*roi)(c)) throw UsageError(fmt::format("target {} lies outside the region of interest", at));
        bool near = false;
        for (PointIndex i : field.zero_layer()) {
            const Vec3d d = lat.coord(i).cast<double>() - t.position;
            if (dot(d, d) <= reach * reach) {
                near = true;
                break;
            }
        }
        if (!near) throw UsageError(fmt::format("target {} has no surface within {:g} voxels (the brush)", at, reach));
    }
}

// One line per target: the finder's verdict and the local genus.
void print_verdicts(const nlohmann::json& verdicts, bool have_band) {
    if (!have_band) fmt::print("  (no hole verdicts: the tissue model cannot tell the sheet's tissue)\n");
    for (const nlohmann::json& v : verdicts) {
        const std::size_t b = v["finder_voxels_near"]["before"], a = v["finder_voxels_near"]["after"];
        fmt::print("  target {},{},{}: finder hole voxels within {:g}: {} -> {} ({}), local genus {} -> {}\n", v["target"][0].get<int>(),
                   v["target"][1].get<int>(), v["target"][2].get<int>(), kVerdictRadius, b, a,
                   b == 0 ? "no hole there" : (v["closed"].get<bool>() ? "closed" : "open"), v["local_genus"]["before"].get<long>(),
                   v["local_genus"]["after"].get<long>());
    }
}

// The swarm steps of `liveset repair` through the session: target k becomes the swarm's target from
// its step on (as run_repair does on a bare field); stops early on Ctrl-C.
std::vector<RepairStepLog> run_targets(Session& session, std::vector<RepairTarget> order, int steps, const std::atomic<bool>& interrupt) {
    std::stable_sort(order.begin(), order.end(), [](const RepairTarget& x, const RepairTarget& y) { return x.step < y.step; });
    std::vector<RepairStepLog> log;
    std::size_t next = 0;
    for (int step = 0; step < steps; ++step) {
        if (interrupt.load(std::memory_order_relaxed)) break;
        const auto t0 = std::chrono::steady_clock::now();
        const std::clock_t c0 = std::clock();
        while (next < order.size() && order[next].step <= step) session.set_target(order[next++].position);
        RepairStepLog rec = session.swarm_step().swarm;
        rec.step = step;
        rec.ms = ms_since(t0);
        rec.cpu_ms = 1000.0 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC;
        log.push_back(rec);
    }
    return log;
}

// Every option checked before any work starts (the sheet band, when given, checked with the rest).
void check_repair_args(RepairArgs& a) {
    if (a.out_phi.empty() && a.out_mask.empty()) throw UsageError("give --out-phi and/or --out-mask");
    if (!a.out_phi.empty()) check_output_path(a.out_phi, OutputKind::kImage, "--out-phi");
    if (!a.out_mask.empty()) check_output_path(a.out_mask, OutputKind::kImage, "--out-mask");
    if (!a.out_mesh.empty()) check_output_path(a.out_mesh, OutputKind::kMesh, "--out-mesh");
    if (!a.log.empty()) check_output_path(a.log, OutputKind::kText, "--log");
    if (a.sheet_lower.has_value() != a.sheet_upper.has_value()) throw UsageError("give both --sheet-lower and --sheet-upper, or neither");
    if (a.sheet_lower && !(*a.sheet_lower < *a.sheet_upper)) throw UsageError("--sheet-lower must be below --sheet-upper");
    if (a.find_holes > 0) {
        if (!a.targets.empty() || !a.targets_mm.empty()) throw UsageError("give --target/--target-mm or --find-holes, not both");
        if (a.decision_given && a.decision != "sheet") throw UsageError("--find-holes repairs with the sheet rule: leave out --decision or give --decision sheet");
        if (a.steps_given) throw UsageError("--find-holes runs --round-steps steps per hole: give --round-steps instead of --steps");
        if (a.round_steps < 1) throw UsageError("--round-steps must be at least 1");
        a.decision = "sheet";
        if (!a.p_given) a.options.swarm.act_probability = FoundHolesInput::default_options().swarm.act_probability;
    } else if (a.targets.empty() && a.targets_mm.empty()) {
        throw UsageError("give at least one --target I,J,K[@STEP] (or --target-mm), or --find-holes N");
    }
    a.options.swarm.decision = edit_decision_named(a.decision).value();  // CLI11 checked the name
    if (a.options.swarm.decision == EditDecision::kCut) {
        if (!a.options.topology_guard)
            throw UsageError("--decision cut removes only what cuts a handle, which the topology guard decides: it cannot go with --no-topology-guard");
        if (!a.range_given) a.options.swarm.edit_range = 3.0;  // the brush around the handle
    }
    if (!a.options.swarm.sheet_between && a.options.swarm.decision != EditDecision::kSheet)
        throw UsageError("--band-only is a setting of the sheet rule: give it with --decision sheet");
    if (a.share_given && a.options.swarm.decision != EditDecision::kSheet)
        throw UsageError("--between-share is a setting of the sheet rule: give it with --decision sheet");
    if (a.share_given && !a.options.swarm.sheet_between)
        throw UsageError("--between-share sets what the between-the-sides test admits: it cannot go with --band-only");
    if (!a.options.close_cracks && !a.options.topology_guard)
        throw UsageError("--no-crack-closing is a setting of the topology guard: it cannot go with --no-topology-guard");
    if (a.options.swarm.decision == EditDecision::kSheet) {  // checked with the band below
        a.options.swarm.sheet_lower = 0.0;
        a.options.swarm.sheet_upper = 1.0;
    }
    try {
        validate(a.options.swarm);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
}

// The step log (--log), the summary (text or --json) of a --target run.
void print_step_summary(const RepairArgs& a, const std::vector<RepairStepLog>& log, const nlohmann::json& verdicts,
                        const std::optional<SheetBand>& band) {
    std::size_t modified = 0, fragments = 0;
    double ms = 0;
    std::string lines;
    for (const RepairStepLog& r : log) {
        modified += r.modified;
        fragments += r.fragments;
        ms += r.ms;
        lines += fmt::format("{{\"step\":{},\"agents_on_surface\":{},\"points_modified\":{},\"changed\":{},\"fragments_rebuilt\":{},\"ms\":{:.4f},"
                             "\"cpu_ms\":{:.4f},\"guard_ms\":{:.4f},\"level_set_ms\":{:.4f},\"mesh_ms\":{:.4f}}}\n",
                             r.step, r.on_surface, r.modified, r.changed, r.fragments, r.ms, r.cpu_ms, r.guard_ms, r.level_set_ms,
                             r.mesh_ms);
    }
    if (!a.log.empty()) write_atomically(a.log, lines);
    nlohmann::json j{{"steps", log.size()}, {"agents", a.options.swarm.agents}, {"points_modified", modified},
                     {"fragments_rebuilt", fragments}, {"ms_per_step", log.empty() ? 0.0 : ms / static_cast<double>(log.size())},
                     {"agents_on_surface_end", log.empty() ? 0 : log.back().on_surface}, {"targets", verdicts},
                     {"verdict_radius", kVerdictRadius}};
    if (band) j["sheet_band"] = {band->lower, band->upper};
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        fmt::print("liveset repair: {} steps of {} agents, {} point edits, {} fragment rebuilds, {:.3f} ms/step\n", log.size(),
                   a.options.swarm.agents, modified, fragments, j["ms_per_step"].get<double>());
        print_verdicts(verdicts, band.has_value());
    }
}

// The outputs every path writes: --out-phi, --out-mask, --out-mesh.
void write_outputs(const RepairArgs& a, const SparseField& field, const Grid<std::uint8_t>& mask, const Lattice& lattice, bool oriented) {
    if (!a.out_phi.empty()) write_image(field.phi(), a.out_phi, {.orientation_known = oriented});
    if (!a.out_mask.empty()) write_label_image(mask, a.out_mask, {.orientation_known = oriented});
    if (!a.out_mesh.empty()) write_mesh(a.out_mesh, marching_cubes_band(field.phi(), field.zero_layer()).view(), lattice);
}

// What a repair run works on: the image, the ROI, the session holding the level set, the sheet band.
struct RepairInputs {
    Grid<float> image;
    bool oriented = true;  // the image's header gave an orientation (the outputs say so too)
    std::optional<Grid<std::uint8_t>> roi;
    std::unique_ptr<Session> session;
    std::optional<SheetBand> band;
    Grid<std::uint8_t> mask_before;
    const Grid<std::uint8_t>* roi_ptr() const { return roi ? &*roi : nullptr; }
};

RepairInputs load_inputs(const RepairArgs& a) {
    Scan scan = read_scan(a.image);
    const std::string note = scan.note(a.image);
    RepairInputs in{std::move(scan.image), scan.header.orientation_known, std::nullopt, nullptr, std::nullopt, {}};
    if (!a.roi.empty()) in.roi = load_mask_like(a.roi, in.image.lattice(), "--roi");
    // The repair edits through a Session (the viewer's edit path: local update, history, mesher of
    // 8³-cell fragments); the session's scale is robust_scale(image, roi), as before.
    SessionOptions so;
    so.fragment_size = 8;
    so.brain_mask = brain_mask_options(scan.header);  // without a ROI the brain is looked for as `segment` looks
    in.session = std::make_unique<Session>(in.image, so, in.roi);
    load_level_set(*in.session, a.input);
    in.mask_before = inside_mask(in.session->field().phi(), in.roi_ptr());
    in.band = sheet_band(a, in.image, in.mask_before, in.roi_ptr(), so.brain_mask);
    if (!a.quiet && !note.empty()) fmt::print(stderr, "liveset: note: {}\n", note);  // the inputs are good
    return in;
}

// --find-holes N: the demo's truth-free repair (finder_repair.hpp) on the user's own segmentation.
int run_found_holes(const RepairArgs& a, RepairInputs& in, const InterruptGuard& interrupt) {
    if (!in.band) throw UsageError("--find-holes: the tissue model cannot tell the sheet's tissue; give --sheet-lower and --sheet-upper");
    FoundHolesInput f{in.image, in.roi_ptr(), in.session->scale()};
    f.band = *in.band;
    f.max_targets = a.find_holes;
    f.min_voxels = a.min_hole;
    f.round_steps = a.round_steps;
    f.options = a.options;
    const nlohmann::json j = repair_found_holes(f, *in.session, true, &interrupt.flag());
    if (interrupt.interrupted()) {
        if (!a.quiet) fmt::print(stderr, "liveset: interrupted after {} steps; nothing written\n", j["steps"].get<std::size_t>());
        return 130;
    }
    const SparseField& field = in.session->field();
    write_outputs(a, field, inside_mask(field.phi(), in.roi_ptr()), in.image.lattice(), in.oriented);
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        fmt::print("liveset repair --find-holes: {} targets from the finder (>= {} voxels; {} such holes before, {} after), {} agents x {} steps each, "
                   "sheet rule: {} of {} closed by the finder's verdict, {} voxels added, {:.3f} ms/step\n",
                   j["targets"].size(), a.min_hole, j["finder"]["before"].get<std::size_t>(), j["finder"]["after"].get<std::size_t>(),
                   a.options.swarm.agents, a.round_steps, j["closed"].get<std::size_t>(), j["targets"].size(),
                   j["voxels_added"].get<std::size_t>(), j["ms_per_step"].get<double>());
        print_verdicts(j["verdicts"], true);
    }
    return 0;
}

// --target / --target-mm: the swarm aimed where the user points, target k from its step on.
int run_given_targets(RepairArgs a, RepairInputs& in, const InterruptGuard& interrupt) {
    std::vector<RepairTarget> targets;
    for (const std::string& t : a.targets) targets.push_back(parse_target(t, in.image.lattice(), false));
    for (const std::string& t : a.targets_mm) targets.push_back(parse_target(t, in.image.lattice(), true));
    Session& session = *in.session;
    const SparseField& field = session.field();
    check_targets(targets, field, in.roi_ptr(), a.options);
    if (a.options.swarm.decision == EditDecision::kSheet) {
        if (!in.band) throw UsageError("--decision sheet: the tissue model cannot tell the sheet's tissue; give --sheet-lower and --sheet-upper");
        a.options.swarm.sheet_lower = session.scale().to_unit(in.band->lower);
        a.options.swarm.sheet_upper = session.scale().to_unit(in.band->upper);
        a.options.swarm.sheet_mean = std::clamp(session.scale().to_unit(in.band->mean), a.options.swarm.sheet_lower,
                                                a.options.swarm.sheet_upper);
    }
    session.set_repair_options(a.options);
    const std::vector<RepairStepLog> log = run_targets(session, targets, a.options.steps, interrupt.flag());
    if (interrupt.interrupted()) {
        if (!a.quiet) fmt::print(stderr, "liveset: interrupted after {} steps; nothing written\n", log.size());
        return 130;
    }
    const Grid<std::uint8_t> mask = inside_mask(field.phi(), in.roi_ptr());
    nlohmann::json verdicts = nlohmann::json::array();
    if (in.band) {  // the finder's verdict per target (no ground truth)
        const Grid<std::uint8_t> hb = hole_voxels(in.mask_before, in.image, in.roi_ptr(), in.band->finder());
        const Grid<std::uint8_t> ha = hole_voxels(mask, in.image, in.roi_ptr(), in.band->finder());
        for (const RepairTarget& t : targets) {
            const HoleVerdict v = hole_verdict(t.position, kVerdictRadius, hb, ha, in.mask_before, mask);
            verdicts.push_back(verdict_json(Vec3i{static_cast<int>(std::lround(t.position.x)), static_cast<int>(std::lround(t.position.y)),
                                                  static_cast<int>(std::lround(t.position.z))}, 0, v));
        }
    }
    write_outputs(a, field, mask, in.image.lattice(), in.oriented);
    print_step_summary(a, log, verdicts, in.band);
    return 0;
}

int run_repair_command(RepairArgs a, int threads) {
    const auto guard = limit_threads(threads);
    const InterruptGuard interrupt;
    check_repair_args(a);
    RepairInputs in = load_inputs(a);
    return a.find_holes > 0 ? run_found_holes(a, in, interrupt) : run_given_targets(a, in, interrupt);
}

}  // namespace

void add_repair_command(CLI::App& app, const int& threads) {
    static RepairArgs ra;
    auto* r = app.add_subcommand("repair", "agent-swarm repair of a segmentation around target points (paper section 4)");
    r->add_option("input", ra.input, "phi (<0 inside) or 0/1 mask to repair")->required();
    r->add_option("--image", ra.image, "the image the segmentation came from: segment's --out-corrected image (segment corrects the bias by default), or the input with --no-bias-correct")->required();
    r->add_option("--target", ra.targets, "target voxel I,J,K[@STEP] (from step STEP on; default 0); repeatable");
    r->add_option("--target-mm", ra.targets_mm, "target X,Y,Z[@STEP] in physical LPS mm; repeatable");
    r->add_option("--find-holes", ra.find_holes, "no targets needed: the truth-free hole finder's N largest holes (as `liveset holes` lists them, >= --min-hole voxels, 12 voxels apart) are repaired one round each with the sheet rule, the brush sized to the hole and the band sampled around it, as `liveset demo --brain --repair` does (p 0.3 unless --p is given)")
        ->check(CLI::Range(std::size_t{1}, std::size_t{1000}));
    r->add_option("--round-steps", ra.round_steps, "with --find-holes: swarm steps per hole")->check(CLI::Range(1, 10'000'000))->capture_default_str();
    r->add_option("--min-hole", ra.min_hole, "with --find-holes: the smallest hole repaired, voxels")->check(CLI::Range(std::size_t{1}, std::size_t{1} << 40))->capture_default_str();
    r->add_option("--roi", ra.roi, "region-of-interest mask the surface may not grow out of");
    r->add_option("--agents", ra.options.swarm.agents, "number of agents")->check(CLI::Range(1, 1'000'000))->capture_default_str();
    r->add_option("--steps", ra.options.steps, "swarm steps")->check(CLI::Range(0, 10'000'000))->capture_default_str();
    r->add_option("--p", ra.options.swarm.act_probability, "probability that an agent edits per step")->check(finite_number())->capture_default_str();
    r->add_option("--radius", ra.options.swarm.edit_radius, "edit radius, voxels")->check(finite_number())->capture_default_str();
    r->add_option("--respawn-distance", ra.options.respawn_distance, "a target farther than this (voxels) from the swarm respawns it there (0: never)")->check(CLI::Range(0.0, 1e6))->capture_default_str();
    r->add_option("--seed", ra.options.swarm.seed, "random seed")->capture_default_str();
    r->add_option("--amount", ra.options.swarm.edit_amount, "|dphi| under an acting agent (<= 0.5)")->check(finite_number())->capture_default_str();
    r->add_option("--expand-sigmas", ra.options.swarm.expand_sigmas, "expand where the outside intensity is within this many population sigmas")->check(finite_number())->capture_default_str();
    r->add_option("--contract-sigmas", ra.options.swarm.contract_sigmas, "contract where the inside intensity is beyond this many sigmas")->check(finite_number())->capture_default_str();
    r->add_option("--sample-depth", ra.options.swarm.sample_depth, "population samples this many voxels inside the surface (0: at the agents)")->check(finite_number())->capture_default_str();
    r->add_option("--edit-range", ra.options.swarm.edit_range, "only agents within this many voxels of the target edit (0: all; --decision cut: 3 unless given, and > 0)")->check(finite_number())->capture_default_str();
    r->add_option("--decision", ra.decision, "how acting agents edit: intensity (population statistics), sheet (grow only into voxels in the sheet tissue's band: hole repair without growing into the neighbours), cut (lower the surface, keeping only the removals that cut a handle of the segmentation; brush 3 voxels unless --edit-range) or random (the paper's speed test)")
        ->check(CLI::IsMember({"intensity", "random", "sheet", "cut"}))
        ->capture_default_str();
    r->add_option("--sheet-lower", ra.sheet_lower, "the sheet tissue's lowest intensity (raw; default: the tissue model's)")->check(finite_number());
    r->add_option("--sheet-upper", ra.sheet_upper, "the sheet tissue's highest intensity (raw; default: the tissue model's)")->check(finite_number());
    r->add_flag("--no-topology-guard{false}", ra.options.topology_guard, "let edits bridge pieces or open tunnels (by default they cannot)");
    r->add_flag("--band-only{false}", ra.options.swarm.sheet_between, "sheet rule: raise only voxels in the band (by default also voxels between the sheet's two sides)");
    r->add_option("--between-share", ra.options.swarm.sheet_between_share, "sheet rule: the smallest share of the sheet's tissue (by its intensity, partial-volume model) a voxel admitted for lying between the sheet's sides must hold; 0.5 = the band only, 0 = up to the neighbouring tissues' means")
        ->check(CLI::Range(0.0, 0.5))
        ->capture_default_str();
    r->add_flag("--no-crack-closing{false}", ra.options.close_cracks, "refuse every bridge (by default a one-voxel crack between two fronts is filled whole when that closes a tunnel)");
    r->add_option("--out-phi", ra.out_phi, "repaired phi");
    r->add_option("--out-mask", ra.out_mask, "repaired mask");
    r->add_option("--out-mesh", ra.out_mesh, "repaired surface (.ply/.obj/.stl)");
    r->add_option("--log", ra.log, "one JSON line per step: step, agents_on_surface, points_modified, changed, fragments_rebuilt, ms, cpu_ms (processor time), and of ms: guard_ms, level_set_ms, mesh_ms (the rest is the agents' move and proposals)");
    r->add_flag("--json", ra.json, "print the summary as one JSON object");
    r->add_flag("--quiet,-q", ra.quiet, "print nothing");
    r->callback([&threads, r] {
        ra.p_given = r->count("--p") > 0;
        ra.decision_given = r->count("--decision") > 0;
        ra.steps_given = r->count("--steps") > 0;
        ra.share_given = r->count("--between-share") > 0;
        ra.range_given = r->count("--edit-range") > 0;
        if (ra.find_holes == 0 && (r->count("--round-steps") > 0 || r->count("--min-hole") > 0))
            throw UsageError("--round-steps and --min-hole are settings of --find-holes");
        const int rc = run_repair_command(ra, threads);
        if (rc != 0) std::exit(rc);
    });
}

}  // namespace liveset::cli
