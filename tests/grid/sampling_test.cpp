// Interpolation and gradients against analytic fields and written-out formulas; branch-free min/max.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "liveset/grid/float_min_max.hpp"
#include "liveset/grid/sampling.hpp"

using namespace liveset;

namespace {
// A 7×6×5 field of values in [-3, 3) from a fixed generator; with `flat`, about a quarter of them
// 0.5 (so that some differences are exactly zero).
Grid<float> random_field(std::uint32_t state, bool flat) {
    Grid<float> g(Lattice({7, 6, 5}));
    for (float& v : g.values()) {
        state = state * 1664525u + 1013904223u;
        v = flat && (state >> 28) < 4 ? 0.5f : static_cast<float>(state >> 8) / static_cast<float>(1u << 24) * 6.0f - 3.0f;
    }
    return g;
}

Grid<float> linear_field() {
    Grid<float> g(Lattice({8, 8, 8}));
    for (int z = 0; z < 8; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 8; ++x) g({x, y, z}) = 2.0f * x - 3.0f * y + 0.5f * z + 1.0f;
    return g;
}
}  // namespace

TEST(Sampling, TrilinearIsExactOnLinearFields) {
    const Grid<float> g = linear_field();
    const Vec3d p{2.25, 3.5, 4.75};
    EXPECT_NEAR(trilinear(g, p), 2 * 2.25 - 3 * 3.5 + 0.5 * 4.75 + 1, 1e-5);
    // Clamped outside the lattice.
    EXPECT_NEAR(trilinear(g, {-3, 0, 0}), g({0, 0, 0}), 1e-6);
    EXPECT_NEAR(trilinear(g, {7, 7, 7}), g({7, 7, 7}), 1e-6);
}

namespace {
// The reference: the 8 corners read through Grid::clamped, the formula written out once more.
float trilinear_reference(const Grid<float>& g, Vec3d p) {
    const Vec3i d = g.dims();
    const double x = std::clamp(p.x, 0.0, d.x - 1.0), y = std::clamp(p.y, 0.0, d.y - 1.0), z = std::clamp(p.z, 0.0, d.z - 1.0);
    const Vec3i c{std::min(static_cast<int>(x), std::max(d.x - 2, 0)), std::min(static_cast<int>(y), std::max(d.y - 2, 0)),
                  std::min(static_cast<int>(z), std::max(d.z - 2, 0))};
    const double fx = x - c.x, fy = y - c.y, fz = z - c.z;
    const auto v = [&](int i, int j, int k) { return static_cast<double>(g.clamped(c + Vec3i{i, j, k})); };
    const double c0 = (v(0, 0, 0) * (1 - fx) + v(1, 0, 0) * fx) * (1 - fy) + (v(0, 1, 0) * (1 - fx) + v(1, 1, 0) * fx) * fy;
    const double c1 = (v(0, 0, 1) * (1 - fx) + v(1, 0, 1) * fx) * (1 - fy) + (v(0, 1, 1) * (1 - fx) + v(1, 1, 1) * fx) * fy;
    return static_cast<float>(c0 * (1 - fz) + c1 * fz);
}
}  // namespace

// The direct-read path (every dimension ≥ 2) and the clamped one (a dimension of 1) give the
// reference's bits everywhere: inside, on the last cell, on the border and outside the lattice.
TEST(Sampling, TrilinearMatchesTheClampedReferenceBitwise) {
    for (const Vec3i dims : {Vec3i{8, 7, 6}, Vec3i{2, 2, 2}, Vec3i{1, 5, 4}, Vec3i{5, 1, 1}, Vec3i{1, 1, 1}}) {
        Grid<float> g{Lattice(dims)};
        std::uint32_t h = 12345u;
        for (float& v : g.values()) {
            h = h * 1664525u + 1013904223u;
            v = static_cast<float>(h >> 8) / 65536.0f - 128.0f;  // irregular values: any corner mix-up shows
        }
        int checked = 0;
        for (double z = -1.25; z <= dims.z + 0.5; z += 0.375)
            for (double y = -1.5; y <= dims.y + 0.5; y += 0.4375)
                for (double x = -0.75; x <= dims.x + 0.5; x += 0.3125) {
                    const float a = trilinear(g, {x, y, z}), b = trilinear_reference(g, {x, y, z});
                    ASSERT_EQ(std::bit_cast<std::uint32_t>(a), std::bit_cast<std::uint32_t>(b))
                        << dims.x << "x" << dims.y << "x" << dims.z << " at " << x << "," << y << "," << z;
                    ++checked;
                }
        EXPECT_GT(checked, 100);
    }
}

TEST(Sampling, CentralGradientOfLinearField) {
    const Grid<float> g = linear_field();
    for (Vec3i p : {Vec3i{3, 3, 3}, Vec3i{0, 0, 0}, Vec3i{7, 7, 7}}) {
        const Vec3f d = central_gradient(g, p);
        EXPECT_NEAR(d.x, 2.0f, 1e-5);
        EXPECT_NEAR(d.y, -3.0f, 1e-5);
        EXPECT_NEAR(d.z, 0.5f, 1e-5);
    }
    const Vec3f di = interpolated_gradient(g, {3.3, 2.2, 4.1});
    EXPECT_NEAR(di.x, 2.0f, 1e-4);
    EXPECT_NEAR(di.y, -3.0f, 1e-4);
}

TEST(Sampling, UpwindGradientPicksTheUpwindSide) {
    // φ = |x - 4| (a kink at x = 4): at the kink the one-sided slopes are -1 (left) and +1 (right).
    Grid<float> g(Lattice({9, 3, 3}));
    for (int z = 0; z < 3; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 9; ++x) g({x, y, z}) = std::abs(x - 4.0f);
    // A minimum (a front point seen as a valley): with F > 0 the viscosity solution
    // φ(x,t) = max over |y-x| <= t of φ0(y) rises at rate 1; with F < 0, φ = min φ0 stays put.
    EXPECT_NEAR(upwind_gradient_norm(g, {4, 1, 1}, +1.0f), 1.0f, 1e-6);
    EXPECT_NEAR(upwind_gradient_norm(g, {4, 1, 1}, -1.0f), 0.0f, 1e-6);
    // Away from the kink both agree with |∇φ| = 1.
    EXPECT_NEAR(upwind_gradient_norm(g, {2, 1, 1}, +1.0f), 1.0f, 1e-6);
    EXPECT_NEAR(upwind_gradient_norm(g, {6, 1, 1}, -1.0f), 1.0f, 1e-6);
}

// central_gradient's unclamped interior path against the clamped one-sided formula written out
// here (the reference) at every point of a random field: the same bits everywhere.
TEST(Sampling, CentralGradientInteriorPathIsBitIdenticalToTheClampedFormula) {
    const Grid<float> g = random_field(7, false);
    const Lattice& lat = g.lattice();
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 6; ++y)
            for (int x = 0; x < 7; ++x) {
                const Vec3i p{x, y, z};
                const Vec3f d = central_gradient(g, p);
                for (int a = 0; a < 3; ++a) {
                    Vec3i lo = p, hi = p;
                    lo[a] = std::max(p[a] - 1, 0);
                    hi[a] = std::min(p[a] + 1, lat.dims()[a] - 1);
                    const float want = (g(hi) - g(lo)) / static_cast<float>(hi[a] - lo[a]);
                    EXPECT_EQ(std::bit_cast<std::uint32_t>(d[a]), std::bit_cast<std::uint32_t>(want)) << p << " axis " << a;
                }
            }
}

// min_of / max_of against std::min / std::max, bit for bit: signed zeros (which one wins a tie
// matters), infinities, and random values.
TEST(Sampling, BranchFreeMinMaxHaveStdMinMaxBits) {
    std::vector<float> v = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, std::numeric_limits<float>::infinity(),
                            -std::numeric_limits<float>::infinity(), 1e-30f, -1e-30f};
    std::uint32_t state = 3;
    for (int n = 0; n < 64; ++n) {
        state = state * 1664525u + 1013904223u;
        v.push_back(static_cast<float>(state >> 8) / static_cast<float>(1u << 24) * 4.0f - 2.0f);
    }
    for (const float a : v)
        for (const float b : v) {
            EXPECT_EQ(std::bit_cast<std::uint32_t>(min_of(a, b)), std::bit_cast<std::uint32_t>(std::min(a, b))) << a << " " << b;
            EXPECT_EQ(std::bit_cast<std::uint32_t>(max_of(a, b)), std::bit_cast<std::uint32_t>(std::max(a, b))) << a << " " << b;
        }
}

// upwind_gradient_norm (unclamped interior path, branch-free one-sided choices) against the Godunov
// formula written out with clamped reads and std::min/std::max, at every point of a field with
// random values and flat runs (zero differences), for both signs of the speed: the same bits.
TEST(Sampling, UpwindGradientHasTheBitsOfTheWrittenOutFormula) {
    const Grid<float> g = random_field(11, true);
    for (const float speed : {0.7f, -0.7f})
        for (int z = 0; z < 5; ++z)
            for (int y = 0; y < 6; ++y)
                for (int x = 0; x < 7; ++x) {
                    const Vec3i p{x, y, z};
                    float sum = 0.0f;
                    for (int a = 0; a < 3; ++a) {
                        Vec3i lo = p, hi = p;
                        lo[a] -= 1;
                        hi[a] += 1;
                        const float dm = g(p) - g.clamped(lo), dp = g.clamped(hi) - g(p);
                        const float a1 = speed > 0 ? std::min(dm, 0.0f) : std::max(dm, 0.0f);
                        const float a2 = speed > 0 ? std::max(dp, 0.0f) : std::min(dp, 0.0f);
                        sum += std::max(a1 * a1, a2 * a2);
                    }
                    const float want = std::sqrt(sum), got = upwind_gradient_norm(g, p, speed);
                    EXPECT_EQ(std::bit_cast<std::uint32_t>(got), std::bit_cast<std::uint32_t>(want)) << p << " speed " << speed;
                }
}
