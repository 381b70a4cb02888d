// `liveset segment`'s thin-front rule (StepOptions::thin_fronts, on by default since session 72):
// the front fills a sheet one voxel thick joined to a seeded cube, by default and with
// --thin-fronts, and stops early in it with --no-thin-fronts (scripts/thin_structures.sh); the report
// says whether the rule ran.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using liveset::testing::run_cli;
using namespace liveset;

namespace {

bool in_sheet(int x, int y, int z) {
    const bool cube = x >= 2 && x < 9 && y >= 4 && y < 20 && z >= 8 && z < 15;
    return cube || (x >= 8 && x < 60 && y >= 4 && y < 20 && z == 12);
}

}  // namespace

TEST(ThinFrontsCli, TheDefaultCarriesTheFrontToTheEndOfASheetOneVoxelThick) {
    const fs::path dir = liveset::testing::scratch_dir("thin_fronts_cli");
    Grid<float> img(Lattice({64, 24, 24}), 0.0f);
    int sheet = 0;
    for (int z = 0; z < 24; ++z)
        for (int y = 0; y < 24; ++y)
            for (int x = 0; x < 64; ++x) {
                const float ripple = static_cast<float>((7 * x + 13 * y + 29 * z) % 5 - 2);  // ±2, as the script's noise
                img({x, y, z}) = (in_sheet(x, y, z) ? 100.0f : 0.0f) + ripple;
                sheet += in_sheet(x, y, z) ? 1 : 0;
            }
    write_image(img, (dir / "sheet.nii.gz").string());
    for (const std::string option : {"", " --thin-fronts", " --no-thin-fronts"}) {
        SCOPED_TRACE(option.empty() ? "the default" : option);
        const bool flag = option != " --no-thin-fronts";
        const fs::path out = dir / ("sheet" + std::to_string(option.size()) + ".nii.gz");
        const auto r = run_cli("segment " + (dir / "sheet.nii.gz").string() +
                               " --roi none --seed 5,11,11 --mu-raw 100 --epsilon-raw 30 --alpha 0 --no-bias-correct --json --out-mask " +
                               out.string() + option);
        ASSERT_EQ(r.rc, 0) << r.err;
        const nlohmann::json report = nlohmann::json::parse(r.out);  // the report says how it stepped
        EXPECT_EQ(report["thin_fronts"], flag);
        EXPECT_EQ(report["step"], "sleeping");
        const Grid<std::uint8_t> mask = read_label_image(out.string());
        int in = 0, outside = 0, last = 0;
        for (int z = 0; z < 24; ++z)
            for (int y = 0; y < 24; ++y)
                for (int x = 0; x < 64; ++x)
                    if (mask({x, y, z}) != 0) {
                        ++(in_sheet(x, y, z) ? in : outside);
                        last = std::max(last, x);
                    }
        EXPECT_EQ(outside, 0);
        if (flag) {
            EXPECT_EQ(in, sheet);
            EXPECT_EQ(last, 59);
        } else {
            EXPECT_LT(last, 20) << "the sparse field's front stops in a sheet one voxel thick";
        }
    }
}
