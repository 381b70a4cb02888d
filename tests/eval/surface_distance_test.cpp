// Surface distances: the exact EDT against brute force, boundary extraction, analytic cases (shifted
// boxes on an anisotropic axis, concentric spheres), the max-of-directed-95th-percentiles HD95
// definition, a brute-force O(n²) reference on random masks, empty masks and bad input.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "eval/mask_shapes.hpp"
#include "liveset/eval/surface_distance.hpp"

using namespace liveset;
using liveset::test::Mask;
using liveset::test::paint_ball_mm;
using liveset::test::paint_box;

namespace {

Mask random_mask(const Lattice& lat, unsigned seed, unsigned percent) {
    std::mt19937 gen(seed);
    Mask m(lat);
    for (auto& v : m.values()) v = (gen() % 100u) < percent ? 1 : 0;
    return m;
}

double distance_mm(const Lattice& lat, PointIndex a, PointIndex b) {
    return norm(hadamard((lat.coord(a) - lat.coord(b)).cast<double>(), lat.spacing()));
}

// Reference boundary test written from the definition, independent of the library's.
bool is_boundary(const Mask& m, Vec3i p) {
    if (m(p) == 0) return false;
    const Vec3i n6[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    for (const Vec3i& o : n6) {
        if (!m.lattice().contains(p + o)) return true;
        if (m(p + o) == 0) return true;
    }
    return false;
}

std::vector<PointIndex> reference_boundary(const Mask& m) {
    std::vector<PointIndex> out;
    for (PointIndex i = 0; i < m.size(); ++i)
        if (is_boundary(m, m.lattice().coord(i))) out.push_back(i);
    return out;
}

std::vector<double> brute_directed(const Lattice& lat, const std::vector<PointIndex>& from,
                                   const std::vector<PointIndex>& to) {
    std::vector<double> out;
    for (PointIndex a : from) {
        double best = std::numeric_limits<double>::infinity();
        for (PointIndex b : to) best = std::min(best, distance_mm(lat, a, b));
        out.push_back(best);
    }
    return out;
}

// numpy.percentile(values, 100·fraction) with the default linear interpolation, via a full sort.
double reference_percentile(std::vector<double> v, double fraction) {
    std::sort(v.begin(), v.end());
    const double rank = fraction * double(v.size() - 1);
    const auto lo = std::size_t(rank);
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    return v[lo] + (rank - double(lo)) * (v[hi] - v[lo]);
}

}  // namespace

TEST(DistanceTransform, MatchesBruteForceWithAnisotropicSpacing) {
    const Lattice lat({13, 9, 7}, {0.7, 1.3, 2.9});
    for (unsigned seed : {1u, 2u, 3u}) {
        const Mask features = random_mask(lat, seed, seed == 3 ? 1 : 8);
        std::vector<PointIndex> sites;
        for (PointIndex i = 0; i < features.size(); ++i)
            if (features[i]) sites.push_back(i);
        ASSERT_FALSE(sites.empty());
        const Grid<double> d2 = squared_distance_transform_mm(features);
        for (PointIndex i = 0; i < features.size(); ++i) {
            double best = std::numeric_limits<double>::infinity();
            for (PointIndex s : sites) best = std::min(best, distance_mm(lat, i, s));
            ASSERT_NEAR(d2[i], best * best, 1e-9 * (1 + best * best)) << "seed " << seed << " voxel " << lat.coord(i);
        }
    }
}

TEST(DistanceTransform, NoFeatureIsInfinite) {
    const Mask none(Lattice({4, 3, 2}));
    const Grid<double> d2 = squared_distance_transform_mm(none);
    for (double v : d2.values()) EXPECT_TRUE(std::isinf(v));
}

TEST(DistanceTransform, SingleSiteGivesExactDistances) {
    const Lattice lat({9, 6, 5}, {0.5, 2.0, 3.0});
    Mask f(lat);
    f({2, 3, 1}) = 1;
    const Grid<double> d2 = squared_distance_transform_mm(f);
    EXPECT_DOUBLE_EQ(d2({2, 3, 1}), 0.0);
    EXPECT_DOUBLE_EQ(d2({8, 3, 1}), 9.0);                     // 6 · 0.5 mm
    EXPECT_DOUBLE_EQ(d2({2, 0, 1}), 36.0);                    // 3 · 2 mm
    EXPECT_DOUBLE_EQ(d2({2, 3, 4}), 81.0);                    // 3 · 3 mm
    EXPECT_DOUBLE_EQ(d2({0, 5, 0}), 1.0 + 16.0 + 9.0);        // (1, 4, 3) mm
}

// The single-precision transform to a mask's outside against a brute force, at anisotropic spacings:
// within a few float ulps.
TEST(DistanceTransform, SinglePrecisionToTheOutsideMatchesBruteForce) {
    const Lattice lat({13, 9, 7}, {0.7, 1.3, 2.9});
    for (unsigned seed : {1u, 2u, 3u}) {
        const Mask mask = random_mask(lat, seed, seed == 3 ? 99 : 92);  // the outside: 1-8 % of the voxels
        std::vector<PointIndex> outside;
        for (PointIndex i = 0; i < mask.size(); ++i)
            if (mask[i] == 0) outside.push_back(i);
        ASSERT_FALSE(outside.empty());
        const Grid<float> d2 = squared_distance_to_outside_mm(mask);
        for (PointIndex i = 0; i < mask.size(); ++i) {
            double best = std::numeric_limits<double>::infinity();
            for (PointIndex s : outside) best = std::min(best, distance_mm(lat, i, s));
            ASSERT_NEAR(d2[i], best * best, 1e-6 * (1 + best * best)) << "seed " << seed << " voxel " << lat.coord(i);
        }
    }
    const Grid<float> none = squared_distance_to_outside_mm(Mask(Lattice({4, 3, 2}), 1));  // no outside
    for (float v : none.values()) EXPECT_TRUE(std::isinf(v));
}

// At integer spacings the single-precision transform gives the double one's values bit for bit
// (depth_mm relies on it for the brain mask's same bits), on masks whose depths reach far past the
// lattice's short sides: blobs, sparse and dense noise, one outside voxel in a long lattice along
// each axis, two in a wide one.
TEST(DistanceTransform, SinglePrecisionAtIntegerSpacingsIsTheDoubleTransform) {
    std::mt19937 gen(7);
    const auto complement = [](const Mask& m) {
        Mask c(m.lattice());
        for (PointIndex i = 0; i < m.size(); ++i) c[i] = m[i] == 0;
        return c;
    };
    const auto check = [&](const Mask& mask, const char* what) {
        const Grid<float> f = squared_distance_to_outside_mm(mask);
        const Grid<double> d = squared_distance_transform_mm(complement(mask));
        std::size_t inside = 0;
        for (PointIndex i = 0; i < mask.size(); ++i) {
            inside += mask[i] != 0;
            ASSERT_EQ(f[i], static_cast<float>(d[i])) << what << " " << mask.lattice().spacing() << " at " << mask.lattice().coord(i);
            ASSERT_EQ(d[i], std::floor(d[i])) << what;  // integers: the premise
        }
        EXPECT_GT(inside, 0u) << what;
    };
    for (const Vec3d spacing : {Vec3d{1, 1, 1}, Vec3d{1, 2, 3}, Vec3d{2, 1, 1}}) {
        const Lattice lat({61, 47, 33}, spacing);
        Mask blobs(lat, 1);  // a few holes: depths up to tens of voxels
        for (int k = 0; k < 6; ++k) paint_ball_mm(blobs, {gen() % 61 * spacing.x, gen() % 47 * spacing.y, gen() % 33 * spacing.z}, 3.0, 0);
        check(blobs, "blobs");
        for (unsigned per_mille : {500u, 970u, 999u}) {  // the share inside
            Mask noise(lat);
            for (auto& v : noise.values()) v = (gen() % 1000u) < per_mille ? 1 : 0;
            check(noise, "noise");
        }
    }
    // Long lines along each axis at 3 mm (the y and z passes' envelopes over 601 points, depths to
    // 1 800 mm), and a case whose break points a float computation moved (a helper's review found
    // 1 793 818 against 1 793 817 mm² there when the passes computed in float).
    for (const Vec3i dims : {Vec3i{601, 3, 2}, Vec3i{3, 601, 2}, Vec3i{2, 3, 601}}) {
        Mask line(Lattice(dims, {3, 3, 3}), 1);
        line({0, 0, 0}) = 0;
        check(line, "line");
    }
    Mask far(Lattice({1300, 1400, 1}, {1, 3, 1}), 1);
    far({6, 1199, 0}) = 0;
    far({353, 1391, 0}) = 0;
    check(far, "far");
}

TEST(Boundary, InteriorVoxelsAreExcludedAndImageBorderCounts) {
    const Lattice lat({7, 7, 7});
    Mask m(lat);
    paint_box(m, {1, 1, 1}, {6, 6, 6});  // 5³ box: 125 - 3³ interior = 98 boundary voxels
    EXPECT_EQ(boundary_voxels(m).size(), 98u);
    EXPECT_EQ(boundary_voxels(m), reference_boundary(m));

    Mask full(lat, 1);  // every voxel on the image border is boundary: 343 - 5³
    EXPECT_EQ(boundary_voxels(full).size(), 343u - 125u);

    const Mask random = random_mask(Lattice({10, 8, 6}), 11, 60);
    EXPECT_EQ(boundary_voxels(random), reference_boundary(random));
}

TEST(SurfaceDistance, IdenticalMasksAreZero) {
    const Lattice lat({12, 12, 12}, {0.9, 1.1, 2.0});
    Mask m(lat);
    paint_ball_mm(m, {6, 6, 6}, 7.0);
    const SurfaceDistance d = surface_distance(m, m);
    EXPECT_DOUBLE_EQ(d.hausdorff_mm, 0.0);
    EXPECT_DOUBLE_EQ(d.hausdorff95_mm, 0.0);
    EXPECT_DOUBLE_EQ(d.mean_mm, 0.0);
}

TEST(SurfaceDistance, BoxesShiftedAlongAnisotropicAxisGiveExactHausdorff) {
    const Lattice lat({16, 16, 20}, {0.5, 0.7, 2.5});
    for (int k = 1; k <= 4; ++k) {
        Mask a(lat), b(lat);
        paint_box(a, {3, 3, 3}, {13, 13, 11});
        paint_box(b, {3, 3, 3 + k}, {13, 13, 11 + k});
        const SurfaceDistance d = surface_distance(a, b);
        EXPECT_DOUBLE_EQ(d.hausdorff_mm, k * 2.5) << "k=" << k;
        EXPECT_LE(d.hausdorff95_mm, d.hausdorff_mm);
        EXPECT_GT(d.mean_mm, 0.0);
        EXPECT_LT(d.mean_mm, d.hausdorff_mm);
    }
    // Same shift along the fine x axis: k · 0.5 mm.
    Mask a(lat), b(lat);
    paint_box(a, {3, 3, 3}, {10, 13, 11});
    paint_box(b, {6, 3, 3}, {13, 13, 11});
    EXPECT_DOUBLE_EQ(surface_distance(a, b).hausdorff_mm, 1.5);
}

TEST(SurfaceDistance, ConcentricSpheresAreRadiusDifferenceApart) {
    const Lattice lat({40, 36, 30}, {0.8, 1.0, 1.25});
    const Vec3d centre{19.5, 17.5, 14.5};  // in index units
    Mask inner(lat), outer(lat);
    paint_ball_mm(inner, centre, 10.0);
    paint_ball_mm(outer, centre, 15.0);
    const SurfaceDistance d = surface_distance(inner, outer);
    const double voxel = 1.25;  // the coarsest spacing
    EXPECT_NEAR(d.hausdorff_mm, 5.0, voxel);
    EXPECT_NEAR(d.hausdorff95_mm, 5.0, voxel);
    EXPECT_NEAR(d.mean_mm, 5.0, 0.5 * voxel);
    EXPECT_LE(d.hausdorff95_mm, d.hausdorff_mm);
    // Symmetric in its arguments.
    const SurfaceDistance r = surface_distance(outer, inner);
    EXPECT_DOUBLE_EQ(r.hausdorff_mm, d.hausdorff_mm);
    EXPECT_DOUBLE_EQ(r.hausdorff95_mm, d.hausdorff95_mm);
    EXPECT_NEAR(r.mean_mm, d.mean_mm, 1e-12);
}

TEST(SurfaceDistance, Hd95IsTheMaxOfTheDirectedPercentilesNotThePooledOne) {
    // mask: a 6³ box (152 boundary voxels). truth: the same box plus 12 isolated voxels hovering
    // d = 3 voxels above its top face, each exactly 3·1.5 mm from the box surface. Truth→mask then has
    // 12 of 164 distances (7.3%) at 4.5 mm, so its 95th percentile is 4.5 mm; the pooled 316
    // distances hold only 3.8% non-zero values, so a pooled 95th percentile would be 0.
    const Lattice lat({12, 14, 12}, {1.0, 1.5, 0.8});
    Mask mask(lat), truth(lat);
    paint_box(mask, {2, 2, 2}, {8, 8, 8});  // top face at y = 7
    paint_box(truth, {2, 2, 2}, {8, 8, 8});
    for (int x = 2; x < 8; ++x) {
        truth({x, 10, 3}) = 1;
        truth({x, 10, 6}) = 1;
    }
    ASSERT_EQ(boundary_voxels(mask).size(), 152u);
    ASSERT_EQ(boundary_voxels(truth).size(), 164u);
    const SurfaceDistance d = surface_distance(mask, truth);
    EXPECT_DOUBLE_EQ(d.hausdorff_mm, 4.5);
    EXPECT_DOUBLE_EQ(d.hausdorff95_mm, 4.5);
    EXPECT_DOUBLE_EQ(d.mean_mm, 12 * 4.5 / (152 + 164));
}

TEST(SurfaceDistance, Hd95InterpolatesBetweenOrderStatistics) {
    // mask: one voxel; truth: a line of 11 voxels starting at it, 2 mm apart. Truth→mask distances
    // are 0, 2, ..., 20 mm, so the 95th percentile sits at rank 0.95·10 = 9.5: 19 mm (the lower
    // order statistic alone would give 18). Mask→truth is a single 0.
    const Lattice lat({14, 3, 3}, {2.0, 1.0, 1.0});
    Mask mask(lat), truth(lat);
    mask({1, 1, 1}) = 1;
    paint_box(truth, {1, 1, 1}, {12, 2, 2});
    const SurfaceDistance d = surface_distance(mask, truth);
    EXPECT_DOUBLE_EQ(d.hausdorff_mm, 20.0);
    EXPECT_DOUBLE_EQ(d.hausdorff95_mm, 19.0);
    EXPECT_DOUBLE_EQ(d.mean_mm, 110.0 / 12.0);
}

TEST(SurfaceDistance, Hd95IgnoresASmallOutlier) {
    const Lattice lat({20, 10, 10}, {1.0, 1.0, 2.0});
    Mask mask(lat), truth(lat);
    paint_box(mask, {1, 2, 2}, {7, 8, 8});
    paint_box(truth, {1, 2, 2}, {7, 8, 8});
    truth({17, 5, 5}) = 1;  // one stray voxel 11 voxels beyond the box's far face at x = 6
    const SurfaceDistance d = surface_distance(mask, truth);
    EXPECT_DOUBLE_EQ(d.hausdorff_mm, 11.0);
    EXPECT_DOUBLE_EQ(d.hausdorff95_mm, 0.0);
    EXPECT_DOUBLE_EQ(d.mean_mm, 11.0 / (152 + 153));
}

TEST(SurfaceDistance, MatchesBruteForceReferenceOnRandomMasks) {
    const Lattice lat({11, 9, 7}, {0.9, 1.3, 2.1});
    for (unsigned seed = 0; seed < 4; ++seed) {
        const Mask mask = random_mask(lat, 100 + seed, 30);
        const Mask truth = random_mask(lat, 200 + seed, 15 + 10 * seed);
        const std::vector<PointIndex> bm = reference_boundary(mask);
        const std::vector<PointIndex> bt = reference_boundary(truth);
        const std::vector<double> m2t = brute_directed(lat, bm, bt);
        const std::vector<double> t2m = brute_directed(lat, bt, bm);
        const double hd = std::max(*std::max_element(m2t.begin(), m2t.end()), *std::max_element(t2m.begin(), t2m.end()));
        const double hd95 = std::max(reference_percentile(m2t, 0.95), reference_percentile(t2m, 0.95));
        double sum = 0;
        for (double v : m2t) sum += v;
        for (double v : t2m) sum += v;
        const double mean = sum / double(m2t.size() + t2m.size());

        const SurfaceDistance d = surface_distance(mask, truth);
        EXPECT_NEAR(d.hausdorff_mm, hd, 1e-9) << "seed " << seed;
        EXPECT_NEAR(d.hausdorff95_mm, hd95, 1e-9) << "seed " << seed;
        EXPECT_NEAR(d.mean_mm, mean, 1e-9) << "seed " << seed;
        EXPECT_GT(d.hausdorff_mm, 0.0);
    }
}

TEST(SurfaceDistance, ResultDoesNotDependOnThreadCount) {
    const Lattice lat({48, 40, 36}, {0.7, 1.0, 1.9});
    Mask mask(lat), truth(lat);
    paint_ball_mm(mask, {22, 20, 17}, 14.0);
    paint_ball_mm(truth, {25, 19, 18}, 12.0);
    const SurfaceDistance parallel = surface_distance(mask, truth);
    SurfaceDistance serial;
    {
        tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
        serial = surface_distance(mask, truth);
    }
    EXPECT_EQ(parallel.hausdorff_mm, serial.hausdorff_mm);
    EXPECT_EQ(parallel.hausdorff95_mm, serial.hausdorff95_mm);
    EXPECT_EQ(parallel.mean_mm, serial.mean_mm);
}

TEST(SurfaceDistance, EmptyMaskGivesNaN) {
    const Lattice lat({6, 6, 6});
    Mask empty(lat), box(lat);
    paint_box(box, {1, 1, 1}, {4, 4, 4});
    for (const SurfaceDistance& d : {surface_distance(empty, box), surface_distance(box, empty),
                                     surface_distance(empty, empty)}) {
        EXPECT_TRUE(std::isnan(d.hausdorff_mm));
        EXPECT_TRUE(std::isnan(d.hausdorff95_mm));
        EXPECT_TRUE(std::isnan(d.mean_mm));
    }
}

TEST(SurfaceDistance, RejectsDifferentLattices) {
    Mask a(Lattice({6, 6, 6})), b(Lattice({6, 7, 6})), c(Lattice({6, 6, 6}, {1, 2, 1}));
    paint_box(a, {1, 1, 1}, {3, 3, 3});
    paint_box(b, {1, 1, 1}, {3, 3, 3});
    paint_box(c, {1, 1, 1}, {3, 3, 3});
    EXPECT_THROW(surface_distance(a, b), std::invalid_argument);
    EXPECT_THROW(surface_distance(a, c), std::invalid_argument);
}
