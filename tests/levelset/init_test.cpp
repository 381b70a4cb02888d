// Sparse-field initialisation: from signed distances, masks and seeds; invariants; bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <tbb/global_control.h>

#include "levelset_test_util.hpp"
#include "liveset/levelset/shapes.hpp"

using namespace liveset;
using liveset::testing::expect_valid;

TEST(SparseFieldInit, SphereHasValidLayersAndTheRightVolume) {
    for (int layers : {1, 2, 3}) {
        SparseField f(Lattice({48, 48, 48}), layers);
        f.init_from_sdf(shapes::Sphere({23.5, 23.5, 23.5}, 15.0));
        expect_valid(f, "sphere");
        EXPECT_GT(f.zero_layer().size(), 1000u);
        for (int k = -layers; k <= layers; ++k) EXPECT_FALSE(f.layer(k).empty()) << k;
        const double v = enclosed_volume(f);
        const double exact = 4.0 / 3.0 * std::numbers::pi * 15.0 * 15.0 * 15.0;
        EXPECT_NEAR(v / exact, 1.0, 0.01);
        // Zero-layer values are the exact distances.
        for (PointIndex i : f.zero_layer()) {
            const Vec3d p = f.lattice().coord(i).cast<double>();
            EXPECT_NEAR(f.phi()[i], norm(p - Vec3d{23.5, 23.5, 23.5}) - 15.0, 1e-5);
        }
    }
}

TEST(SparseFieldInit, FromMaskPutsTheFrontHalfwayBetweenVoxels) {
    Grid<std::uint8_t> mask(Lattice({20, 20, 20}), 0);
    for (int z = 5; z < 15; ++z)
        for (int y = 5; y < 15; ++y)
            for (int x = 5; x < 15; ++x) mask({x, y, z}) = 1;
    SparseField f(mask.lattice(), 2);
    f.init_from_mask(mask);
    expect_valid(f, "mask");
    EXPECT_FLOAT_EQ(f.phi()({5, 10, 10}), -0.5f);
    EXPECT_FLOAT_EQ(f.phi()({4, 10, 10}), 0.5f);
    EXPECT_FLOAT_EQ(f.phi()({3, 10, 10}), 1.5f);
    EXPECT_FLOAT_EQ(f.phi()({6, 10, 10}), -1.5f);
    EXPECT_EQ(f.status()({10, 10, 10}), f.far_inside());
    EXPECT_NEAR(enclosed_volume(f), 1000.0, 1e-9);
}

TEST(SparseFieldInit, SeedSpheresUnion) {
    const Lattice lat({40, 30, 30});
    SparseField f(lat, 2);
    f.init_from_sdf(shapes::SeedSpheres(lat, {shapes::Sphere({10, 15, 15}, 4), shapes::Sphere({30, 15, 15}, 5)}));
    expect_valid(f, "seeds");
    EXPECT_LT(f.phi()({10, 15, 15}), 0);
    EXPECT_LT(f.phi()({30, 15, 15}), 0);
    EXPECT_GT(f.phi()({20, 15, 15}), 0);
}

TEST(SparseFieldInit, SteepFunctionStillGetsAClosedFront) {
    // A step function (not a distance) would leave no zero layer; both sides are pulled onto it.
    SparseField f(Lattice({16, 16, 16}), 2);
    f.init_from_sdf([](Vec3d p) { return p.x < 8 ? -10.0 : 10.0; });
    expect_valid(f, "step");
    EXPECT_EQ(f.status()({7, 3, 3}), 0);
    EXPECT_EQ(f.status()({8, 3, 3}), 0);
}

TEST(SparseFieldInit, RejectsBadParameters) {
    const Lattice lat({16, 16, 16});
    EXPECT_THROW(SparseField(lat, 0), std::invalid_argument);
    EXPECT_THROW(SparseField(lat, SparseField::kMaxLayers + 1), std::invalid_argument);
    EXPECT_THROW(shapes::Sphere({1, 1, 1}, -2), std::invalid_argument);
    EXPECT_THROW(shapes::Sphere({1, NAN, 1}, 2), std::invalid_argument);
    EXPECT_THROW(shapes::Box({1, 1, 1}, {1, 0, 1}), std::invalid_argument);
    EXPECT_THROW(shapes::SeedSpheres(lat, {shapes::Sphere({20, 1, 1}, 2)}), std::invalid_argument);
    EXPECT_THROW(shapes::SeedSpheres(lat, {}), std::invalid_argument);
    SparseField f(lat, 2);
    EXPECT_THROW(f.init_from_sdf([](Vec3d) { return NAN; }), std::invalid_argument);
    Grid<std::uint8_t> wrong(Lattice({8, 8, 8}), 0);
    EXPECT_THROW(f.init_from_mask(wrong), std::invalid_argument);
}

TEST(SparseFieldInit, AThrowingInitialisationLeavesTheFieldAsItWas) {
    // Strong guarantee: a signed distance that is not finite somewhere, or that throws, is refused
    // before anything of the field changes — φ, statuses and layers are those of the sphere before.
    const Lattice lat({20, 20, 20});
    SparseField f(lat, 2);
    f.init_from_sdf(shapes::Sphere({10, 10, 10}, 5));
    const std::vector<float> phi(f.phi().values().begin(), f.phi().values().end());
    const std::vector<std::int8_t> status(f.status().values().begin(), f.status().values().end());
    const std::size_t zero = f.zero_layer().size();
    ASSERT_GT(zero, 0u);
    const auto nan_at_corner = [](Vec3d p) { return p.x == 19 && p.y == 19 && p.z == 19 ? NAN : p.x - 10.0; };
    const auto throws = [](Vec3d p) -> double {
        if (p.z > 15) throw std::invalid_argument("refused by the caller");
        return p.x - 10.0;
    };
    EXPECT_THROW(f.init_from_sdf(nan_at_corner), std::invalid_argument);
    EXPECT_THROW(f.init_from_sdf(throws), std::invalid_argument);
    expect_valid(f, "after the refused initialisations");
    EXPECT_TRUE(std::equal(phi.begin(), phi.end(), f.phi().values().begin()));
    EXPECT_TRUE(std::equal(status.begin(), status.end(), f.status().values().begin()));
    EXPECT_EQ(f.zero_layer().size(), zero);
}

// init_from_sdf(sdf, lo, hi) evaluates only the box, where sdf ≥ N + 1 outside it: the same φ,
// statuses and list order as evaluating the whole lattice. Seed spheres (one clipped by a corner
// of the lattice, overlapping pairs, N = 1..3), and a step function whose sign change lies on the
// box's faces, so that the points pulled onto the zero layer lie just outside the box.
TEST(SparseFieldInit, InABoxHasTheBitsOfTheWholeLattice) {
    const Lattice lat({37, 29, 31});
    const std::vector<shapes::Sphere> spheres = {shapes::Sphere({1.5, 2.0, 0.5}, 3.0), shapes::Sphere({20.2, 14.7, 15.1}, 4.4),
                                                 shapes::Sphere({24.0, 15.0, 16.0}, 2.5), shapes::Sphere({30.0, 20.0, 9.0}, 0.5)};
    for (int layers : {1, 2, 3}) {
        const shapes::SeedSpheres sdf(lat, spheres);
        const double reach = layers + 1.0;
        Vec3i lo{1000, 1000, 1000}, hi{-1000, -1000, -1000};
        for (const shapes::Sphere& s : spheres)
            for (int a = 0; a < 3; ++a) {
                lo[a] = std::min(lo[a], static_cast<int>(std::floor(s.center[a] - s.radius - reach)));
                hi[a] = std::max(hi[a], static_cast<int>(std::ceil(s.center[a] + s.radius + reach)));
            }
        SparseField whole(lat, layers), boxed(lat, layers);
        whole.init_from_sdf(sdf);
        boxed.init_from_sdf(shapes::Sphere({18, 14, 15}, 6));  // an earlier front, replaced
        boxed.init_from_sdf(sdf, lo, hi);
        EXPECT_TRUE(liveset::testing::same_state(whole, boxed)) << "layers " << layers;
        liveset::testing::expect_same_list_order(whole, boxed);
        expect_valid(boxed, "seeds in a box");
    }
    const auto step = [](Vec3d p) { return p.x >= 10 && p.x <= 20 && p.y >= 8 && p.y <= 18 && p.z >= 5 && p.z <= 25 ? -10.0 : 10.0; };
    SparseField whole(lat, 2), boxed(lat, 2);
    whole.init_from_sdf(step);
    boxed.init_from_sdf(step, {10, 8, 5}, {20, 18, 25});
    EXPECT_TRUE(liveset::testing::same_state(whole, boxed));
    liveset::testing::expect_same_list_order(whole, boxed);
    EXPECT_EQ(boxed.status()({9, 12, 12}), 0);  // pulled onto the zero layer from outside the box
    expect_valid(boxed, "step in a box");
    // A value that is not finite inside the box is refused before anything changes.
    EXPECT_THROW(boxed.init_from_sdf([](Vec3d p) { return p.x == 12 ? NAN : 10.0; }, {10, 8, 5}, {20, 18, 25}),
                 std::invalid_argument);
    EXPECT_TRUE(liveset::testing::same_state(whole, boxed));
}

// init_from_mask writes φ straight from the mask, its whole-box passes plane by plane in parallel:
// the same φ, statuses and list order as init_from_sdf of the mask's distance written as a
// function (±½ at a voxel with a neighbour across the boundary, ±(N + 1) elsewhere), on 1 and 2
// threads. A random mask: specks, one-voxel sheets and the lattice's faces.
TEST(SparseFieldInit, FromMaskHasTheBitsOfItsDistanceFunctionOnAnyThreadCount) {
    Grid<std::uint8_t> mask(Lattice({33, 27, 30}), 0);
    std::mt19937 rng(11);
    for (std::size_t i = 0; i < mask.size(); ++i) mask[static_cast<PointIndex>(i)] = rng() % 7 < 3;
    for (int z = 0; z < 30; ++z)
        for (int y = 0; y < 27; ++y)
            for (int x = 0; x < 33; ++x)
                if (x > 8 && x < 24 && y > 5 && y < 20 && z > 4 && z < 25) mask({x, y, z}) = x != 16;  // a block cut by a sheet
    const Lattice& lat = mask.lattice();
    for (int layers : {1, 2, 3}) {
        SparseField reference(lat, layers);
        reference.init_from_sdf([&](Vec3d p) {
            const Vec3i c = p.cast<int>();
            const bool inside = mask(c) != 0;
            bool boundary = false;
            for (const Vec3i o : {Vec3i{1, 0, 0}, Vec3i{-1, 0, 0}, Vec3i{0, 1, 0}, Vec3i{0, -1, 0}, Vec3i{0, 0, 1}, Vec3i{0, 0, -1}})
                if (lat.contains(c + o) && (mask(c + o) != 0) != inside) boundary = true;
            return boundary ? (inside ? -0.5 : 0.5) : (inside ? -(layers + 1.0) : layers + 1.0);
        });
        for (int threads : {1, 2}) {
            const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
            SparseField f(lat, layers);
            f.init_from_sdf(shapes::Sphere({16, 13, 15}, 5));  // an earlier front, replaced
            f.init_from_mask(mask);
            EXPECT_TRUE(liveset::testing::same_state(reference, f)) << "layers " << layers << ", threads " << threads;
            liveset::testing::expect_same_list_order(reference, f);
            expect_valid(f, "random mask");
        }
    }
}
