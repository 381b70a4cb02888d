// A real window under Xvfb driven by real input events (xdotool, window_smoke.sh): the drag
// rotates the 3D view, the click with the target tool picks a point on the surface (within half a
// voxel of the zero level set) and aims the swarm there, T runs and stops the swarm, the panel's
// "Reset view" button restores the home camera, Ctrl+Q quits cleanly with status 0. What the
// viewer did is read from its --log-events file.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "liveset/grid/sampling.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/session/recovery.hpp"
#include "scratch_dir.hpp"
#include "viewer_test_util.hpp"

namespace liveset {
namespace {

using testing::have;

namespace fs = std::filesystem;


TEST(WindowSmoke, DragClickKeysAndAButtonUnderXvfb) {
    if (!have("xvfb-run") || !have("xdotool") || !have("xauth"))
        GTEST_SKIP() << "xvfb-run, xauth and xdotool are needed (scripts/setup.sh installs them)";
    const fs::path dir = testing::scratch_dir("window");
    PhantomOptions o;
    o.size = 64;
    const Phantom ph = make_phantom(o);
    const std::string image = (dir / "t1.nii.gz").string(), mask = (dir / "truth.nii.gz").string(),
                      log = (dir / "events.jsonl").string();
    write_image(ph.image, image);
    write_label_image(ph.truth, mask);

    const std::string cmd = "cd " + dir.string() + " && timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' bash " +
                            std::string(LIVESET_SOURCE_DIR) + "/tests/render/window_smoke.sh " + LIVESET_CLI_PATH + " " + image +
                            " " + mask + " " + log + " > driver.out 2>&1";
    const int status = std::system(cmd.c_str());
    std::ifstream driver(dir / "driver.out");
    const std::string driver_out((std::istreambuf_iterator<char>(driver)), std::istreambuf_iterator<char>());
    ASSERT_TRUE(WIFEXITED(status)) << driver_out;
    ASSERT_EQ(WEXITSTATUS(status), 0) << driver_out;  // the viewer's own exit status

    std::vector<nlohmann::json> events;
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);) events.push_back(nlohmann::json::parse(line));
    const auto find = [&](const std::string& type, const std::function<bool(const nlohmann::json&)>& also = {}) {
        for (const auto& e : events)
            if (e["type"] == type && (!also || also(e))) return e;
        return nlohmann::json();
    };
    ASSERT_FALSE(find("ready").is_null());

    // The drag rotated the camera away from the home pose (yaw -30, pitch 20).
    const auto rotate = find("camera", [](const auto& e) { return e["gesture"] == "rotate"; });
    ASSERT_FALSE(rotate.is_null()) << driver_out;
    EXPECT_LT(rotate["yaw"].get<double>(), -30.0 - 5.0);  // dragged right: the object turned right

    // The click picked a point on the surface and made it the target.
    const auto pick = find("pick");
    ASSERT_FALSE(pick.is_null());
    SparseField field(ph.image.lattice(), 2);
    field.init_from_mask(ph.truth);
    const Vec3d p{pick["index"][0].get<double>(), pick["index"][1].get<double>(), pick["index"][2].get<double>()};
    EXPECT_LE(std::abs(trilinear(field.phi(), p)), 0.5) << pick.dump();
    const auto target = find("target");
    ASSERT_FALSE(target.is_null());
    EXPECT_EQ(target["index"], pick["index"]);

    // The swarm ran and stopped; the button reset the camera; Ctrl+Q ended the session.
    EXPECT_FALSE(find("swarm", [](const auto& e) { return e["running"] == true; }).is_null());
    EXPECT_FALSE(find("swarm", [](const auto& e) { return e["running"] == false; }).is_null());
    EXPECT_FALSE(find("button", [](const auto& e) { return e["name"] == "reset_view"; }).is_null());
    const auto exit = find("exit");
    ASSERT_FALSE(exit.is_null());
    EXPECT_EQ(exit["reason"], "ctrl+q");
    EXPECT_DOUBLE_EQ(exit["camera"]["yaw"].get<double>(), -30.0);
    EXPECT_DOUBLE_EQ(exit["camera"]["pitch"].get<double>(), 20.0);
    ASSERT_TRUE(exit.contains("target"));
    // The swarm's edits were never saved: they wait in a recovery file for the next start.
    const fs::path kept = recovery_path(dir / "recovery", image, "n4");  // the viewer's default: N4 first
    ASSERT_TRUE(fs::exists(kept)) << driver_out;
    EXPECT_EQ(read_recovery(kept).signal, 0);
    fs::remove_all(dir);
}

// The image has a recovery file (unsaved work of a headless run): the window opens with the
// restore dialog, a real click on "Restore" restores it, Ctrl+Q quits with status 0.
TEST(WindowSmoke, TheRestoreDialogRestoresUnsavedWorkUnderXvfb) {
    if (!have("xvfb-run") || !have("xdotool") || !have("xauth"))
        GTEST_SKIP() << "xvfb-run, xauth and xdotool are needed (scripts/setup.sh installs them)";
    const fs::path dir = testing::scratch_dir("window_recovery");
    PhantomOptions o;
    o.size = 48;
    const Phantom ph = make_phantom(o);
    const std::string image = (dir / "t1.nii.gz").string(), log = (dir / "events.jsonl").string();
    write_image(ph.image, image);
    std::string script = "[";
    for (const Vec3i& s : ph.seeds) script += "{\"seed\": [" + std::to_string(s.x) + ", " + std::to_string(s.y) + ", " + std::to_string(s.z) + "]}, ";
    script += "{\"segment\": 30}]";
    std::ofstream(dir / "work.json") << script;
    const fs::path recovery = dir / "recovery";
    const std::string work = std::string(LIVESET_CLI_PATH) + " view " + image + " --headless --recovery-dir " + recovery.string() +
                             " --script " + (dir / "work.json").string() + " > " + (dir / "work.out").string() + " 2>&1";
    ASSERT_EQ(std::system(work.c_str()), 0);
    ASSERT_TRUE(fs::exists(recovery_path(recovery, image, "n4")));  // the viewer's default: N4 first

    const std::string cmd = "cd " + dir.string() + " && timeout 300 xvfb-run -a -s '-screen 0 1280x720x24' bash " +
                            std::string(LIVESET_SOURCE_DIR) + "/tests/render/window_recovery.sh " + LIVESET_CLI_PATH + " " + image +
                            " " + recovery.string() + " " + log + " > driver.out 2>&1";
    const int status = std::system(cmd.c_str());
    std::ifstream driver(dir / "driver.out");
    const std::string driver_out((std::istreambuf_iterator<char>(driver)), std::istreambuf_iterator<char>());
    ASSERT_TRUE(WIFEXITED(status)) << driver_out;
    ASSERT_EQ(WEXITSTATUS(status), 0) << driver_out;

    std::vector<nlohmann::json> events;
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);) events.push_back(nlohmann::json::parse(line));
    const auto count = [&](const std::string& type) {
        return std::count_if(events.begin(), events.end(), [&](const nlohmann::json& e) { return e["type"] == type; });
    };
    EXPECT_EQ(count("recovery_offer"), 1);
    EXPECT_EQ(count("restore"), 1) << driver_out;
    const auto exit = std::find_if(events.begin(), events.end(), [](const nlohmann::json& e) { return e["type"] == "exit"; });
    ASSERT_NE(exit, events.end());
    EXPECT_EQ((*exit)["seeds"], ph.seeds.size()) << "the restored seeds";
    EXPECT_EQ((*exit)["iterations"], 30);
    // Still unsaved after the restore: the file is kept for the next start.
    EXPECT_EQ(read_recovery(recovery_path(recovery, image, "n4")).marks.iterations, 30);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace liveset
