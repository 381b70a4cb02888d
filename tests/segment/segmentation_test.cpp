// The segmentation loop on images with a known answer: a bright ball is recovered from one seed,
// the region of interest stops the front, interrupts stop the loop, thread count does not matter.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>

#include <tbb/global_control.h>

#include "liveset/levelset/shapes.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/threshold_speed.hpp"

using namespace liveset;

namespace {

constexpr double kRadius = 12.0;
const Vec3d kCentre{24.0, 24.0, 24.0};

// Bright ball (0.7) in a dark background (0.2), partial volume at the border by 4x4x4 supersampling.
Grid<float> ball_image() {
    Grid<float> g(Lattice({48, 48, 48}), 0.2f);
    for (int z = 0; z < 48; ++z)
        for (int y = 0; y < 48; ++y)
            for (int x = 0; x < 48; ++x) {
                int in = 0;
                for (int k = 0; k < 64; ++k) {
                    const Vec3d q{x + ((k & 3) - 1.5) / 4, y + (((k >> 2) & 3) - 1.5) / 4, z + ((k >> 4) - 1.5) / 4};
                    in += norm(q - kCentre) < kRadius;
                }
                g({x, y, z}) = static_cast<float>(0.2 + 0.5 * in / 64.0);
            }
    return g;
}

double dice(const Grid<std::uint8_t>& a, const Grid<std::uint8_t>& b) {
    std::size_t na = 0, nb = 0, both = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        na += a[p] != 0;
        nb += b[p] != 0;
        both += a[p] != 0 && b[p] != 0;
    }
    return 2.0 * static_cast<double>(both) / static_cast<double>(na + nb);
}

Grid<std::uint8_t> truth_ball(const Lattice& l, bool half) {
    Grid<std::uint8_t> t(l, 0);
    for (std::size_t i = 0; i < t.size(); ++i) {
        const Vec3i p = l.coord(static_cast<PointIndex>(i));
        const Vec3d q{static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z)};
        t[static_cast<PointIndex>(i)] = norm(q - kCentre) < kRadius && (!half || p.x < 24);
    }
    return t;
}

const ThresholdParams kParams{0.7, 0.25, 2.0, 0.2};
const SeedBall kSeeds[] = {{{24, 24, 24}, 2.0}};

}  // namespace

TEST(Segmentation, RecoversABrightBallFromOneSeed) {
    const Grid<float> img = ball_image();
    const ThresholdSpeed speed(img, kParams);
    SparseField field(img.lattice(), 2);
    init_from_seeds(field, kSeeds);
    int calls = 0;
    const SegmentationResult r = run_segmentation(field, speed, {}, [&](const SegmentationProgress& p, const ChangedPoints& x) {
        ++calls;
        EXPECT_EQ(p.iteration, calls);
        EXPECT_EQ(p.changed, x.size());
        return true;
    });
    EXPECT_EQ(r.reason, StopReason::kConverged) << r.iterations;
    EXPECT_EQ(calls, r.iterations);
    EXPECT_LT(r.iterations, 400);
    const Grid<std::uint8_t> mask = inside_mask(field.phi());
    EXPECT_GE(dice(mask, truth_ball(img.lattice(), false)), 0.97);
    std::size_t inside = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) inside += mask[static_cast<PointIndex>(i)];
    EXPECT_EQ(r.inside, inside);
}

TEST(Segmentation, ProgressReportsThePointsEachStepEvaluated) {
    // `awake` is the number of zero-layer points the step evaluated: the whole zero layer it
    // started from under the exact step, and under sleeping too for the first `sleep_after` steps;
    // fewer once still stretches sleep.
    const Grid<float> img = ball_image();
    const ThresholdSpeed speed(img, kParams);
    for (const int sleep_after : {0, 5}) {
        SparseField field(img.lattice(), 2);
        init_from_seeds(field, kSeeds);
        SegmentationOptions o;
        if (sleep_after > 0) o.step = sleeping_step(sleep_after);
        std::size_t before = field.zero_layer().size(), slept = 0;
        run_segmentation(field, speed, o, [&](const SegmentationProgress& p, const ChangedPoints&) {
            if (sleep_after == 0 || p.iteration <= sleep_after) {
                EXPECT_EQ(p.awake, before) << p.iteration;
            }
            EXPECT_LE(p.awake, before) << p.iteration;
            slept += before - p.awake;
            before = p.zero_layer;
            return true;
        });
        if (sleep_after == 0) {
            EXPECT_EQ(slept, 0u);
        } else {
            EXPECT_GT(slept, 0u);
        }
    }
}

TEST(Segmentation, RegionOfInterestStopsTheFront) {
    const Grid<float> img = ball_image();
    Grid<std::uint8_t> roi(img.lattice(), 0);
    for (std::size_t i = 0; i < roi.size(); ++i) roi[static_cast<PointIndex>(i)] = img.lattice().coord(static_cast<PointIndex>(i)).x < 24;
    const ThresholdSpeed speed(img, kParams, &roi);
    SparseField field(img.lattice(), 2);
    const SeedBall seeds[] = {{{18, 24, 24}, 2.0}};
    init_from_seeds(field, seeds);
    run_segmentation(field, speed, {});
    // The raw front never settles more than a voxel outside the ROI; the mask is clipped to it.
    std::size_t beyond = 0;
    for (int z = 0; z < 48; ++z)
        for (int y = 0; y < 48; ++y)
            for (int x = 25; x < 48; ++x) beyond += field.phi()({x, y, z}) < 0.0f;
    EXPECT_EQ(beyond, 0u);
    const Grid<std::uint8_t> mask = inside_mask(field.phi(), &roi);
    EXPECT_GE(dice(mask, truth_ball(img.lattice(), true)), 0.95);
}

TEST(Segmentation, InterruptAndLimits) {
    const Grid<float> img = ball_image();
    const ThresholdSpeed speed(img, kParams);
    SparseField field(img.lattice(), 2);
    init_from_seeds(field, kSeeds);
    std::atomic<bool> stop{true};
    const SegmentationResult r = run_segmentation(field, speed, {}, {}, &stop);
    EXPECT_EQ(r.reason, StopReason::kInterrupted);
    EXPECT_EQ(r.iterations, 0);
    SegmentationOptions few;
    few.max_iterations = 5;
    EXPECT_EQ(run_segmentation(field, speed, few).reason, StopReason::kIterationLimit);
    const SegmentationResult by_hook =
        run_segmentation(field, speed, {}, [](const SegmentationProgress& p, const ChangedPoints&) { return p.iteration < 3; });
    EXPECT_EQ(by_hook.reason, StopReason::kInterrupted);
    EXPECT_EQ(by_hook.iterations, 3);
    SegmentationOptions bad;
    bad.window = 0;
    EXPECT_THROW(run_segmentation(field, speed, bad), std::invalid_argument);
    const SeedBall outside[] = {{{60, 1, 1}, 2.0}};
    EXPECT_THROW(init_from_seeds(field, outside), std::invalid_argument);
}

TEST(Segmentation, SameResultForAnyThreadCount) {
    const Grid<float> img = ball_image();
    const ThresholdSpeed speed(img, kParams);
    auto run = [&](int threads) {
        tbb::global_control gc(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        SparseField field(img.lattice(), 2);
        init_from_seeds(field, kSeeds);
        SegmentationOptions o;
        o.max_iterations = 60;
        o.step.parallel_band_min = 0;  // a small field too: 2 threads run the parallel loops
        run_segmentation(field, speed, o);
        return std::vector<float>(field.phi().values().begin(), field.phi().values().end());
    };
    EXPECT_EQ(run(1), run(2));
}

// init_from_seeds evaluates the spheres only in their bounding box: the same φ, statuses and
// zero-layer order as the union evaluated over the whole lattice (seeds at a corner and an edge
// of the lattice, a tiny one whose radius becomes 0.5, overlapping ones; N = 1 and 3).
TEST(Segmentation, SeedsInitialiseOnlyTheirBoxWithTheBitsOfTheWholeLattice) {
    const Lattice lat({41, 33, 27});
    const SeedBall seeds[] = {{{0, 0, 0}, 3.0}, {{40, 16, 13}, 2.0}, {{20, 16, 13}, 0.1}, {{22, 17, 12}, 4.5}};
    for (int layers : {1, 3}) {
        SparseField boxed(lat, layers), whole(lat, layers);
        init_from_seeds(boxed, seeds);
        std::vector<shapes::Sphere> spheres;
        for (const SeedBall& s : seeds) spheres.emplace_back(s.center, std::max(s.radius, 0.5));
        whole.init_from_sdf(shapes::SeedSpheres(lat, spheres));
        const auto pb = boxed.phi().values(), pw = whole.phi().values();
        const auto sb = boxed.status().values(), sw = whole.status().values();
        std::size_t differ = 0;
        for (std::size_t i = 0; i < pb.size(); ++i)
            differ += std::bit_cast<std::uint32_t>(pb[i]) != std::bit_cast<std::uint32_t>(pw[i]) || sb[i] != sw[i];
        EXPECT_EQ(differ, 0u) << "layers " << layers;
        const auto zb = boxed.zero_layer(), zw = whole.zero_layer();
        EXPECT_TRUE(std::equal(zb.begin(), zb.end(), zw.begin(), zw.end())) << "layers " << layers;
        EXPECT_GT(zb.size(), 100u);
    }
}
