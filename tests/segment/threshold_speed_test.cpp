// The paper's threshold speed: D at analytic points, F's split into propagation and curvature,
// and the region of interest.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "liveset/levelset/shapes.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/segment/threshold_speed.hpp"

using namespace liveset;

TEST(ThresholdTerm, MatchesEquation3) {
    const ThresholdParams p{0.5, 0.1, 2.0, 0.2};
    EXPECT_DOUBLE_EQ(threshold_term(0.5, p), -1.0);                 // at the ideal value
    EXPECT_NEAR(threshold_term(0.6, p), 0.0, 1e-12);                // at the window edge
    EXPECT_NEAR(threshold_term(0.4, p), 0.0, 1e-12);
    const double d = 0.3;  // |µ − I| = 0.3: 2·0.09/(0.01 + 0.09) − 1 = 0.8
    EXPECT_NEAR(threshold_term(0.8, p), 2 * d * d / (0.01 + d * d) - 1, 1e-12);
    EXPECT_NEAR(threshold_term(0.8, p), 0.8, 1e-12);
    EXPECT_LT(threshold_term(0.55, p), 0.0);
    EXPECT_GT(threshold_term(0.65, p), 0.0);
    // Steeper n: closer to a step.
    const ThresholdParams steep{0.5, 0.1, 16.0, 0.2};
    EXPECT_LT(threshold_term(0.59, steep), threshold_term(0.59, p));
    EXPECT_GT(threshold_term(0.61, steep), threshold_term(0.61, p));
    EXPECT_DOUBLE_EQ(threshold_term(1.0, ThresholdParams{0.0, 1e-6, 100.0, 0.0}), 1.0);  // overflow -> limit
}

TEST(ThresholdParams, Validation) {
    EXPECT_NO_THROW(validate(ThresholdParams{}));
    EXPECT_THROW(validate(ThresholdParams{0.5, 0.0, 2, 0.2}), std::invalid_argument);
    EXPECT_THROW(validate(ThresholdParams{0.5, -1, 2, 0.2}), std::invalid_argument);
    EXPECT_THROW(validate(ThresholdParams{0.5, 0.1, 0, 0.2}), std::invalid_argument);
    EXPECT_THROW(validate(ThresholdParams{0.5, 0.1, 2, 1.0}), std::invalid_argument);
    EXPECT_THROW(validate(ThresholdParams{1.5, 0.1, 2, 0.2}), std::invalid_argument);
    EXPECT_THROW(validate(ThresholdParams{std::nan(""), 0.1, 2, 0.2}), std::invalid_argument);
}

TEST(ThresholdSpeed, PropagationCurvatureAndRoi) {
    const Lattice lat({32, 32, 32});
    Grid<float> img(lat, 0.5f);
    img({3, 3, 3}) = 0.9f;
    Grid<std::uint8_t> roi(lat, 1);
    roi({4, 4, 4}) = 0;
    const ThresholdParams p{0.5, 0.1, 2.0, 0.3};
    const ThresholdSpeed speed(img, p, &roi);
    EXPECT_FLOAT_EQ(speed.curvature_weight(), 0.15f);
    EXPECT_FLOAT_EQ(speed.propagation({10, 10, 10}), static_cast<float>(0.5 * 0.7 * -1.0));
    EXPECT_FLOAT_EQ(speed.propagation({3, 3, 3}), static_cast<float>(0.35 * threshold_term(0.9, p)));
    EXPECT_FLOAT_EQ(speed.propagation({4, 4, 4}), 0.5f);

    SparseField f(lat, 2);
    f.init_from_sdf(shapes::Sphere({16, 16, 16}, 8.0));
    const PointIndex z0 = f.zero_layer()[0];
    const Vec3i q = lat.coord(z0);
    const SpeedSample s = speed.at(f.phi(), q);
    EXPECT_FLOAT_EQ(s.propagation, -0.35f);
    EXPECT_FLOAT_EQ(s.curvature, 0.15f * mean_curvature(f.phi(), q));
    EXPECT_GT(s.curvature, 0.0f);  // convex sphere

    Grid<std::uint8_t> wrong(Lattice({8, 8, 8}), 1);
    EXPECT_THROW(ThresholdSpeed(img, p, &wrong), std::invalid_argument);
    EXPECT_THROW(ThresholdSpeed(img, ThresholdParams{0.5, -0.1, 2, 0.3}), std::invalid_argument);
}

// The thin-front rule's sign table (2 bits a voxel) against the sign of the propagation part at
// every voxel of a lattice whose size is no multiple of four: inside and outside the window, on
// its edge (D exactly 0: |µ − I| = ε), outside the ROI (+½), and against Speed's own default,
// which asks at(). Asked in a scrambled order (as the rule's scattered points), in batches shorter
// and longer than the distance it fetches ahead.
TEST(ThresholdSpeed, PropagationSignIsThePropagationsSignAtEveryVoxel) {
    // 105 voxels, and 144 050 (the table built in several parallel chunks, the last byte partial).
    for (const Vec3i dims : {Vec3i{7, 5, 3}, Vec3i{67, 43, 50}}) {
        const Lattice lat(dims);
        Grid<float> img(lat, 0.0f);
        Grid<std::uint8_t> roi(lat, 1);
        const float levels[4] = {0.5f, 0.75f, 0.9f, 0.3f};  // inside, on the edge, outside, inside
        for (PointIndex i = 0; i < lat.size(); ++i) {
            img[i] = levels[(i * 7u + i / 13u) % 4u];
            if (i % 5u == 3u) roi[i] = 0;
        }
        const ThresholdParams p{0.5, 0.25, 4.0, 0.2};
        const ThresholdSpeed speed(img, p, &roi);
        const Grid<float> phi(lat, 1.0f);
        // Every voxel once, scrambled: 97 is coprime to both sizes (3·5·7 and 2·5²·43·67).
        std::vector<PointIndex> order(lat.size());
        for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<PointIndex>(k * 97 % lat.size());
        std::vector<std::int8_t> sign(order.size(), 9), by_default(order.size(), 9);
        for (std::size_t b = 0, len = 1; b < order.size(); b += len, len = len * 3 + 1) {
            const std::size_t e = std::min(order.size(), b + len);
            speed.propagation_signs(phi, std::span(order).subspan(b, e - b), std::span(sign).subspan(b, e - b));
        }
        if (lat.size() < 1000) speed.Speed::propagation_signs(phi, order, by_default);  // at(), with the curvature
        int seen[3] = {0, 0, 0}, wrong = 0;
        for (std::size_t k = 0; k < order.size(); ++k) {
            const float f = speed.propagation(lat.coord(order[k]));
            const int want = static_cast<int>(f > 0.0f) - static_cast<int>(f < 0.0f);
            wrong += sign[k] != want ? 1 : 0;
            if (lat.size() < 1000) {
                EXPECT_EQ(by_default[k], want) << "voxel " << order[k];
            }
            ++seen[want + 1];
        }
        EXPECT_EQ(wrong, 0) << lat.size() << " voxels";
        for (const int n : seen) EXPECT_GT(n, 0);  // each sign occurs
    }
}

// The batched rates (curvature, central and upwind |∇φ| four stencils at a time) against Speed's
// formula sample by sample, bit for bit: random φ and image, a ROI with holes, every point (the
// border's one-sided stencils included), in a scrambled order; and φ on plateaus (values in
// steps of 0.5), where one-sided differences are exactly ±0 and the upwind picks between zeros. On a
// 1 mm lattice and an anisotropic one (the curvature per mm: the batch's scaled kernel).
TEST(ThresholdSpeed, BatchedRatesHaveTheBitsOfTheFormula) {
    for (const Vec3d h : {Vec3d{1, 1, 1}, Vec3d{0.9375, 0.9375, 1.2}}) {
        SCOPED_TRACE(h.z);
        const Lattice lat({11, 9, 8}, h);
        Grid<float> phi(lat), img(lat);
        Grid<std::uint8_t> roi(lat, 1);
        std::uint32_t state = 7;
        const auto next = [&] {
            state = state * 1664525u + 1013904223u;
            return static_cast<float>(state >> 8) / static_cast<float>(1u << 24);
        };
        for (std::size_t n = 0; n < phi.size(); ++n) {
            const auto i = static_cast<PointIndex>(n);
            phi[i] = next() * 4.0f - 2.0f;
            img[i] = next();
            if (next() < 0.2f) roi[i] = 0;
        }
        Grid<float> plateaus(lat);
        for (std::size_t n = 0; n < phi.size(); ++n) plateaus[static_cast<PointIndex>(n)] = std::round(next() * 4.0f) * 0.5f - 1.0f;
        const ThresholdParams params{0.5, 0.2, 2.0, 0.3};
        std::vector<PointIndex> points(phi.size());
        for (std::size_t n = 0; n < points.size(); ++n) points[n] = static_cast<PointIndex>((n * 37) % points.size());
        const Grid<std::uint8_t>* const masks[] = {nullptr, &roi};
        for (const bool flat : {false, true}) {
            if (flat) phi = plateaus;
            for (const Grid<std::uint8_t>* mask : masks) {
                const ThresholdSpeed speed(img, params, mask);
                std::vector<double> rates(points.size());
                speed.rates(phi, points, rates);
                for (std::size_t n = 0; n < points.size(); ++n) {
                    const Vec3i p = lat.coord(points[n]);
                    const double want = rate_of(speed.at(phi, p), phi, p);
                    ASSERT_EQ(std::bit_cast<std::uint64_t>(rates[n]), std::bit_cast<std::uint64_t>(want))
                        << (flat ? "plateaus " : "") << p.x << "," << p.y << "," << p.z;
                }
            }
        }
    }
}
