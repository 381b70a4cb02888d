// The tissue model against samples drawn from known mixtures (with partial-volume voxels), Otsu's
// thresholds against brute force, the window rule's invariances and its warnings and fallbacks.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>

#include "liveset/segment/alpha.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/segment/tissue_model.hpp"
#include "liveset/segment/window.hpp"

using namespace liveset;

namespace {

struct TrueClass {
    double mean, sigma, share;
};

// `n` values: pure classes with the given shares, the rest partial-volume voxels split evenly
// between neighbours (fraction uniform in [0, 1], noise interpolated as the model assumes).
std::vector<float> sample(const std::vector<TrueClass>& classes, double pv_share, std::size_t n, std::uint32_t seed) {
    std::mt19937 rng(seed);
    std::normal_distribution<double> z(0.0, 1.0);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    std::vector<float> v;
    for (const TrueClass& c : classes)
        for (std::size_t i = 0; i < static_cast<std::size_t>(c.share * n); ++i) v.push_back(static_cast<float>(c.mean + c.sigma * z(rng)));
    const std::size_t per_pair = static_cast<std::size_t>(pv_share * n / (classes.size() - 1));
    for (std::size_t k = 0; k + 1 < classes.size(); ++k)
        for (std::size_t i = 0; i < per_pair; ++i) {
            const double f = u(rng);
            const TrueClass &a = classes[k], &b = classes[k + 1];
            const double s = std::sqrt((1 - f) * a.sigma * a.sigma + f * b.sigma * b.sigma);
            v.push_back(static_cast<float>((1 - f) * a.mean + f * b.mean + s * z(rng)));
        }
    return v;
}

const std::vector<TrueClass> kT1 = {{48, 10, 0.2}, {97, 8, 0.3}, {131, 6, 0.25}};  // CSF, GM, WM (raw)

}  // namespace

TEST(TissueModel, RecoversTheClassesOfAPartialVolumeMixture) {
    const std::vector<float> v = sample(kT1, 0.25, 200000, 1);
    const TissueModel m = fit_tissue_model(v);
    ASSERT_TRUE(m.usable()) << m.degenerate;
    ASSERT_EQ(m.classes.size(), 3u);
    for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_NEAR(m.classes[c].mean, kT1[c].mean, 1.5) << c;
        EXPECT_NEAR(m.classes[c].sigma, kT1[c].sigma, 1.5) << c;
    }
    double pv = 0;
    for (double w : m.mixed) pv += w;
    EXPECT_NEAR(pv, 0.25 / 1.0, 0.06);
    EXPECT_EQ(m.classify(97.0), 1);
    EXPECT_EQ(m.classify(40.0), 0);
    EXPECT_EQ(m.classify(140.0), 2);
}

// The histogram's own peak widths on a sound mixture: no narrower than 0.9 of the fit's σ (the noise
// ratio then reads σ, as before) and within 35 % of the true spread (partial-volume voxels widen a
// peak's side, never narrow it). The end to end case, a pinned white matter: PinnedT1Cli.
TEST(TissueModel, APeakWidthIsNoNarrowerThanASoundFit) {
    const std::vector<float> v = sample(kT1, 0.25, 200000, 1);
    const TissueModel m = fit_tissue_model(v);
    ASSERT_TRUE(m.usable()) << m.degenerate;
    for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_GT(m.classes[c].peak_sigma, 0.9 * kT1[c].sigma) << c;
        EXPECT_LT(m.classes[c].peak_sigma, 1.35 * kT1[c].sigma) << c;
        EXPECT_EQ(m.classes[c].spread(), m.classes[c].sigma) << c;
    }
}

// A class that takes voxels its peak does not hold (here a shoulder of grey matter's partial volume
// with a pinned white matter, fitted without the mixed classes, as the EM ends up on FreeSurfer's
// T1.mgz) widens; its peak does not, and the spread the noise ratio reads is the peak's.
TEST(TissueModel, APeakWidthBoundsAFitWidenedByVoxelsItsPeakDoesNotHold) {
    std::vector<float> v = sample({{40, 5, 0.15}, {82, 4, 0.45}}, 0.0, 200000, 3);
    std::mt19937 rng(4);
    std::uniform_real_distribution<double> shoulder(95.0, 108.0);
    for (int i = 0; i < 20000; ++i) v.push_back(static_cast<float>(shoulder(rng)));
    v.insert(v.end(), 60000, 110.0f);  // white matter pinned to one value
    TissueModelOptions o;
    o.partial_volume = false;
    const TissueModel m = fit_tissue_model(v, o);
    ASSERT_TRUE(m.usable()) << m.degenerate;
    ASSERT_EQ(m.classes.size(), 3u);
    const TissueClass& gm = m.classes[1];
    EXPECT_GT(gm.sigma, 1.8 * gm.peak_sigma);
    EXPECT_NEAR(gm.peak_sigma, 4.0, 1.0);
    EXPECT_EQ(gm.spread(), gm.peak_sigma);
    TissueClass c = gm;  // between 1.3 and 1.8 peaks the spread blends linearly from σ to the peak
    c.sigma = 1.3 * c.peak_sigma;
    EXPECT_EQ(c.spread(), c.sigma);
    c.sigma = 1.55 * c.peak_sigma;
    EXPECT_NEAR(c.spread(), 0.5 * (c.sigma + c.peak_sigma), 1e-12);
    const AlphaChoice a = automatic_alpha(&m, 82.0, {1.0f, 1.0f, 1.0f}, 1);
    EXPECT_NEAR(a.noise_ratio, std::max(gm.spread(), m.classes[2].spread()) / (m.classes[2].mean - gm.mean), 1e-12);
    EXPECT_LT(a.noise_ratio, std::max(gm.sigma, m.classes[2].sigma) / (m.classes[2].mean - gm.mean));
}

// A white matter pinned to one value (FreeSurfer's T1.mgz: the voxels within ±12 of 110 set to 110)
// under Rician-like noise leaves a spike and, beyond the pin, a small bump. Started at the
// histogram's peaks, the EM gives the spike a class of σ ≈ 1 whose likelihood outweighs every
// tissue's, and grey matter's voxels a class with CSF (BrainWeb so pinned: the seeds' class became
// CSF, GM Dice 0.92 → 0.78). A class narrower than the histogram's smoothing is no tissue: Otsu's
// start stands, and grey matter keeps its class.
TEST(TissueModel, ASpikeAnIntensityNormalisationLeftIsNoTissueClass) {
    std::vector<float> v = sample({{31, 7, 0.05}, {84, 9, 0.40}, {110, 9, 0.40}}, 0.15, 200000, 8);
    for (float& x : v)
        if (std::abs(x - 110.0f) <= 12.0f && x > 98.0f) x = 110.0f;
    const TissueModel m = fit_tissue_model(v);
    ASSERT_TRUE(m.usable()) << m.degenerate;
    ASSERT_EQ(m.classes.size(), 3u);
    EXPECT_EQ(m.start, "otsu");
    EXPECT_NEAR(m.classes[1].mean, 84.0, 4.0);
    const std::vector<float> seeds(50, 84.0f);
    EXPECT_EQ(model_window(m, seeds).seed_class, 1);
}

TEST(TissueModel, PartialVolumeClassesKeepThePureMeansWhereAPlainMixtureShiftsThem) {
    const std::vector<float> v = sample(kT1, 0.35, 200000, 2);
    TissueModelOptions plain;
    plain.partial_volume = false;
    const TissueModel a = fit_tissue_model(v), b = fit_tissue_model(v, plain);
    ASSERT_TRUE(a.usable() && b.usable());
    double err_pv = 0, err_plain = 0;
    for (std::size_t c = 0; c < 3; ++c) {
        err_pv += std::abs(a.classes[c].mean - kT1[c].mean);
        err_plain += std::abs(b.classes[c].mean - kT1[c].mean);
    }
    EXPECT_LT(err_pv, 3.0);
    EXPECT_GT(err_plain, 2.0 * err_pv);
}

TEST(TissueModel, WindowReachesTheMidpointsOfTheNeighbouringClasses) {
    const TissueModel m = fit_tissue_model(sample(kT1, 0.25, 200000, 3));
    const std::vector<float> gm_seeds(50, 95.0f);
    const ModelWindow w = model_window(m, gm_seeds);
    EXPECT_EQ(w.seed_class, 1);
    EXPECT_DOUBLE_EQ(w.seed_class_share, 1.0);
    EXPECT_TRUE(w.warnings.empty());
    EXPECT_NEAR(w.lower, 0.5 * (m.classes[0].mean + m.classes[1].mean), 1e-9);
    EXPECT_NEAR(w.upper, 0.5 * (m.classes[1].mean + m.classes[2].mean), 1e-9);
    EXPECT_NEAR(w.lower, (48 + 97) / 2.0, 1.5);
    EXPECT_NEAR(w.upper, (97 + 131) / 2.0, 1.5);
    // The brightest class has one neighbour: the window is symmetric about its mean, at least 3σ.
    const ModelWindow wm = model_window(m, std::vector<float>(20, 133.0f));
    EXPECT_EQ(wm.seed_class, 2);
    EXPECT_NEAR(wm.lower, 0.5 * (m.classes[1].mean + m.classes[2].mean), 1e-9);
    EXPECT_NEAR(wm.upper - m.classes[2].mean, std::max(m.classes[2].mean - wm.lower, 3 * m.classes[2].sigma), 1e-9);
    const ModelWindow csf = model_window(m, std::vector<float>(20, 45.0f));
    EXPECT_EQ(csf.seed_class, 0);
    EXPECT_NEAR(m.classes[0].mean - csf.lower, std::max(csf.upper - m.classes[0].mean, 3 * m.classes[0].sigma), 1e-9);
}

TEST(TissueModel, TheWindowFollowsALinearChangeOfIntensityUnits) {
    const std::vector<float> v = sample(kT1, 0.25, 100000, 4);
    std::vector<float> scaled(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) scaled[i] = 7.3f * v[i] + 300.0f;
    const ModelWindow a = model_window(fit_tissue_model(v), std::vector<float>(10, 97.0f));
    const ModelWindow b = model_window(fit_tissue_model(scaled), std::vector<float>(10, 7.3f * 97.0f + 300.0f));
    EXPECT_NEAR(b.lower, 7.3 * a.lower + 300, 7.3 * 0.05);
    EXPECT_NEAR(b.upper, 7.3 * a.upper + 300, 7.3 * 0.05);
}

// Intensities of both signs (z-scored or CT-like units, exact zeros of both signs among them):
// the model of the values shifted by −100 is the shifted model, so the sort that finds the
// histogram's quantiles orders negative floats correctly.
TEST(TissueModel, NegativeIntensitiesGiveTheShiftedModel) {
    std::vector<float> v = sample(kT1, 0.25, 100000, 9);
    std::vector<float> shifted(v.size());
    for (std::size_t i = 0; i < v.size(); ++i) shifted[i] = v[i] - 100.0f;
    for (std::size_t i = 0; i < 40; ++i) shifted[i * 97] = i % 2 == 0 ? 0.0f : -0.0f;
    const TissueModel a = fit_tissue_model(v), b = fit_tissue_model(shifted);
    ASSERT_TRUE(a.usable() && b.usable()) << a.degenerate << b.degenerate;
    ASSERT_EQ(b.classes.size(), 3u);
    for (std::size_t c = 0; c < 3; ++c) {
        EXPECT_NEAR(b.classes[c].mean, a.classes[c].mean - 100.0, 0.3) << c;
        EXPECT_NEAR(b.classes[c].sigma, a.classes[c].sigma, 0.3) << c;
    }
    const std::vector<double> ta = otsu_thresholds(v, 3), tb = otsu_thresholds(shifted, 3);
    ASSERT_EQ(ta.size(), tb.size());
    for (std::size_t k = 0; k < ta.size(); ++k) EXPECT_NEAR(tb[k], ta[k] - 100.0, 1.0) << k;
}

TEST(TissueModel, SeedsInTwoClassesAreWarnedAbout) {
    const TissueModel m = fit_tissue_model(sample(kT1, 0.25, 100000, 5));
    std::vector<float> seeds(60, 97.0f);
    seeds.insert(seeds.end(), 40, 132.0f);
    const ModelWindow w = model_window(m, seeds);
    EXPECT_EQ(w.seed_class, 1);
    EXPECT_NEAR(w.seed_class_share, 0.6, 1e-12);
    ASSERT_EQ(w.warnings.size(), 1u);
    EXPECT_NE(w.warnings[0].find("two tissue classes"), std::string::npos) << w.warnings[0];
    // A window given by hand that holds GM's and WM's means is warned about; one that holds only GM's is not.
    EXPECT_EQ(window_warnings(m, 60, 140).size(), 1u);
    EXPECT_TRUE(window_warnings(m, 75, 115).empty());
}

TEST(TissueModel, OtsuThresholdsMatchBruteForce) {
    std::mt19937 rng(6);
    std::vector<float> v;
    std::uniform_int_distribution<int> level(0, 39);
    for (int i = 0; i < 3000; ++i) v.push_back(static_cast<float>(level(rng) * level(rng) % 40));  // 40 levels, lumpy
    const std::vector<double> t = otsu_thresholds(v, 3, 40);
    ASSERT_EQ(t.size(), 2u);
    // Brute force over all pairs of cuts between the 40 integer levels.
    std::vector<double> n(40, 0);
    for (float x : v) n[static_cast<std::size_t>(x)] += 1;
    double best = -1;
    int b1 = 0, b2 = 0;
    for (int i = 1; i < 40; ++i)
        for (int j = i + 1; j < 40; ++j) {
            double score = 0;
            for (auto [a, b] : {std::pair{0, i}, std::pair{i, j}, std::pair{j, 40}}) {
                double w = 0, s = 0;
                for (int k = a; k < b; ++k) {
                    w += n[static_cast<std::size_t>(k)];
                    s += n[static_cast<std::size_t>(k)] * k;
                }
                if (w > 0) score += s * s / w;
            }
            if (score > best + 1e-9) {
                best = score;
                b1 = i;
                b2 = j;
            }
        }
    // A threshold lies between the last level of one class and the first of the next.
    EXPECT_GT(t[0], b1 - 1);
    EXPECT_LT(t[0], b1);
    EXPECT_GT(t[1], b2 - 1);
    EXPECT_LT(t[1], b2);
}

TEST(TissueModel, DegenerateDataIsRefusedOrFlagged) {
    EXPECT_THROW(fit_tissue_model(std::vector<float>(1000, 5.0f)), std::invalid_argument);  // constant
    EXPECT_THROW(fit_tissue_model(std::vector<float>{}), std::invalid_argument);
    std::vector<float> two_levels(1000, 1.0f);
    for (std::size_t i = 0; i < 500; ++i) two_levels[i] = 2.0f;
    EXPECT_THROW(fit_tissue_model(two_levels), std::invalid_argument);  // too few levels for 3 classes
    // One tissue only: a single Gaussian asked for three classes ends in overlapping classes.
    const TissueModel one = fit_tissue_model(sample({{100, 10, 1.0}}, 0.0, 50000, 7));
    EXPECT_FALSE(one.usable()) << one.classes[0].mean << "±" << one.classes[0].sigma << " " << one.classes[1].mean << "±"
                               << one.classes[1].sigma << " " << one.classes[2].mean << "±" << one.classes[2].sigma;
    EXPECT_THROW(model_window(one, std::vector<float>(5, 100.0f)), std::invalid_argument);
    TissueModelOptions bad;
    bad.classes = 1;
    EXPECT_THROW(bad.validate(), std::invalid_argument);
    bad = {};
    bad.bins = 4;
    EXPECT_THROW(bad.validate(), std::invalid_argument);
    std::vector<float> nan = sample(kT1, 0.2, 1000, 8);
    nan[3] = std::nanf("");
    EXPECT_THROW(fit_tissue_model(nan), std::invalid_argument);
}

// A tissue seen mostly mixed - a PD's CSF in a brain mask that keeps 0.8 % of it pure and 20 % mixed
// with grey matter - is a class all the same: its presence counts half its mixed voxels, so the
// partial-volume fit is kept (before session 69 it "failed", and the plain mixture's grey matter,
// widened by the mixed voxels, moved the window and raised α: PD GM Dice 0.907, 0.918 now). Without
// the mixed voxels, 0.8 % pure is no class: the partial-volume fit still gives way.
TEST(TissueModel, AClassSeenMostlyMixedIsAClass) {
    const auto fit = [](double pv, double pure = 0.008) {
        std::vector<float> v = sample({{140, 6, 0.35}, {170, 7, 0.40}}, 0.05, 200000, 21);  // WM, GM
        const std::vector<float> csf = sample({{170, 7, 0.0}, {200, 5, pure}}, pv, 200000, 22);
        v.insert(v.end(), csf.begin(), csf.end());
        return fit_tissue_model(v);
    };
    const TissueModel mixed = fit(0.2);
    ASSERT_TRUE(mixed.usable()) << mixed.degenerate;
    ASSERT_EQ(mixed.classes.size(), 3u);
    EXPECT_EQ(mixed.note, "");
    EXPECT_LT(mixed.classes[2].weight, 0.01);  // under the old 1 % of pure voxels
    EXPECT_GT(mixed.mixed[1], 0.1);
    EXPECT_NEAR(mixed.classes[2].mean, 200.0, 4.0);
    EXPECT_NEAR(mixed.classes[1].mean, 170.0, 1.5);
    EXPECT_NEAR(mixed.classes[1].sigma, 7.0, 1.0);
    const TissueModel pure = fit(0.0);
    std::printf("without the mixed voxels: usable %d, note '%s', degenerate '%s'\n", pure.usable(), pure.note.c_str(), pure.degenerate.c_str());
    EXPECT_TRUE(!pure.usable() || !pure.note.empty());
    // Nor is a class of 0.2 % pure voxels, however many it shares (kMinPure: a noisy T1's fit with
    // 0.0 % pure CSF and 8.5 % mixed put that CSF at 21 ± 0.3).
    const TissueModel thin = fit(0.2, 0.002);
    std::printf("0.2 %% pure, 20 %% mixed: usable %d, note '%s'\n", thin.usable(), thin.note.c_str());
    EXPECT_NE(thin.note.find("under 0.5 % of the voxels pure"), std::string::npos) << thin.note;
}

TEST(TissueModel, AnUnusableModelFallsBackToTheSeedsWithAWarning) {
    // A flat-topped single tissue: the model is degenerate, the window comes from the seeds.
    Grid<float> image(Lattice({24, 24, 24}));
    std::mt19937 rng(9);
    std::normal_distribution<double> z(100.0, 5.0);
    for (float& x : image.values()) x = static_cast<float>(z(rng));
    const IntensityScale scale = robust_scale(image);
    const SeedBall seed{{12, 12, 12}, 2.0};
    std::vector<std::string> warnings;
    const std::optional<TissueModel> m = fit_window_model(image, Grid<std::uint8_t>(image.lattice(), 1), {}, warnings);
    ASSERT_TRUE(m.has_value());
    EXPECT_FALSE(m->usable());
    ASSERT_FALSE(warnings.empty());
    const WindowEstimate w = estimate_window(image, scale, {&seed, 1}, nullptr, &*m, {});
    EXPECT_EQ(w.source, WindowSource::kSeeds);
    ASSERT_TRUE(w.seed_stats.has_value());
    EXPECT_DOUBLE_EQ(w.mu, w.seed_stats->median);
    ASSERT_FALSE(w.warnings.empty());
}

// A skull-stripped image's constant background inside the region (between gyri, in the ventricles)
// is a spike at the minimum no tissue makes: the model leaves it out and finds the same classes.
TEST(TissueModel, TheBackgroundSpikeOfAStrippedImageIsLeftOut) {
    std::vector<float> v = sample(kT1, 0.25, 60000, 10);
    Grid<float> image(Lattice({static_cast<int>(v.size()) + 30000, 1, 1}), 0.0f);  // 30 000 background zeros
    for (std::size_t i = 0; i < v.size(); ++i) image[static_cast<PointIndex>(i)] = v[i];
    const TissueModel with = fit_tissue_model(image, nullptr), without = fit_tissue_model(v);
    ASSERT_TRUE(with.usable()) << with.degenerate;
    for (std::size_t c = 0; c < 3; ++c) EXPECT_NEAR(with.classes[c].mean, without.classes[c].mean, 1e-6) << c;
}

// A region with two tissues where three classes are asked for (a tight mask with next to no CSF):
// the model drops to two classes, says so, and the window still reaches the GM/WM midpoint.
TEST(TissueModel, TooManyClassesFallBackToFewerWithAWarning) {
    const std::vector<float> v = sample({{97, 8, 0.6}, {131, 6, 0.3}}, 0.1, 60000, 11);
    Grid<float> image(Lattice({static_cast<int>(v.size()), 1, 1}));
    for (std::size_t i = 0; i < v.size(); ++i) image[static_cast<PointIndex>(i)] = v[i];
    std::vector<std::string> warnings;
    const std::optional<TissueModel> m = fit_window_model(image, Grid<std::uint8_t>(image.lattice(), 1), {}, warnings);
    ASSERT_TRUE(m.has_value());
    ASSERT_TRUE(m->usable()) << m->degenerate;
    EXPECT_EQ(m->classes.size(), 2u);
    ASSERT_FALSE(warnings.empty());
    EXPECT_NE(warnings[0].find("2 used"), std::string::npos) << warnings[0];
    const ModelWindow w = model_window(*m, std::vector<float>(20, 96.0f));
    EXPECT_EQ(w.seed_class, 0);
    EXPECT_NEAR(w.upper, (97 + 131) / 2.0, 1.5);
}

// A bright class holding 2 % of the region (a bias field can split white matter so, session 47):
// a warning that points at bias correction; the usual T1 mixture (its thinnest class above the
// darkest: 25 %) and a thin darkest class (little CSF in a tight mask) give none.
TEST(TissueModel, AThinBrightClassIsWarnedAbout) {
    const auto warnings_for = [](const std::vector<TrueClass>& classes) {
        const std::vector<float> v = sample(classes, 0.2, 80000, 12);
        Grid<float> image(Lattice({static_cast<int>(v.size()), 1, 1}));
        for (std::size_t i = 0; i < v.size(); ++i) image[static_cast<PointIndex>(i)] = v[i];
        std::vector<std::string> warnings;
        const std::optional<TissueModel> m = fit_window_model(image, Grid<std::uint8_t>(image.lattice(), 1), {}, warnings);
        EXPECT_TRUE(m.has_value() && m->usable());
        std::string thin;
        for (const std::string& w : warnings)
            if (w.find("holds only") != std::string::npos) thin += w;
        return thin;
    };
    const std::string bright = warnings_for({{48, 10, 0.35}, {97, 8, 0.43}, {150, 5, 0.02}});
    EXPECT_NE(bright.find("WM class"), std::string::npos) << bright;
    EXPECT_NE(bright.find("bias-corrected"), std::string::npos) << bright;
    EXPECT_EQ(warnings_for(kT1), "");
    EXPECT_EQ(warnings_for({{48, 10, 0.025}, {97, 8, 0.45}, {131, 6, 0.325}}), "");
}
