// `liveset view` with workspaces, seed files and threshold options, end to end through the CLI
// (headless scripts) and in a real window under Xvfb driven by xdotool (window_workspace.sh,
// window_prompts.sh): a workspace continues bit for bit where it was saved; a φ loaded alone takes
// µ, ε from the tissue model (checked against sheet_window) and says so; --mu-raw/--epsilon-raw
// mean what they mean for `liveset segment`; a bad workspace is one line and the viewer still
// runs; a seed outside the ROI is refused; Ctrl+Q with unsaved work asks first.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <bit>
#include <filesystem>
#include <fmt/core.h>
#include <fstream>
#include <nlohmann/json.hpp>

#include "analytic_head.hpp"
#include "cli/cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/window.hpp"
#include "scratch_dir.hpp"
#include "workspace.hpp"
#include "viewer_test_util.hpp"

namespace liveset {
namespace {

using testing::have;
using testing::same_bits;

namespace fs = std::filesystem;
using testing::CliResult;
using testing::run_cli;

struct Fixture {
    fs::path dir;
    Phantom ph;
    std::string image, seeds;  // seeds: a seed file of the phantom's seeds
};

const Fixture& fixture() {
    static const Fixture f = [] {
        Fixture x;
        x.dir = testing::scratch_dir("view_workspace");
        PhantomOptions o;
        o.size = 48;
        x.ph = make_phantom(o);
        x.image = (x.dir / "t1.nii.gz").string();
        write_image(x.ph.image, x.image);
        x.seeds = (x.dir / "seeds.txt").string();
        std::ofstream out(x.seeds);
        for (const Vec3i& s : x.ph.seeds) out << s.x << "," << s.y << "," << s.z << "\n";
        return x;
    }();
    return f;
}

std::string script(const std::string& name, const std::string& json) {
    const fs::path p = fixture().dir / name;
    std::ofstream(p) << json;
    return p.string();
}

std::size_t lines(const std::string& text) { return static_cast<std::size_t>(std::count(text.begin(), text.end(), '\n')); }

TEST(ViewCommand, HelpListsTheWindowAndWorkspaceOptions) {
    const CliResult r = run_cli("view --help");
    ASSERT_EQ(r.rc, 0) << r.err;
    for (const char* option : {"--mu-raw", "--epsilon-raw", "--workspace", "--mu ", "--epsilon ", "--n ", "--alpha", "--seeds"})
        EXPECT_NE(r.out.find(option), std::string::npos) << option;
}

// Segment 45 steps and save a workspace; reopen it and take 25 more: φ is bit for bit what 70
// steps in one run give (the level set, the parameters, the iteration count and the sleeping step's
// wake stamps continue: stretches of front are asleep by step 45 of the default step, sleeping with
// the thin-front rule).
TEST(ViewCommand, AWorkspaceContinuesBitForBit) {
    const Fixture& f = fixture();
    const std::string w = (f.dir / "cont.json").string(), p2 = (f.dir / "cont_phi.nii.gz").string(), p3 = (f.dir / "one_phi.nii.gz").string();
    CliResult r = run_cli(fmt::format("view {} --seeds {} --headless --script {}", f.image, f.seeds,
                                      script("a.json", R"([{"segment": 45}, {"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("view --workspace {} --headless --script {}", w, script("b.json", R"([{"segment": 25}, {"save_phi": ")" + p2 + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("from the workspace " + w), std::string::npos) << r.err;
    r = run_cli(fmt::format("view {} --seeds {} --headless --script {}", f.image, f.seeds,
                            script("c.json", R"([{"segment": 70}, {"save_phi": ")" + p3 + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(same_bits(read_image(p2), read_image(p3)));
    EXPECT_EQ(viewer::read_workspace(w).marks.iterations, 45);
}

// A workspace keeps the step it was saved with: saved after 30 steps of `--step exact
// --no-thin-fronts`, reopened without either flag and stepped 20 more, φ is bit for bit 50 steps in
// one run with them (and not the default step's 50: sleeping, the rule on); --thin-fronts over it
// is honoured and said in a note.
TEST(ViewCommand, AWorkspaceKeepsItsStep) {
    const Fixture& f = fixture();
    const std::string w = (f.dir / "step.json").string(), cont = (f.dir / "step_cont.nii.gz").string();
    const std::string one = (f.dir / "step_one.nii.gz").string(), plain = (f.dir / "step_plain.nii.gz").string();
    const std::string thin = (f.dir / "step_thin.nii.gz").string();
    CliResult r = run_cli(fmt::format("view {} --seeds {} --step exact --no-thin-fronts --headless --script {}", f.image, f.seeds,
                                      script("st_a.json", R"([{"segment": 30}, {"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    const viewer::Workspace ws = viewer::read_workspace(w);
    ASSERT_TRUE(ws.step && ws.thin_fronts);
    EXPECT_EQ(*ws.step, "exact");
    EXPECT_FALSE(*ws.thin_fronts);
    r = run_cli(fmt::format("view --workspace {} --headless --script {}", w, script("st_b.json", R"([{"segment": 20}, {"save_phi": ")" + cont + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.err.find("continues with"), std::string::npos) << r.err;
    r = run_cli(fmt::format("view {} --seeds {} --step exact --no-thin-fronts --headless --script {}", f.image, f.seeds,
                            script("st_c.json", R"([{"segment": 50}, {"save_phi": ")" + one + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("view {} --seeds {} --headless --script {}", f.image, f.seeds,
                            script("st_d.json", R"([{"segment": 50}, {"save_phi": ")" + plain + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(same_bits(read_image(cont), read_image(one)));
    EXPECT_FALSE(same_bits(read_image(plain), read_image(one)));

    r = run_cli(fmt::format("view --workspace {} --thin-fronts --headless --script {}", w,
                            script("st_e.json", R"([{"segment": 20}, {"save_phi": ")" + thin + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("continues with --thin-fronts (saved without) as asked"), std::string::npos) << r.err;
    EXPECT_FALSE(same_bits(read_image(thin), read_image(one)));

    // --step over it: honoured and said; the rule stays off as saved.
    const std::string sleeping = (f.dir / "step_sleeping.nii.gz").string();
    r = run_cli(fmt::format("view --workspace {} --step sleeping --headless --script {}", w,
                            script("st_f.json", R"([{"segment": 20}, {"save_phi": ")" + sleeping + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("continues with --step sleeping (saved with --step exact) as asked"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("thin-fronts"), std::string::npos) << r.err;
}

// A workspace keeps its --coarse-start: saved before the first step with `--coarse-start on` (the
// phantom's 1 mm grid would not start coarse by default), reopened without the flag, its Run starts
// coarse and gives bit for bit the φ of one run with the flag (not the default's); --coarse-start
// off over it is honoured and said in a note. A bad value in the file is one line.
TEST(ViewCommand, AWorkspaceKeepsItsCoarseStart) {
    const Fixture& f = fixture();
    const std::string w = (f.dir / "coarse.json").string(), cont = (f.dir / "coarse_cont.nii.gz").string();
    const std::string one = (f.dir / "coarse_one.nii.gz").string(), plain = (f.dir / "coarse_plain.nii.gz").string();
    const std::string off = (f.dir / "coarse_off.nii.gz").string();
    CliResult r = run_cli(fmt::format("view {} --seeds {} --coarse-start on --headless --script {}", f.image, f.seeds,
                                      script("co_a.json", R"([{"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    const viewer::Workspace ws = viewer::read_workspace(w);
    ASSERT_TRUE(ws.coarse_start.has_value());
    EXPECT_EQ(*ws.coarse_start, CoarseStart::kOn);
    const std::string run = R"([{"segment": "converge", "max": 3000}, {"save_phi": ")";
    r = run_cli(fmt::format("view --workspace {} --headless --script {}", w, script("co_b.json", run + cont + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.err.find("continues with"), std::string::npos) << r.err;
    r = run_cli(fmt::format("view {} --seeds {} --coarse-start on --headless --script {}", f.image, f.seeds, script("co_c.json", run + one + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("view {} --seeds {} --headless --script {}", f.image, f.seeds, script("co_d.json", run + plain + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_TRUE(same_bits(read_image(cont), read_image(one)));
    EXPECT_FALSE(same_bits(read_image(plain), read_image(one)));

    r = run_cli(fmt::format("view --workspace {} --coarse-start off --headless --script {}", w, script("co_e.json", run + off + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("continues with --coarse-start off (saved with --coarse-start on) as asked"), std::string::npos) << r.err;
    EXPECT_TRUE(same_bits(read_image(off), read_image(plain)));

    std::ifstream in(w);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t at = text.find("\"coarse_start\": \"on\"");
    ASSERT_NE(at, std::string::npos) << text;
    text.replace(at, std::string("\"coarse_start\": \"on\"").size(), "\"coarse_start\": \"sometimes\"");
    const fs::path bad = f.dir / "coarse_bad.json";
    std::ofstream(bad) << text;
    fs::copy_file(viewer::workspace_state_path(w), viewer::workspace_state_path(bad), fs::copy_options::overwrite_existing);
    EXPECT_THROW(
        {
            try {
                viewer::read_workspace(bad);
            } catch (const std::runtime_error& e) {
                EXPECT_NE(std::string(e.what()).find("'coarse_start' is \"sometimes\""), std::string::npos) << e.what();
                throw;
            }
        },
        std::runtime_error);
}

// The viewer segments the image `liveset segment` does: N4-corrected by default (the workspace
// records it and holds the checksum of the corrected image `segment --out-corrected` writes), raw
// with --no-bias-correct; a workspace saved with N4 refuses --no-bias-correct in one line.
TEST(ViewCommand, TheViewerCorrectsTheBiasAsSegmentDoes) {
    const Fixture& f = fixture();
    const std::string w_on = (f.dir / "bias_on.json").string(), w_off = (f.dir / "bias_off.json").string();
    const std::string corrected = (f.dir / "bias_corrected.nii.gz").string(), mask = (f.dir / "bias_mask.nii.gz").string();
    CliResult r = run_cli(fmt::format("view {} --seeds {} --headless --script {}", f.image, f.seeds,
                                      script("bias_on.json", R"([{"save_workspace": ")" + w_on + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("view {} --no-bias-correct --seeds {} --headless --script {}", f.image, f.seeds,
                            script("bias_off.json", R"([{"save_workspace": ")" + w_off + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("segment {} --seed {},{},{} --iterations 1 --quiet --out-mask {} --out-corrected {}", f.image, f.ph.seeds[0].x,
                            f.ph.seeds[0].y, f.ph.seeds[0].z, mask, corrected));
    ASSERT_EQ(r.rc, 0) << r.err;
    const viewer::Workspace on = viewer::read_workspace(w_on), off = viewer::read_workspace(w_off);
    EXPECT_TRUE(on.bias_corrected);
    EXPECT_FALSE(off.bias_corrected);
    EXPECT_EQ(on.image_checksum, viewer::image_checksum(read_image(corrected)));
    EXPECT_EQ(off.image_checksum, viewer::image_checksum(read_image(f.image)));
    EXPECT_NE(on.image_checksum, off.image_checksum);

    r = run_cli(fmt::format("view --workspace {} --no-bias-correct --headless --script {}", w_on, script("bias_none.json", "[]")));
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find("was saved with bias correction; drop --no-bias-correct"), std::string::npos) << r.err;
}

// A φ loaded alone: µ, ε from the tissue model's window of the class most of its inside falls in,
// said on stderr; with --workspace, the workspace's; with --mu-raw/--epsilon-raw, those. (Without
// N4: the reference below is the library's window on the raw image.)
TEST(ViewCommand, APhiLoadedAloneSaysWhereItsParametersCameFrom) {
    const Fixture& f = fixture();
    const std::string phi = (f.dir / "alone_phi.nii.gz").string(), w = (f.dir / "alone.json").string();
    CliResult r = run_cli(fmt::format("view {} --no-bias-correct --seeds {} --headless --script {}", f.image, f.seeds,
                                      script("d.json", R"([{"segment": 40}, {"save_phi": ")" + phi + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("view {} --no-bias-correct --phi {} --headless --script {}", f.image, phi,
                            script("e.json", R"([{"undo": 1}, {"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("µ, ε from the tissue model"), std::string::npos) << r.err;
    // The same window computed here from the library: the class of the φ's inside.
    const Grid<float> phi_image = read_image(phi);
    Grid<std::uint8_t> inside(phi_image.lattice());
    for (std::size_t i = 0; i < inside.size(); ++i) inside[static_cast<PointIndex>(i)] = phi_image[static_cast<PointIndex>(i)] < 0.0f;
    std::vector<std::string> warnings;
    const auto window = sheet_window(f.ph.image, inside, nullptr, TissueModelOptions{}, warnings);
    ASSERT_TRUE(window.has_value());
    const IntensityScale scale = robust_scale(f.ph.image);
    viewer::Workspace ws = viewer::read_workspace(w);
    EXPECT_NEAR(scale.to_raw(ws.marks.params.mu), window->mu(), 1e-6 * window->mu());
    EXPECT_NEAR(scale.raw_length(ws.marks.params.epsilon), window->epsilon(), 1e-6 * window->epsilon());
    // (after an undo: the start parameters are not an undoable action that Ctrl+Z would take back)

    r = run_cli(fmt::format("view {} --phi {} --workspace {} --headless --script {}", f.image, phi, w,
                            script("f.json", "[]")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("µ, ε, n, α from the workspace"), std::string::npos) << r.err;

    r = run_cli(fmt::format("view {} --no-bias-correct --phi {} --mu-raw 500 --epsilon-raw 120 --alpha 0.2 --headless --script {}", f.image, phi,
                            script("g.json", R"([{"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("µ, ε from the command line"), std::string::npos) << r.err;
    ws = viewer::read_workspace(w);
    EXPECT_NEAR(scale.to_raw(ws.marks.params.mu), 500.0, 1e-9);
    EXPECT_NEAR(scale.raw_length(ws.marks.params.epsilon), 120.0, 1e-9);
    EXPECT_EQ(ws.marks.params.alpha, 0.2);
    EXPECT_EQ(ws.marks.params.smooth_mm, 0.0);  // a given α without --smooth: no blur, as segment
    EXPECT_FALSE(ws.marks.window_from_seeds);
    r = run_cli(fmt::format("view {} --no-bias-correct --phi {} --alpha 0.2 --smooth 0.6 --headless --script {}", f.image, phi,
                            script("g2.json", R"([{"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("n, α, smoothing from the command line"), std::string::npos) << r.err;
    EXPECT_EQ(viewer::read_workspace(w).marks.params.smooth_mm, 0.6);

    // The same validation as `liveset segment`: one line and a non-zero status.
    for (const std::string& bad : {std::string("--mu 0.5 --mu-raw 500"), std::string("--epsilon 0.1 --epsilon-raw 3"),
                                   std::string("--mu-raw 1e9"), std::string("--alpha 1.5"), std::string("--epsilon-raw -4"),
                                   std::string("--smooth 0.5"), std::string("--alpha 0.1 --smooth -2")}) {
        r = run_cli(fmt::format("view {} --phi {} {} --headless --script {}", f.image, phi, bad, script("h.json", "[]")));
        EXPECT_NE(r.rc, 0) << bad;
        EXPECT_EQ(lines(r.err), 1u) << bad << ": " << r.err;
    }
}

// A missing, truncated or mismatching workspace: one line on stderr, and the viewer still runs.
TEST(ViewCommand, ABadWorkspaceIsOneLineAndTheViewerStillOpens) {
    const Fixture& f = fixture();
    const std::string w = (f.dir / "bad_base.json").string();
    const CliResult made = run_cli(fmt::format("view {} --seeds {} --headless --script {}", f.image, f.seeds,
                                               script("n.json", R"([{"segment": 3}, {"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(made.rc, 0) << made.err;
    PhantomOptions o;
    o.size = 40;
    const std::string other = (f.dir / "other.nii.gz").string();
    write_image(make_phantom(o).image, other);
    std::ifstream in(w);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string cut = (f.dir / "cut.json").string();
    std::ofstream(cut) << text.substr(0, text.size() / 3);
    fs::copy_file(viewer::workspace_state_path(w), viewer::workspace_state_path(cut), fs::copy_options::overwrite_existing);
    const std::string empty = script("i.json", "[]");
    const struct {
        std::string args, says;
    } cases[] = {{f.image + " --workspace " + (f.dir / "missing.json").string(), "no such file"},
                 {f.image + " --workspace " + cut, "invalid or truncated JSON"},
                 {other + " --workspace " + w, "was saved for another image"}};
    for (const auto& c : cases) {
        const CliResult r = run_cli("view " + c.args + " --headless --script " + empty);
        EXPECT_EQ(r.rc, 0) << c.args << ": " << r.err;
        EXPECT_EQ(lines(r.err), 1u) << r.err;
        EXPECT_NE(r.err.find(c.says), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("the viewer opens without it"), std::string::npos) << r.err;
    }
}

// A seed outside the ROI: on the command line as `segment` takes it (left out with a warning; every
// seed outside a ROI asked for: one line, exit 1; most of them outside the default ROI: the image
// opened as with --roi none), and refused in a script (the entry named).
TEST(ViewCommand, ASeedOutsideTheRoiIsRefused) {
    const Fixture& f = fixture();
    Grid<std::uint8_t> roi(f.ph.image.lattice());
    const Vec3i d = roi.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x / 2; ++x) roi({x, y, z}) = 1;
    const std::string roi_path = (f.dir / "half.nii.gz").string();
    write_label_image(roi, roi_path);
    CliResult r = run_cli(fmt::format("view {} --roi {} --seed 40,24,24 --headless --script {}", f.image, roi_path, script("j.json", "[]")));
    EXPECT_NE(r.rc, 0);
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    EXPECT_NE(r.err.find("every seed lies outside the ROI " + roi_path + ", the first at voxel (40, 24, 24)"), std::string::npos) << r.err;
    const std::string seeds_json = (f.dir / "kept_seeds.json").string();
    r = run_cli(fmt::format("view {} --roi {} --seed 40,24,24 --seed 10,24,24 --headless --script {}", f.image, roi_path,
                            script("j2.json", "[{\"save_seeds\": \"" + seeds_json + "\"}]")));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find("the seed at voxel (40, 24, 24) lies outside the ROI " + roi_path + ": it is left out"), std::string::npos) << r.err;
    {
        std::ifstream in(seeds_json);
        const std::string kept((std::istreambuf_iterator<char>(in)), {});
        EXPECT_NE(kept.find("10,24,24"), std::string::npos) << kept;
        EXPECT_EQ(kept.find("40,24,24"), std::string::npos) << kept;
    }
    r = run_cli(fmt::format("view {} --roi {} --headless --script {}", f.image, roi_path,
                            script("k.json", R"([{"seed": [10, 24, 24]}, {"seed": [40, 24, 24]}])")));
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find("entry 2 (\"seed\")"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("outside the region of interest"), std::string::npos) << r.err;

    // A full head without --roi: its automatic brain mask by default, and a seed in the air is told
    // how to segment outside it, on the command line and when clicked (a script's seed).
    const std::string head = (f.dir / "head.nii.gz").string();
    write_image(testing::analytic_head(false), head);
    const std::string hint = "the automatic brain mask bounds the front by default on a head; open the image with --roi none";
    r = run_cli(fmt::format("view {} --no-bias-correct --seed 2,2,2 --seed 32,32,32 --headless --script {}", head, script("h.json", "[]")));
    EXPECT_EQ(r.rc, 0) << r.err;  // left out, named; the default ROI kept (1 of 2 outside)
    EXPECT_NE(r.err.find("the seed at voxel (2, 2, 2) lies outside the automatic brain mask (the default ROI of a head): it is left out; "
                         "pass --roi none to segment outside the brain"),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find("by default"), std::string::npos) << r.err;
    r = run_cli(fmt::format("view {} --no-bias-correct --seed 2,2,2 --headless --script {}", head, script("h1.json", "[]")));
    EXPECT_EQ(r.rc, 0) << r.err;  // the seeds ask for something else than the brain: the whole image, as segment
    EXPECT_NE(r.err.find("every seed lies outside the automatic brain mask (a T1 brain's), the first at voxel (2, 2, 2): the whole image is "
                         "segmented, as with --roi none"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("the front stays in the automatic brain mask by default"), std::string::npos) << r.err;
    r = run_cli(fmt::format("view {} --no-bias-correct --headless --script {}", head, script("i.json", R"([{"seed": [32, 32, 32]}, {"seed": [2, 2, 2]}])")));
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find("entry 2 (\"seed\")"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(hint), std::string::npos) << r.err;
    r = run_cli(fmt::format("view {} --no-bias-correct --roi none --seed 2,2,2 --headless --script {}", head, script("n.json", "[]")));
    EXPECT_EQ(r.rc, 0) << r.err;
    // A level set to continue keeps the whole image unless --roi says otherwise (it may come from
    // another tool): no default ROI with --mask.
    Grid<std::uint8_t> ball(read_image(head).lattice(), 0);
    ball({32, 32, 32}) = ball({33, 32, 32}) = 1;
    const std::string ball_path = (f.dir / "head_ball.nii.gz").string();
    write_label_image(ball, ball_path);
    r = run_cli(fmt::format("view {} --no-bias-correct --mask {} --headless --script {}", head, ball_path, script("m.json", "[]")));
    EXPECT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(r.err.find("by default"), std::string::npos) << r.err;
    // A seed whose centre lies just outside the ROI but whose ball reaches into it is taken (and
    // clipped), as `segment` takes it.
    r = run_cli(fmt::format("view {} --roi {} --headless --script {}", f.image, roi_path, script("edge.json", R"([{"seed": [25, 24, 24], "radius": 2}])")));
    EXPECT_EQ(r.rc, 0) << r.err;
}

// A workspace records its ROI's checksum. Without N4: reopened with the ROI unchanged it says
// nothing; after the ROI file changed on disk it continues the level set as saved and warns on
// stderr and in the event log, naming the ROI and its voxel count now; so it does when opened with
// another ROI, or with one where it was saved without. With N4 (fitted in the ROI) the image itself
// changed: refused in one line that names the ROI, and logged.
TEST(ViewCommand, AWorkspaceWhoseRoiChangedSaysSo) {
    const Fixture& f = fixture();
    Grid<std::uint8_t> roi(f.ph.image.lattice());
    const Vec3i d = roi.dims();
    const auto write_roi = [&](int margin, const std::string& path) {
        for (int z = 0; z < d.z; ++z)
            for (int y = 0; y < d.y; ++y)
                for (int x = 0; x < d.x; ++x) roi({x, y, z}) = z >= margin && z < d.z - margin;
        write_label_image(roi, path);
        std::size_t n = 0;
        for (std::uint8_t v : roi.values()) n += v;
        return n;
    };
    const auto logged = [](const fs::path& log, const std::string& text) {
        std::ifstream in(log);
        for (std::string line; std::getline(in, line);) {
            const nlohmann::json e = nlohmann::json::parse(line);
            if (e["type"] == "warning" && e["message"].get<std::string>().find(text) != std::string::npos) return true;
        }
        return false;
    };
    const std::string roi_path = (f.dir / "ws_roi.nii.gz").string(), other = (f.dir / "ws_roi_other.nii.gz").string();
    const std::string w = (f.dir / "ws_roi.json").string(), w_n4 = (f.dir / "ws_roi_n4.json").string(), w_none = (f.dir / "ws_roi_none.json").string();
    const std::string p_saved = (f.dir / "ws_roi_saved.nii.gz").string(), p_again = (f.dir / "ws_roi_again.nii.gz").string();
    write_roi(2, roi_path);
    const std::size_t other_voxels = write_roi(4, other);
    CliResult r = run_cli(fmt::format("view {} --no-bias-correct --roi {} --seeds {} --headless --script {}", f.image, roi_path, f.seeds,
                                      script("ws_roi_a.json", R"([{"segment": 10}, {"save_phi": ")" + p_saved + R"("}, {"save_workspace": ")" + w + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("view {} --roi {} --seeds {} --headless --script {}", f.image, roi_path, f.seeds,
                            script("ws_roi_n4.json", R"([{"segment": 10}, {"save_workspace": ")" + w_n4 + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    r = run_cli(fmt::format("view {} --no-bias-correct --seeds {} --headless --script {}", f.image, f.seeds,
                            script("ws_roi_none.json", R"([{"save_workspace": ")" + w_none + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    ASSERT_TRUE(viewer::read_workspace(w).roi_checksum.has_value());
    EXPECT_EQ(*viewer::read_workspace(w).roi_checksum, mask_checksum(read_label_image(roi_path)));
    EXPECT_TRUE(viewer::read_workspace(w_none).roi_recorded);
    EXPECT_FALSE(viewer::read_workspace(w_none).roi_checksum.has_value());
    for (const std::string& ws : {w, w_n4, w_none}) {
        r = run_cli(fmt::format("view --workspace {} --headless --script {}", ws, script("ws_roi_b.json", "[]")));
        ASSERT_EQ(r.rc, 0) << r.err;
        EXPECT_EQ(r.err.find("ROI"), std::string::npos) << r.err;
        EXPECT_NE(r.err.find("from the workspace " + ws), std::string::npos) << r.err;
    }
    const std::string differs = "its ROI is not the one it was saved with ";
    r = run_cli(fmt::format("view --workspace {} --roi {} --headless --script {}", w, other, script("ws_roi_e.json", "[]")));
    EXPECT_NE(r.err.find(fmt::format("warning: workspace {}: {}(saved with {}, opened with {} of {} voxels)", w, differs,
                                     fs::absolute(roi_path).string(), fs::absolute(other).string(), other_voxels)), std::string::npos) << r.err;
    r = run_cli(fmt::format("view --workspace {} --roi {} --headless --script {}", w_none, other, script("ws_roi_f.json", "[]")));
    EXPECT_NE(r.err.find(fmt::format("warning: workspace {}: {}(saved without one, opened with {} of {} voxels)", w_none, differs,
                                     fs::absolute(other).string(), other_voxels)), std::string::npos) << r.err;

    const std::size_t now = write_roi(3, roi_path);
    const std::string change = fmt::format("({} has {} voxels now)", fs::absolute(roi_path).string(), now);
    const fs::path log = f.dir / "ws_roi.jsonl", log_n4 = f.dir / "ws_roi_n4.jsonl";
    r = run_cli(fmt::format("view --workspace {} --headless --log-events {} --script {}", w, log.string(),
                            script("ws_roi_c.json", R"([{"save_phi": ")" + p_again + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_NE(r.err.find(fmt::format("warning: workspace {}: {}{}", w, differs, change)), std::string::npos) << r.err;
    EXPECT_TRUE(same_bits(read_image(p_again), read_image(p_saved)));  // the level set continues as saved
    EXPECT_TRUE(logged(log, differs + change));

    r = run_cli(fmt::format("view --workspace {} --headless --log-events {} --script {}", w_n4, log_n4.string(), script("ws_roi_d.json", "[]")));
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(lines(r.err), 1u) << r.err;
    const std::string refused = fmt::format("workspace {}: {}{}, and N4 fitted in the ROI corrects the image otherwise", w_n4, differs, change);
    EXPECT_NE(r.err.find("error: " + refused + "; the viewer opens without it"), std::string::npos) << r.err;
    EXPECT_TRUE(logged(log_n4, refused));
}

// Scripts save and load seed files: what load_seeds read, save_seeds writes back; a file with a
// seed outside the ROI loads the others and fails the entry naming the refused seed.
TEST(ViewCommand, ScriptsSaveAndLoadSeedFiles) {
    const Fixture& f = fixture();
    const std::string out = (f.dir / "seeds_out.txt").string();
    CliResult r = run_cli(fmt::format("view {} --headless --script {}", f.image,
                                      script("l.json", R"([{"load_seeds": ")" + f.seeds + R"("}, {"save_seeds": ")" + out + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    std::ifstream in(out);
    std::vector<std::string> saved;
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && line[0] != '#') saved.push_back(line);
    ASSERT_EQ(saved.size(), f.ph.seeds.size());
    for (std::size_t i = 0; i < saved.size(); ++i)
        EXPECT_EQ(saved[i], fmt::format("{},{},{}:2", f.ph.seeds[i].x, f.ph.seeds[i].y, f.ph.seeds[i].z));
    Grid<std::uint8_t> roi(f.ph.image.lattice());
    const Vec3i s0 = f.ph.seeds[0];
    const Vec3i d = roi.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x <= s0.x + 2; ++x) roi({x, y, z}) = 1;  // the first seed inside, 6 voxels along x outside
    const std::string roi_path = (f.dir / "slab.nii.gz").string();
    write_label_image(roi, roi_path);
    const std::string two = (f.dir / "two_seeds.txt").string();
    std::ofstream(two) << fmt::format("{},{},{}\n{},{},{}:3\n", s0.x, s0.y, s0.z, s0.x + 6, s0.y, s0.z);  // its ball 1 voxel off
    r = run_cli(fmt::format("view {} --roi {} --headless --script {}", f.image, roi_path, script("m.json", R"([{"load_seeds": ")" + two + R"("}])")));
    EXPECT_NE(r.rc, 0);
    EXPECT_NE(r.err.find("loaded 1 of 2 seed(s)"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(fmt::format("refused {},{},{}:3", s0.x + 6, s0.y, s0.z)), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("outside the region of interest"), std::string::npos) << r.err;
}

// --- real windows -----------------------------------------------------------------------------


// Runs a driver under Xvfb in `dir`; its output on failure.
std::string run_driver(const fs::path& dir, const std::string& driver, const std::string& args, int& rc) {
    const std::string cmd = "cd " + dir.string() + " && timeout 120 xvfb-run -a -s '-screen 0 1280x720x24' bash " + std::string(LIVESET_SOURCE_DIR) +
                            "/tests/render/" + driver + " " + LIVESET_CLI_PATH + " " + args + " > driver.out 2>&1";
    const int status = std::system(cmd.c_str());
    rc = WIFEXITED(status) ? WEXITSTATUS(status) : 128;
    std::ifstream in(dir / "driver.out");
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<nlohmann::json> events(const fs::path& log) {
    std::vector<nlohmann::json> out;
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);) out.push_back(nlohmann::json::parse(line));
    return out;
}

nlohmann::json last_of(const std::vector<nlohmann::json>& ev, const std::string& type) {
    for (auto it = ev.rbegin(); it != ev.rend(); ++it)
        if ((*it)["type"] == type) return *it;
    return {};
}

// Saved from the panel, reopened with --workspace, continued: φ after 5 + 3 steps in two windows
// is bit for bit φ after 8 steps in one headless run, and the camera is where it was left.
TEST(WindowWorkspace, SavedReopenedAndContinuedBitForBitUnderXvfb) {
    if (!have("xvfb-run") || !have("xdotool") || !have("xauth"))
        GTEST_SKIP() << "xvfb-run, xauth and xdotool are needed (scripts/setup.sh installs them)";
    const Fixture& f = fixture();
    const fs::path dir = f.dir / "window_ws";
    fs::create_directories(dir);
    int rc = 0;
    std::string out = run_driver(dir, "window_workspace.sh", f.image + " " + f.seeds + " " + (dir / "one.jsonl").string() + " 1", rc);
    ASSERT_EQ(rc, 0) << out;
    const auto first = events(dir / "one.jsonl");
    out = run_driver(dir, "window_workspace.sh", f.image + " " + f.seeds + " " + (dir / "two.jsonl").string() + " 2", rc);
    ASSERT_EQ(rc, 0) << out;
    const auto second = events(dir / "two.jsonl");

    const std::string ref = (f.dir / "ref8.json").string();
    const CliResult r = run_cli(fmt::format("view {} --seeds {} --headless --script {}", f.image, f.seeds,
                                            script("ref8_script.json", R"([{"segment": 8}, {"save_workspace": ")" + ref + R"("}])")));
    ASSERT_EQ(r.rc, 0) << r.err;
    const viewer::Workspace continued = viewer::read_workspace(dir / "workspace.json"), reference = viewer::read_workspace(ref);
    EXPECT_EQ(continued.marks.iterations, 8);
    EXPECT_TRUE(same_bits(continued.phi, reference.phi));
    // The camera the first window left is the one the second opened with (and left untouched).
    const auto exit1 = last_of(first, "exit"), exit2 = last_of(second, "exit");
    ASSERT_FALSE(exit1.is_null());
    ASSERT_FALSE(exit2.is_null());
    EXPECT_NE(exit1["camera"]["yaw"].get<double>(), -30.0);  // turned
    EXPECT_EQ(exit1["camera"], exit2["camera"]);
    EXPECT_EQ(exit2["iterations"], 8);
    EXPECT_EQ(exit1["reason"], "ctrl+q");  // saved: no question asked
    // The status's FPS and frame time agree: FPS x mean frame time <= 1 s.
    for (const auto& e : {exit1, exit2}) {
        EXPECT_GT(e["frame_ms"].get<double>(), 0.0);
        EXPECT_LE(e["fps"].get<double>() * e["frame_ms"].get<double>(), 1000.0 + 1e-6) << e.dump();
    }
    EXPECT_TRUE(last_of(first, "quit_prompt").is_null());
}

// A seed click outside the ROI is refused, one inside placed; µ typed in raw units applies; Ctrl+Q asks (the prompt names the
// recovery file), Cancel keeps the window, Quit quits with status 0 and the work in the file.
TEST(WindowWorkspace, SeedOutsideTheRoiRefusedAndQuitAsksFirstUnderXvfb) {
    if (!have("xvfb-run") || !have("xdotool") || !have("xauth"))
        GTEST_SKIP() << "xvfb-run, xauth and xdotool are needed (scripts/setup.sh installs them)";
    const Fixture& f = fixture();
    const fs::path dir = f.dir / "window_prompts";
    fs::create_directories(dir);
    Grid<std::uint8_t> roi(f.ph.image.lattice());
    const Vec3i d = roi.dims(), c{d.x / 2, d.y / 2, d.z / 2};
    for (int z = c.z - 4; z <= c.z + 4; ++z)
        for (int y = c.y - 4; y <= c.y + 4; ++y)
            for (int x = c.x - 4; x <= c.x + 4; ++x) roi({x, y, z}) = 1;  // a 9^3 cube at the centre
    const std::string roi_path = (dir / "cube.nii.gz").string();
    write_label_image(roi, roi_path);
    const IntensityScale scale = robust_scale(f.ph.image, &roi);  // the session's: inside the ROI
    const int mu = static_cast<int>(std::lround(scale.low + 0.4 * (scale.high - scale.low)));
    int rc = 0;
    const std::string out =
        run_driver(dir, "window_prompts.sh", f.image + " " + roi_path + " " + (dir / "events.jsonl").string() + " " + std::to_string(mu), rc);
    ASSERT_EQ(rc, 0) << out;
    const auto ev = events(dir / "events.jsonl");
    const auto error = last_of(ev, "error");
    ASSERT_FALSE(error.is_null()) << out;
    EXPECT_NE(error["message"].get<std::string>().find("outside the region of interest"), std::string::npos) << error.dump();
    const auto seed = last_of(ev, "seed");
    ASSERT_FALSE(seed.is_null());
    EXPECT_EQ(seed["seeds"], 1);
    const Vec3d s{seed["index"][0].get<double>(), seed["index"][1].get<double>(), seed["index"][2].get<double>()};
    EXPECT_NE(roi({static_cast<int>(s.x), static_cast<int>(s.y), static_cast<int>(s.z)}), 0);
    // µ typed in raw units: the normalised value is it mapped through the image's scale.
    const auto params = last_of(ev, "params");
    ASSERT_FALSE(params.is_null()) << out;
    EXPECT_NEAR(params["mu_raw"].get<double>(), mu, 1e-9);
    EXPECT_FALSE(params["auto_window"].get<bool>());
    EXPECT_NEAR(params["mu"].get<double>(), (mu - scale.low) / (scale.high - scale.low), 1e-12);
    std::size_t prompts = 0, cancels = 0;
    std::string file;
    for (const auto& e : ev)
        if (e["type"] == "quit_prompt") {
            if (e.contains("buttons")) ++prompts, file = e["file"].get<std::string>();
            if (e.value("answer", "") == "cancel") ++cancels;
        }
    EXPECT_EQ(prompts, 2u);
    EXPECT_EQ(cancels, 1u);
    ASSERT_FALSE(file.empty());
    EXPECT_TRUE(fs::exists(file)) << "the unsaved seed waits in the recovery file the prompt named";
    EXPECT_EQ(last_of(ev, "exit")["seeds"], 1);
}

}  // namespace
}  // namespace liveset
