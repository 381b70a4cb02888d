// segment_image's warning for a front that converged far short of its tissue: grey-matter-like
// cells walled off by a darker tissue, one seed in one cell, the window from the tissue model. The
// front fills its cell (a few hundred voxels of tens of thousands) and the outcome says so; without
// the walls it fills the tissue and says nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <random>
#include <string>

#include "liveset/segment/pipeline.hpp"

using namespace liveset;

namespace {

constexpr int kSize = 64;
const Vec3d kCentre{31.5, 31.5, 31.5};

// A ball of radius 29: a dark shell (40) from 24 mm out, a bright core (160) within 12 mm, the
// middle tissue (100) between; `walls`: the middle tissue cut into 7-voxel cells by 1-voxel walls of
// the dark one. Gaussian noise of σ 6 (a fixed generator). The ROI is the ball.
struct Scene {
    Grid<float> image{Lattice({kSize, kSize, kSize}), 0.0f};
    Grid<std::uint8_t> roi{Lattice({kSize, kSize, kSize}), 0};
};

Scene scene(bool walls) {
    Scene s;
    std::mt19937 rng(5);
    std::normal_distribution<float> noise(0.0f, 6.0f);
    for (int z = 0; z < kSize; ++z)
        for (int y = 0; y < kSize; ++y)
            for (int x = 0; x < kSize; ++x) {
                const double r = norm(Vec3d{double(x), double(y), double(z)} - kCentre);
                if (r >= 29.0) continue;
                float v = r >= 24.0 ? 40.0f : (r < 12.0 ? 160.0f : 100.0f);
                if (walls && v == 100.0f && (x % 8 == 0 || y % 8 == 0 || z % 8 == 0)) v = 40.0f;
                s.image({x, y, z}) = v + noise(rng);
                s.roi({x, y, z}) = 1;
            }
    return s;
}

SegmentOutcome segment_from_one_seed(const Scene& s) {
    SegmentRequest req;
    req.seeds = {{{12.0, 28.0, 28.0}, 2.0}};  // the middle tissue (20 mm out), inside a cell (walls at multiples of 8)
    req.roi = &s.roi;
    return segment_image(s.image, req);
}

std::size_t count(const Grid<std::uint8_t>& m) {
    std::size_t n = 0;
    for (const std::uint8_t v : m.values()) n += v != 0;
    return n;
}

}  // namespace

TEST(StalledFront, AFrontThatStopsFarShortOfItsTissueIsWarnedAbout) {
    const SegmentOutcome walled = segment_from_one_seed(scene(true));
    ASSERT_EQ(walled.window_source, WindowSource::kModel);
    ASSERT_TRUE(walled.model_window.has_value());
    EXPECT_EQ(walled.result.reason, StopReason::kConverged);
    const std::size_t inside = count(walled.mask);
    EXPECT_GT(inside, 200u);  // its cell (7³ = 343), eroded a little by the noise and the curvature
    EXPECT_LT(inside, 400u);
    ASSERT_EQ(walled.warnings.size(), 1u) << (walled.warnings.empty() ? "" : walled.warnings.front());
    const std::string& w = walled.warnings.front();
    EXPECT_NE(w.find("the segmentation holds " + std::to_string(inside) + " voxels"), std::string::npos) << w;
    EXPECT_NE(w.find("the front stopped early"), std::string::npos) << w;

    const SegmentOutcome open = segment_from_one_seed(scene(false));
    EXPECT_GT(count(open.mask), 30000u);  // the whole middle tissue: 4/3 π (24³ − 12³) ≈ 50 700 voxels less its borders
    EXPECT_TRUE(open.warnings.empty()) << open.warnings.front();
}
