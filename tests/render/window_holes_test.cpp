// The hole finder in a real window under Xvfb, driven by xdotool (window_holes.sh): a click on
// "Find holes" lists the drilled phantom's hole first (its site a drilled voxel); a click on the
// list's first row moves the cursor to that site and aims the swarm there; N selects the next
// (round to the first again when the drill is the only candidate).
// What the viewer did is read from its --log-events file.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "liveset/io/image_io.hpp"
#include "scratch_dir.hpp"
#include "session/hole_phantom.hpp"
#include "viewer_test_util.hpp"

namespace liveset {
namespace {

using testing::have;
using testing::vec3i;

namespace fs = std::filesystem;



TEST(WindowHoles, FindHolesThenClickTheFirstRowUnderXvfb) {
    if (!have("xvfb-run") || !have("xdotool") || !have("xauth"))
        GTEST_SKIP() << "xvfb-run, xauth and xdotool are needed (scripts/setup.sh installs them)";
    const fs::path dir = testing::scratch_dir("window_holes");
    const testing::DrilledPhantom& d = testing::drilled_phantom();
    const std::string image = (dir / "t1.nii.gz").string(), mask = (dir / "drilled.nii.gz").string(), log = (dir / "events.jsonl").string();
    write_image(d.phantom.image, image);
    write_label_image(d.mask, mask);
    const std::string cmd = "cd " + dir.string() + " && timeout 120 xvfb-run -a -s '-screen 0 1280x1024x24' bash " +
                            std::string(LIVESET_SOURCE_DIR) + "/tests/render/window_holes.sh " + LIVESET_CLI_PATH + " " + image + " " +
                            mask + " " + log + " > driver.out 2>&1";
    const int status = std::system(cmd.c_str());
    std::ifstream driver(dir / "driver.out");
    const std::string driver_out((std::istreambuf_iterator<char>(driver)), std::istreambuf_iterator<char>());
    ASSERT_TRUE(WIFEXITED(status)) << driver_out;
    ASSERT_EQ(WEXITSTATUS(status), 0) << driver_out;

    std::vector<nlohmann::json> events;
    std::ifstream in(log);
    for (std::string line; std::getline(in, line);) events.push_back(nlohmann::json::parse(line));
    const auto all = [&](const std::string& type) {
        std::vector<nlohmann::json> out;
        for (const auto& e : events)
            if (e["type"] == type) out.push_back(e);
        return out;
    };
    const auto found = all("holes"), selected = all("select_hole"), cursors = all("cursor"), targets = all("target");
    ASSERT_EQ(found.size(), 1u) << driver_out;
    const int count = found[0]["count"].get<int>();
    EXPECT_GE(count, 1);
    ASSERT_EQ(selected.size(), 2u);
    EXPECT_EQ(selected[0]["rank"], 1);
    EXPECT_EQ(selected[1]["rank"], 1 % count + 1);  // the N key: the next one (the list wraps round)
    const Vec3i site = vec3i(selected[0]["site"]);
    EXPECT_TRUE(d.drilled(site)) << selected[0].dump();
    ASSERT_GE(cursors.size(), 2u);
    EXPECT_EQ(vec3i(cursors[0]["voxel"]), site);
    EXPECT_EQ(cursors[0]["how"], "hole");
    ASSERT_GE(targets.size(), 1u);
    EXPECT_EQ(vec3i(targets[0]["index"]), site);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace liveset
