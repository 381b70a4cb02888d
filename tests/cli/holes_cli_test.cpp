// `liveset holes` and `liveset repair --decision sheet` on a drilled shell written to disk: the hole
// listed with a site inside the drill, the repair closing it by the finder's verdict; bad input
// gets one line and a non-zero exit.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

using testing::run_cli;
using testing::scratch_dir;

// 64^3: WM 130 (r <= 21), GM 100 (21 < r <= 25), CSF 50; the mask is the GM shell minus a drill of
// radius 3 along +x from the centre.
struct Files {
    std::filesystem::path dir, image, mask, small;
};

Files write_shell() {
    Files f;
    f.dir = scratch_dir("holes_cli");
    const Lattice lat({64, 64, 64});
    Grid<float> image(lat, 50.0f);
    Grid<std::uint8_t> mask(lat, 0);
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const double r = std::sqrt((x - 32.0) * (x - 32.0) + (y - 32.0) * (y - 32.0) + (z - 32.0) * (z - 32.0));
                if (r <= 21) image({x, y, z}) = 130.0f;
                else if (r <= 25) {
                    image({x, y, z}) = 100.0f;
                    mask({x, y, z}) = !(x > 32 && std::hypot(y - 32.0, z - 32.0) <= 3.0);
                }
            }
    f.image = f.dir / "t1.nii.gz";
    f.mask = f.dir / "seg.nii.gz";
    f.small = f.dir / "small.nii.gz";
    write_image(image, f.image.string());
    write_label_image(mask, f.mask.string());
    write_label_image(Grid<std::uint8_t>(Lattice({8, 8, 8}), 1), f.small.string());
    return f;
}

TEST(HolesCli, ListsTheDrilledHoleAndRepairClosesIt) {
    const Files f = write_shell();
    const std::string band = " --sheet-lower 75 --sheet-upper 115";
    auto r = run_cli("holes " + f.mask.string() + " --image " + f.image.string() + band + " --json");
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto j = nlohmann::json::parse(r.out);
    ASSERT_EQ(j["holes"].get<int>(), 1);
    const auto t = j["sites"][0]["target"];
    const int x = t[0], y = t[1], z = t[2];
    EXPECT_GT(x, 32 + 21);  // in the drilled part of the shell
    EXPECT_LE(std::hypot(y - 32.0, z - 32.0), 3.0);
    const std::string target = std::to_string(x) + "," + std::to_string(y) + "," + std::to_string(z);
    const auto out = f.dir / "rep.nii.gz";
    r = run_cli("repair " + f.mask.string() + " --image " + f.image.string() + band + " --decision sheet --p 0.3 --radius 2 --edit-range 6 --steps 300 --target " +
                target + " --out-mask " + out.string() + " --json");
    ASSERT_EQ(r.rc, 0) << r.err;
    const auto rj = nlohmann::json::parse(r.out);
    ASSERT_EQ(rj["targets"].size(), 1u);
    EXPECT_TRUE(rj["targets"][0]["closed"].get<bool>());
    EXPECT_GT(rj["targets"][0]["finder_voxels_near"]["before"].get<int>(), 0);
    EXPECT_EQ(rj["targets"][0]["finder_voxels_near"]["after"].get<int>(), 0);
    EXPECT_EQ(rj["targets"][0]["local_genus"]["after"].get<int>(), 0);
    r = run_cli("holes " + out.string() + " --image " + f.image.string() + band + " --json");
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["holes"].get<int>(), 0);
    std::filesystem::remove_all(f.dir);
}

TEST(HolesCli, BadInputGetsOneLineAndNonZeroExit) {
    const Files f = write_shell();
    for (const std::string& args : {"holes " + f.mask.string() + " --image " + f.dir.string() + "/missing.nii.gz",
                                    "holes " + f.small.string() + " --image " + f.image.string(),
                                    "holes " + f.mask.string() + " --image " + f.image.string() + " --sheet-lower 75",
                                    "holes " + f.mask.string() + " --image " + f.image.string() + " --sheet-lower 90 --sheet-upper 80",
                                    "repair " + f.mask.string() + " --image " + f.image.string() +
                                        " --decision sheet --sheet-lower 90 --sheet-upper 80 --target 57,32,32 --out-mask " +
                                        (f.dir / "x.nii.gz").string(),
                                    // the centre of the white matter: no surface within an 8-voxel brush
                                    "repair " + f.mask.string() + " --image " + f.image.string() +
                                        " --edit-range 8 --target 32,32,32 --out-mask " + (f.dir / "x.nii.gz").string(),
                                    // outside the ROI (the 8^3 corner box is not its size: use the mask itself as ROI)
                                    "repair " + f.mask.string() + " --image " + f.image.string() + " --roi " + f.mask.string() +
                                        " --target 57,32,32 --out-mask " + (f.dir / "x.nii.gz").string()}) {
        const auto r = run_cli(args);
        EXPECT_NE(r.rc, 0) << args;
        EXPECT_EQ(testing::lines(r.err), 1) << args << "\n" << r.err;
        EXPECT_TRUE(r.out.empty()) << args;
    }
    EXPECT_FALSE(std::filesystem::exists(f.dir / "x.nii.gz"));
    std::filesystem::remove_all(f.dir);
}

// The paper's Figure 5 as the issue checks it, against BrainWeb's truth (≈ 1.5 min on 2 cores):
// at least 80 % of the finder's targets closed (the true GM voxels missing within 6 voxels at least
// halved), Dice not lower, at least half of the added voxels GM. scripts/judge_repair.py checks the
// same with nibabel.
TEST(HolesCli, BrainDemoRepairMeetsTheChecksAgainstTheTruth) {
    const std::filesystem::path data = std::filesystem::path(LIVESET_DATA_DIR) / "brainweb";
    ASSERT_TRUE(std::filesystem::exists(data / "t1.mha")) << "BrainWeb data not found in " << data;
    const auto dir = scratch_dir("holes_demo_brain_repair") / "out";  // the demo makes its --out folder
    const auto r = run_cli("--threads 2 demo --brain --repair --out " + dir.string() + " --quiet");
    ASSERT_EQ(r.rc, 0) << r.err;
    std::ifstream in(dir / "report.json");
    const auto j = nlohmann::json::parse(in);
    const Grid<std::uint8_t> before = read_label_image((dir / "seg.nii.gz").string());
    const Grid<std::uint8_t> after = read_label_image((dir / "seg_repaired.nii.gz").string());
    Grid<std::uint8_t> gm = read_label_image((data / "labels_crisp.nii.gz").string());
    for (std::uint8_t& v : gm.values()) v = v == 2;
    ASSERT_TRUE(before.lattice().same_geometry(gm.lattice()));
    ASSERT_TRUE(after.lattice().same_geometry(gm.lattice()));
    const auto targets = j["targets"];
    ASSERT_GE(targets.size(), 5u);
    std::size_t closed = 0;
    for (const auto& t : targets) {
        const Vec3i c{t[0].get<int>(), t[1].get<int>(), t[2].get<int>()};
        std::size_t mb = 0, ma = 0;
        for (int dz = -6; dz <= 6; ++dz)
            for (int dy = -6; dy <= 6; ++dy)
                for (int dx = -6; dx <= 6; ++dx) {
                    const Vec3i q = c + Vec3i{dx, dy, dz};
                    if (dx * dx + dy * dy + dz * dz > 36 || !gm.lattice().contains(q) || !gm(q)) continue;
                    mb += !before(q);
                    ma += !after(q);
                }
        closed += 2 * ma <= mb;
    }
    EXPECT_GE(static_cast<double>(closed), 0.8 * static_cast<double>(targets.size()));  // measured 9 of 10 (N4's settings before session 47)
    std::size_t added = 0, added_gm = 0, both = 0, sum_b = 0, sum_a = 0, gm_n = 0;
    for (PointIndex i = 0; i < gm.size(); ++i) {
        added += after[i] && !before[i];
        added_gm += after[i] && !before[i] && gm[i];
        sum_b += before[i] && gm[i];
        sum_a += after[i] && gm[i];
        both += before[i];
        gm_n += gm[i];
    }
    EXPECT_GT(added, 0u);
    EXPECT_GE(2 * added_gm, added);  // measured 90.5 %
    std::size_t after_n = 0;
    for (PointIndex i = 0; i < after.size(); ++i) after_n += after[i];
    const double dice_before = 2.0 * double(sum_b) / double(both + gm_n), dice_after = 2.0 * double(sum_a) / double(after_n + gm_n);
    EXPECT_GE(dice_after, dice_before);
    EXPECT_NEAR(j["before"]["dice"].get<double>(), dice_before, 1e-9);
    EXPECT_NEAR(j["after"]["dice"].get<double>(), dice_after, 1e-9);
    std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace liveset
