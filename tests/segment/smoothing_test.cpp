// gaussian_smooth() against a brute-force 3D convolution with the product kernel (anisotropic
// voxels, replicated border), its edge cases, thread-count independence, and the threshold speed
// reading the blurred image.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <vector>

#include <tbb/global_control.h>

#include "liveset/segment/smoothing.hpp"
#include "liveset/segment/threshold_speed.hpp"

using namespace liveset;

namespace {

Grid<float> random_grid(Vec3i dims, Vec3d spacing, std::uint32_t seed) {
    Grid<float> g(Lattice(dims, spacing));
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (float& v : g.values()) v = u(rng);
    return g;
}

// The kernel written out independently: exp(−k²/2σ²) for |k| ≤ ⌊4σ + ½⌋, normalised, σ rounded to
// 1e-4 voxel; a single tap of weight 1 where σ is under kNegligibleSigma voxels.
std::vector<double> weights(double sigma) {
    sigma = std::round(sigma * 1e4) / 1e4;
    if (sigma < kNegligibleSigma) return {1.0};
    const int r = static_cast<int>(std::floor(4.0 * sigma + 0.5));
    std::vector<double> w;
    double sum = 0.0;
    for (int k = -r; k <= r; ++k) sum += w.emplace_back(std::exp(-(k * k) / (2.0 * sigma * sigma)));
    for (double& v : w) v /= sum;
    return w;
}

double brute_force(const Grid<float>& g, Vec3i p, const std::vector<double> (&w)[3]) {
    const Vec3i d = g.dims();
    const int rx = static_cast<int>(w[0].size() / 2), ry = static_cast<int>(w[1].size() / 2), rz = static_cast<int>(w[2].size() / 2);
    double sum = 0.0;
    for (int c = -rz; c <= rz; ++c)
        for (int b = -ry; b <= ry; ++b)
            for (int a = -rx; a <= rx; ++a) {
                const Vec3i q{std::clamp(p.x + a, 0, d.x - 1), std::clamp(p.y + b, 0, d.y - 1), std::clamp(p.z + c, 0, d.z - 1)};
                sum += w[0][static_cast<std::size_t>(a + rx)] * w[1][static_cast<std::size_t>(b + ry)] * w[2][static_cast<std::size_t>(c + rz)] * g(q);
            }
    return sum;
}

}  // namespace

TEST(GaussianSmooth, EqualsTheBruteForceProductKernelOnAnisotropicVoxels) {
    const Vec3d spacing{0.8, 1.0, 2.5};
    const Grid<float> g = random_grid({13, 11, 9}, spacing, 5);
    for (const double sigma_mm : {0.4, 1.0, 2.2}) {
        const Grid<float> s = gaussian_smooth(g, sigma_mm);
        const Vec3f h = g.lattice().spacing_float();  // as the curvature reads voxel sizes
        const std::vector<double> w[3] = {weights(sigma_mm / h.x), weights(sigma_mm / h.y), weights(sigma_mm / h.z)};
        for (int z = 0; z < 9; ++z)
            for (int y = 0; y < 11; ++y)
                for (int x = 0; x < 13; ++x)
                    ASSERT_NEAR(s({x, y, z}), brute_force(g, {x, y, z}, w), 2e-6) << "sigma " << sigma_mm << " at " << x << "," << y << "," << z;
    }
    // σ 0.4 mm is 0.16 voxel along z (filtered) and σ 0.3 mm 0.12 (not): the cut-off as documented.
    const Grid<float> thin = gaussian_smooth(g, 0.3);
    const std::vector<double> w[3] = {weights(0.3 / static_cast<double>(0.8f)), weights(0.3), {1.0}};
    EXPECT_NEAR(thin({6, 5, 4}), brute_force(g, {6, 5, 4}, w), 2e-6);
}

TEST(GaussianSmooth, KeepsConstantsAndZeroSigmaAndRefusesBadSigmas) {
    Grid<float> flat(Lattice({7, 6, 5}, {1.0, 1.0, 1.0}), 0.375f);
    const Grid<float> blurred = gaussian_smooth(flat, 1.5);  // a kernel wider than the image
    for (const float v : blurred.values()) EXPECT_NEAR(v, 0.375f, 1e-6f);
    const Grid<float> g = random_grid({7, 6, 5}, {1.0, 1.0, 1.0}, 9);
    const Grid<float> same = gaussian_smooth(g, 0.0);
    EXPECT_TRUE(std::equal(same.values().begin(), same.values().end(), g.values().begin(), g.values().end()));
    for (const double bad : {-0.1, kMaxSmoothMm + 0.5, std::nan(""), HUGE_VAL}) EXPECT_THROW(gaussian_smooth(g, bad), std::invalid_argument) << bad;
}

TEST(GaussianSmooth, OneAndTwoThreadsGiveTheSameBits) {
    const Grid<float> g = random_grid({70, 50, 40}, {0.9, 0.9, 1.2}, 3);
    Grid<float> one, two;
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
        one = gaussian_smooth(g, 0.7);
    }
    {
        tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
        two = gaussian_smooth(g, 0.7);
    }
    for (std::size_t i = 0; i < one.size(); ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(one[static_cast<PointIndex>(i)]), std::bit_cast<std::uint32_t>(two[static_cast<PointIndex>(i)])) << i;
}

// The speed with smooth_mm tabulates D of the blurred image: the same bits as the speed of the
// image blurred beforehand, and as the speed handed that blurred image (a session's kept blur; a
// blurred image is ignored without smooth_mm, refused with other dimensions); a σ outside
// [0, kMaxSmoothMm] is refused by validate().
TEST(GaussianSmooth, TheThresholdSpeedReadsTheBlurredImage) {
    const Grid<float> g = random_grid({20, 18, 16}, {1.0, 1.0, 1.0}, 11);
    ThresholdParams p{0.5, 0.2, 4.0, 0.1, 0.5};
    const ThresholdSpeed smoothed(g, p);
    ThresholdParams plain = p;
    plain.smooth_mm = 0.0;
    const Grid<float> blurred = gaussian_smooth(g, 0.5);
    const ThresholdSpeed before(blurred, plain), raw(g, plain), kept(g, p, nullptr, &blurred), unused(g, plain, nullptr, &blurred);
    const auto bits = [](const ThresholdSpeed& s, Vec3i q) { return std::bit_cast<std::uint32_t>(s.propagation(q)); };
    int differ = 0;
    for (int z = 0; z < 16; ++z)
        for (int y = 0; y < 18; ++y)
            for (int x = 0; x < 20; ++x) {
                ASSERT_EQ(bits(smoothed, {x, y, z}), bits(before, {x, y, z}));
                ASSERT_EQ(bits(kept, {x, y, z}), bits(before, {x, y, z}));
                ASSERT_EQ(bits(unused, {x, y, z}), bits(raw, {x, y, z}));
                differ += smoothed.propagation({x, y, z}) != raw.propagation({x, y, z});
            }
    EXPECT_GT(differ, 20 * 18 * 16 / 2);  // the blur changed most of D
    const Grid<float> other = random_grid({20, 18, 15}, {1.0, 1.0, 1.0}, 12);
    EXPECT_THROW(ThresholdSpeed(g, p, nullptr, &other), std::invalid_argument);
    p.smooth_mm = -1.0;
    EXPECT_THROW(validate(p), std::invalid_argument);
    p.smooth_mm = kMaxSmoothMm * 2.0;
    EXPECT_THROW(validate(p), std::invalid_argument);
}

// One scan stored as NIfTI (float voxel sizes: 1.2000000477 mm) and as MINC (double: 1.1999999552,
// the neighbouring float): the same blur, bit for bit.
TEST(GaussianSmooth, NiftiAndMincVoxelSizesGiveTheSameBits) {
    const Grid<float> nifti = random_grid({12, 10, 8}, {1.2000000477, 1.2000000477, 0.7}, 4);
    Grid<float> minc(Lattice(nifti.dims(), {1.1999999552, 1.1999999552, 0.7}));
    std::copy(nifti.values().begin(), nifti.values().end(), minc.values().begin());
    ASSERT_NE(nifti.lattice().spacing_float().x, minc.lattice().spacing_float().x);
    const Grid<float> a = gaussian_smooth(nifti, 0.35), b = gaussian_smooth(minc, 0.35);
    for (std::size_t i = 0; i < a.size(); ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(a[static_cast<PointIndex>(i)]), std::bit_cast<std::uint32_t>(b[static_cast<PointIndex>(i)])) << i;
}
