// An intensity-normalised T1 (FreeSurfer's T1.mgz: white matter scaled to 110, its voxels near it
// pinned to exactly 110, uint8) through `liveset segment`'s default run: the noise ratio reads each
// class's spread no wider than its histogram peak (TissueClass::peak_sigma), so grey matter's fit,
// where the partial-volume voxels the pinned white matter leaves it widen it, does not set α 0.15
// and a blur. The widening itself: TissueModel.APeakWidthBoundsAFitWidenedByVoxelsItsPeakDoesNotHold.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_run.hpp"
#include "liveset/io/image_io.hpp"
#include "scratch_dir.hpp"

namespace fs = std::filesystem;
using liveset::testing::run_cli;
using namespace liveset;

namespace {

fs::path pinned_dir() {
    static const fs::path dir = liveset::testing::scratch_dir("pinned_t1_cli");
    return dir;
}

// The report of a default run (N4, the automatic brain mask, the 8 seeds) stopped after one iteration.
nlohmann::json model_report(const fs::path& image) {
    const auto r = run_cli("--threads 2 segment " + image.string() +
                           " --seed-mm 35,83,113 --seed-mm 35,125,38 --seed-mm 44,164,92 --seed-mm 71,74,53 --seed-mm 122,149,47"
                           " --seed-mm 140,86,74 --seed-mm 38,71,26 --seed-mm 83,23,71 --iterations 1 --json --out-mask " +
                           (pinned_dir() / "mask.nii.gz").string());
    EXPECT_EQ(r.rc, 0) << r.err;
    return r.rc == 0 ? nlohmann::json::parse(r.out) : nlohmann::json();
}

// max(σ_GM, σ_WM) / (µ_WM − µ_GM) from the report's fitted spreads, and from the spreads bounded by the peaks.
double fitted_ratio(const nlohmann::json& classes) {
    return std::max(classes[1]["sigma"].get<double>(), classes[2]["sigma"].get<double>()) /
           (classes[2]["mean"].get<double>() - classes[1]["mean"].get<double>());
}
double spread(const nlohmann::json& c) {  // TissueClass::spread
    const double s = c["sigma"].get<double>();
    if (c["peak_sigma"].is_null() || !(s > 1.3 * c["peak_sigma"].get<double>())) return s;
    const double p = c["peak_sigma"].get<double>();
    const double t = (s / p - 1.3) / 0.5;
    return t >= 1.0 ? p : s - t * (s - p);
}

}  // namespace

// BrainWeb scaled to white matter 110 and stored as uint8, with and without the pin (the voxels
// labelled white matter within ±12 of 110, as mri_normalize pins those it takes for white matter):
// unpinned, no peak is narrower than its fit, so the ratio is the fit's (as before session 62);
// pinned, grey matter's fit widens over 1.7× the unpinned one (13.2 against 4.8) and its ratio would
// exceed 0.45 (α 0.15 and a blur: GM Dice 0.923, docs/BENCHMARKS.md session 62), while its peak
// keeps within 1.5× and the ratio read stays under 0.3 (0.935).
TEST(PinnedT1Cli, AWhiteMatterPinnedToOneValueLeavesGreyMatterItsNoise) {
    const std::string dir = std::string(LIVESET_DATA_DIR) + "/brainweb/";
    const Grid<float> t1 = read_image(dir + "t1.mha");
    const Grid<std::uint8_t> labels = read_label_image(dir + "labels_crisp.nii.gz");
    double wm = 0, n = 0;
    for (PointIndex p = 0; p < t1.size(); ++p)
        if (labels[p] == 3) wm += t1[p], n += 1;
    Grid<std::uint8_t> scaled(t1.lattice()), pinned(t1.lattice());
    for (PointIndex p = 0; p < t1.size(); ++p) {
        const double v = std::clamp(std::round(110.0 / (wm / n) * t1[p]), 0.0, 255.0);
        scaled[p] = static_cast<std::uint8_t>(v);
        pinned[p] = static_cast<std::uint8_t>(labels[p] == 3 && std::abs(v - 110.0) <= 12.0 ? 110.0 : v);
    }
    write_label_image(scaled, (pinned_dir() / "scaled.nii.gz").string());
    write_label_image(pinned, (pinned_dir() / "pinned.nii.gz").string());
    const nlohmann::json a = model_report(pinned_dir() / "scaled.nii.gz"), b = model_report(pinned_dir() / "pinned.nii.gz");
    ASSERT_TRUE(a.contains("tissue_model") && b.contains("tissue_model"));
    const nlohmann::json &ca = a["tissue_model"]["classes"], &cb = b["tissue_model"]["classes"];
    ASSERT_EQ(ca.size(), 3u);
    ASSERT_EQ(cb.size(), 3u);
    EXPECT_EQ(a["alpha_choice"]["class"], "GM");
    EXPECT_EQ(b["alpha_choice"]["class"], "GM");
    EXPECT_NEAR(a["alpha_choice"]["noise_ratio"].get<double>(), fitted_ratio(ca), 1e-9);  // as before
    const double gm = ca[1]["sigma"].get<double>();
    EXPECT_GT(cb[1]["sigma"].get<double>(), 1.7 * gm) << cb.dump();
    EXPECT_GT(fitted_ratio(cb), 0.45);
    EXPECT_LT(spread(cb[1]), 1.5 * gm) << cb.dump();
    const double ratio = b["alpha_choice"]["noise_ratio"].get<double>();
    EXPECT_LT(ratio, 0.3);
    EXPECT_NEAR(ratio, std::max(spread(cb[1]), spread(cb[2])) / (cb[2]["mean"].get<double>() - cb[1]["mean"].get<double>()), 1e-9);
}
