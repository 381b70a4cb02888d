// `liveset repair --find-holes N`: the truth-free repair of `demo --brain --repair` on a user's own
// segmentation — its targets are the finder's sites (as `liveset holes` lists them), the drilled
// holes of a shell close, nothing is added outside the shell; bad combinations get one line.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

using testing::run_cli;
using testing::scratch_dir;

double radius(int x, int y, int z) { return std::sqrt((x - 32.0) * (x - 32.0) + (y - 32.0) * (y - 32.0) + (z - 32.0) * (z - 32.0)); }
bool in_shell(int x, int y, int z) { return radius(x, y, z) > 21 && radius(x, y, z) <= 25; }
// Two drills through the shell: radius 3 along +x, radius 2 along -y.
bool drilled(int x, int y, int z) { return (x > 32 && std::hypot(y - 32.0, z - 32.0) <= 3.0) || (y < 32 && std::hypot(x - 32.0, z - 32.0) <= 2.0); }

// 64^3: WM 130 (r <= 21), GM 100 (21 < r <= 25), CSF 50; the segmentation is the GM shell less the
// two drills (GM-bright: holes a user sees and the finder lists).
void write_fixture(const std::filesystem::path& dir) {
    const Lattice lat({64, 64, 64});
    Grid<float> image(lat, 50.0f);
    Grid<std::uint8_t> mask(lat, 0);
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                if (radius(x, y, z) <= 21) image({x, y, z}) = 130.0f;
                if (in_shell(x, y, z)) {
                    image({x, y, z}) = 100.0f;
                    mask({x, y, z}) = !drilled(x, y, z);
                }
            }
    write_image(image, (dir / "t1.nii.gz").string());
    write_label_image(mask, (dir / "seg.nii.gz").string());
}

TEST(FindHolesCli, ClosesTheFindersHolesWithoutGrowingOutOfTheSheet) {
    const auto dir = scratch_dir("find_holes_close");
    write_fixture(dir);
    const std::string io = (dir / "seg.nii.gz").string() + " --image " + (dir / "t1.nii.gz").string() + " --sheet-lower 75 --sheet-upper 115";
    auto r = run_cli("holes " + io + " --json");
    ASSERT_EQ(r.rc, 0) << r.err;
    const nlohmann::json holes = nlohmann::json::parse(r.out);
    ASSERT_GE(holes["sites"].size(), 2u);
    r = run_cli("--threads 1 repair " + io + " --find-holes 2 --min-hole 10 --round-steps 400 --json --out-mask " + (dir / "rep.nii.gz").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["targets"].size(), 2u);
    for (int k = 0; k < 2; ++k) EXPECT_EQ(j["targets"][k], holes["sites"][k]["target"]) << k;  // the finder's sites, largest first
    EXPECT_EQ(j["closed"].get<int>(), 2);
    EXPECT_EQ(j["finder"]["after"].get<int>(), 0);

    // Against the fixture itself: the drills filled, nothing raised outside the shell.
    const Grid<std::uint8_t> before = read_label_image((dir / "seg.nii.gz").string());
    const Grid<std::uint8_t> after = read_label_image((dir / "rep.nii.gz").string());
    std::size_t drill = 0, filled = 0, outside = 0;
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const bool shell = in_shell(x, y, z);
                if (shell && drilled(x, y, z)) drill += 1, filled += after({x, y, z}) != 0;
                if (!shell && after({x, y, z}) && !before({x, y, z})) ++outside;
            }
    EXPECT_GE(filled * 10, drill * 9) << filled << " of " << drill;
    EXPECT_EQ(outside, 0u);
    std::filesystem::remove_all(dir);
}

TEST(FindHolesCli, BadCombinationsGetOneLineAndNonZeroExit) {
    const auto dir = scratch_dir("find_holes_bad");
    write_fixture(dir);
    const std::string base = "repair " + (dir / "seg.nii.gz").string() + " --image " + (dir / "t1.nii.gz").string() + " --out-mask " +
                             (dir / "x.nii.gz").string();
    for (const char* extra : {" --find-holes 2 --target 55,32,32", " --find-holes 2 --decision intensity", " --find-holes 2 --steps 100",
                              " --target 55,32,32 --round-steps 100", " --target 55,32,32 --min-hole 5", " --find-holes 0", " --round-steps 100"}) {
        const auto r = run_cli(base + extra);
        EXPECT_NE(r.rc, 0) << extra;
        EXPECT_EQ(testing::lines(r.err), 1) << extra << "\n" << r.err;
        EXPECT_TRUE(r.out.empty()) << extra;
    }
    EXPECT_FALSE(std::filesystem::exists(dir / "x.nii.gz"));
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace liveset
