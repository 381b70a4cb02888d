// Morphology in mm against brute force: erosion/dilation by a ball with anisotropic spacing,
// closing, largest component and hole filling on small grids; the Gaussian blur in mm.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "liveset/segment/morphology.hpp"

using namespace liveset;

namespace {

using Mask = Grid<std::uint8_t>;

Mask random_blobs(const Lattice& lat, unsigned seed) {
    std::mt19937 rng(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    Mask m(lat);
    const Vec3i d = lat.dims();
    for (int b = 0; b < 6; ++b) {  // a few balls (in index space) of random size
        const Vec3d c{u(rng) * d.x, u(rng) * d.y, u(rng) * d.z};
        const double r = 1.5 + 3.5 * u(rng);
        for (int z = 0; z < d.z; ++z)
            for (int y = 0; y < d.y; ++y)
                for (int x = 0; x < d.x; ++x)
                    if (norm(Vec3d{x - c.x, y - c.y, z - c.z}) <= r) m({x, y, z}) = 1;
    }
    for (std::uint8_t& v : m.values()) v ^= u(rng) < 0.03;  // speckle
    return m;
}

// Squared mm distance between two lattice points.
double dist2(const Lattice& lat, Vec3i a, Vec3i b) {
    const Vec3d s = lat.spacing();
    const Vec3d d{(a.x - b.x) * s.x, (a.y - b.y) * s.y, (a.z - b.z) * s.z};
    return dot(d, d);
}

// Brute force: is any voxel with `value` within r mm of p? (Ties within rounding count as within,
// as in morphology.cpp.)
bool any_within(const Mask& m, Vec3i p, double r, std::uint8_t value) {
    const Vec3i d = m.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if ((m({x, y, z}) != 0) == (value != 0) && dist2(m.lattice(), p, {x, y, z}) <= r * r * (1 + 1e-9)) return true;
    return false;
}

}  // namespace

TEST(Morphology, ErodeAndDilateMatchBruteForceBallsWithAnisotropicSpacing) {
    const Lattice lat({14, 12, 10}, {1.0, 1.3, 0.7});
    for (unsigned seed : {1u, 2u, 3u}) {
        const Mask m = random_blobs(lat, seed);
        for (double r : {0.9, 1.5, 2.6}) {
            const Mask e = erode_mm(m, r), g = dilate_mm(m, r);
            for (int z = 0; z < 10; ++z)
                for (int y = 0; y < 12; ++y)
                    for (int x = 0; x < 14; ++x) {
                        const Vec3i p{x, y, z};
                        // eroded: inside and no outside voxel within r (outside the lattice does not count)
                        EXPECT_EQ(e(p) != 0, m(p) != 0 && !any_within(m, p, r, 0)) << seed << " r " << r << " at " << p;
                        EXPECT_EQ(g(p) != 0, any_within(m, p, r, 1)) << seed << " r " << r << " at " << p;
                    }
            // closing = m ∪ erode(dilate(m)) ⊇ m
            const Mask c = close_mm(m, r), ce = erode_mm(g, r);
            for (std::size_t i = 0; i < m.size(); ++i)
                EXPECT_EQ(c[static_cast<PointIndex>(i)] != 0, m[static_cast<PointIndex>(i)] != 0 || ce[static_cast<PointIndex>(i)] != 0);
        }
    }
}

// A small blob away from the border (the work is cropped to its box grown by the ball), balls from
// a few voxels to wider than the chord path takes (the distance transform then), and the thread
// count varied: always the brute force.
TEST(Morphology, ErodeAndDilateMatchBruteForceWhateverTheBallAndThreads) {
    const Lattice lat({11, 24, 22}, {1.0, 0.15, 0.15});
    Mask m(lat);
    for (int z = 7; z < 15; ++z)
        for (int y = 8; y < 16; ++y)
            for (int x = 3; x < 7; ++x) m({x, y, z}) = (x + 2 * y + 3 * z) % 7 != 0;
    // 0.4 and 1.1 mm: the byte chords (177 at 1.1 mm); 1.6 mm: over 200 chords, the separable form; 3.3 mm:
    // 22 + 21 voxels along y and z, past the chords' 40, the distance transform.
    for (double r : {0.4, 1.1, 1.6, 3.3}) {
        for (int threads : {1, 3}) {
            tbb::task_arena arena(threads);
            Mask e, g;
            arena.execute([&] {
                e = erode_mm(m, r);
                g = dilate_mm(m, r);
            });
            for (PointIndex i = 0; i < m.size(); ++i) {
                const Vec3i p = lat.coord(i);
                ASSERT_EQ(e[i] != 0, m[i] != 0 && !any_within(m, p, r, 0)) << "r " << r << " threads " << threads << " at " << p;
                ASSERT_EQ(g[i] != 0, any_within(m, p, r, 1)) << "r " << r << " threads " << threads << " at " << p;
            }
        }
    }
}

TEST(Morphology, DepthIsTheDistanceToTheNearestOutsideVoxel) {
    const Lattice lat({9, 8, 7}, {1.0, 2.0, 0.5});
    const Mask m = random_blobs(lat, 9);
    const Grid<float> depth = depth_mm(m);
    for (PointIndex i = 0; i < m.size(); ++i) {
        double best = std::numeric_limits<double>::infinity();
        for (PointIndex j = 0; j < m.size(); ++j)
            if (m[j] == 0) best = std::min(best, dist2(lat, lat.coord(i), lat.coord(j)));
        EXPECT_NEAR(depth[i], std::sqrt(best), 1e-5) << lat.coord(i);
    }
}

TEST(Morphology, LargestComponentAndFillHoles) {
    Mask m(Lattice({12, 10, 10}));
    // a hollow 5x5x5 box (a 3x3x3 cavity) and a separate 2x2x2 cube; a 1-voxel diagonal neighbour
    // of the box is a different 6-connected component.
    for (int z = 1; z <= 5; ++z)
        for (int y = 1; y <= 5; ++y)
            for (int x = 1; x <= 5; ++x) m({x, y, z}) = !(x > 1 && x < 5 && y > 1 && y < 5 && z > 1 && z < 5);
    for (int z = 7; z <= 8; ++z)
        for (int y = 7; y <= 8; ++y)
            for (int x = 8; x <= 9; ++x) m({x, y, z}) = 1;
    m({6, 6, 6}) = 1;
    const Mask lc = largest_component(m);
    EXPECT_EQ(std::count(lc.values().begin(), lc.values().end(), 1), 125 - 27);
    EXPECT_EQ(lc({8, 7, 7}), 0);
    EXPECT_EQ(lc({6, 6, 6}), 0);
    const Mask big = large_components(m, 0.05);  // 8 >= 0.05·98, 1 < 0.05·98
    EXPECT_EQ(std::count(big.values().begin(), big.values().end(), 1), 98 + 8);
    EXPECT_EQ(big({6, 6, 6}), 0);
    const Mask f = fill_holes(m);
    EXPECT_EQ(std::count(f.values().begin(), f.values().end(), 1), 125 + 8 + 1);
    EXPECT_EQ(f({3, 3, 3}), 1);
    // an opening to the border: the cavity is not a hole any more
    Mask open = m;
    for (int x = 0; x <= 2; ++x) open({x, 3, 3}) = 0;
    EXPECT_EQ(fill_holes(open)({3, 3, 3}), 0);
    const Mask none = largest_component(Mask(Lattice({3, 3, 3})));
    EXPECT_EQ(std::count(none.values().begin(), none.values().end(), 1), 0);
    EXPECT_THROW(erode_mm(m, -1.0), std::invalid_argument);
    EXPECT_THROW(dilate_mm(m, std::nan("")), std::invalid_argument);
}

// The chords' inner loop, 16 and 32 bytes at a time, against its definition on random rows: every
// width the processor runs (the 32-byte loop only where it has AVX2).
TEST(Morphology, ChordLoopsMatchTheirDefinition) {
    namespace md = morphology_detail;
    std::mt19937 rng(74);
    for (int trial = 0; trial < 200; ++trial) {
        const std::size_t n = md::kRowBytes * (1 + rng() % 8);
        std::vector<std::uint8_t> d(n), acc(n);
        for (std::size_t x = 0; x < n; ++x) {
            d[x] = static_cast<std::uint8_t>(rng() % 4 == 0 ? 255 : rng() % 4 == 0 ? rng() % 256 : rng() % 12);
            acc[x] = static_cast<std::uint8_t>(rng() % 3 == 0 ? 255 : rng() % 256);
        }
        const auto w = static_cast<std::uint8_t>(trial % 5 == 0 ? 254 : trial % 5 == 1 ? rng() % 255 : rng() % 10);
        std::vector<std::uint8_t> want = acc;
        for (std::size_t x = 0; x < n; ++x) want[x] = std::min<std::uint8_t>(want[x], d[x] > w ? static_cast<std::uint8_t>(d[x] - w) : 0);
        std::vector<std::uint8_t> got16 = acc;
        md::min_over_chord_16(got16.data(), d.data(), w, n);
        ASSERT_EQ(got16, want) << "trial " << trial;
        if (md::has_avx2()) {
            std::vector<std::uint8_t> got32 = acc;
            md::min_over_chord_32(got32.data(), d.data(), w, n);
            ASSERT_EQ(got32, want) << "trial " << trial;
        }
    }
}

// Balls reaching up to 254 voxels along x (fine x spacing) take the byte distances to their limit;
// one reaching 255 or more takes the separable form: the brute force either way, with features far
// apart along the rows (so distances near the byte cap are met) and rows many 32-byte blocks long.
TEST(Morphology, BallsAtAndBeyondTheByteDistancesAlongXAreExact) {
    const Lattice lat({600, 5, 4}, {0.01, 1.0, 1.0});
    Mask m(lat);
    for (const Vec3i p : {Vec3i{3, 2, 1}, Vec3i{250, 0, 0}, Vec3i{420, 4, 3}, Vec3i{599, 1, 2}, Vec3i{300, 2, 2}}) m(p) = 1;
    for (int x = 100; x < 180; ++x) m({x, 3, 0}) = 1;
    for (double r : {1.3, 2.54, 2.55}) {  // 130, 254 and 255 voxels along x
        const Mask e = erode_mm(m, r), g = dilate_mm(m, r);
        for (PointIndex i = 0; i < m.size(); ++i) {
            const Vec3i p = lat.coord(i);
            ASSERT_EQ(e[i] != 0, m[i] != 0 && !any_within(m, p, r, 0)) << "r " << r << " at " << p;
            ASSERT_EQ(g[i] != 0, any_within(m, p, r, 1)) << "r " << r << " at " << p;
        }
    }
}
