// The hole finder in the viewer, through `liveset view --headless --script` on the 64^3 phantom with
// a hole drilled by hand in its grey-matter truth (session/hole_phantom.hpp): "find_holes" lists the
// drill first, its site on the drilled voxels; "select_hole" moves the cursor there (event log) and
// draws the selected marker - a ring in the highlight colour around the site's projection in the
// axial pane, and none elsewhere; a swarm repair aimed there and a second "find_holes" give the
// finder's verdict "closed" on that site and the drill is no longer listed. Bad entries: one line.
#include <gtest/gtest.h>

#include <filesystem>
#include <fmt/core.h>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/render/png_writer.hpp"
#include "liveset/render/slice_geometry.hpp"
#include "liveset/render/slice_renderer.hpp"
#include "scratch_dir.hpp"
#include "session/hole_phantom.hpp"
#include "viewer_test_util.hpp"

namespace liveset {
namespace {

using testing::vec3i;

namespace fs = std::filesystem;
using testing::run_cli;
using testing::CliResult;

fs::path holes_dir() {
    static const fs::path d = testing::scratch_dir("viewer_holes");
    return d;
}

// The image and the drilled segmentation on disk, once.
struct Files {
    std::string image, mask;
};
const Files& files() {
    static const Files f = [] {
        const testing::DrilledPhantom& d = testing::drilled_phantom();
        Files r{(holes_dir() / "t1.nii.gz").string(), (holes_dir() / "drilled.nii.gz").string()};
        write_image(d.phantom.image, r.image);
        write_label_image(d.mask, r.mask);
        return r;
    }();
    return f;
}

// The "holes" objects a script printed, in order.
std::vector<nlohmann::json> hole_reports(const std::string& out) {
    std::vector<nlohmann::json> r;
    std::istringstream in(out);
    for (std::string line; std::getline(in, line);)
        if (!line.empty() && line.front() == '{') {
            const nlohmann::json j = nlohmann::json::parse(line);
            if (j.contains("holes")) r.push_back(j["holes"]);
        }
    return r;
}

std::vector<nlohmann::json> events(const fs::path& log, const std::string& type) {
    std::vector<nlohmann::json> r;
    std::istringstream in(testing::slurp(log));
    for (std::string line; std::getline(in, line);)
        if (!line.empty()) {
            const nlohmann::json j = nlohmann::json::parse(line);
            if (j.value("type", "") == type) r.push_back(j);
        }
    return r;
}


bool is_highlight(const render::Image& img, int x, int y) {
    if (x < 0 || y < 0 || x >= img.width || y >= img.height) return false;
    const std::size_t k = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x));
    const glm::vec4 c = render::SliceStyle{}.marker_selected * 255.0f;  // drawn opaque on the selected slice
    return std::abs(img.rgba[k] - c.r) <= 40 && std::abs(img.rgba[k + 1] - c.g) <= 40 && std::abs(img.rgba[k + 2] - c.b) <= 40;
}

TEST(ViewerHoles, FindSelectRepairAndTheFindersVerdict) {
    const testing::DrilledPhantom& d = testing::drilled_phantom();
    const Files& f = files();
    const fs::path dir = holes_dir(), log = dir / "events.jsonl", shot = dir / "axial.png";
    const int w = 256, h = 256;
    std::ofstream(dir / "holes.json") << fmt::format(
        R"([{{"find_holes": {{}}}}, {{"select_hole": 1}}, {{"screenshot": "{}", "pane": "axial", "size": [{}, {}]}},
            {{"swarm": 300}}, {{"find_holes": {{}}}}])",
        shot.string(), w, h);
    const CliResult r = run_cli("view " + f.image + " --mask " + f.mask + " --headless --no-autosave --log-events " + log.string() +
                                " --script " + (dir / "holes.json").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    const std::vector<nlohmann::json> reports = hole_reports(r.out);
    ASSERT_EQ(reports.size(), 2u) << r.out;

    // The drill is listed first, its site a drilled voxel; 1-based voxel = target + 1.
    const nlohmann::json& first = reports[0]["sites"][0];
    const Vec3i site = vec3i(first["target"]);
    EXPECT_EQ(first["rank"], 1);
    EXPECT_TRUE(d.drilled(site)) << first.dump();
    EXPECT_EQ(vec3i(first["voxel1"]), (site + Vec3i{1, 1, 1}));
    EXPECT_EQ(reports[0]["band_from"], "tissue model");

    // select_hole: the cursor on the site (all three slices follow: one cursor), the swarm's target.
    const std::vector<nlohmann::json> cursors = events(log, "cursor");
    ASSERT_FALSE(cursors.empty());
    EXPECT_EQ(cursors.back()["how"], "hole");
    EXPECT_EQ(vec3i(cursors.back()["voxel"]), site);
    const std::vector<nlohmann::json> targets = events(log, "target");
    ASSERT_EQ(targets.size(), 1u);
    EXPECT_EQ(vec3i(targets[0]["index"]), site);

    // The selected marker: highlight pixels on the ring about the site's projection (the diagonals,
    // clear of the crosshair), none far from it.
    const render::Image img = render::read_png(shot.string());
    const render::SliceViewport vp =
        render::SliceViewport::fit(render::slice_geometry(d.phantom.image.lattice(), render::SliceAxis::kAxial), w, h);
    const glm::dvec2 c = vp.to_pixel(vp.geometry.to_uv(site.cast<double>()));
    int on_ring = 0, far = 0;
    for (const double rad : {render::kMarkerRadiusPx, render::kMarkerRadiusPx + 3.0f})
        for (const int sx : {-1, 1})
            for (const int sy : {-1, 1}) {
                bool hit = false;
                const int px = static_cast<int>(std::floor(c.x + sx * rad * 0.7071)), py = static_cast<int>(std::floor(c.y + sy * rad * 0.7071));
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) hit = hit || is_highlight(img, px + dx, py + dy);
                on_ring += hit;
            }
    for (int y = 0; y < img.height; ++y)
        for (int x = 0; x < img.width; ++x)
            if (std::hypot(x - c.x, y - c.y) > 40.0) far += is_highlight(img, x, y);
    EXPECT_EQ(on_ring, 8) << "site pixel " << c.x << "," << c.y;
    EXPECT_EQ(far, 0);

    // After 300 swarm steps at the site: the finder's verdict there is "closed", as `liveset repair`
    // reports it, and no candidate is left within the verdict radius of the drill.
    const nlohmann::json& after = reports[1];
    ASSERT_EQ(after["verdicts"].size(), 1u) << after.dump();
    const nlohmann::json& v = after["verdicts"][0];
    EXPECT_EQ(vec3i(v["target"]), site);
    EXPECT_GT(v["before"].get<int>(), 0);
    EXPECT_TRUE(v["closed"].get<bool>()) << v.dump();
    EXPECT_LE(2 * v["after"].get<int>(), v["before"].get<int>());
    for (const nlohmann::json& s : after["sites"]) EXPECT_GT(norm((vec3i(s["target"]) - site).cast<double>()), 6.0) << s.dump();
}

TEST(ViewerHoles, BadEntriesAreRefusedWithOneLine) {
    const Files& f = files();
    const fs::path dir = holes_dir();
    struct Case {
        std::string script, phrase;
    };
    const Case cases[] = {
        {R"([{"select_hole": 1}])", "entry 1 (\"select_hole\"): no hole candidates"},
        {R"([{"find_holes": {}}, {"select_hole": 999}])", "entry 2 (\"select_hole\"): no hole 999"},
        {R"([{"select_hole": 0}])", "the rank must be in"},
        {R"([{"find_holes": {"min_voxels": 0}}])", "min_voxels must be in"},
        {R"([{"find_holes": {"sheet_band": [5, 2]}}])", "lower end must be below"},
        {R"([{"find_holes": {"band": [1, 2]}}])", "unknown key \"band\""},
        {R"([{"find_holes": 3}])", "expected an object"},
    };
    for (const Case& c : cases) {
        std::ofstream(dir / "bad.json") << c.script;
        const CliResult r = run_cli("view " + f.image + " --mask " + f.mask + " --headless --no-autosave --script " + (dir / "bad.json").string());
        EXPECT_EQ(r.rc, 1) << c.script;
        std::size_t errors = 0;  // (a note on where the start parameters came from may precede it)
        for (std::size_t at = 0; (at = r.err.find("liveset: error:", at)) != std::string::npos; ++at) ++errors;
        EXPECT_EQ(errors, 1u) << c.script << ": " << r.err;
        EXPECT_EQ(r.err.back(), '\n');
        EXPECT_EQ(r.err.find('\n', r.err.find("liveset: error:")), r.err.size() - 1) << r.err;  // one line
        EXPECT_NE(r.err.find(c.phrase), std::string::npos) << c.script << ": " << r.err;
    }
}

}  // namespace
}  // namespace liveset
