// A scripted session, end to end through `liveset view --headless --script`: seeds and
// segmentation of the 128^3 phantom leave its two perforations (holes = 2); then, round by round,
// a script aims the swarm at the largest hole left (perforations, then sealed-off cavities, found
// from the truth as the demo does) with the demo's swarm settings, until `holes` = 0 without losing
// more than 0.005 of Dice. Also:
// a bad script is refused with one line naming the entry, before anything runs; a "display" entry's
// zoom and window/level reach the slice pane's pixels (a second window re-grades the same slice);
// the cut rule, chosen by a script, cuts a handle at the target; `--bench` reports the renderer
// and its four scenarios, of which only the repairing ones rebuild fragments.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <sstream>

#include "analytic_head.hpp"
#include "cli/cli_run.hpp"
#include "cli/rod_shell.hpp"
#include "liveset/eval/perforations.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/render/png_writer.hpp"
#include "noisy_phantom.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;
using testing::run_cli;
using testing::CliResult;

fs::path scripts_dir() {
    static const fs::path d = testing::scratch_dir("script_test");
    return d;
}

void write_text(const fs::path& p, const std::string& text) {
    std::ofstream(p) << text;
}

// The eval lines ({"entry": k, "eval": {...}}) a script printed.
std::vector<nlohmann::json> evals(const std::string& out) {
    std::vector<nlohmann::json> r;
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && line.front() == '{') r.push_back(nlohmann::json::parse(line)["eval"]);
    return r;
}

struct RepairRun {
    nlohmann::json before, after;  // eval reports after segmentation / after the last round
    std::size_t holes_left = 0;  // perforations, then cavities, as the demo targets them
    int rounds = 0;
};

// Segments the 128^3 phantom with one script, then repairs it round by round with more scripts.
RepairRun scripted_repair() {
    RepairRun run;
    const Phantom ph = make_phantom();  // 128^3: the demo's size, where its swarm settings are tuned
    const fs::path dir = scripts_dir();
    const std::string image = (dir / "t1.nii.gz").string(), truth = (dir / "truth.nii.gz").string();
    write_image(ph.image, image);
    write_label_image(ph.truth, truth);

    std::string seeds;
    for (const Vec3i& s : ph.seeds) seeds += fmt::format("{{\"seed\": [{}, {}, {}]}}, ", s.x, s.y, s.z);
    write_text(dir / "segment.json", "[" + seeds + R"({"segment": "converge"},
        {"save_phi": ")" + (dir / "phi.nii.gz").string() + R"("}, {"save_mask": ")" + (dir / "seg.nii.gz").string() + R"("},
        {"eval": {"truth": ")" + truth + R"("}}])");
    // The seeds' statistics window, which the demo's repair presets were made for, and the exact
    // step (as the phantom demo; with the default sleeping step the segmentation ends with one
    // tunnel that these 20 rounds do not close: issue 18); no N4, as the phantom demo: the phantom's
    // holes are bias bumps, which N4 partly flattens (3 perforations instead of 2); the paper's
    // α 0.1, as the demo (the automatic one is about 0 on this phantom); and without the thin-front
    // rule, as the demo (the paper's sparse field: on this phantom the rule carries the front around
    // the weak spots along their partial-volume rims, a pocket and a handle where the perforations
    // were, docs/BENCHMARKS.md session 71).
    const CliResult seg = run_cli("view " + image + " --window-from seeds --step exact --no-thin-fronts --alpha 0.1 --no-bias-correct --headless --script " +
                                  (dir / "segment.json").string());
    EXPECT_EQ(seg.rc, 0) << seg.err;
    const auto before = evals(seg.out);
    if (before.size() != 1u) {
        ADD_FAILURE() << seg.out << seg.err;
        return run;
    }
    run.before = before[0];

    // As the demo: each round, the user clicks at the largest perforation left (found from the
    // truth) and lets 200 agents with the demo's settings work for 100 steps; every round is its
    // own scripted session continuing from the last one's saved phi.
    Grid<std::uint8_t> white(ph.labels.lattice(), 0);
    for (PointIndex i = 0; i < white.size(); ++i) white[i] = ph.labels[i] == kWhiteMatter;
    std::string phi = (dir / "phi.nii.gz").string(), mask = (dir / "seg.nii.gz").string();
    // The holes a user would point at, as the demo finds them: perforations first, then spurious
    // cavities (bubbles) the repair may have sealed off.
    const auto holes_left = [&](const Grid<std::uint8_t>& m) {
        std::vector<Perforation> h = find_perforations(m, ph.truth, white);
        return h.empty() ? find_cavities(m, white) : h;
    };
    EXPECT_EQ(find_perforations(read_label_image(mask), ph.truth, white).size(), 2u);
    auto holes = holes_left(read_label_image(mask));
    int& rounds = run.rounds;
    for (; rounds < 20 && !holes.empty(); ++rounds) {
        const Vec3d c = holes.front().centroid;
        const std::string next_phi = (dir / fmt::format("phi_{}.nii.gz", rounds)).string();
        mask = (dir / fmt::format("mask_{}.nii.gz", rounds)).string();
        write_text(dir / "repair.json",
                   fmt::format(R"([{{"params": {{"preset": "demo", "seed": {}}}}}, {{"target": [{}, {}, {}]}}, {{"swarm": 100}},
                                  {{"save_phi": "{}"}}, {{"save_mask": "{}"}}, {{"eval": {{"truth": "{}"}}}}])",
                               rounds + 1, c.x, c.y, c.z, next_phi, mask, truth));
        const CliResult rep =
            run_cli("view " + image + " --phi " + phi + " --alpha 0.1 --no-bias-correct --headless --script " + (dir / "repair.json").string());
        const auto e = evals(rep.out);
        if (rep.rc != 0 || e.size() != 1u) {
            ADD_FAILURE() << rep.err;
            return run;
        }
        run.after = e[0];
        phi = next_phi;
        holes = holes_left(read_label_image(mask));
    }
    run.holes_left = holes.size();
    return run;
}

TEST(ScriptedSession, SegmentsThePhantomThenTheSwarmRepairsItToNoHoles) {
    const RepairRun run = scripted_repair();
    ASSERT_FALSE(run.after.is_null());
    EXPECT_EQ(run.before["holes"].get<long>(), 2) << run.before.dump();  // the bias perforates the shell twice
    EXPECT_EQ(run.holes_left, 0u) << "after " << run.rounds << " rounds";
    EXPECT_EQ(run.after["holes"].get<long>(), 0) << run.after.dump();
    EXPECT_EQ(run.after["genus"].get<long>(), 0) << run.after.dump();  // both tunnels closed, none made
    // With the demo's fixed 8-voxel brush the viewer's path closes both holes but Dice falls a little
    // (0.9741 -> ~0.971; the demo now sizes its brush to each hole and Dice rises, see
    // Repair.SwarmClosesThePhantomPerforations). Replayed here round by round through saved phi files
    // (re-initialised each round), the sized brush stalls with one tunnel left after 20 rounds
    // (Dice 0.9786): closing the last tunnel is sensitive to the trajectory (docs/BENCHMARKS.md).
    EXPECT_GE(run.after["dice"].get<double>(), run.before["dice"].get<double>() - 0.005);
}

// At zoom 4 about voxel (20, 20, 24) the axial pane's centre pixel is that voxel's centre: its grey
// is the window's mapping of the voxel's intensity (mid-grey, then a tenth of the way up).
TEST(ScriptedSession, DisplayWindowAndZoomReachTheSlicePixels) {
    const fs::path dir = scripts_dir();
    PhantomOptions o;
    o.size = 48;
    const Phantom ph = make_phantom(o);
    const std::string image = (dir / "display.nii.gz").string();
    write_image(ph.image, image);
    const double v = read_image(image)({20, 20, 24});
    write_text(dir / "display.json",
               fmt::format(R"([{{"cursor": [24, 24, 24]}}, {{"display": {{"label_opacity": 0, "contour": false, "roi": "off"}}}},
        {{"display": {{"pane": "axial", "zoom": 4, "center": [20, 20, 24], "window": [{}, {}]}}}},
        {{"screenshot": "{}", "pane": "axial", "size": [200, 200]}},
        {{"display": {{"window": [{}, {}]}}}}, {{"screenshot": "{}", "pane": "axial", "size": [200, 200]}}])",
                           v - 50.0, v + 50.0, (dir / "mid.png").string(), v - 10.0, v + 90.0, (dir / "tenth.png").string()));
    // (The display shows the session's image: the raw one without N4, whose value v is.)
    const CliResult r = run_cli("view " + image + " --no-bias-correct --headless --no-autosave --script " + (dir / "display.json").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto centre = [](const std::string& path) {
        const render::Image img = render::read_png(path);
        const std::size_t k = 4 * (100 * static_cast<std::size_t>(img.width) + 100);
        return std::array<int, 3>{img.rgba[k], img.rgba[k + 1], img.rgba[k + 2]};
    };
    EXPECT_EQ(centre((dir / "mid.png").string()), (std::array<int, 3>{128, 128, 128}));  // 127.5 rounds up
    EXPECT_EQ(centre((dir / "tenth.png").string()), (std::array<int, 3>{26, 26, 26}));   // 25.5
}

// A shell (9 < r <= 12 in 32^3) whose mask took in a one-voxel rod of the core's tissue across the
// core (a handle): a script choosing the cut rule and aiming at the rod removes rod voxels only and
// leaves genus 0 — the viewer's panel sets the same option (its "rule" combo).
TEST(ScriptedSession, TheCutRuleCutsAHandleAtTheTarget) {
    const fs::path dir = scripts_dir();
    const testing::RodShell c = testing::rod_shell();
    ASSERT_EQ(mask_topology(c.mask).genus, 1);
    write_image(c.image, (dir / "rod_t1.nii.gz").string());
    write_label_image(c.mask, (dir / "rod_seg.nii.gz").string());
    const std::string out = (dir / "rod_cut.nii.gz").string();
    write_text(dir / "cut.json", R"([{"params": {"decision": "cut", "p": 0.3}}, {"target": [16, 16, 16]}, {"swarm": 100},
        {"save_mask": ")" + out + R"("}])");
    const CliResult r = run_cli("view " + (dir / "rod_t1.nii.gz").string() + " --mask " + (dir / "rod_seg.nii.gz").string() +
                                " --headless --script " + (dir / "cut.json").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    testing::expect_rod_cut(c, read_label_image(out));
}

// The viewer's saved mask and φ of an image whose file gave no orientation are written without one
// too (as `segment`'s outputs: ImageIo.AnImageWithoutOrientationIsWrittenAsOne, and nibabel's
// placement in the Python suite); an oriented image's keep theirs.
TEST(ScriptedSession, SavesOfAnImageWithoutOrientationHaveNone) {
    const fs::path dir = scripts_dir();
    const testing::RodShell c = testing::rod_shell();
    for (const bool oriented : {true, false}) {
        const std::string tag = oriented ? "o" : "u", image = (dir / ("rod_" + tag + ".nii.gz")).string();
        write_image(c.image, image, {.orientation_known = oriented});
        write_label_image(c.mask, (dir / "rod_seg.nii.gz").string());
        const std::string mask = (dir / ("saved_mask_" + tag + ".nii.gz")).string(), phi = (dir / ("saved_phi_" + tag + ".nii")).string();
        write_text(dir / "save.json", R"([{"save_mask": ")" + mask + R"("}, {"save_phi": ")" + phi + R"("}])");
        const CliResult r = run_cli("view " + image + " --mask " + (dir / "rod_seg.nii.gz").string() + " --headless --script " +
                                    (dir / "save.json").string());
        ASSERT_EQ(r.rc, 0) << r.err;
        EXPECT_EQ(read_image_header(mask).orientation_known, oriented);
        EXPECT_EQ(read_image_header(phi).orientation_known, oriented);
        const Grid<std::uint8_t> saved = read_label_image(mask);
        EXPECT_TRUE(std::equal(saved.values().begin(), saved.values().end(), c.mask.values().begin()));
    }
}

TEST(ScriptedSession, BadScriptsAreRefusedWithOneLineNamingTheEntry) {
    const fs::path dir = scripts_dir();
    PhantomOptions o;
    o.size = 48;
    const std::string image = (dir / "small.nii.gz").string();
    write_image(make_phantom(o).image, image);
    struct Case {
        std::string script, phrase;
    };
    const Case cases[] = {
        {"[{\"segment\": 10}", "not valid JSON"},
        {"[{\"segment\": 1e999}]", "not valid JSON"},  // a number beyond a double (found by fuzz_session_script)
        {"{\"segment\": 10}", "must be a JSON list"},
        {"[{\"seed\": [1, 2, 3]}, {\"segmnet\": 5}]", "entry 2: no action (unknown key \"segmnet\")"},
        {"[{\"seed\": [1, 2, 300]}]", "entry 1 (\"seed\"): the seed (1, 2, 300) lies outside"},
        {"[{\"segment\": -4}]", "entry 1 (\"segment\")"},
        {"[{\"params\": {\"alpha\": 2}}]", "entry 1 (\"params\")"},
        {"[{\"swarm\": 5}]", "entry 1 (\"swarm\"): no target"},
        {"[{\"save_mask\": \"/nonexistent/m.nii.gz\"}]", "does not exist"},
        {"[{\"screenshot\": \"x.jpg\"}]", ".png"},
        {"[{\"camera\": {\"view\": \"sideways\"}}]", "view must be"},
        {"[{\"seed\": [10, 10, 10], \"segment\": 3}]", "two actions"},
        {"[{\"display\": {\"window\": [5, 2]}}]", "window must be [low, high]"},
        {"[{\"display\": {\"window\": \"bone\"}}]", "window must be auto, minmax, narrow"},
        {"[{\"display\": {\"zoom\": 2}}]", "need a \"pane\""},
        {"[{\"display\": {\"pane\": \"3d\", \"zoom\": 2}}]", "pane must be axial, sagittal or coronal"},
        {"[{\"display\": {\"pane\": \"axial\", \"center\": [1, 2, 300]}}]", "lies outside"},
        {"[{\"display\": {\"roi\": \"dotted\"}}]", "roi must be off, outline or tint"},
        {"[{\"display\": {\"label_opacity\": 2}}]", "label_opacity must be in [0, 1]"},
        {"[{\"display\": {\"preview\": 1}}]", "preview must be true or false"},
        {"[{\"params\": {\"decision\": \"maybe\"}}]", "decision must be"},
        {"[{\"params\": {\"decision\": \"cut\", \"edit_range\": 0}}]", "entry 1 (\"params\")"},
    };
    for (const Case& c : cases) {
        write_text(dir / "bad.json", c.script);
        const CliResult r = run_cli("view " + image + " --headless --script " + (dir / "bad.json").string());
        EXPECT_EQ(r.rc, 1) << c.script;
        EXPECT_EQ(testing::lines(r.err), 1) << c.script << ": " << r.err;
        EXPECT_NE(r.err.find(c.phrase), std::string::npos) << c.script << ": " << r.err;
    }
    // Missing files and mismatched inputs: one line, non-zero, never a crash.
    EXPECT_EQ(run_cli("view " + (dir / "none.nii.gz").string() + " --headless --script x.json").rc, 2);
    PhantomOptions other;
    other.size = 40;
    write_image(make_phantom(other).image, (dir / "other.nii.gz").string());
    const CliResult wrong = run_cli("view " + image + " --phi " + (dir / "other.nii.gz").string() + " --headless --script " +
                                    (dir / "bad.json").string());
    EXPECT_EQ(wrong.rc, 1);
    EXPECT_NE(wrong.err.find("does not overlay"), std::string::npos) << wrong.err;
    EXPECT_EQ(testing::lines(wrong.err), 1);
    const CliResult nodisplay = run_cli("view " + image + " --headless");
    EXPECT_EQ(nodisplay.rc, 1);
    EXPECT_NE(nodisplay.err.find("--script or --bench"), std::string::npos);
}

TEST(ViewBench, ReportsTheRendererAndOnlyTheRepairingScenariosRebuildFragments) {
    const fs::path dir = scripts_dir();
    PhantomOptions o;
    o.size = 48;
    const Phantom ph = make_phantom(o);
    write_image(ph.image, (dir / "bench.nii.gz").string());
    write_label_image(ph.truth, (dir / "bench_truth.nii.gz").string());
    const CliResult r = run_cli("view " + (dir / "bench.nii.gz").string() + " --mask " + (dir / "bench_truth.nii.gz").string() +
                                " --headless --bench --bench-frames 3 --size 480x320 --json");
    ASSERT_EQ(r.rc, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_NE(j["renderer"].get<std::string>().find("(EGL surfaceless)"), std::string::npos) << j["renderer"];
    ASSERT_EQ(j["scenarios"].size(), 4u);
    const char* names[] = {"static", "agents moving", "repairing p=0.1", "repairing p=0.5"};
    for (std::size_t k = 0; k < 4; ++k) {
        const nlohmann::json& sc = j["scenarios"][k];
        EXPECT_EQ(sc["scenario"], names[k]);
        EXPECT_EQ(sc["frames"], 3);
        EXPECT_GT(sc["triangles"].get<double>(), 0.0);
        EXPECT_GE(sc["frame_ms"].get<double>(), sc["draw_ms"].get<double>());
        EXPECT_NEAR(sc["fps"].get<double>(), 1000.0 / sc["frame_ms"].get<double>(), 1e-6 * sc["fps"].get<double>());
        if (k < 2) EXPECT_EQ(sc["fragments_per_frame"].get<double>(), 0.0) << names[k];  // nothing edits the surface
        else EXPECT_GT(sc["fragments_per_frame"].get<double>(), 0.0) << names[k];
    }
}

// The voxels where two label images differ (asserting that the second holds a real segmentation).
std::size_t differing_voxels(const std::string& a_path, const std::string& b_path) {
    const Grid<std::uint8_t> a = read_label_image(a_path), b = read_label_image(b_path);
    EXPECT_EQ(a.size(), b.size());
    std::size_t differ = 0, inside = 0;
    for (PointIndex i = 0; i < std::min(a.size(), b.size()); ++i) {
        differ += (a[i] != 0) != (b[i] != 0);
        inside += b[i] != 0;
    }
    EXPECT_GT(inside, 10000u);
    return differ;
}

// `liveset view IMAGE --seed ...` starts with the α `liveset segment` chooses for the same seeds
// (segment/alpha.hpp; a noisy phantom on 1 x 1 x 1.5 mm voxels, so α is neither 0 nor 0.1), says
// so, and its converged mask is segment's, voxel for voxel.
TEST(ScriptedSession, SeedsOnTheCommandLineStartWithSegmentsAutomaticAlpha) {
    const testing::NoisyAnisotropicPhantom noisy = testing::noisy_anisotropic_phantom(64);
    const Phantom& ph = noisy.phantom;
    const Grid<float>& image = noisy.image;
    const fs::path dir = scripts_dir();
    const std::string path = (dir / "aniso_t1.nii.gz").string(), view_mask = (dir / "aniso_view.nii.gz").string(),
                      seg_mask = (dir / "aniso_seg.nii.gz").string();
    write_image(image, path);
    std::string seeds;
    for (const Vec3i& s : ph.seeds) seeds += fmt::format(" --seed {},{},{}", s.x, s.y, s.z);
    const CliResult seg = run_cli("segment " + path + seeds + " --no-bias-correct --json --out-mask " + seg_mask);
    ASSERT_EQ(seg.rc, 0) << seg.err;
    const nlohmann::json report = nlohmann::json::parse(seg.out);
    const double alpha = report["alpha"].get<double>();
    ASSERT_EQ(report["alpha_choice"]["source"], "automatic");
    EXPECT_NEAR(report["alpha_choice"]["anisotropy"].get<double>(), 1.5, 1e-9);
    EXPECT_GT(alpha, 0.0);
    EXPECT_LT(alpha, 0.1);
    EXPECT_EQ(report["smooth_mm"].get<double>(), 0.5);  // noisy: the automatic blur too (segment/alpha.hpp)
    write_text(dir / "aniso.json", R"([{"segment": "converge"}, {"save_mask": ")" + view_mask + R"("}])");
    const CliResult view = run_cli("view " + path + seeds + " --no-bias-correct --headless --no-autosave --script " +
                                   (dir / "aniso.json").string());
    ASSERT_EQ(view.rc, 0) << view.err;
    EXPECT_NE((view.out + view.err).find(fmt::format("α {:.3g} automatic", alpha)), std::string::npos) << view.out << view.err;
    EXPECT_NE((view.out + view.err).find("blurred by σ 0.5 mm"), std::string::npos) << view.out << view.err;
    const Grid<std::uint8_t> a = read_label_image(view_mask), b = read_label_image(seg_mask);
    ASSERT_EQ(a.size(), b.size());
    std::size_t differ = 0;
    for (PointIndex i = 0; i < a.size(); ++i) differ += (a[i] != 0) != (b[i] != 0);
    EXPECT_EQ(differ, 0u);

    // Seeds placed in the viewer (a script's seed entries, as clicks) rather than on the command
    // line: α follows them the same way, so the viewer still gives segment's mask.
    std::string clicks;
    for (const Vec3i& s : ph.seeds) clicks += fmt::format(R"({{"seed": [{}, {}, {}]}}, )", s.x, s.y, s.z);
    const std::string clicked_mask = (dir / "aniso_clicked.nii.gz").string();
    write_text(dir / "clicked.json", "[" + clicks + R"({"segment": "converge"}, {"save_mask": ")" + clicked_mask + R"("}])");
    const CliResult clicked = run_cli("view " + path + " --no-bias-correct --headless --no-autosave --script " + (dir / "clicked.json").string());
    ASSERT_EQ(clicked.rc, 0) << clicked.err;
    const Grid<std::uint8_t> c = read_label_image(clicked_mask);
    differ = 0;
    for (PointIndex i = 0; i < c.size(); ++i) differ += (c[i] != 0) != (b[i] != 0);
    EXPECT_EQ(differ, 0u);
    // A script's "alpha" fixes it; "auto_alpha" with "alpha" is refused before anything runs.
    write_text(dir / "both.json", R"([{"params": {"alpha": 0.2, "auto_alpha": true}}])");
    const CliResult both = run_cli("view " + path + " --no-bias-correct --headless --no-autosave --script " + (dir / "both.json").string());
    EXPECT_NE(both.rc, 0);
    EXPECT_NE(both.err.find("not both"), std::string::npos) << both.err;

    // A script's "alpha" with "smooth_mm" gives `segment --alpha --smooth`'s mask; "smooth_mm" alone
    // while α is automatic is refused (the automatic choice sets both), as `--smooth` without `--alpha`.
    const std::string given_seg = (dir / "aniso_given_seg.nii.gz").string(), given_view = (dir / "aniso_given_view.nii.gz").string();
    const CliResult fixed = run_cli("segment " + path + seeds + " --no-bias-correct --alpha 0.04 --smooth 0.8 --out-mask " + given_seg);
    ASSERT_EQ(fixed.rc, 0) << fixed.err;
    write_text(dir / "given.json", "[" + clicks + R"({"params": {"alpha": 0.04, "smooth_mm": 0.8}}, {"segment": "converge"}, {"save_mask": ")" +
                                       given_view + R"("}])");
    const CliResult given = run_cli("view " + path + " --no-bias-correct --headless --no-autosave --script " + (dir / "given.json").string());
    ASSERT_EQ(given.rc, 0) << given.err;
    EXPECT_EQ(differing_voxels(given_view, given_seg), 0u);
    EXPECT_GT(differing_voxels(given_seg, seg_mask), 0u);  // the given blur and α make another mask
    write_text(dir / "alone.json", "[" + clicks + R"({"params": {"smooth_mm": 0.8}}])");
    const CliResult alone = run_cli("view " + path + " --no-bias-correct --headless --no-autosave --script " + (dir / "alone.json").string());
    EXPECT_NE(alone.rc, 0);
    EXPECT_NE(alone.err.find("smooth_mm needs alpha"), std::string::npos) << alone.err;
}

// The 64³ phantom written to the work folder as NAME_t1.nii.gz, with its seeds as `--seed`
// options and as script entries (clicks).
struct ClickedPhantom {
    std::string path, seeds, clicks;
};
ClickedPhantom clicked_phantom(const std::string& name) {
    PhantomOptions po;
    po.size = 64;
    const Phantom ph = make_phantom(po);
    ClickedPhantom c{(scripts_dir() / (name + "_t1.nii.gz")).string(), "", ""};
    write_image(ph.image, c.path);
    for (const Vec3i& s : ph.seeds) {
        c.seeds += fmt::format(" --seed {},{},{}", s.x, s.y, s.z);
        c.clicks += fmt::format(R"({{"seed": [{}, {}, {}]}}, )", s.x, s.y, s.z);
    }
    return c;
}


// With bias correction (the default) and no ROI, `view` fits the tissue model where `segment` does:
// in prepare_image's automatic brain mask (it once computed its own: 43 voxels of this mask
// differed), so seeds placed in the viewer still give segment's mask.
TEST(ScriptedSession, WithBiasCorrectionAndNoRoiTheViewerFitsTheModelWhereSegmentDoes) {
    const ClickedPhantom ph = clicked_phantom("n4");
    const fs::path dir = scripts_dir();
    const std::string view_mask = (dir / "n4_view.nii.gz").string(), seg_mask = (dir / "n4_seg.nii.gz").string();
    write_text(dir / "clicked_n4.json", "[" + ph.clicks + R"({"segment": "converge"}, {"save_mask": ")" + view_mask + R"("}])");
    const CliResult seg = run_cli("segment " + ph.path + ph.seeds + " --out-mask " + seg_mask);
    ASSERT_EQ(seg.rc, 0) << seg.err;
    const CliResult view = run_cli("view " + ph.path + " --headless --no-autosave --script " + (dir / "clicked_n4.json").string());
    ASSERT_EQ(view.rc, 0) << view.err;
    EXPECT_EQ(differing_voxels(view_mask, seg_mask), 0u);
}

// `--roi auto` is `segment --roi auto`'s brain mask, and a workspace saved with it keeps "auto" (not
// a path to a file named auto) and continues exactly. On the analytic head with a bridge to the
// scalp, where the ROI decides the result: without it the front leaks along the bridge.
TEST(ScriptedSession, RoiAutoIsSegmentsBrainMaskAndTheWorkspaceKeepsIt) {
    const fs::path dir = scripts_dir();
    const std::string path = (dir / "auto_head.nii.gz").string(), view_mask = (dir / "auto_view.nii.gz").string(),
                      seg_mask = (dir / "auto_seg.nii.gz").string(), again = (dir / "auto_again.nii.gz").string(),
                      ws = (dir / "auto_ws.json").string();
    write_image(testing::analytic_head(true), path);
    const std::string o = " --seed 32,32,32:3 --mu-raw 130 --epsilon-raw 40 --no-bias-correct";
    write_text(dir / "auto.json",
               R"([{"segment": 40}, {"save_workspace": ")" + ws + R"("}, {"segment": "converge"}, {"save_mask": ")" + view_mask + R"("}])");
    const CliResult seg = run_cli("segment " + path + o + " --roi auto --out-mask " + seg_mask);
    ASSERT_EQ(seg.rc, 0) << seg.err;
    const CliResult view = run_cli("view " + path + o + " --roi auto --headless --no-autosave --script " + (dir / "auto.json").string());
    ASSERT_EQ(view.rc, 0) << view.err;
    EXPECT_NE(view.err.find("--roi auto: brain mask of"), std::string::npos) << view.err;
    EXPECT_EQ(differing_voxels(view_mask, seg_mask), 0u);
    const std::string leaked = (dir / "auto_leaked.nii.gz").string();  // the same run without the ROI differs
    ASSERT_EQ(run_cli("segment " + path + o + " --roi none --out-mask " + leaked).rc, 0);
    EXPECT_GT(differing_voxels(leaked, seg_mask), 1000u);
    // Without --roi, a head: the automatic brain mask by default, in the viewer as in `segment`.
    const std::string by_default = (dir / "auto_default.nii.gz").string();
    write_text(dir / "default.json", R"([{"segment": "converge"}, {"save_mask": ")" + by_default + R"("}])");
    const CliResult dv = run_cli("view " + path + o + " --headless --no-autosave --script " + (dir / "default.json").string());
    ASSERT_EQ(dv.rc, 0) << dv.err;
    EXPECT_NE(dv.err.find("the front stays in the automatic brain mask by default"), std::string::npos) << dv.err;
    EXPECT_EQ(differing_voxels(by_default, seg_mask), 0u);
    std::ifstream in(ws);
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["roi"], "auto");
    // Continued from the workspace (its ROI recomputed from the image): the same converged mask.
    write_text(dir / "continue_auto.json", R"([{"segment": "converge"}, {"save_mask": ")" + again + R"("}])");
    const CliResult cont = run_cli("view " + path + " --workspace " + ws + " --headless --no-autosave --script " + (dir / "continue_auto.json").string());
    ASSERT_EQ(cont.rc, 0) << cont.err;
    EXPECT_EQ(differing_voxels(again, view_mask), 0u);
}

// As `segment`: with --roi none on a head, a front that leaked out of the automatic brain mask is
// warned about when it converges (stderr when headless, the event log); with --roi auto or the
// default (the same mask on a head) it is not.
TEST(ScriptedSession, AFrontThatLeaksOutOfTheBrainWithoutARoiIsWarnedAbout) {
    const fs::path dir = scripts_dir();
    const std::string path = (dir / "bridged_head.nii.gz").string(), events = (dir / "leak_events.jsonl").string();
    write_image(testing::analytic_head(true), path);
    write_text(dir / "leak.json", R"([{"segment": "converge"}])");
    const std::string common = " --seed 32,32,32:3 --mu-raw 130 --epsilon-raw 40 --no-bias-correct --headless --no-autosave --script " +
                               (dir / "leak.json").string();
    const CliResult leaked = run_cli("view " + path + " --roi none" + common + " --log-events " + events);
    ASSERT_EQ(leaked.rc, 0) << leaked.err;
    EXPECT_NE(leaked.err.find("outside the automatic brain mask"), std::string::npos) << leaked.err;
    std::ifstream in(events);
    std::size_t logged = 0;
    for (std::string line; std::getline(in, line);) {
        const nlohmann::json e = nlohmann::json::parse(line);
        logged += e.value("type", "") == "warning" && e["message"].get<std::string>().find("outside the automatic brain mask") != std::string::npos;
    }
    EXPECT_EQ(logged, 1u);
    for (const std::string roi : {" --roi auto", ""}) {
        const CliResult inside = run_cli("view " + path + roi + common);
        ASSERT_EQ(inside.rc, 0) << inside.err;
        EXPECT_EQ(inside.err.find("outside the automatic brain mask"), std::string::npos) << roi << ": " << inside.err;
    }
}

}  // namespace
}  // namespace liveset
