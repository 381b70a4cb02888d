// A scan's NaN voxels (a masked image's "no data": SPM's masked images, fslmaths -nan) through the
// commands: read as lying below every other value, so a NaN-masked brain is segmented exactly as
// the same brain with that lowered outside; the outputs keep NaN where the scan had it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <limits>
#include <nlohmann/json.hpp>

#include "analytic_head.hpp"
#include "cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/intensity.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using liveset::testing::run_cli;
using namespace liveset;

namespace {

fs::path no_data_dir() {
    static const fs::path dir = liveset::testing::scratch_dir("no_data_cli");
    return dir;
}

struct ScanRun {
    Grid<std::uint8_t> mask;
    Grid<float> corrected;
    nlohmann::json report;
    std::string err;
};

ScanRun segment_scan(const fs::path& image, const std::string& name) {
    const fs::path mask = no_data_dir() / (name + "_mask.nii.gz"), corrected = no_data_dir() / (name + "_corrected.nii.gz");
    const auto r = run_cli("--threads 2 segment " + image.string() + " --seed 49,32,32:2 --iterations 200 --json --out-mask " +
                           mask.string() + " --out-corrected " + corrected.string());
    EXPECT_EQ(r.rc, 0) << r.err;
    if (r.rc != 0) return {};
    return {read_label_image(mask.string()), read_image(corrected.string(), kDefaultImageMemoryLimit, nullptr, NanVoxels::keep),
            nlohmann::json::parse(r.out), r.err};
}

}  // namespace

// The analytic head stripped to its brain (white and grey matter, CSF), the rest NaN, as a NIfTI
// (which niftilib alone would read as 0 there) and as a MetaImage; and the same brain with its
// outside set to the value lower_no_data gives it. All three give the same mask, bit for bit, none
// of it where the NaN were; the corrected images are NaN there and equal elsewhere.
TEST(NoDataCli, ANanMaskedBrainIsSegmentedAsItsLoweredOutside) {
    Grid<float> brain = liveset::testing::analytic_head(false);
    std::size_t nan = 0;
    for (PointIndex i = 0; i < brain.size(); ++i) {
        const Vec3i p = brain.lattice().coord(i);
        if (1.5 * norm(Vec3d{p.x - 31.5, p.y - 31.5, p.z - 31.5}) < 29) continue;
        brain[i] = std::numeric_limits<float>::quiet_NaN();
        ++nan;
    }
    const fs::path nii = no_data_dir() / "nan_brain.nii.gz", mha = no_data_dir() / "nan_brain.mha", low = no_data_dir() / "low_brain.nii.gz";
    write_image(brain, nii.string());
    write_image(brain, mha.string());
    Grid<float> lowered = brain;
    ASSERT_TRUE(lower_no_data(lowered).has_value());
    float lo = std::numeric_limits<float>::max(), hi = -lo;
    for (float v : brain.values())
        if (!std::isnan(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    const float below = lo - 0.01f * (hi - lo);
    for (PointIndex i = 0; i < brain.size(); ++i) ASSERT_EQ(lowered[i], std::isnan(brain[i]) ? below : brain[i]);
    write_image(lowered, low.string());

    const ScanRun a = segment_scan(nii, "nii"), b = segment_scan(mha, "mha"), c = segment_scan(low, "low");
    ASSERT_TRUE(a.report.is_object() && b.report.is_object() && c.report.is_object());
    EXPECT_EQ(a.report["no_data_voxels"].get<std::size_t>(), nan);
    EXPECT_EQ(b.report["no_data_voxels"].get<std::size_t>(), nan);
    EXPECT_EQ(c.report["no_data_voxels"].get<std::size_t>(), 0u);
    EXPECT_NE(a.err.find(std::to_string(nan) + " voxel(s) of \"" + nii.string() + "\""), std::string::npos) << a.err;
    EXPECT_NE(a.err.find("are NaN"), std::string::npos) << a.err;
    std::size_t inside = 0, in_nan = 0, differ_ab = 0, differ_ac = 0, corrected_differ = 0, nan_kept = 0;
    for (PointIndex i = 0; i < brain.size(); ++i) {
        inside += a.mask[i] != 0;
        in_nan += a.mask[i] != 0 && std::isnan(brain[i]);
        differ_ab += a.mask[i] != b.mask[i];
        differ_ac += a.mask[i] != c.mask[i];
        if (std::isnan(brain[i])) {
            nan_kept += std::isnan(a.corrected[i]) && std::isnan(b.corrected[i]) && !std::isnan(c.corrected[i]);
        } else {
            corrected_differ += a.corrected[i] != c.corrected[i] || b.corrected[i] != c.corrected[i];
        }
    }
    EXPECT_GT(inside, 10000u);  // the grey matter shell (r 18..27 mm at 1.5 mm: ~22 000 voxels)
    EXPECT_EQ(in_nan, 0u);
    EXPECT_EQ(differ_ab, 0u);
    EXPECT_EQ(differ_ac, 0u);
    EXPECT_EQ(nan_kept, nan);
    EXPECT_EQ(corrected_differ, 0u);
}

// Bad scans are one line each: an image all NaN; an infinite voxel (damage, not "no data"); NaN in a
// mask or a level set (no data is no answer there).
TEST(NoDataCli, AllNanOrInfiniteScansAndNanMasksAreRefused) {
    const Lattice l({12, 12, 12});
    const fs::path all = no_data_dir() / "all_nan.nii.gz", inf = no_data_dir() / "inf.nii.gz", good = no_data_dir() / "good.nii.gz",
                   nan_mask = no_data_dir() / "nan_mask.nii.gz";
    write_image(Grid<float>(l, std::numeric_limits<float>::quiet_NaN()), all.string());
    Grid<float> g(l, 10.0f);
    for (PointIndex i = 0; i < g.size(); ++i) g[i] = static_cast<float>(i % 7);
    write_image(g, good.string());
    Grid<float> m(l, 0.0f);
    m[100] = 1.0f;
    m[5] = std::numeric_limits<float>::quiet_NaN();
    write_image(m, nan_mask.string());
    g[9] = std::numeric_limits<float>::infinity();
    write_image(g, inf.string());
    const std::string out = " --seed 6,6,6 --quiet --out-mask " + (no_data_dir() / "bad_mask.nii.gz").string();
    const struct {
        std::string args, phrase;
    } cases[] = {
        {"segment " + all.string() + out, "every voxel of the image is NaN"},
        {"segment " + inf.string() + out, "1 voxel is infinite"},
        {"segment " + good.string() + " --roi " + nan_mask.string() + out, "NaN"},
        {"segment " + good.string() + " --init-mask " + nan_mask.string() + out, "NaN"},
    };
    for (const auto& c : cases) {
        const auto r = run_cli(c.args);
        EXPECT_NE(r.rc, 0) << c.args;
        EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << c.args << ": " << r.err;
        EXPECT_NE(r.err.find(c.phrase), std::string::npos) << c.args << ": " << r.err;
        EXPECT_FALSE(fs::exists(no_data_dir() / "bad_mask.nii.gz")) << c.args;
    }
}
