// The preprocessing's parallel whole-image loops (voxel_loops.hpp) and the brain mask's histogram
// and head geometry built on them, against serial loops written out here, on 1 and 3 threads.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "liveset/segment/brain_histogram.hpp"
#include "liveset/segment/head_geometry.hpp"
#include "liveset/segment/voxel_loops.hpp"

using namespace liveset;

namespace {

// Not a multiple of the 64 Ki block: the last block is partial.
constexpr std::size_t kN = 3 * voxel_loops::kBlock + 12345;

template <class F>
void on_threads(int threads, const F& f) {
    tbb::task_arena(threads).execute(f);
}

}  // namespace

TEST(VoxelLoops, MapCountAndHistogramAreTheSerialLoops) {
    std::mt19937 rng(76);
    std::vector<int> v(kN);
    for (int& x : v) x = static_cast<int>(rng() % 1000) - 100;  // bins: x / 10, none below 0 or from 80 on
    std::vector<int> serial_map(kN);
    std::size_t serial_count = 0;
    std::vector<std::size_t> serial_hist(80, 0);
    for (std::size_t i = 0; i < kN; ++i) {
        serial_map[i] = 3 * v[i] + 1;
        serial_count += v[i] % 7 == 0 ? 1 : 0;
        if (v[i] >= 0 && v[i] / 10 < 80) ++serial_hist[static_cast<std::size_t>(v[i] / 10)];
    }
    for (const int threads : {1, 3})
        on_threads(threads, [&] {
            std::vector<int> map(kN, -7);
            voxel_loops::for_each(kN, [&](std::size_t i) { map[i] = 3 * v[i] + 1; });
            EXPECT_EQ(map, serial_map) << threads << " threads";
            EXPECT_EQ(voxel_loops::count_if(kN, [&](std::size_t i) { return v[i] % 7 == 0; }), serial_count) << threads << " threads";
            const std::vector<std::size_t> h = voxel_loops::histogram(kN, 80, [&](std::size_t i) {
                return v[i] < 0 ? std::size_t{80} : static_cast<std::size_t>(v[i] / 10);  // 80..89: out of range
            });
            EXPECT_EQ(h, serial_hist) << threads << " threads";
            EXPECT_EQ(voxel_loops::count_if(0, [](std::size_t) { return true; }), 0u);
            EXPECT_EQ(voxel_loops::histogram(0, 4, [](std::size_t) { return std::size_t{0}; }), std::vector<std::size_t>(4, 0));
        });
}

// A reduction's parts: min(kMaxParts, n / grain) of them (at least one), consecutive, covering
// [0, n), set by n and grain alone and folded in order, on any thread count.
TEST(VoxelLoops, ReductionsFoldFixedPartsInOrder) {
    using Parts = std::vector<std::pair<std::size_t, std::size_t>>;
    const auto parts = [](std::size_t n, std::size_t grain) {
        return voxel_loops::reduce(
            n, grain, Parts{},
            [](std::size_t b, std::size_t e, Parts p) {
                p.emplace_back(b, e);
                return p;
            },
            [](Parts a, const Parts& b) {
                a.insert(a.end(), b.begin(), b.end());
                return a;
            });
    };
    for (const int threads : {1, 3})
        on_threads(threads, [&] {
            for (const auto& [n, grain] : std::vector<std::pair<std::size_t, std::size_t>>{{0, 1}, {5, 10}, {37, 10}, {1000, 10}, {kN, voxel_loops::kBlock}}) {
                const Parts p = parts(n, grain);
                const std::size_t expected = std::clamp<std::size_t>(n / grain, 1, voxel_loops::kMaxParts);
                ASSERT_EQ(p.size(), expected) << n << " / " << grain << ", " << threads << " threads";
                EXPECT_EQ(p.front().first, 0u);
                EXPECT_EQ(p.back().second, n);
                for (std::size_t k = 1; k < p.size(); ++k) {
                    EXPECT_EQ(p[k].first, p[k - 1].second);
                    EXPECT_GE(p[k].second - p[k].first, n / expected);  // no part below the average's floor
                }
            }
        });
}

// counted_writes: the kept items in item order after `first`, as the serial filter gives them, on
// any thread count and whatever the parts (a wrong offset drops or overwrites an item).
TEST(VoxelLoops, CountedWritesAreTheSerialFilter) {
    std::mt19937 rng(5);
    std::vector<std::uint32_t> items(100000);
    for (auto& v : items) v = rng();
    const auto keep = [](std::uint32_t v) { return v % 3 != 0; };
    std::vector<std::uint32_t> expected{7, 8};
    for (std::uint32_t v : items)
        if (keep(v)) expected.push_back(v);
    for (const int threads : {1, 3})
        on_threads(threads, [&] {
            for (const std::size_t grain : {std::size_t{1} << 20, std::size_t{1000}, std::size_t{7}}) {
                std::vector<std::uint32_t> out{7, 8};
                voxel_loops::counted_writes(
                    items.size(), grain, out.size(),
                    [&](std::size_t b, std::size_t e) { return static_cast<std::size_t>(std::count_if(items.begin() + b, items.begin() + e, keep)); },
                    [&](std::size_t total) { out.resize(total); },
                    [&](std::size_t b, std::size_t e, std::size_t at) {
                        for (std::size_t k = b; k < e; ++k)
                            if (keep(items[k])) out[at++] = items[k];
                    });
                EXPECT_EQ(out, expected) << "grain " << grain << ", " << threads << " threads";
            }
        });
}

// brain_detail::histogram: its bins as the serial `+= 1.0` over the voxels in the mask within
// [lo, hi] (the top value in the last bin; NaN, below lo and above hi left out).
TEST(VoxelLoops, BrainHistogramCountsAsTheSerialLoop) {
    const Lattice lat({97, 83, 41});
    Grid<float> image(lat, 0.0f);
    Grid<std::uint8_t> mask(lat, 0);
    std::mt19937 rng(7);
    std::normal_distribution<float> value(50.0f, 25.0f);
    const double lo = 10.0, hi = 90.0;
    for (std::size_t i = 0; i < image.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        const unsigned r = rng() % 100;
        image[p] = r < 2 ? std::numeric_limits<float>::quiet_NaN() : r < 4 ? 90.0f : r < 6 ? 10.0f : value(rng);
        mask[p] = rng() % 4 != 0;
    }
    std::vector<double> serial(brain_detail::kBins, 0.0);
    const double width = (hi - lo) / brain_detail::kBins;
    for (std::size_t i = 0; i < image.size(); ++i) {
        const double v = image[static_cast<PointIndex>(i)];
        if (mask[static_cast<PointIndex>(i)] == 0 || std::isnan(v) || v < lo || v > hi) continue;
        serial[static_cast<std::size_t>(std::min(brain_detail::kBins - 1, static_cast<int>((v - lo) / width)))] += 1.0;
    }
    for (const int threads : {1, 3})
        on_threads(threads, [&] {
            const brain_detail::Histogram h = brain_detail::histogram(image, mask, lo, hi);
            EXPECT_EQ(h.counts, serial) << threads << " threads";
            EXPECT_EQ(h.lo, lo);
            EXPECT_EQ(h.width, width);
        });
}

// The head geometry's counts (cranial, head_diameter_mm, cut_contact_mm2) against serial loops on a
// tilted "up" over a random head, on 1 and 3 threads.
TEST(VoxelLoops, HeadGeometryCountsAsTheSerialLoops) {
    const Lattice lat({61, 57, 73}, {0.9, 1.1, 1.3});
    Grid<std::uint8_t> head(lat, 0);
    std::mt19937 rng(11);
    for (std::size_t i = 0; i < head.size(); ++i) head[static_cast<PointIndex>(i)] = rng() % 3 != 0;
    brain_detail::Vertical up;
    up.g[0] = 0.2, up.g[1] = -0.35, up.g[2] = 1.25;
    const Vec3i d = lat.dims();
    double top = -std::numeric_limits<double>::infinity();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if (head({x, y, z}) != 0) top = std::max(top, up.height({x, y, z}));
    // cranial: the head within 40 mm of its top.
    Grid<std::uint8_t> kept = head;
    std::size_t below = 0;
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if (kept({x, y, z}) != 0 && up.height({x, y, z}) < top - 40.0) kept({x, y, z}) = 0, ++below;
    // head_diameter_mm: the widest layer within 50 mm of the top.
    const double layer_mm = 1.25;
    std::vector<std::size_t> layer(static_cast<std::size_t>(std::lround(50.0 / layer_mm)) + 1, 0);
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const auto k = static_cast<std::size_t>(std::lround((top - up.height({x, y, z})) / layer_mm));
                if (head({x, y, z}) != 0 && k < layer.size()) ++layer[k];
            }
    const double widest = static_cast<double>(*std::max_element(layer.begin(), layer.end())) * 0.9 * 1.1 * 1.3 / layer_mm;
    const double diameter = 2.0 * std::sqrt(widest / std::numbers::pi);
    // cut_contact_mm2: the head's voxels in the slab [cut, cut + 3 layers) 30 mm below the top.
    const double cut = top - 30.0, slab = layer_mm * std::ceil(3.0 / layer_mm - 1e-9);
    std::size_t in_slab = 0;
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if (head({x, y, z}) != 0) {
                    const double h = up.height({x, y, z});
                    in_slab += h >= cut && h < cut + slab;
                }
    const double contact = static_cast<double>(in_slab) * 0.9 * 1.1 * 1.3 / slab;
    ASSERT_GT(below, 0u);
    ASSERT_GT(in_slab, 0u);
    for (const int threads : {1, 3})
        on_threads(threads, [&] {
            std::size_t n = 0;
            const Grid<std::uint8_t> c = brain_detail::cranial(head, up, 40.0, n);
            EXPECT_EQ(n, below) << threads << " threads";
            EXPECT_TRUE(std::equal(c.values().begin(), c.values().end(), kept.values().begin())) << threads << " threads";
            EXPECT_EQ(brain_detail::head_diameter_mm(head, up, 50.0), diameter) << threads << " threads";
            EXPECT_EQ(brain_detail::cut_contact_mm2(head, up, cut), contact) << threads << " threads";
        });
}
