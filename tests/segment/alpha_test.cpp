// automatic_alpha(): the rule on hand-made tissue models, voxel shapes and the fallbacks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "liveset/grid/lattice.hpp"
#include "liveset/segment/alpha.hpp"

using namespace liveset;

namespace {

TissueModel three_classes(double gm_sigma) {
    TissueModel m;
    m.classes = {{37.0, 15.0, 0.15}, {98.0, gm_sigma, 0.24}, {132.0, 4.0, 0.2}};
    return m;
}

// The rule written out: (σ / nearest gap − 0.2) / 2 in [0, 0.15], over the anisotropy cubed.
double expected(double sigma, double gap, double anisotropy) {
    return std::clamp((sigma / gap - 0.2) * 0.5, 0.0, 0.15) / (anisotropy * anisotropy * anisotropy);
}

}  // namespace

TEST(AutomaticAlpha, NoneOnAQuietScanMoreWithNoiseCappedAndLessOnThickSlices) {
    const TissueModel quiet = three_classes(5.7), loud = three_classes(13.1), wild = three_classes(60.0);
    const AlphaChoice a = automatic_alpha(&quiet, 91.0, {1, 1, 1});
    EXPECT_TRUE(a.automatic);
    EXPECT_EQ(a.tissue_class, 1);
    EXPECT_DOUBLE_EQ(a.noise_ratio, 5.7 / 34.0);  // GM's nearest other class is WM, 34 above (σ 4 < 5.7)
    EXPECT_EQ(a.alpha, 0.0);
    const AlphaChoice b = automatic_alpha(&loud, 91.0, {1, 1, 1});
    EXPECT_NEAR(b.alpha, expected(13.1, 34.0, 1.0), 1e-12);
    EXPECT_GT(b.alpha, 0.08);
    EXPECT_DOUBLE_EQ(automatic_alpha(&wild, 91.0, {1, 1, 1}).alpha, kAlphaMax);
    const AlphaChoice thick = automatic_alpha(&loud, 91.0, {1, 1, 3});
    EXPECT_DOUBLE_EQ(thick.anisotropy, 3.0);
    EXPECT_NEAR(thick.alpha, expected(13.1, 34.0, 3.0), 1e-12);
    EXPECT_NEAR(automatic_alpha(&loud, 91.0, {0.5, 0.5, 2.0}).alpha, expected(13.1, 34.0, 4.0), 1e-12);
    EXPECT_NEAR(automatic_alpha(&loud, 91.0, {0.8, 0.8, 0.8}).alpha, b.alpha, 1e-12);  // isotropic: any size alike
}

TEST(AutomaticAlpha, TheClassNearestTheWindowsCentreSetsTheRatio) {
    const TissueModel m = three_classes(13.1);
    const AlphaChoice wm = automatic_alpha(&m, 128.0, {1, 1, 1});
    EXPECT_EQ(wm.tissue_class, 2);
    EXPECT_DOUBLE_EQ(wm.noise_ratio, 13.1 / 34.0);  // WM's border with GM is blurred by GM's larger spread
    const AlphaChoice csf = automatic_alpha(&m, 20.0, {1, 1, 1});
    EXPECT_EQ(csf.tissue_class, 0);
    EXPECT_DOUBLE_EQ(csf.noise_ratio, 15.0 / 61.0);
    EXPECT_NEAR(csf.alpha, expected(15.0, 61.0, 1.0), 1e-12);
}

TEST(AutomaticAlpha, WithoutAUsableModelTheFallbackStillFollowsTheVoxelShape) {
    const AlphaChoice none = automatic_alpha(nullptr, 91.0, {1, 1, 1});
    EXPECT_TRUE(none.automatic);
    EXPECT_TRUE(std::isnan(none.noise_ratio));
    EXPECT_EQ(none.tissue_class, -1);
    EXPECT_DOUBLE_EQ(none.alpha, kFallbackAlpha);
    EXPECT_NEAR(automatic_alpha(nullptr, 91.0, {0.5, 0.5, 5}).alpha, kFallbackAlpha / 1000.0, 1e-15);
    TissueModel broken = three_classes(5.7);
    broken.degenerate = "classes 1 and 2 merged";
    EXPECT_DOUBLE_EQ(automatic_alpha(&broken, 91.0, {1, 1, 1}).alpha, kFallbackAlpha);
    TissueModel one;
    one.classes = {{98.0, 5.0, 1.0}};
    EXPECT_DOUBLE_EQ(automatic_alpha(&one, 91.0, {1, 1, 1}).alpha, kFallbackAlpha);
}

TEST(AutomaticAlpha, TheWindowsOwnClassWinsAndDegenerateRatiosFallBack) {
    const TissueModel m = three_classes(13.1);
    // The window's class from the model (its seeds' class) is used even where another mean lies nearer.
    const AlphaChoice own = automatic_alpha(&m, 120.0, {1, 1, 1}, 1);
    EXPECT_EQ(own.tissue_class, 1);
    EXPECT_DOUBLE_EQ(own.noise_ratio, 13.1 / 34.0);
    EXPECT_EQ(automatic_alpha(&m, 120.0, {1, 1, 1}).tissue_class, 2);  // without it: the nearest mean
    EXPECT_EQ(automatic_alpha(&m, 120.0, {1, 1, 1}, 7).tissue_class, 2);  // an index out of range is ignored
    EXPECT_EQ(automatic_alpha(&m, 115.0, {1, 1, 1}).tissue_class, 1);  // a tie between 98 and 132: the darker
    TissueModel two;
    two.classes = {{98.0, 10.0, 0.5}, {132.0, 4.0, 0.5}};
    EXPECT_NEAR(automatic_alpha(&two, 95.0, {1, 1, 1}).alpha, expected(10.0, 34.0, 1.0), 1e-12);
    two.classes[1].sigma = 12.0;  // the neighbour's larger spread counts
    EXPECT_NEAR(automatic_alpha(&two, 95.0, {1, 1, 1}).alpha, expected(12.0, 34.0, 1.0), 1e-12);
    TissueModel flat = three_classes(13.1);
    flat.classes[2].mean = flat.classes[1].mean;  // no gap: no ratio, the fallback
    EXPECT_DOUBLE_EQ(automatic_alpha(&flat, 98.0, {1, 1, 1}).alpha, kFallbackAlpha);
    TissueModel wild = three_classes(std::numeric_limits<double>::quiet_NaN());
    const AlphaChoice nan = automatic_alpha(&wild, 98.0, {1, 1, 1});
    EXPECT_EQ(nan.tissue_class, -1);
    EXPECT_DOUBLE_EQ(nan.alpha, kFallbackAlpha);
}

// The voxel sizes a NIfTI stores (float) and a MINC stores (double) give the same α bit for bit.
TEST(AutomaticAlpha, FloatAndDoubleVoxelSizesGiveTheSameBits) {
    const TissueModel m = three_classes(11.0);
    const Lattice as_float({8, 8, 8}, {0.9375, 0.9375, static_cast<double>(1.2f)});
    const Lattice as_double({8, 8, 8}, {0.9375, 0.9375, 1.2});
    EXPECT_EQ(automatic_alpha(&m, 98.0, as_float.spacing_float()).alpha, automatic_alpha(&m, 98.0, as_double.spacing_float()).alpha);
    EXPECT_GT(automatic_alpha(&m, 98.0, as_double.spacing_float()).alpha, 0.0);
}

// The pre-smoothing follows the same noise floor: half the finest voxel side above it (in mm, the
// same along every axis), none at or below it or without a ratio.
TEST(AutomaticAlpha, ThePreSmoothingIsHalfTheFinestVoxelAboveTheNoiseFloor) {
    const TissueModel quiet = three_classes(5.7), loud = three_classes(13.1), edge = three_classes(0.2 * 34.0);
    EXPECT_EQ(automatic_alpha(&quiet, 91.0, {1, 1, 1}).smooth_mm, 0.0);
    EXPECT_EQ(automatic_alpha(&edge, 91.0, {1, 1, 1}).smooth_mm, 0.0);  // exactly at the floor: α 0, no blur
    EXPECT_DOUBLE_EQ(automatic_alpha(&loud, 91.0, {1, 1, 1}).smooth_mm, 0.5);
    EXPECT_DOUBLE_EQ(automatic_alpha(&loud, 91.0, {0.7f, 0.9f, 3.0f}).smooth_mm, 0.5 * static_cast<double>(0.7f));
    EXPECT_DOUBLE_EQ(automatic_alpha(&loud, 91.0, {2, 2, 2}).smooth_mm, 1.0);
    EXPECT_EQ(automatic_alpha(nullptr, 91.0, {1, 1, 1}).smooth_mm, 0.0);  // the fallback α measures no noise
}

// A model fitted on the blurred image (window.cpp, noise hiding a tissue) keeps its blur for D
// whatever its own (narrowed) noise ratio says; an unusable one does not count.
TEST(AutomaticAlpha, AModelFittedOnTheBlurredImageKeepsItsBlur) {
    TissueModel quiet = three_classes(5.7);
    quiet.smooth_mm = 0.5;
    const AlphaChoice a = automatic_alpha(&quiet, 91.0, {1, 1, 1});
    EXPECT_EQ(a.alpha, 0.0);  // under the noise floor
    EXPECT_DOUBLE_EQ(a.smooth_mm, 0.5);
    TissueModel loud = three_classes(13.1);
    loud.smooth_mm = 0.25;  // the rule's own blur is larger: it stays
    EXPECT_DOUBLE_EQ(automatic_alpha(&loud, 91.0, {1, 1, 1}).smooth_mm, 0.5);
    quiet.degenerate = "tissue classes 1 and 2 overlap";
    EXPECT_EQ(automatic_alpha(&quiet, 91.0, {1, 1, 1}).smooth_mm, 0.0);
}
