// Intensity normalisation and seed statistics against values computed by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <optional>

#include "liveset/segment/intensity.hpp"

using namespace liveset;

namespace {

// 10x10x10 image whose values are 0..999 in index order.
Grid<float> ramp() {
    Grid<float> g(Lattice({10, 10, 10}));
    for (std::size_t i = 0; i < g.size(); ++i) g[static_cast<PointIndex>(i)] = static_cast<float>(i);
    return g;
}

}  // namespace

TEST(IntensityScale, PercentilesOfARamp) {
    const Grid<float> g = ramp();
    const IntensityScale s = robust_scale(g, nullptr, {1.0, 99.0});
    EXPECT_NEAR(s.low, 9.99, 1e-9);  // 0.01 * 999
    EXPECT_NEAR(s.high, 989.01, 1e-9);
    EXPECT_DOUBLE_EQ(s.to_unit(s.low), 0.0);
    EXPECT_DOUBLE_EQ(s.to_unit(s.high), 1.0);
    EXPECT_DOUBLE_EQ(s.to_unit(-100), 0.0);
    EXPECT_DOUBLE_EQ(s.to_unit(5000), 1.0);
    EXPECT_NEAR(s.to_raw(s.to_unit(500)), 500, 1e-9);
    const Grid<float> u = normalise(g, s);
    EXPECT_FLOAT_EQ(u[500], static_cast<float>((500 - 9.99) / (989.01 - 9.99)));
}

TEST(IntensityScale, RoiRestrictsThePercentiles) {
    const Grid<float> g = ramp();
    Grid<std::uint8_t> roi(g.lattice(), 0);
    for (PointIndex i = 100; i <= 200; ++i) roi[i] = 1;
    const IntensityScale s = robust_scale(g, &roi, {0.0, 100.0});
    EXPECT_DOUBLE_EQ(s.low, 100.0);
    EXPECT_DOUBLE_EQ(s.high, 200.0);
}

TEST(IntensityScale, RejectsFlatImagesBadPercentilesAndEmptyRoi) {
    Grid<float> flat(Lattice({4, 4, 4}), 3.0f);
    EXPECT_THROW(robust_scale(flat), std::invalid_argument);
    const Grid<float> g = ramp();
    EXPECT_THROW(robust_scale(g, nullptr, {50.0, 50.0}), std::invalid_argument);
    EXPECT_THROW(robust_scale(g, nullptr, {-1.0, 50.0}), std::invalid_argument);
    Grid<std::uint8_t> empty(g.lattice(), 0);
    EXPECT_THROW(robust_scale(g, &empty), std::invalid_argument);
    Grid<std::uint8_t> wrong(Lattice({3, 3, 3}), 1);
    EXPECT_THROW(robust_scale(g, &wrong), std::invalid_argument);
    Grid<float> nan = ramp();
    nan[7] = std::nanf("");
    EXPECT_THROW(robust_scale(nan), std::invalid_argument);
}

// NaN voxels (a masked image's no data) become the lowest value, 1 % of the others' range below
// them; the others are untouched; an image all NaN, or one with an infinite voxel, is refused.
TEST(NoData, NanVoxelsAreLoweredBelowEveryOtherValue) {
    Grid<float> g = ramp();  // 0..999
    for (PointIndex i : {PointIndex{0}, PointIndex{500}, PointIndex{999}}) g[i] = std::nanf("");
    const Grid<float> before = g;
    const std::optional<Grid<std::uint8_t>> where = lower_no_data(g);
    ASSERT_TRUE(where.has_value());
    const float below = 1.0f - 0.01f * (998.0f - 1.0f);  // the finite values span 1..998
    for (PointIndex i = 0; i < g.size(); ++i) {
        EXPECT_EQ((*where)[i], std::isnan(before[i]) ? 1 : 0) << i;
        if (std::isnan(before[i])) EXPECT_EQ(g[i], below) << i;
        else EXPECT_EQ(g[i], before[i]) << i;
    }
    Grid<float> none = ramp();
    EXPECT_FALSE(lower_no_data(none).has_value());
    EXPECT_EQ(none.values()[999], 999.0f);
    Grid<float> flat(Lattice({4, 4, 4}), 5.0f);
    flat[3] = std::nanf("");
    EXPECT_TRUE(lower_no_data(flat).has_value());
    EXPECT_EQ(flat[3], 4.0f);  // one below a flat image
    Grid<float> again = g;  // lowered again (after N4 moved them): below the others' range as it is now
    for (PointIndex i = 0; i < again.size(); ++i) again[i] = (*where)[i] ? 2000.0f : 2.0f * before[i];
    lower_voxels(again, *where);
    for (PointIndex i = 0; i < again.size(); ++i)
        EXPECT_EQ(again[i], (*where)[i] ? 2.0f - 0.01f * (1996.0f - 2.0f) : 2.0f * before[i]) << i;
    Grid<float> all(Lattice({2, 2, 2}), std::nanf(""));
    EXPECT_THROW(lower_no_data(all), std::invalid_argument);
    Grid<float> inf = ramp();
    inf[5] = -std::numeric_limits<float>::infinity();
    inf[6] = std::nanf("");
    EXPECT_THROW(lower_no_data(inf), std::invalid_argument);
}

TEST(SeedStatistics, BallAroundASeed) {
    // Value = x: a ball of radius 1 around (5,5,5) holds x = 4, 5 (5 times), 6 -> mean 5, median 5.
    Grid<float> g(Lattice({10, 10, 10}));
    for (int z = 0; z < 10; ++z)
        for (int y = 0; y < 10; ++y)
            for (int x = 0; x < 10; ++x) g({x, y, z}) = static_cast<float>(x);
    const SeedBall seeds[] = {{{5, 5, 5}, 1.0}};
    const SeedStatistics st = seed_statistics(g, seeds);
    EXPECT_EQ(st.voxels, 7u);
    EXPECT_DOUBLE_EQ(st.mean, 5.0);
    EXPECT_DOUBLE_EQ(st.median, 5.0);
    EXPECT_NEAR(st.stddev, std::sqrt(2.0 / 7.0), 1e-12);
    EXPECT_DOUBLE_EQ(st.mad_sigma, 0.0);  // most deviations are 0
    const SeedBall outside[] = {{{10.5, 5, 5}, 1.0}};
    EXPECT_THROW(seed_statistics(g, outside), std::invalid_argument);
}
