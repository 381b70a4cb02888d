// Overlap scores: exact Dice/Jaccard/volume difference of boxes, mm³ volumes with anisotropic spacing,
// the empty-mask conventions and rejection of masks on different lattices.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "eval/mask_shapes.hpp"
#include "liveset/eval/overlap.hpp"

using namespace liveset;
using liveset::test::Mask;
using liveset::test::paint_box;

TEST(Overlap, TwoBoxesWithKnownOverlap) {
    const Lattice lat({12, 8, 8});
    Mask mask(lat), truth(lat);
    paint_box(mask, {2, 2, 2}, {6, 6, 6});    // 4x4x4 = 64 voxels
    paint_box(truth, {4, 2, 2}, {10, 6, 6});  // 6x4x4 = 96 voxels, overlap x in [4,6): 32
    const OverlapMetrics m = compare_overlap(mask, truth);
    EXPECT_EQ(m.mask_voxels, 64u);
    EXPECT_EQ(m.truth_voxels, 96u);
    EXPECT_EQ(m.intersection_voxels, 32u);
    EXPECT_DOUBLE_EQ(m.dice, 2.0 * 32 / (64 + 96));  // 0.4
    EXPECT_DOUBLE_EQ(m.jaccard, 32.0 / 128.0);       // 0.25
    EXPECT_DOUBLE_EQ(m.volume_difference, (64.0 - 96.0) / 96.0);
    EXPECT_DOUBLE_EQ(m.mask_volume_mm3, 64.0);
    EXPECT_DOUBLE_EQ(m.truth_volume_mm3, 96.0);

    // Swapping the roles flips the sign of the volume difference only.
    const OverlapMetrics r = compare_overlap(truth, mask);
    EXPECT_DOUBLE_EQ(r.dice, m.dice);
    EXPECT_DOUBLE_EQ(r.jaccard, m.jaccard);
    EXPECT_DOUBLE_EQ(r.volume_difference, (96.0 - 64.0) / 64.0);
}

TEST(Overlap, AnyNonzeroValueIsForeground) {
    const Lattice lat({6, 6, 6});
    Mask mask(lat), truth(lat);
    paint_box(mask, {1, 1, 1}, {4, 4, 4}, 255);
    paint_box(truth, {1, 1, 1}, {4, 4, 4}, 7);
    const OverlapMetrics m = compare_overlap(mask, truth);
    EXPECT_EQ(m.intersection_voxels, 27u);
    EXPECT_DOUBLE_EQ(m.dice, 1.0);
    EXPECT_DOUBLE_EQ(m.jaccard, 1.0);
    EXPECT_DOUBLE_EQ(m.volume_difference, 0.0);
}

TEST(Overlap, VolumesUseAnisotropicSpacing) {
    const Lattice lat({10, 10, 10}, {0.5, 2.0, 3.0}, {-4, 7, 1});
    Mask mask(lat), truth(lat);
    paint_box(mask, {0, 0, 0}, {4, 4, 4});   // 64 voxels of 3 mm³
    paint_box(truth, {0, 0, 0}, {5, 4, 4});  // 80 voxels
    const OverlapMetrics m = compare_overlap(mask, truth);
    EXPECT_DOUBLE_EQ(m.mask_volume_mm3, 192.0);
    EXPECT_DOUBLE_EQ(m.truth_volume_mm3, 240.0);
    EXPECT_DOUBLE_EQ(m.volume_difference, -0.2);
    EXPECT_DOUBLE_EQ(m.dice, 128.0 / 144.0);
    EXPECT_DOUBLE_EQ(m.jaccard, 64.0 / 80.0);
}

TEST(Overlap, DisjointMasksScoreZero) {
    const Lattice lat({10, 4, 4});
    Mask mask(lat), truth(lat);
    paint_box(mask, {0, 0, 0}, {3, 4, 4});
    paint_box(truth, {5, 0, 0}, {8, 4, 4});
    const OverlapMetrics m = compare_overlap(mask, truth);
    EXPECT_EQ(m.intersection_voxels, 0u);
    EXPECT_DOUBLE_EQ(m.dice, 0.0);
    EXPECT_DOUBLE_EQ(m.jaccard, 0.0);
    EXPECT_DOUBLE_EQ(m.volume_difference, 0.0);
}

TEST(Overlap, EmptyMaskConventions) {
    const Lattice lat({5, 5, 5});
    Mask empty(lat), box(lat);
    paint_box(box, {1, 1, 1}, {3, 3, 3});

    const OverlapMetrics both = compare_overlap(empty, empty);
    EXPECT_DOUBLE_EQ(both.dice, 1.0);
    EXPECT_DOUBLE_EQ(both.jaccard, 1.0);
    EXPECT_DOUBLE_EQ(both.volume_difference, 0.0);

    const OverlapMetrics no_mask = compare_overlap(empty, box);
    EXPECT_DOUBLE_EQ(no_mask.dice, 0.0);
    EXPECT_DOUBLE_EQ(no_mask.jaccard, 0.0);
    EXPECT_DOUBLE_EQ(no_mask.volume_difference, -1.0);

    const OverlapMetrics no_truth = compare_overlap(box, empty);
    EXPECT_DOUBLE_EQ(no_truth.dice, 0.0);
    EXPECT_DOUBLE_EQ(no_truth.jaccard, 0.0);
    EXPECT_TRUE(std::isinf(no_truth.volume_difference) && no_truth.volume_difference > 0);
}

TEST(Overlap, RejectsDifferentLattices) {
    const Mask a(Lattice({8, 8, 8})), b(Lattice({8, 8, 9}));
    EXPECT_THROW(compare_overlap(a, b), std::invalid_argument);
    try {
        compare_overlap(a, b);
        FAIL() << "expected std::invalid_argument";
    } catch (const std::invalid_argument& e) {
        const std::string what = e.what();
        EXPECT_NE(what.find("compare_overlap"), std::string::npos) << what;
        EXPECT_NE(what.find("8x8x8"), std::string::npos) << what;
        EXPECT_NE(what.find("8x8x9"), std::string::npos) << what;
        EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }

    const Mask spaced(Lattice({8, 8, 8}, {1, 1, 1.5}));
    EXPECT_THROW(compare_overlap(a, spaced), std::invalid_argument);
    const Mask shifted(Lattice({8, 8, 8}, {1, 1, 1}, {0, 0, 2}));
    EXPECT_THROW(compare_overlap(a, shifted), std::invalid_argument);
    // Differences below the tolerance (float rounding in image headers) are accepted.
    const Mask nearly(Lattice({8, 8, 8}, {1 + 1e-7, 1, 1}, {1e-6, 0, 0}));
    EXPECT_NO_THROW(compare_overlap(a, nearly));
}
