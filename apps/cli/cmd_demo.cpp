// `liveset demo`, the README's main job: phantom -> segment (seeds, default parameters but no N4:
// the phantom's bias leaves the holes the demo repairs) -> mesh -> eval -> swarm repair with targets placed at the holes (as a user would
// click them, one after another) -> eval again, with a report (Dice and holes before and after,
// timings) and every output written to a folder.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "demo_brain.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "demo_pictures.hpp"
#include "liveset/eval/perforations.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/window.hpp"
#include "liveset/session/repair_presets.hpp"
#include "liveset/swarm/repair.hpp"
#include "liveset/swarm/repair_schedule.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::cli {

namespace {

struct DemoArgs {
    std::string out = "liveset-demo";
    int size = 128;
    std::uint64_t seed = 1;
    int rounds = 30;        // repair rounds (one target each; the schedule stops when no hole is left)
    int round_steps = 100;  // swarm steps per round
    // Repair rule: sheet-fallback (the default: the sheet rule, a stalled hole's round the intensity
    // rule), sheet, or intensity (population statistics).
    std::string rule = "sheet-fallback";
    bool json = false, quiet = false, no_view = false;
    bool brain = false;  // the real-brain demo instead (demo_brain.hpp)
    bool repair = false;  // with --brain: the paper's Figure 5 (low threshold, finder, swarm repair)
    BrainDemoArgs brain_args;
};

// --repair-rule sheet: the sheet rule (EditDecision::kSheet) with the grey matter's band from the
// tissue model of the phantom, shifted to the sheet's intensity around each target.
// With `fallback` (--repair-rule sheet-fallback) a round aimed at a hole whose earlier round stalled
// (HoleSite::stalled_rounds: the sheet rule changed nothing there, e.g. a bias-bright tunnel whose
// voxels lie above the band) uses the intensity rule of demo_repair_options() instead, its brush
// at most that rule's 8 voxels: only where the sheet rule already failed, one small brush at a time.
RoundSetup sheet_rule_setup(const Grid<float>& image, const SegmentOutcome& o, const SparseField& repaired, RepairOptions& ro,
                            bool fallback) {
    std::vector<std::string> warnings;
    TissueModel model;
    const std::optional<ModelWindow> w = sheet_window(image, o.mask, nullptr, TissueModelOptions{}, warnings, &model);
    if (!w) throw UsageError("demo --repair-rule sheet: the tissue model cannot tell the sheet's tissue");
    const double lo = o.scale.to_unit(w->lower), hi = o.scale.to_unit(w->upper);
    const double mean = o.scale.to_unit(model.classes[static_cast<std::size_t>(w->seed_class)].mean);
    ro.swarm.decision = EditDecision::kSheet;
    ro.swarm.sheet_lower = lo;
    ro.swarm.sheet_upper = hi;
    // The phantom's holes are local bias bumps that lift the shell's grey matter to the white
    // matter's intensity (phantom.hpp, "Bias"): no intensity tells their tissue, so the between test
    // decides alone here. On real scans (finder_repair, repair --decision sheet) the limit holds.
    ro.swarm.sheet_between_limited = false;
    ro.swarm.edit_radius = 2.0;
    const SparseField* field = &repaired;
    auto unit = std::make_shared<Grid<float>>(normalise(image, o.scale));
    return [=](RepairOptions& r, const HoleSite& t) {
        const auto [l, u] = local_sheet_band(*unit, field->phi(), t.position, 10.0, lo, hi, mean);
        r.swarm.sheet_lower = l;
        r.swarm.sheet_upper = u;
        if (fallback && t.stalled_rounds > 0) {
            const RepairOptions d = demo_repair_options();
            r.swarm.decision = d.swarm.decision;
            r.swarm.edit_radius = d.swarm.edit_radius;
            r.swarm.edit_range = std::min(r.swarm.edit_range, d.swarm.edit_range);
        }
    };
}

// The demo's repair, through `session`: each round points the swarm at the largest perforation left
// (found from the truth, as a user would see it) with the brush (edit range) sized to that hole, and
// runs round_steps swarm steps. Returns the report's "repair" object (without the triangles) and
// the first hole (where the live window aims the swarm).
nlohmann::json run_demo_repair(const DemoArgs& a, const Phantom& ph, const SegmentOutcome& o, Session& session,
                               std::optional<Vec3d>& first_hole) {
    Grid<std::uint8_t> white(ph.labels.lattice(), 0);
    for (PointIndex i = 0; i < white.size(); ++i) white[i] = ph.labels[i] == kWhiteMatter;
    RepairOptions ro = demo_repair_options();
    ro.swarm.seed = a.seed;
    // The holes a user would point at: perforations first, then spurious cavities (bubbles).
    // The sheet rule is aimed at each hole's widest opening, the intensity rule at its centroid.
    const bool sheet = a.rule != "intensity";
    const HoleAim aim = sheet ? HoleAim::kOpening : HoleAim::kCentroid;
    const HoleSiteFinder holes_left = [&](const SparseField& field) {
        return truth_hole_sites(inside_mask(field.phi()), ph.truth, white, aim);
    };
    const std::vector<HoleSite> first = holes_left(session.field());
    first_hole = first.empty() ? std::nullopt : std::optional<Vec3d>(first.front().position);
    RepairScheduleOptions so;
    so.rounds = a.rounds;
    so.round_steps = a.round_steps;
    RoundSetup setup;
    if (sheet) {
        setup = sheet_rule_setup(ph.image, o, session.field(), ro, a.rule == "sheet-fallback");
        // The sheet rule raises only the sheet's tissue or what lies between its sides, so the
        // brush may span a whole hole (the intensity rule's growth spills, its brush stays at 8).
        so.max_range = 16.0;
    }
    SessionRepairDriver driver(session);
    const RepairScheduleResult sched = run_repair_schedule(driver, ro, so, holes_left, setup);
    nlohmann::json rounds = nlohmann::json::array();
    std::size_t steps = 0, fragments = 0, modified = 0;
    double repair_ms = 0.0;
    for (const RepairRoundLog& r : sched.rounds) {
        const Vec3d t = r.target.position;
        rounds.push_back({{"target", {t.x, t.y, t.z}}, {"hole_voxels", r.target.voxels}, {"holes", r.holes}, {"edit_range", r.edit_range},
                          {"cut", r.target.cut}});
        steps += static_cast<std::size_t>(r.steps);
        fragments += r.fragments;
        modified += r.modified;
        repair_ms += r.ms;
    }
    return {{"rule", a.rule}, {"agents", ro.swarm.agents}, {"p", ro.swarm.act_probability}, {"rounds", rounds}, {"steps", steps},
            {"holes_left", sched.holes_left}, {"points_modified", modified}, {"fragments_rebuilt", fragments},
            {"ms_per_step", steps ? repair_ms / static_cast<double>(steps) : 0.0}, {"ms", repair_ms}};
}

// The text summary (the report `j` holds every figure).
void print_demo_summary(const DemoArgs& a, const nlohmann::json& j, std::size_t seeds) {
    const nlohmann::json &t = j["timings_ms"], &r = j["repair"], &ev = j["before"], &after = j["after"];
    fmt::print("liveset demo: threshold level-set segmentation of the grey matter of a {}^3 synthetic cortex phantom\n", a.size);
    fmt::print("  phantom      {:.0f} ms ({} seeds in grey matter)\n", t["phantom"].get<double>(), seeds);
    print_segmentation_summary(j["segmentation"]);
    fmt::print("  mesh         {} triangles in {} fragments of 16^3 cells, {:.1f} ms\n", j["mesh"]["triangles"].get<std::size_t>(),
               j["mesh"]["fragments"].get<std::size_t>(), t["mesh"].get<double>());
    fmt::print("  evaluation   against the phantom's ground truth ({:.0f} ms):\n", t["eval"].get<double>());
    print_evaluation(ev, "               ");
    fmt::print("  repair       {} rounds, each {} agents for {} steps at the largest hole left (p = {}): {} steps, {:.3f} ms/step,\n"
               "               {} fragment rebuilds; perforations/cavities left {}\n",
               r["rounds"].size(), r["agents"].get<std::size_t>(), a.round_steps, r["p"].get<double>(), r["steps"].get<std::size_t>(),
               r["ms_per_step"].get<double>(), r["fragments_rebuilt"].get<std::size_t>(), r["holes_left"].get<std::size_t>());
    fmt::print("  before       dice {:.4f}  holes {}\n", ev["dice"].get<double>(), ev["holes"].get<long>());
    fmt::print("  after        dice {:.4f}  holes {}\n", after["dice"].get<double>(), after["holes"].get<long>());
    fmt::print("  outputs      {}/ (t1, truth_gm, seg, phi, seg_repaired, phi_repaired .nii.gz; surface(_repaired).ply; before/after.png; report.json)\n", a.out);
}

// The README's main job, step by step in the order the report lists them (phantom, segmentation,
// the session's mesh, evaluation, repair, outputs): a little over 80 lines, kept in one piece so it
// reads as the pipeline it demonstrates.
int run_demo(const DemoArgs& a, int threads, const DemoWindow& window) {
    namespace fs = std::filesystem;
    using clock = std::chrono::steady_clock;
    const auto guard = limit_threads(threads);
    std::error_code ec;
    fs::create_directories(a.out, ec);
    if (ec || !fs::is_directory(a.out)) throw UsageError(fmt::format("cannot create output folder {}", a.out));
    const fs::path dir(a.out);
    check_output_path((dir / "seg.nii.gz").string(), OutputKind::kImage, "--out");

    auto t0 = clock::now();
    PhantomOptions po;
    po.size = a.size;
    po.seed = a.seed;
    const Phantom ph = make_phantom(po);
    const double phantom_ms = ms_since(t0);

    SegmentRequest req;
    for (const Vec3i& s : ph.seeds) req.seeds.push_back({{static_cast<double>(s.x), static_cast<double>(s.y), static_cast<double>(s.z)}, 2.0});
    // The phantom's holes come from its bias field, on purpose: the demo segments with the seeds'
    // statistics window, which its repair presets were made for. (The tissue model's window, the
    // default of `liveset segment`, gives Dice 0.9752 here, but the repair rounds then leave one
    // tunnel: holes 2 -> 1; docs/BENCHMARKS.md. `liveset demo --brain` shows the model window.)
    // --repair-rule sheet alone segments with the model's window (docs/BENCHMARKS.md, session 10);
    // its tunnels at 96^3 include handles of bias-bright voxels that no growth can close.
    req.window.estimate = a.rule == "sheet" ? WindowSource::kModel : WindowSource::kSeeds;
    req.alpha = 0.1;  // the curvature the presets were made with (the automatic α would pick its own)
    const bool quiet_progress = a.quiet || a.json;
    const SegmentRun run = segment_with_progress(ph.image, req, quiet_progress);
    if (run.interrupted) {
        fmt::print(stderr, "liveset: interrupted; nothing written\n");
        return 130;
    }
    const SegmentOutcome& o = run.outcome;

    // Everything after the segmentation edits through a Session (the viewer's edit path): it takes
    // over the segmentation's level set bit for bit and its intensity scale, meshes it (16³-cell
    // fragments), and meshes and records every swarm step of the repair.
    t0 = clock::now();
    SessionOptions session_options;
    session_options.given_scale = o.scale;
    Session session(ph.image, session_options);
    if (!session.load_recovered(o.field->phi(), o.field->status(), SessionMarks{}))
        throw std::logic_error("the session did not take the segmentation's level set over exactly");
    const FragmentMesher& mesher = session.mesher();
    const double mesh_ms = ms_since(t0);
    const Mesh surface = weld_vertices(mesher.merged().view());
    const Grid<float> phi_before = o.field->phi();

    t0 = clock::now();
    nlohmann::json ev = evaluation_report(o.mask, ph.truth);
    const double eval_ms = ms_since(t0);

    std::optional<Vec3d> first_hole;
    nlohmann::json repair = run_demo_repair(a, ph, o, session, first_hole);
    const double repair_ms = repair["ms"].get<double>();
    repair.erase("ms");
    const Grid<std::uint8_t> repaired = inside_mask(session.field().phi());
    nlohmann::json after = evaluation_report(repaired, ph.truth);
    const Mesh repaired_surface = weld_vertices(mesher.merged().view());

    write_image(ph.image, (dir / "t1.nii.gz").string());
    write_label_image(ph.truth, (dir / "truth_gm.nii.gz").string());
    write_label_image(o.mask, (dir / "seg.nii.gz").string());
    write_image(phi_before, (dir / "phi.nii.gz").string());
    write_mesh(dir / "surface.ply", surface.view(), ph.image.lattice());
    write_label_image(repaired, (dir / "seg_repaired.nii.gz").string());
    write_image(session.field().phi(), (dir / "phi_repaired.nii.gz").string());
    write_mesh(dir / "surface_repaired.ply", repaired_surface.view(), ph.image.lattice());

    nlohmann::json j;
    j["demo"] = "phantom -> segment -> mesh -> eval -> swarm repair at the holes -> eval";
    j["phantom"] = {{"size", a.size}, {"seed", a.seed}, {"seeds", ph.seeds.size()}};
    j["segmentation"] = segmentation_report(o, ph.image.lattice());
    j["mesh"] = {{"fragments", mesher.fragment_count()}, {"fragment_size", 16}, {"triangles", surface.triangle_count()},
                 {"vertices", surface.vertices.size()}, {"euler", euler_characteristic(surface.view())}};
    j["eval"] = ev;
    j["before"] = ev;
    j["after"] = after;
    j["dice"] = after["dice"];
    j["holes"] = after["holes"];
    j["repair"] = repair;
    j["repair"]["triangles"] = repaired_surface.triangle_count();
    j["timings_ms"] = {{"phantom", phantom_ms}, {"segment", 1000.0 * o.result.seconds}, {"mesh", mesh_ms}, {"eval", eval_ms},
                       {"repair", repair_ms}};
    j["outputs"] = a.out;
    j["screenshots"] = write_before_after_pictures(dir, phi_before, mesher);  // superior view, headless
    write_atomically((dir / "report.json").string(), j.dump(2) + "\n");
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        print_demo_summary(a, j, ph.seeds.size());
    }
    // With a display: the viewer on the segmented phantom, the swarm repairing the first hole live.
    if (!a.no_view && !a.json && first_hole && window.available && window.open && window.available()) {
        auto session = std::make_unique<Session>(ph.image, SessionOptions{});
        session->load_phi(phi_before);
        return window.open(std::move(session), *first_hole);
    }
    return 0;
}

}  // namespace

void add_demo_command(CLI::App& app, const int& threads, DemoWindow window) {
    static DemoArgs da;
    static DemoWindow live;
    live = std::move(window);
    auto* demo = app.add_subcommand("demo", "the main job: phantom -> segment -> mesh -> eval, with a report");
    CLI::Option* out = demo->add_option("--out", da.out, "output folder (liveset-demo; liveset-demo-brain with --brain)")->capture_default_str();
    demo->add_option("--size", da.size, "phantom voxels per axis")->check(CLI::Range(48, 256))->capture_default_str();
    demo->add_option("--seed", da.seed, "phantom noise seed")->capture_default_str();
    demo->add_option("--rounds", da.rounds, "repair rounds (one target, the largest hole left, each)")->check(CLI::Range(0, 1000))->capture_default_str();
    demo->add_option("--round-steps", da.round_steps, "swarm steps per repair round")->check(CLI::Range(1, 100000))->capture_default_str();
    demo->add_option("--repair-rule", da.rule, "sheet-fallback: the sheet rule, a hole whose round stalled gets the intensity rule (seeds' window); intensity: the population-statistics rule with the seeds' window (the presets); sheet: the sheet rule with the tissue model's window")->check(CLI::IsMember({"sheet-fallback", "intensity", "sheet"}))->capture_default_str();
    demo->add_flag("--json", da.json, "print the report as one JSON object on stdout");
    demo->add_flag("--quiet,-q", da.quiet, "print nothing");
    demo->add_flag("--no-view", da.no_view, "do not open the viewer even when a display is available (--json implies it)");
    demo->add_flag("--brain", da.brain, "the real-brain path instead: BrainWeb T1 (bundled in data/brainweb), seeds only -> segment -> mesh -> eval");
    demo->add_flag("--repair", da.repair, "with --brain: segment with a sub-optimally low threshold, find the holes without truth, repair them with 200 agents (the paper's Figure 5)");
    demo->add_option("--data", da.brain_args.data, "with --brain: the folder holding t1.mha, labels_crisp.nii.gz and brain_mask.nii.gz")->capture_default_str();
    demo->callback([&threads, out] {
        if (da.brain) {
            da.brain_args.json = da.json;
            da.brain_args.quiet = da.quiet;
            da.brain_args.repair = da.repair;
            if (out->count() > 0) da.brain_args.out = da.out;
            const int rc = run_brain_demo(da.brain_args, threads);
            if (rc != 0) std::exit(rc);
            return;
        }
        const int rc = run_demo(da, threads, live);
        if (rc != 0) std::exit(rc);
    });
}

}  // namespace liveset::cli
