// The coarse-to-fine start: the block grid's placement, block means and majorities and the upsampled
// front against brute force and exact linear answers; on a finely sampled cortex-like shell, the
// fine run from the coarse result against the direct run and the truth, on 1 and 2 threads.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <stdexcept>
#include <utility>

#include "liveset/segment/coarse_start.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/segment/smoothing.hpp"
#include "fine_shell.hpp"

using namespace liveset;

namespace {

// An odd-sized, anisotropic, rotated lattice.
Lattice odd_lattice() {
    const Mat3d rot{0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0};
    return Lattice({7, 6, 5}, {0.7, 0.8, 0.6}, {-10.0, 4.0, 2.5}, rot);
}

TEST(CoarseStart, BlockGridSitsAtTheBlocksCentres) {
    const Lattice fine = odd_lattice();
    const Lattice coarse = coarse_lattice(fine);
    EXPECT_EQ(coarse.dims(), (Vec3i{4, 3, 3}));
    EXPECT_DOUBLE_EQ(coarse.spacing().x, 1.4);
    EXPECT_DOUBLE_EQ(coarse.spacing().y, 1.6);
    EXPECT_DOUBLE_EQ(coarse.spacing().z, 1.2);
    for (const Vec3d c : {Vec3d{0, 0, 0}, Vec3d{3, 2, 1}, Vec3d{1.5, 0.25, 2}}) {
        const Vec3d want = fine.to_world({2 * c.x + 0.5, 2 * c.y + 0.5, 2 * c.z + 0.5});
        const Vec3d got = coarse.to_world(c);
        EXPECT_NEAR(norm(got - want), 0.0, 1e-9);
    }
    const SeedBall s = coarse_seed({{4.5, 2.5, 0.5}, 3.0}, coarse);
    EXPECT_DOUBLE_EQ(s.center.x, 2.0);
    EXPECT_DOUBLE_EQ(s.center.y, 1.0);
    EXPECT_DOUBLE_EQ(s.center.z, 0.0);
    EXPECT_DOUBLE_EQ(s.radius, 1.5);
    // Seeds on the border (the first voxel; the last of an even axis, 5 on y) stay on the coarse grid.
    const SeedBall b = coarse_seed({{0.0, 5.0, 4.0}, 2.0}, coarse);
    EXPECT_DOUBLE_EQ(b.center.x, 0.0);
    EXPECT_DOUBLE_EQ(b.center.y, 2.0);
    EXPECT_DOUBLE_EQ(b.center.z, 1.75);
}

// The coarse D at each block is the mean of the fine D over the block (+1 outside the ROI), the
// fine D read after the blur when there is one; the ROI's majority is the brute-force count's.
void check_block_terms(double smooth_mm) {
    const Lattice fine = odd_lattice();
    Grid<float> image(fine);
    Grid<std::uint8_t> mask(fine);
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (std::size_t i = 0; i < image.size(); ++i) {
        image[static_cast<PointIndex>(i)] = u(rng);
        mask[static_cast<PointIndex>(i)] = static_cast<std::uint8_t>(rng() % 3 == 0 ? 0 : 1 + rng() % 4);  // 0 or a label
    }
    ThresholdParams params;
    params.mu = 0.45;
    params.epsilon = 0.2;
    params.n = 4.0;
    params.alpha = 0.2;
    params.smooth_mm = smooth_mm;
    const ThresholdSpeed speed(image, params, &mask);
    const Grid<float> coarse = block_threshold_terms(speed);
    const Grid<float> seen = smooth_mm > 0.0 ? gaussian_smooth(image, smooth_mm) : image;
    const Grid<std::uint8_t> majority = downsample_majority(mask);
    ASSERT_EQ(coarse.dims(), (Vec3i{4, 3, 3}));
    const Vec3i d = fine.dims();
    int checked = 0, inside = 0;
    for (int cz = 0; cz < 3; ++cz)
        for (int cy = 0; cy < 3; ++cy)
            for (int cx = 0; cx < 4; ++cx) {
                double sum = 0.0;
                int n = 0, set = 0;
                for (int z = 2 * cz; z < 2 * cz + 2; ++z)
                    for (int y = 2 * cy; y < 2 * cy + 2; ++y)
                        for (int x = 2 * cx; x < 2 * cx + 2; ++x) {
                            if (x >= d.x || y >= d.y || z >= d.z) continue;
                            const bool in = mask({x, y, z}) != 0;
                            sum += in ? threshold_term(seen({x, y, z}), params) : 1.0;
                            set += in;
                            ++n;
                        }
                EXPECT_NEAR(coarse({cx, cy, cz}), sum / n, 1e-6) << cx << "," << cy << "," << cz;
                EXPECT_EQ(majority({cx, cy, cz}), 2 * set >= n ? 1 : 0) << cx << "," << cy << "," << cz;
                inside += majority({cx, cy, cz});
                ++checked;
            }
    EXPECT_EQ(checked, 36);
    EXPECT_GT(inside, 0);
    EXPECT_LT(inside, 36);
}

TEST(CoarseStart, BlockThresholdTermsAndMajoritiesMatchBruteForce) { check_block_terms(0.0); }
TEST(CoarseStart, BlockThresholdTermsReadTheBlurredImage) { check_block_terms(0.9); }

// The coarse speed tabulates the block terms as given, even where the fine speed's n is so small
// that no finite intensity has them (D = ±1 at the window's edge and beyond).
TEST(CoarseStart, TermSpeedTabulatesTheTermsAsGiven) {
    const Lattice lat({4, 3, 2}, {1.4, 1.4, 1.4});
    Grid<float> terms(lat);
    for (std::size_t i = 0; i < terms.size(); ++i) terms[static_cast<PointIndex>(i)] = -1.0f + 2.0f * static_cast<float>(i) / 23.0f;
    Grid<std::uint8_t> roi(lat, 1);
    roi({3, 2, 1}) = 0;
    ThresholdParams params;
    params.n = 0.01;
    params.alpha = 0.3;
    const ThresholdSpeed speed = ThresholdSpeed::from_terms(terms, params, &roi);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 4; ++x) {
                const float want = x == 3 && y == 2 && z == 1 ? 0.5f : static_cast<float>(0.35 * terms({x, y, z}));
                EXPECT_FLOAT_EQ(speed.propagation({x, y, z}), want);
            }
    terms({1, 1, 1}) = 1.5f;
    EXPECT_THROW(ThresholdSpeed::from_terms(terms, params), std::invalid_argument);
    terms({1, 1, 1}) = std::nanf("");
    EXPECT_THROW(ThresholdSpeed::from_terms(terms, params), std::invalid_argument);
}

// Trilinear interpolation is exact for a linear φ: inside where the plane, at the fine voxel's
// coarse coordinate (i - 0.5) / 2, is negative (within the coarse grid: no clamping there).
TEST(CoarseStart, UpsampledFrontIsTheLinearPlanesSide) {
    const Lattice fine({20, 18, 16}, {0.7, 0.7, 0.7});
    const Lattice coarse = coarse_lattice(fine);
    Grid<float> phi(coarse);
    const auto plane = [](double x, double y, double z) { return 0.9 * x - 0.35 * y + 0.2 * z - 3.3; };
    for (int z = 0; z < coarse.dims().z; ++z)
        for (int y = 0; y < coarse.dims().y; ++y)
            for (int x = 0; x < coarse.dims().x; ++x) phi({x, y, z}) = static_cast<float>(plane(x, y, z));
    Grid<std::uint8_t> roi(fine, 1);
    roi({5, 5, 5}) = 0;  // inside the plane's negative side
    const Grid<std::uint8_t> up = upsample_inside(phi, fine, &roi);
    int inside = 0, compared = 0;
    for (int z = 1; z < 15; ++z)
        for (int y = 1; y < 17; ++y)
            for (int x = 1; x < 19; ++x) {
                const double v = plane((x - 0.5) / 2, (y - 0.5) / 2, (z - 0.5) / 2);
                if (std::abs(v) < 1e-4) continue;
                const int want = v < 0 && !(x == 5 && y == 5 && z == 5);
                EXPECT_EQ(up({x, y, z}), want) << x << "," << y << "," << z;
                inside += want;
                ++compared;
            }
    EXPECT_GT(inside, 500);
    EXPECT_LT(inside, compared - 500);
    const Grid<std::uint8_t> wrong(coarse, 1);  // an ROI of another grid
    EXPECT_THROW(upsample_inside(phi, fine, &wrong), std::invalid_argument);
}

// An odd grid, edges included: the fine voxel's coarse coordinate (i - 0.5) / 2 clamped to the
// coarse grid on each axis (the first voxel and the last of an odd axis lie beyond its points).
TEST(CoarseStart, UpsamplingClampsAtTheEdgesOfAnOddGrid) {
    const Lattice fine({9, 7, 5}, {0.7, 0.7, 0.7});
    const Lattice coarse = coarse_lattice(fine);
    ASSERT_EQ(coarse.dims(), (Vec3i{5, 4, 3}));
    Grid<float> phi(coarse);
    const auto plane = [](double x, double y, double z) { return 0.8 * x + 0.45 * y - 0.3 * z - 2.1; };
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 4; ++y)
            for (int x = 0; x < 5; ++x) phi({x, y, z}) = static_cast<float>(plane(x, y, z));
    const Grid<std::uint8_t> up = upsample_inside(phi, fine);
    const Vec3i c = coarse.dims();
    const auto at = [](int i, int dim) { return std::clamp((i - 0.5) / 2.0, 0.0, dim - 1.0); };
    int inside = 0, compared = 0;
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 7; ++y)
            for (int x = 0; x < 9; ++x) {
                const double v = plane(at(x, c.x), at(y, c.y), at(z, c.z));
                if (std::abs(v) < 1e-4) continue;
                EXPECT_EQ(up({x, y, z}), v < 0 ? 1 : 0) << x << "," << y << "," << z;
                inside += v < 0;
                ++compared;
            }
    EXPECT_GT(inside, 40);
    EXPECT_LT(inside, compared - 40);
}

// The value a viewer previews at each fine voxel: the plane at the clamped coarse coordinate, and
// negative exactly where upsample_inside says inside (the same bits, on a curved φ too).
TEST(CoarseStart, UpsampledValueIsWhatUpsamplingTests) {
    const Lattice fine({11, 8, 7}, {0.7, 0.7, 0.7});
    const Lattice coarse = coarse_lattice(fine);
    Grid<float> plane(coarse), ball(coarse);
    const auto linear = [](double x, double y, double z) { return 0.6 * x - 0.5 * y + 0.35 * z - 1.2; };
    const auto curved = [](double x, double y, double z) { return std::hypot(x - 2.6, y - 1.7, z - 1.4) - 1.9; };
    for (int z = 0; z < coarse.dims().z; ++z)
        for (int y = 0; y < coarse.dims().y; ++y)
            for (int x = 0; x < coarse.dims().x; ++x) {
                plane({x, y, z}) = static_cast<float>(linear(x, y, z));
                ball({x, y, z}) = static_cast<float>(curved(x, y, z));
            }
    const Grid<std::uint8_t> up = upsample_inside(ball, fine);
    const Vec3i c = coarse.dims();
    const auto at = [](int i, int dim) { return std::clamp((i - 0.5) / 2.0, 0.0, dim - 1.0); };
    int inside = 0;
    for (int z = 0; z < 7; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 11; ++x) {
                EXPECT_NEAR(upsampled_phi(plane, {x, y, z}), linear(at(x, c.x), at(y, c.y), at(z, c.z)), 1e-5) << x << "," << y << "," << z;
                const bool in = upsampled_phi(ball, {x, y, z}) < 0.0f;
                EXPECT_EQ(up({x, y, z}), in ? 1 : 0) << x << "," << y << "," << z;
                inside += in;
            }
    EXPECT_GT(inside, 20);
    EXPECT_LT(inside, 11 * 8 * 7 - 20);
}

TEST(CoarseStart, AutoRuleAndNames) {
    EXPECT_TRUE(coarse_start_applies(CoarseStart::kAuto, Lattice({200, 200, 200}, {0.7, 0.7, 0.7})));
    EXPECT_TRUE(coarse_start_applies(CoarseStart::kAuto, Lattice({200, 200, 200}, {0.85, 0.8, 0.8})));
    EXPECT_FALSE(coarse_start_applies(CoarseStart::kAuto, Lattice({200, 200, 200}, {0.7, 0.7, 1.0})));
    EXPECT_FALSE(coarse_start_applies(CoarseStart::kAuto, Lattice({200, 200, 200}, {1.0, 1.0, 1.0})));
    EXPECT_TRUE(coarse_start_applies(CoarseStart::kOn, Lattice({200, 200, 200}, {1.0, 1.0, 1.0})));
    EXPECT_FALSE(coarse_start_applies(CoarseStart::kOff, Lattice({200, 200, 200}, {0.5, 0.5, 0.5})));
    EXPECT_FALSE(coarse_start_applies(CoarseStart::kOn, Lattice({200, 200, kCoarseStartMinDim - 1}, {0.5, 0.5, 0.5})));
    for (const CoarseStart m : {CoarseStart::kAuto, CoarseStart::kOn, CoarseStart::kOff}) EXPECT_EQ(parse_coarse_start(to_string(m)), m);
    EXPECT_THROW(parse_coarse_start("yes"), std::invalid_argument);
}

using liveset::testing::kShell;
using liveset::testing::Shell;
using liveset::testing::shell;
using liveset::testing::shell_seed;

SegmentOutcome segment_shell(CoarseStart mode) {
    const Shell& s = shell();
    SegmentRequest req;
    req.seeds = {{liveset::testing::shell_seed(), 2.0}};  // 15.5 mm out along x: in the grey shell
    req.roi = &s.roi;
    req.mu_raw = 100.0;
    req.epsilon_raw = 25.0;
    req.loop.step = segment_step();
    req.coarse_start = mode;
    return segment_image(s.image, req);
}

double shell_dice(const Grid<std::uint8_t>& a, const Grid<std::uint8_t>& b) {
    std::size_t both = 0, na = 0, nb = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const bool x = a[static_cast<PointIndex>(i)] != 0, y = b[static_cast<PointIndex>(i)] != 0;
        both += x && y;
        na += x;
        nb += y;
    }
    return 2.0 * static_cast<double>(both) / static_cast<double>(na + nb);
}

TEST(CoarseStart, FineShellFromTheCoarseStartMatchesTheDirectRun) {
    const SegmentOutcome direct = segment_shell(CoarseStart::kOff);
    const SegmentOutcome coarse = segment_shell(CoarseStart::kAuto);  // 0.5 mm: auto starts coarse
    EXPECT_FALSE(direct.coarse.has_value());
    ASSERT_TRUE(coarse.coarse.has_value());
    EXPECT_TRUE(coarse.coarse->used);
    EXPECT_EQ(coarse.coarse->dims, (Vec3i{44, 44, 44}));
    EXPECT_EQ(coarse.coarse->result.reason, StopReason::kConverged);
    EXPECT_EQ(direct.result.reason, StopReason::kConverged);
    EXPECT_EQ(coarse.result.reason, StopReason::kConverged);
    EXPECT_GT(coarse.coarse->upsampled, 0u);
    const double truth_direct = shell_dice(direct.mask, shell().truth), truth_coarse = shell_dice(coarse.mask, shell().truth);
    EXPECT_GT(truth_direct, 0.93);
    EXPECT_GT(truth_coarse, truth_direct - 0.01);
    EXPECT_GT(shell_dice(direct.mask, coarse.mask), 0.98);
    // The fine grid's iterations: a few dozen refining ones instead of the whole way from the seed.
    EXPECT_LT(coarse.result.iterations * 2, direct.result.iterations);
}

// The fine start is the upsampled coarse front without the voxels the image's own data term
// refuses (propagation > 0): brute force on the shell, whose one-voxel sulci the 2x2x2 blocks blur
// into the grey - the coarse front covers them, the fine start leaves them out.
TEST(CoarseStart, TheFineStartLeavesOutWhatTheImagesDataTermRefuses) {
    const Shell& s = shell();
    Grid<float> unit(s.image.lattice());
    for (std::size_t i = 0; i < unit.size(); ++i) unit[static_cast<PointIndex>(i)] = s.image[static_cast<PointIndex>(i)] / 200.0f;
    // Voxels in the grey at the window's edge, |µ - I| = ε exactly: D = 0, which the cut keeps.
    const Vec3i seed_voxel{static_cast<int>(std::lround(shell_seed().x)), static_cast<int>(std::lround(shell_seed().y)),
                           static_cast<int>(std::lround(shell_seed().z))};
    const std::vector<Vec3i> edge{seed_voxel + Vec3i{0, 3, 0}, seed_voxel + Vec3i{0, -3, 0}, seed_voxel + Vec3i{0, 0, 3}};
    for (const Vec3i& q : edge) unit(q) = 0.625f;
    ThresholdParams params;
    params.mu = 0.5;
    params.epsilon = 0.125;
    params.alpha = 0.05;
    const ThresholdSpeed speed(unit, params, &s.roi);
    SegmentationOptions loop;
    loop.step = segment_step();
    const std::vector<SeedBall> seeds{{shell_seed(), 2.0}};
    CoarseRun run(speed, unit.lattice(), &s.roi, seeds, loop, 2);
    while (run.advance()) {
    }
    CoarseStartReport report;
    const std::optional<Grid<std::uint8_t>> start = run.fine_start(report);
    ASSERT_TRUE(start.has_value());
    const Grid<std::uint8_t> up = upsample_inside(run.field().phi(), unit.lattice(), &s.roi);
    std::size_t refused = 0, kept = 0, sulci = 0;
    for (int z = 0; z < kShell; ++z)
        for (int y = 0; y < kShell; ++y)
            for (int x = 0; x < kShell; ++x) {
                const Vec3i q{x, y, z};
                const bool refuses = speed.propagation(q) > 0.0f;
                ASSERT_EQ((*start)(q), up(q) && !refuses ? 1 : 0) << q;
                refused += up(q) && refuses;
                kept += (*start)(q) != 0;
                sulci += up(q) && s.image(q) < 70.0f && s.truth(q) == 0 && norm(unit.lattice().to_world(q.cast<double>()) - unit.lattice().to_world(Vec3d{43.5, 43.5, 43.5})) < 19.0;
            }
    int edge_kept = 0;
    for (const Vec3i& q : edge) {
        ASSERT_EQ(speed.propagation(q), 0.0f) << q;
        EXPECT_EQ((*start)(q), up(q)) << q;  // kept wherever the coarse front covered it
        edge_kept += (*start)(q);
    }
    EXPECT_GT(edge_kept, 0);
    EXPECT_EQ(report.refused, refused);
    EXPECT_EQ(report.upsampled, kept);
    EXPECT_GT(sulci, 100u);    // the coarse front covered the sulci...
    EXPECT_GT(refused, sulci);  // ...which the fine start leaves out, with the noise's outliers
}

TEST(CoarseStart, SameBitsOnOneAndTwoThreads) {
    const auto run = [](int threads) {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        return segment_shell(CoarseStart::kOn);
    };
    const SegmentOutcome one = run(1), two = run(2);
    ASSERT_TRUE(one.coarse && two.coarse);
    EXPECT_EQ(one.coarse->result.iterations, two.coarse->result.iterations);
    EXPECT_EQ(one.result.iterations, two.result.iterations);
    const auto a = one.field->phi().values(), b = two.field->phi().values();
    ASSERT_EQ(a.size(), b.size());
    std::size_t differ = 0;
    for (std::size_t i = 0; i < a.size(); ++i) differ += std::bit_cast<std::uint32_t>(a[i]) != std::bit_cast<std::uint32_t>(b[i]);
    EXPECT_EQ(differ, 0u);
}

}  // namespace

namespace {

// A block and, apart from it, a plate three voxels thick at 0.7 mm, which 2x2x2 blocks blur half
// out of the window: the plate's own coarse front dies, the block's lives. A ripple of ±2.
constexpr int kPlateSize = 64;
bool in_plate(int x, int y, int z) { return x >= 9 && x <= 11 && y >= 4 && y < 60 && z < 60; }
bool in_block(int x, int y, int z) { return x >= 24 && x < 60 && y >= 4 && y < 60 && z >= 4 && z < 60; }

const Grid<float>& plate_and_block() {
    static const Grid<float> g = [] {
        Grid<float> img(Lattice({kPlateSize, kPlateSize, kPlateSize}, {0.7, 0.7, 0.7}), 0.0f);
        for (int z = 0; z < kPlateSize; ++z)
            for (int y = 0; y < kPlateSize; ++y)
                for (int x = 0; x < kPlateSize; ++x)
                    img({x, y, z}) = (in_plate(x, y, z) || in_block(x, y, z) ? 100.0f : 0.0f) +
                                     static_cast<float>((7 * x + 13 * y + 29 * z) % 5 - 2);
        return img;
    }();
    return g;
}

SegmentRequest plate_request(CoarseStart mode) {
    SegmentRequest req;
    req.seeds = {{{44.0, 30.0, 30.0}, 2.0}, {{10.0, 30.0, 0.0}, 1.0}};  // the block; the plate, on the image's first slice
    req.mu_raw = 100.0;
    req.epsilon_raw = 25.0;
    req.alpha = 0.05;
    req.loop.step = segment_step();
    req.coarse_start = mode;
    return req;
}

std::size_t count_in(const Grid<std::uint8_t>& mask, bool (*region)(int, int, int)) {
    std::size_t n = 0;
    for (int z = 0; z < kPlateSize; ++z)
        for (int y = 0; y < kPlateSize; ++y)
            for (int x = 0; x < kPlateSize; ++x) n += mask({x, y, z}) != 0 && region(x, y, z);
    return n;
}

}  // namespace

// A seed whose coarse front died keeps its ball in the fine start, so its region is segmented as
// the direct run segments it; a seed on the image's first slice is placed on the coarse grid.
TEST(CoarseStart, ASeedWhoseCoarseFrontDiedIsNotLost) {
    {  // the plate's seed alone: its coarse front dies (else this test would not test the balls)
        SegmentRequest alone = plate_request(CoarseStart::kOn);
        alone.seeds.erase(alone.seeds.begin());
        const SegmentOutcome o = segment_image(plate_and_block(), alone);
        ASSERT_TRUE(o.coarse.has_value());
        EXPECT_FALSE(o.coarse->used);
        EXPECT_EQ(o.coarse->result.reason, StopReason::kVanished);
    }
    const SegmentOutcome direct = segment_image(plate_and_block(), plate_request(CoarseStart::kOff));
    const SegmentOutcome coarse = segment_image(plate_and_block(), plate_request(CoarseStart::kOn));
    ASSERT_TRUE(coarse.coarse && coarse.coarse->used);
    const std::size_t plate = 3 * 56 * 60, block = 36 * 56 * 56;
    EXPECT_GT(count_in(direct.mask, in_plate), plate * 9 / 10);
    EXPECT_GT(count_in(coarse.mask, in_plate), plate * 9 / 10);
    EXPECT_GT(count_in(coarse.mask, in_block), block * 9 / 10);
}

// Nothing of the coarse front left in the ROI (a plane one voxel thick: no 2x2x2 block is half in
// it): the fine run starts from the seeds, the direct run's φ bit for bit.
TEST(CoarseStart, AnEmptyCoarseFrontFallsBackToTheSeeds) {
    Grid<std::uint8_t> roi(plate_and_block().lattice(), 0);
    for (int y = 4; y < 60; ++y)
        for (int x = 24; x < 60; ++x) roi({x, y, 30}) = 1;
    SegmentRequest off = plate_request(CoarseStart::kOff), on = plate_request(CoarseStart::kOn);
    off.seeds = on.seeds = {{{44.0, 30.0, 30.0}, 2.0}};
    off.roi = on.roi = &roi;
    const SegmentOutcome direct = segment_image(plate_and_block(), off), fallback = segment_image(plate_and_block(), on);
    ASSERT_TRUE(fallback.coarse.has_value());
    EXPECT_FALSE(fallback.coarse->used);
    EXPECT_GT(fallback.coarse->result.iterations, 0);
    EXPECT_EQ(fallback.result.iterations, direct.result.iterations);
    const auto a = direct.field->phi().values(), b = fallback.field->phi().values();
    ASSERT_EQ(a.size(), b.size());
    EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), [](float x, float y) { return std::bit_cast<std::uint32_t>(x) == std::bit_cast<std::uint32_t>(y); }));
    EXPECT_GT(count_in(direct.mask, in_block), 0u);
}

// A bright ball in a 104³ grid: its float grids (4.5 MB) are large blocks, kept by the allocator
// and given back by segment_image, which the 64³ plate's are not.
const Grid<float>& large_ball() {
    static const Grid<float> g = [] {
        Grid<float> out(Lattice({104, 104, 104}), 20.0f);
        for (int z = 0; z < 104; ++z)
            for (int y = 0; y < 104; ++y)
                for (int x = 0; x < 104; ++x)
                    if (norm(Vec3d{x - 51.5, y - 52.0, z - 50.5}) < 24.0) out({x, y, z}) = 100.0f + static_cast<float>((x * 7 + y * 3 + z) % 9);
        return out;
    }();
    return g;
}

// The image handed over (segment_image(Grid&&), as `liveset segment` hands it without
// --out-corrected) is left empty, and the outcome is the kept image's bit for bit: coarse or
// direct, blurred or not, on grids of large blocks or small ones.
TEST(CoarseStart, AnImageHandedOverGivesTheSameOutcomeAndIsFreed) {
    SegmentRequest ball = plate_request(CoarseStart::kOff);
    ball.seeds = {{{52.0, 52.0, 50.0}, 3.0}};
    ball.smooth_mm = 0.8;
    const auto check = [](const Grid<float>& given, const SegmentRequest& req) -> SegmentOutcome {
        const SegmentOutcome kept = segment_image(given, req);
        Grid<float> image = given;
        SegmentOutcome handed = segment_image(std::move(image), req);
        EXPECT_EQ(image.size(), 0u);
        EXPECT_EQ(handed.result.iterations, kept.result.iterations);
        EXPECT_EQ(handed.coarse.has_value(), kept.coarse.has_value());
        EXPECT_EQ(handed.params.mu, kept.params.mu);
        EXPECT_EQ(handed.params.smooth_mm, kept.params.smooth_mm);
        const auto a = kept.field->phi().values(), b = handed.field->phi().values();
        EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), b.end(), [](float x, float y) { return std::bit_cast<std::uint32_t>(x) == std::bit_cast<std::uint32_t>(y); }));
        EXPECT_TRUE(std::equal(kept.mask.values().begin(), kept.mask.values().end(), handed.mask.values().begin(), handed.mask.values().end()));
        return handed;
    };
    for (const CoarseStart mode : {CoarseStart::kOff, CoarseStart::kOn}) {
        SCOPED_TRACE(to_string(mode));
        ball.coarse_start = mode;
        const SegmentOutcome o = check(large_ball(), ball);
        EXPECT_GT(o.params.smooth_mm, 0.0);
        EXPECT_EQ(o.result.reason, StopReason::kConverged);
        EXPECT_NEAR(static_cast<double>(std::count(o.mask.values().begin(), o.mask.values().end(), std::uint8_t{1})),
                    4.0 / 3.0 * std::numbers::pi * 24.0 * 24.0 * 24.0, 0.05 * 4.0 / 3.0 * std::numbers::pi * 24.0 * 24.0 * 24.0);
    }
    for (const CoarseStart mode : {CoarseStart::kOff, CoarseStart::kOn}) {
        const SegmentRequest req = plate_request(mode);
        const SegmentOutcome kept = segment_image(plate_and_block(), req);
        Grid<float> image = plate_and_block();
        const SegmentOutcome handed = segment_image(std::move(image), req);
        EXPECT_EQ(image.size(), 0u) << to_string(mode);
        EXPECT_EQ(handed.result.iterations, kept.result.iterations) << to_string(mode);
        EXPECT_EQ(handed.coarse.has_value(), kept.coarse.has_value()) << to_string(mode);
        EXPECT_EQ(handed.params.mu, kept.params.mu);
        EXPECT_EQ(handed.params.alpha, kept.params.alpha);
        const auto a = kept.field->phi().values(), b = handed.field->phi().values();
        ASSERT_EQ(a.size(), b.size());
        EXPECT_TRUE(std::equal(a.begin(), a.end(), b.begin(), [](float x, float y) { return std::bit_cast<std::uint32_t>(x) == std::bit_cast<std::uint32_t>(y); }))
            << to_string(mode);
        EXPECT_TRUE(std::equal(kept.mask.values().begin(), kept.mask.values().end(), handed.mask.values().begin(), handed.mask.values().end()));
        EXPECT_GT(count_in(handed.mask, in_block), 0u);
    }
}

// A seed outside the image is refused as the direct run refuses it, not clamped onto the coarse grid.
TEST(CoarseStart, ASeedOutsideTheImageIsRefused) {
    for (const CoarseStart mode : {CoarseStart::kOff, CoarseStart::kOn}) {
        SegmentRequest req = plate_request(mode);
        req.seeds.push_back({{-40.0, 30.0, 30.0}, 2.0});
        EXPECT_THROW(segment_image(plate_and_block(), req), std::invalid_argument) << to_string(mode);
    }
}

// A tiny n with blocks cut by the ROI (D̄ about ½ there): no intensity has that D (3^(1/n)
// overflows), so the coarse speed takes the terms themselves; the run goes as the direct one does.
TEST(CoarseStart, ATinyNWithBlocksCutByTheRoiRuns) {
    Grid<std::uint8_t> roi(plate_and_block().lattice(), 0);
    for (int z = 0; z < kPlateSize; ++z)
        for (int y = 0; y < kPlateSize; ++y)
            for (int x = 25; x < kPlateSize; ++x) roi({x, y, z}) = 1;  // cuts the blocks of x 24-25
    SegmentRequest req = plate_request(CoarseStart::kOn);
    req.seeds = {{{44.0, 30.0, 30.0}, 2.0}};
    req.roi = &roi;
    req.n = 0.01;
    req.loop.max_iterations = 30;
    const SegmentOutcome o = segment_image(plate_and_block(), req);
    ASSERT_TRUE(o.coarse.has_value());
    EXPECT_GT(o.coarse->result.iterations, 0);
    EXPECT_GT(o.result.iterations, 0);
}

// The hook stops the run during the coarse start: interrupted there, no fine step taken.
TEST(CoarseStart, AnInterruptDuringTheCoarseStartStopsTheRun) {
    int coarse_steps = 0, fine_steps = 0;
    const SegmentationHook hook = [&](const SegmentationProgress& p, const ChangedPoints&) {
        ++(p.level == 1 ? coarse_steps : fine_steps);
        return p.level != 1 || p.iteration < 3;
    };
    const SegmentOutcome o = segment_image(plate_and_block(), plate_request(CoarseStart::kOn), hook);
    EXPECT_EQ(o.result.reason, StopReason::kInterrupted);
    ASSERT_TRUE(o.coarse.has_value());
    EXPECT_EQ(o.coarse->result.reason, StopReason::kInterrupted);
    EXPECT_EQ(o.coarse->result.iterations, 3);
    EXPECT_EQ(coarse_steps, 3);
    EXPECT_EQ(fine_steps, 0);
    EXPECT_EQ(o.result.iterations, 0);
}
