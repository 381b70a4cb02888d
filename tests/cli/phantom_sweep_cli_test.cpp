// The phantom repair sweep of issue 18 item 5, the cases it meets (docs/BENCHMARKS.md has the whole
// 3 sizes x 3 seeds table): `liveset demo` ends at holes 0 with Dice up. 64^3 and 128^3 seed 1 with
// the sheet rule (aimed at each hole's widest opening, stalled holes skipped; the intensity rule
// closes the 64^3 ones too but overgrows, Dice 0.955 -> 0.926) and 96^3 with the intensity rule
// (the sheet rule leaves one or two tunnels there). Not met, so not here: 128^3 seeds 2-3 under
// either rule, 96^3 under the sheet rule.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "cli_run.hpp"

namespace liveset {
namespace {

using testing::run_cli;

void expect_closed_with_dice_up(int size, int seed, const std::string& rule) {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("liveset_sweep_" + std::to_string(::getpid()) + "_" + std::to_string(size) + "_" + std::to_string(seed));
    const auto r = run_cli("--threads 1 demo --size " + std::to_string(size) + " --seed " + std::to_string(seed) +
                           " --repair-rule " + rule + " --json --no-view --out " + dir.string());
    std::filesystem::remove_all(dir);
    ASSERT_EQ(r.rc, 0) << r.err;
    const nlohmann::json j = nlohmann::json::parse(r.out);
    const auto &before = j["before"], &after = j["after"];
    EXPECT_GT(before["holes"].get<long>(), 0) << size << "/" << seed << ": the segmentation leaves holes to repair";
    EXPECT_EQ(after["holes"].get<long>(), 0) << size << "/" << seed;
    EXPECT_EQ(after["genus"].get<long>(), 0) << size << "/" << seed;
    EXPECT_GT(after["dice"].get<double>(), before["dice"].get<double>()) << size << "/" << seed;
}

TEST(PhantomSweep, SheetRuleClosesThe64Phantoms) {
    for (int seed = 1; seed <= 3; ++seed) expect_closed_with_dice_up(64, seed, "sheet");
}

TEST(PhantomSweep, SheetRuleClosesThe128PhantomSeed1) { expect_closed_with_dice_up(128, 1, "sheet"); }

TEST(PhantomSweep, IntensityRuleClosesThe96Phantoms) {
    for (int seed = 1; seed <= 3; ++seed) expect_closed_with_dice_up(96, seed, "intensity");
}

}  // namespace
}  // namespace liveset
