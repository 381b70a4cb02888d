// The slice panes in a real window under Xvfb, driven by xdotool (window_slices.sh): zoom about the
// pointer keeps the voxel under it (a click before and after Ctrl+wheel lands on the same voxel),
// a middle-drag pan carries it along with the pointer, a right drag zooms in, Shift+drag widens
// the window and raises the level, the opacity slider at 1 paints an inside voxel in the label
// colour and at 0 leaves it grey (window screenshots), typed 1-based voxels and LPS millimetres
// land on the right voxel. What the viewer did is read from its --log-events file.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include <fmt/core.h>

#include "liveset/io/image_io.hpp"
#include "liveset/phantom/phantom.hpp"
#include "liveset/render/png_writer.hpp"
#include "scratch_dir.hpp"
#include "viewer_test_util.hpp"

namespace liveset {
namespace {

using testing::have;

namespace fs = std::filesystem;


std::array<int, 3> rgb_at(const render::Image& img, int x, int y) {
    const std::size_t k = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x));
    return {img.rgba[k], img.rgba[k + 1], img.rgba[k + 2]};
}

TEST(WindowSlices, ZoomPanWindowLevelOpacityAndTypedCursorUnderXvfb) {
    if (!have("xvfb-run") || !have("xdotool") || !have("xauth"))
        GTEST_SKIP() << "xvfb-run, xauth and xdotool are needed (scripts/setup.sh installs them)";
    const fs::path dir = testing::scratch_dir("window_slices");
    PhantomOptions o;
    o.size = 48;
    const Phantom ph = make_phantom(o);
    // The phantom on an anisotropic, off-centre, x-flipped lattice: millimetres are not voxels.
    const Lattice lat(ph.image.lattice().dims(), {1.2, 1.0, 0.9}, {30.0, -12.5, 7.0}, Mat3d{-1, 0, 0, 0, 1, 0, 0, 0, 1});
    Grid<float> image(lat);
    Grid<std::uint8_t> box(lat);
    for (PointIndex i = 0; i < image.size(); ++i) {
        image[i] = ph.image[i];
        const Vec3i p = lat.coord(i);
        box[i] = p.x >= 8 && p.x < 40 && p.y >= 8 && p.y < 40 && p.z >= 8 && p.z < 40;
    }
    const std::string image_path = (dir / "t1.nii.gz").string(), mask = (dir / "box.nii.gz").string(), log = (dir / "events.jsonl").string();
    write_image(image, image_path);
    write_label_image(box, mask);
    const Vec3i typed_mm_voxel{5, 6, 7};
    const Vec3d lps = lat.to_world(typed_mm_voxel.cast<double>());
    const std::string mm = fmt::format("{:.3f} {:.3f} {:.3f}", lps.x, lps.y, lps.z);

    const std::string cmd = "cd " + dir.string() + " && timeout 300 xvfb-run -a -s '-screen 0 1280x1024x24' bash " +
                            std::string(LIVESET_SOURCE_DIR) + "/tests/render/window_slices.sh " + LIVESET_CLI_PATH + " " + image_path +
                            " " + mask + " " + log + " '" + mm + "' > driver.out 2>&1";
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
    const auto cursors = all("cursor"), views = all("slice_view"), windows = all("window"), displays = all("display");
    ASSERT_EQ(cursors.size(), 5u) << driver_out;
    // The voxel under the pointer stays under it through the wheel zoom and moves with the pan.
    EXPECT_EQ(cursors[1]["voxel"], cursors[0]["voxel"]);
    EXPECT_EQ(cursors[2]["voxel"], cursors[0]["voxel"]);
    ASSERT_GE(views.size(), 5u);
    EXPECT_NEAR(views[2]["zoom"].get<double>(), 1.2 * 1.2 * 1.2, 1e-9);
    const auto zoomed = std::find_if(views.begin(), views.end(), [](const auto& e) { return e["gesture"] == "zoom"; });
    ASSERT_NE(zoomed, views.end());
    EXPECT_GT((*zoomed)["zoom"].get<double>(), 1.2 * 1.728);  // dragged 40 px up: 1.01^40 more
    // Window/level: the first is the automatic one, then the drag widened it and raised the level.
    ASSERT_EQ(windows.size(), 2u);
    EXPECT_EQ(windows[0]["preset"], "auto");
    EXPECT_GT(windows[1]["width"].get<double>(), 1.2 * windows[0]["width"].get<double>());
    EXPECT_GT(windows[1]["level"].get<double>(), windows[0]["level"].get<double>());
    // Opacity 1 then 0; the cursor's voxel (inside the box mask) shows the label colour, then grey.
    ASSERT_EQ(displays.size(), 2u);
    EXPECT_GE(displays[0]["label_opacity"].get<double>(), 0.99);
    EXPECT_LE(displays[1]["label_opacity"].get<double>(), 0.01);
    const Vec3i c{cursors[2]["voxel"][0].get<int>(), cursors[2]["voxel"][1].get<int>(), cursors[2]["voxel"][2].get<int>()};
    ASSERT_TRUE(box(c)) << "the clicked voxel should lie inside the mask";
    const auto ready = all("ready").at(0);
    const int x = ready["panes"]["axial"][0].get<int>() + ready["panes"]["axial"][2].get<int>() / 2 + 37 + 30;
    const int y = ready["panes"]["axial"][1].get<int>() + ready["panes"]["axial"][3].get<int>() / 2 + 23 + 20;
    const render::Image opaque = render::read_png((dir / "opaque.png").string()), clear = render::read_png((dir / "clear.png").string());
    const auto a = rgb_at(opaque, x, y), b = rgb_at(clear, x, y);
    EXPECT_NEAR(a[0], 230, 2);
    EXPECT_NEAR(a[1], 60, 2);
    EXPECT_NEAR(a[2], 50, 2);
    EXPECT_EQ(b[0], b[1]);  // grey: the image alone
    EXPECT_EQ(b[1], b[2]);
    // Typed entry: 1-based "10 20 30" is voxel (9, 19, 29); the LPS point lands on its voxel.
    EXPECT_EQ(cursors[3]["how"], "typed");
    EXPECT_EQ(cursors[3]["voxel1"], nlohmann::json({10, 20, 30}));
    EXPECT_EQ(cursors[3]["voxel"], nlohmann::json({9, 19, 29}));
    EXPECT_EQ(cursors[4]["voxel"], nlohmann::json({typed_mm_voxel.x, typed_mm_voxel.y, typed_mm_voxel.z})) << mm;
    fs::remove_all(dir);
}

}  // namespace
}  // namespace liveset
