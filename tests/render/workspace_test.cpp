// Workspaces and seed files: a workspace written and read back gives φ and the sparse field's
// layers bit for bit, the seeds, parameters, swarm settings, target and view exactly, and a session
// continued from it steps exactly as the original does; every bad workspace (missing, truncated,
// another version, another image, a state file of another save) is refused with one line; seed
// files round-trip bit for bit in the CLI's --seed format.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "render/render_test_util.hpp"
#include "scratch_dir.hpp"
#include "viewer.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/session/repair_presets.hpp"
#include "seed_file.hpp"
#include "workspace.hpp"
#include "viewer_test_util.hpp"

namespace liveset {
namespace {

using testing::same_bits;

namespace fs = std::filesystem;
using viewer::Workspace;

using testing::phantom48;

SessionOptions options() {
    SessionOptions o;
    o.fragment_size = 8;
    o.repair = demo_repair_options();
    return o;
}

fs::path workspaces_dir() {
    static const fs::path d = testing::scratch_dir("workspace_test");
    return d;
}

bool same_status(const Grid<std::int8_t>& a, const Grid<std::int8_t>& b) {
    if (a.size() != b.size()) return false;
    for (std::size_t i = 0; i < a.size(); ++i)
        if (a[static_cast<PointIndex>(i)] != b[static_cast<PointIndex>(i)]) return false;
    return true;
}

// A session with work in it: seeds, 25 steps, user parameters, swarm settings and a target.
std::unique_ptr<Session> worked_session() {
    const Phantom& ph = phantom48();
    auto s = std::make_unique<Session>(ph.image, options());
    for (const Vec3i& c : ph.seeds) s->add_seed({c.cast<double>() + Vec3d{0.25, -0.125, 1.0 / 3.0}, 2.0 + 1.0 / 7.0});
    for (int i = 0; i < 25; ++i) s->segment_step();
    s->end_action();
    ThresholdParams p = s->params();
    p.mu += 1.0 / 97.0;
    p.alpha = 0.15;
    s->set_params(p, false);
    RepairOptions r = s->repair_options();
    r.swarm.agents = 77;
    r.swarm.act_probability = 0.3;
    r.swarm.edit_range = 6.5;
    r.swarm.sheet_between = false;  // the issue-18 settings, off their defaults
    r.swarm.sheet_reach = 5.0;
    r.swarm.sheet_between_share = 0.4;
    r.swarm.sheet_between_limited = false;
    r.close_cracks = false;
    s->set_repair_options(r);
    const Vec3d t = s->lattice().coord(s->field().zero_layer().front()).cast<double>();
    s->set_target(t);
    s->end_action();
    return s;
}

viewer::WorkspaceView a_view() {
    viewer::WorkspaceView v;
    v.camera = {12.5, -33.25, 1.7, glm::dvec3(1.5, -2.0, 0.25)};
    v.cursor = {10, 20, 30};
    return v;
}

std::string testing_slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::exception& e) {
        return e.what();
    }
    return "(no error)";
}

TEST(WorkspaceFile, RoundTripIsBitExactAndTheSessionContinuesExactly) {
    const auto original = worked_session();
    const fs::path w = workspaces_dir() / "roundtrip.json";
    viewer::save_workspace(w, *original, "t1.nii.gz", "", true, a_view());
    ASSERT_TRUE(fs::exists(viewer::workspace_state_path(w)));

    const Workspace ws = viewer::read_workspace(w);
    EXPECT_EQ(ws.image, fs::absolute("t1.nii.gz").string());
    EXPECT_EQ(ws.roi, "none");  // saved without a ROI (an older file's empty string reads the same)
    EXPECT_TRUE(ws.bias_corrected);
    EXPECT_TRUE(ws.lattice.same_geometry(original->lattice(), 0.0));
    EXPECT_TRUE(same_bits(ws.phi, original->field().phi()));
    EXPECT_TRUE(same_status(ws.status, original->field().status()));
    ASSERT_EQ(ws.marks.seeds.size(), original->seeds().size());
    for (std::size_t i = 0; i < ws.marks.seeds.size(); ++i) {
        EXPECT_EQ(ws.marks.seeds[i].center, original->seeds()[i].center);
        EXPECT_EQ(ws.marks.seeds[i].radius, original->seeds()[i].radius);
    }
    const ThresholdParams& p = original->params();
    EXPECT_EQ(ws.marks.params.mu, p.mu);
    EXPECT_EQ(ws.marks.params.epsilon, p.epsilon);
    EXPECT_EQ(ws.marks.params.n, p.n);
    EXPECT_EQ(ws.marks.params.alpha, p.alpha);
    EXPECT_FALSE(ws.marks.window_from_seeds);
    EXPECT_FALSE(ws.marks.alpha_automatic);
    EXPECT_EQ(ws.marks.iterations, 25);
    ASSERT_TRUE(ws.step && ws.thin_fronts);  // the session's step as the viewer names it
    EXPECT_EQ(*ws.step, step_name(original->options().segmentation.step));
    EXPECT_EQ(*ws.thin_fronts, original->options().segmentation.step.thin_fronts);
    EXPECT_EQ(ws.repair.swarm.agents, 77u);
    EXPECT_EQ(ws.repair.swarm.act_probability, 0.3);
    EXPECT_EQ(ws.repair.swarm.edit_range, 6.5);
    EXPECT_FALSE(ws.repair.swarm.sheet_between);
    EXPECT_EQ(ws.repair.swarm.sheet_reach, 5.0);
    EXPECT_EQ(ws.repair.swarm.sheet_between_share, 0.4);
    EXPECT_FALSE(ws.repair.swarm.sheet_between_limited);
    EXPECT_TRUE(std::isnan(ws.repair.swarm.sheet_mean));  // the band's centre, kept as null
    EXPECT_FALSE(ws.repair.close_cracks);
    EXPECT_EQ(ws.repair.swarm.decision, original->repair_options().swarm.decision);
    ASSERT_TRUE(ws.target.has_value());
    EXPECT_EQ(*ws.target, *original->target());
    EXPECT_EQ(ws.view.camera.yaw_deg, 12.5);
    EXPECT_EQ(ws.view.camera.pitch_deg, -33.25);
    EXPECT_EQ(ws.view.camera.zoom, 1.7);
    EXPECT_EQ(ws.view.camera.pan, glm::dvec3(1.5, -2.0, 0.25));
    EXPECT_EQ(ws.view.cursor, (Vec3i{10, 20, 30}));

    // Continued in a fresh session on the same image: the same state, and the same next steps.
    Session continued(phantom48().image, options());
    viewer::check_workspace_image(ws, w, continued.image(), continued.roi(), "");
    viewer::apply_workspace(continued, ws);
    EXPECT_TRUE(same_bits(continued.field().phi(), original->field().phi()));
    EXPECT_TRUE(same_status(continued.field().status(), original->field().status()));
    EXPECT_EQ(continued.marks().iterations, 25);
    EXPECT_EQ(continued.repair_options().swarm.agents, 77u);
    original->clear_target();
    continued.clear_target();
    for (int i = 0; i < 10; ++i) {
        original->segment_step();
        continued.segment_step();
    }
    EXPECT_TRUE(same_bits(continued.field().phi(), original->field().phi()));
    EXPECT_TRUE(same_status(continued.field().status(), original->field().status()));
    EXPECT_EQ(continued.segment_status().iterations, 35);

    // The automatic α's flag travels too; a workspace written before it (no key) had a set α. The
    // smoothing σ travels as well; one written before it (no key) ran without.
    ThresholdParams q = original->params();
    q.smooth_mm = 0.75;
    original->set_params(q, false, false);
    const fs::path w1 = workspaces_dir() / "smoothed.json";
    viewer::save_workspace(w1, *original, "t1.nii.gz", "", true, a_view());
    EXPECT_EQ(viewer::read_workspace(w1).marks.params.smooth_mm, 0.75);
    nlohmann::json j1 = nlohmann::json::parse(testing_slurp(w1));
    j1["params"].erase("smooth_mm");
    std::ofstream(w1) << j1.dump();
    EXPECT_EQ(viewer::read_workspace(w1).marks.params.smooth_mm, 0.0);
    original->set_params(q, false, true);
    const fs::path w2 = workspaces_dir() / "automatic_alpha.json";
    viewer::save_workspace(w2, *original, "t1.nii.gz", "", true, a_view());
    const Workspace automatic = viewer::read_workspace(w2);
    EXPECT_TRUE(automatic.marks.alpha_automatic);
    EXPECT_EQ(automatic.marks.params.alpha, original->params().alpha);
    nlohmann::json j = nlohmann::json::parse(testing_slurp(w2));
    ASSERT_TRUE(j["params"].contains("alpha_automatic"));
    j["params"].erase("alpha_automatic");
    std::ofstream(w2) << j.dump();
    EXPECT_FALSE(viewer::read_workspace(w2).marks.alpha_automatic);
}

TEST(WorkspaceFile, BadWorkspacesAreRefusedWithOneClearLine) {
    const auto s = worked_session();
    const fs::path dir = workspaces_dir() / "bad";
    fs::create_directories(dir);
    const fs::path good = dir / "good.json";
    viewer::save_workspace(good, *s, "t1.nii.gz", "", false, a_view());
    const std::string json_text = testing_slurp(good);
    const auto copy_as = [&](const std::string& name, const std::string& text) {
        const fs::path p = dir / name;
        std::ofstream(p, std::ios::binary) << text;
        fs::copy_file(viewer::workspace_state_path(good), viewer::workspace_state_path(p), fs::copy_options::overwrite_existing);
        return p;
    };
    const auto expect_line = [](const std::string& message, const std::string& says) {
        EXPECT_NE(message.find(says), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    };
    const auto read = [](const fs::path& p) { return error_of([&] { viewer::read_workspace(p); }); };

    expect_line(read(dir / "missing.json"), "no such file");
    expect_line(read(copy_as("truncated.json", json_text.substr(0, json_text.size() / 2))), "invalid or truncated JSON");
    expect_line(read(copy_as("empty.json", "")), "invalid or truncated JSON");
    expect_line(read(copy_as("other.json", R"({"something": "else"})")), "not a liveset workspace");
    nlohmann::json j = nlohmann::json::parse(json_text);
    j["liveset_workspace"] = 2;
    expect_line(read(copy_as("v2.json", j.dump())), "workspace version 2; this liveset reads version 1");
    j = nlohmann::json::parse(json_text);
    j.erase("params");
    expect_line(read(copy_as("noparams.json", j.dump())), "missing field 'params'");
    j = nlohmann::json::parse(json_text);
    j["seeds"] = "many";
    expect_line(read(copy_as("badseeds.json", j.dump())), "field 'seeds' is not a list");
    j = nlohmann::json::parse(json_text);
    j["image"] = 5;
    expect_line(read(copy_as("badimage.json", j.dump())), "a field has the wrong type");
    j = nlohmann::json::parse(json_text);
    j["step"]["kind"] = "fast";
    expect_line(read(copy_as("badstep.json", j.dump())), "step kind 'fast' is neither sleeping nor exact");
    j = nlohmann::json::parse(json_text);
    j["step"]["thin_fronts"] = 1;
    expect_line(read(copy_as("badthin.json", j.dump())), "field 'thin_fronts' is not true or false");
    j = nlohmann::json::parse(json_text);
    j.erase("step");  // a file written before session 72: no --step recorded, the rule off as then
    const fs::path older = copy_as("nostep.json", j.dump());
    EXPECT_EQ(read(older), "(no error)");
    EXPECT_FALSE(viewer::read_workspace(older).step.has_value());
    EXPECT_EQ(viewer::read_workspace(older).thin_fronts, std::optional<bool>(false));

    // The state file: missing, truncated, or from another save.
    const fs::path nostate = copy_as("nostate.json", json_text);
    fs::remove(viewer::workspace_state_path(nostate));
    expect_line(read(nostate), "its level set");
    const fs::path cut = copy_as("cutstate.json", json_text);
    fs::resize_file(viewer::workspace_state_path(cut), fs::file_size(viewer::workspace_state_path(cut)) / 2);
    expect_line(read(cut), "its level set");
    const fs::path other = dir / "other_save.json";
    s->segment_step();
    s->end_action();
    viewer::save_workspace(other, *s, "t1.nii.gz", "", false, a_view());
    fs::copy_file(viewer::workspace_state_path(other), viewer::workspace_state_path(copy_as("mixed.json", json_text)),
                  fs::copy_options::overwrite_existing);
    expect_line(read(dir / "mixed.json"), "belongs to another save");

    // Another image: other dimensions, other spacing (same size), other voxels (same geometry).
    const Workspace ws = viewer::read_workspace(good);
    const auto check = [&](const Grid<float>& image) { return error_of([&] { viewer::check_workspace_image(ws, good, image, nullptr, ""); }); };
    EXPECT_EQ(check(phantom48().image), "(no error)");
    PhantomOptions o;
    o.size = 40;
    expect_line(check(make_phantom(o).image), "was saved for another image");
    Grid<float> spaced(Lattice(phantom48().image.dims(), {1.0, 1.0, 1.5}));
    for (std::size_t i = 0; i < spaced.size(); ++i) spaced[static_cast<PointIndex>(i)] = phantom48().image[static_cast<PointIndex>(i)];
    expect_line(check(spaced), "size, spacing, origin or direction");
    Grid<float> changed = phantom48().image;
    changed[static_cast<PointIndex>(changed.size() / 2)] += 1.0f;
    expect_line(check(changed), "other voxel values");
}

TEST(SeedFile, RoundTripIsBitExactInTheCliFormat) {
    const std::vector<SeedBall> seeds = {{{35, 83, 113}, 2.0}, {{0.1, 1.0 / 3.0, 1e-7}, 2.5}, {{180, 216.75, 179}, 1.0 / 7.0}};
    const std::string text = cli::format_seed_file(seeds);
    EXPECT_NE(text.find("\n35,83,113:2\n"), std::string::npos) << text;  // what `--seed 35,83,113:2` takes
    const fs::path p = workspaces_dir() / "seeds.txt";
    cli::write_seed_file(p, seeds);
    const std::vector<SeedBall> back = cli::read_seed_file(p, 2.0);
    ASSERT_EQ(back.size(), seeds.size());
    for (std::size_t i = 0; i < seeds.size(); ++i) {
        EXPECT_EQ(std::bit_cast<std::uint64_t>(back[i].center.x), std::bit_cast<std::uint64_t>(seeds[i].center.x)) << i;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(back[i].center.y), std::bit_cast<std::uint64_t>(seeds[i].center.y)) << i;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(back[i].center.z), std::bit_cast<std::uint64_t>(seeds[i].center.z)) << i;
        EXPECT_EQ(std::bit_cast<std::uint64_t>(back[i].radius), std::bit_cast<std::uint64_t>(seeds[i].radius)) << i;
    }
    // Comments, blank lines and the default radius; a bad line is named by its number.
    const auto parsed = cli::parse_seed_file("# mine\n\n  1,2,3  \n4,5,6:3 # grey matter\n", "s.txt", 2.5);
    ASSERT_EQ(parsed.size(), 2u);
    EXPECT_EQ(parsed[0].center, (Vec3d{1, 2, 3}));
    EXPECT_EQ(parsed[0].radius, 2.5);
    EXPECT_EQ(parsed[1].radius, 3.0);
    const std::string bad = error_of([] { cli::parse_seed_file("1,2,3\n1,2\n", "s.txt", 2.0); });
    EXPECT_NE(bad.find("s.txt line 2:"), std::string::npos) << bad;
    EXPECT_NE(error_of([] { cli::read_seed_file("/nonexistent/seeds.txt", 2.0); }).find("cannot read the seed file"), std::string::npos);
}

// The viewer's save: an existing file it did not load or write is not overwritten without the
// answer "overwrite" (the panel asks); once written it is its own. Work counts as unsaved from the
// first change until the workspace is saved; a headless quit does not ask.
TEST(ViewerWorkspace, NothingOverwrittenWithoutAskingAndUnsavedTracksTheWork) {
    testing::gl_context();
    viewer::ViewerConfig config;
    config.headless = true;
    auto session = std::make_unique<Session>(phantom48().image, options());
    viewer::Viewer v(std::move(session), "t1", config);
    EXPECT_FALSE(v.unsaved());
    ASSERT_TRUE(v.add_seed(phantom48().seeds[0].cast<double>(), 2.0));
    EXPECT_TRUE(v.unsaved());
    const fs::path foreign = workspaces_dir() / "foreign.json";
    std::ofstream(foreign) << "someone else's file\n";
    EXPECT_FALSE(v.save_workspace(foreign.string()));
    EXPECT_EQ(testing_slurp(foreign), "someone else's file\n");
    EXPECT_FALSE(fs::exists(viewer::workspace_state_path(foreign)));
    EXPECT_TRUE(v.unsaved());
    ASSERT_TRUE(v.save_workspace(foreign.string(), true)) << v.message();  // the user said "overwrite"
    EXPECT_FALSE(v.unsaved());
    EXPECT_EQ(viewer::read_workspace(foreign).marks.seeds.size(), 1u);
    ASSERT_TRUE(v.add_seed(phantom48().seeds[1].cast<double>(), 2.0));
    EXPECT_TRUE(v.unsaved());
    ASSERT_TRUE(v.save_workspace(foreign.string())) << v.message();  // its own file now: no question
    EXPECT_EQ(viewer::read_workspace(foreign).marks.seeds.size(), 2u);
    EXPECT_FALSE(v.unsaved());
    v.ask_quit("test");
    EXPECT_TRUE(v.quit_requested());
}

}  // namespace
}  // namespace liveset
