// `liveset repair --band-only` (the sheet rule's between-the-sides test off) compared with the
// default run on a bias-bright hole; --band-only, --between-share and --no-crack-closing in bad combinations get one
// line on stderr and a non-zero exit. (--no-crack-closing's behaviour is tested on the guard itself,
// Repair.ACrackBetweenTwoFrontsClosesWithItsTunnel: on a CLI fixture the fronts zip a slit shut
// from its ends within a few steps either way.) `--decision cut` cuts a handle and nothing else.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/io/image_io.hpp"
#include "rod_shell.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

using testing::run_cli;
using testing::scratch_dir;

std::size_t added_voxels(const std::filesystem::path& before, const std::filesystem::path& after) {
    const Grid<std::uint8_t> a = read_label_image(before.string()), b = read_label_image(after.string());
    std::size_t n = 0;
    for (PointIndex i = 0; i < a.size(); ++i) n += b[i] && !a[i];
    return n;
}

// 64^3 shell: WM 130 (r <= 21), GM 100 (21 < r <= 25), CSF 50; a drill of radius 3 along +x is
// missing from the mask and bias-bright (120: above the band 75..115, but more than a quarter the
// sheet's tissue: below 115 + (115 - 95)/2). Only the between-the-sides test can raise it;
// --band-only raises nothing (nothing outside the mask is in the band), nor does --between-share 0.5
// (a between voxel must then lie in the band).
TEST(RepairFlagsCli, BandOnlyLeavesABrightHoleThatTheBetweenTestCloses) {
    const auto dir = scratch_dir("repair_flags_band");
    const Lattice lat({64, 64, 64});
    Grid<float> image(lat, 50.0f);
    Grid<std::uint8_t> mask(lat, 0);
    for (int z = 0; z < 64; ++z)
        for (int y = 0; y < 64; ++y)
            for (int x = 0; x < 64; ++x) {
                const double r = std::sqrt((x - 32.0) * (x - 32.0) + (y - 32.0) * (y - 32.0) + (z - 32.0) * (z - 32.0));
                const bool drill = x > 32 && std::hypot(y - 32.0, z - 32.0) <= 3.0;
                if (r <= 21) image({x, y, z}) = 130.0f;
                else if (r <= 25) {
                    image({x, y, z}) = drill ? 120.0f : 100.0f;
                    mask({x, y, z}) = !drill;
                }
            }
    write_image(image, (dir / "t1.nii.gz").string());
    write_label_image(mask, (dir / "seg.nii.gz").string());
    const std::string base = "--threads 1 repair " + (dir / "seg.nii.gz").string() + " --image " + (dir / "t1.nii.gz").string() +
                             " --sheet-lower 75 --sheet-upper 115 --decision sheet --p 0.3 --radius 2 --edit-range 6 --steps 300 --target 55,32,32 --json";
    auto r = run_cli(base + " --out-mask " + (dir / "between.nii.gz").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(nlohmann::json::parse(r.out)["targets"][0]["local_genus"]["after"].get<int>(), 0);
    const std::size_t between = added_voxels(dir / "seg.nii.gz", dir / "between.nii.gz");
    EXPECT_GE(between, 20u);  // the drill's 4 x ~29 voxels, at least its plug
    r = run_cli(base + " --band-only --out-mask " + (dir / "band.nii.gz").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(added_voxels(dir / "seg.nii.gz", dir / "band.nii.gz"), 0u);
    EXPECT_EQ(nlohmann::json::parse(r.out)["targets"][0]["local_genus"]["after"].get<int>(), 1);
    r = run_cli(base + " --between-share 0.5 --out-mask " + (dir / "half.nii.gz").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    EXPECT_EQ(added_voxels(dir / "seg.nii.gz", dir / "half.nii.gz"), 0u);
    std::filesystem::remove_all(dir);
}

// 32^3 shell (9 < r <= 12) whose mask took in a one-voxel rod of the core's tissue along x (a
// handle: genus 1). `--decision cut` aimed at the rod removes rod voxels only and leaves genus 0.
TEST(RepairFlagsCli, CutRemovesOnlyTheHandle) {
    const auto dir = scratch_dir("repair_flags_cut");
    const testing::RodShell c = testing::rod_shell();
    ASSERT_EQ(mask_topology(c.mask).genus, 1);
    write_image(c.image, (dir / "t1.nii.gz").string());
    write_label_image(c.mask, (dir / "seg.nii.gz").string());
    const auto r = run_cli("--threads 1 repair " + (dir / "seg.nii.gz").string() + " --image " + (dir / "t1.nii.gz").string() +
                           " --decision cut --p 0.3 --steps 100 --target 16,16,16 --out-mask " + (dir / "cut.nii.gz").string());
    ASSERT_EQ(r.rc, 0) << r.err;
    testing::expect_rod_cut(c, read_label_image((dir / "cut.nii.gz").string()));
    std::filesystem::remove_all(dir);
}

TEST(RepairFlagsCli, BadCombinationsGetOneLineAndNonZeroExit) {
    const auto dir = scratch_dir("repair_flags_bad");
    const Lattice lat({16, 16, 16});
    Grid<float> image(lat, 50.0f);
    Grid<std::uint8_t> mask(lat, 0);
    for (int z = 4; z < 12; ++z)
        for (int y = 4; y < 12; ++y)
            for (int x = 4; x < 12; ++x) mask({x, y, z}) = 1, image({x, y, z}) = 100.0f;
    write_image(image, (dir / "t1.nii.gz").string());
    write_label_image(mask, (dir / "seg.nii.gz").string());
    const std::string base = "repair " + (dir / "seg.nii.gz").string() + " --image " + (dir / "t1.nii.gz").string() +
                             " --target 8,8,4 --out-mask " + (dir / "x.nii.gz").string();
    for (const char* extra : {" --band-only", " --band-only --decision intensity", " --no-crack-closing --no-topology-guard",
                              " --between-share 0.3", " --between-share 0.3 --decision sheet --band-only",
                              " --between-share 0.7 --decision sheet", " --between-share nan --decision sheet",
                              " --decision cut --no-topology-guard", " --decision cut --edit-range 0"}) {
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
