// Real data: grey matter of the BrainWeb T1 (data/brainweb) segmented with the paper's
// threshold speed inside the brain mask, on a cortical sub-volume so the test stays short (the
// whole-volume figures are in docs/BENCHMARKS.md). Skips when the data is absent.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "liveset/eval/overlap.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/pipeline.hpp"

using namespace liveset;

namespace {

template <class T>
Grid<T> crop(const Grid<T>& g, Vec3i lo, Vec3i size) {
    const Lattice& l = g.lattice();
    const Vec3d o = l.to_world({static_cast<double>(lo.x), static_cast<double>(lo.y), static_cast<double>(lo.z)});
    Grid<T> out(Lattice(size, l.spacing(), o, l.direction()));
    for (int z = 0; z < size.z; ++z)
        for (int y = 0; y < size.y; ++y)
            for (int x = 0; x < size.x; ++x) out({x, y, z}) = g({lo.x + x, lo.y + y, lo.z + z});
    return out;
}

}  // namespace

TEST(BrainWeb, GreyMatterDiceInsideTheBrainMask) {
    const std::filesystem::path dir = std::filesystem::path(LIVESET_DATA_DIR) / "brainweb";
    ASSERT_TRUE(std::filesystem::exists(dir / "t1.mha")) << "BrainWeb data (bundled in data/brainweb) not found in " << dir;
    const Vec3i lo{40, 50, 70}, size{100, 120, 48};  // a slab through the middle of the brain
    const Grid<float> t1 = crop(read_image((dir / "t1.mha").string()), lo, size);
    const Grid<std::uint8_t> brain = crop(read_label_image((dir / "brain_mask.nii.gz").string()), lo, size);
    Grid<std::uint8_t> gm = crop(read_label_image((dir / "labels_crisp.nii.gz").string()), lo, size);
    for (std::uint8_t& v : gm.values()) v = v == 2;

    // Seeds: GM voxels whose whole 3x3x3 neighbourhood is GM, on a 10-voxel grid (as a user would
    // click a few dozen points in clearly grey voxels).
    SegmentRequest req;
    for (int z = 2; z < size.z - 2; z += 10)
        for (int y = 2; y < size.y - 2; y += 10)
            for (int x = 2; x < size.x - 2; x += 10) {
                bool deep = true;
                for (int k = 0; k < 27 && deep; ++k) deep = gm({x + k % 3 - 1, y + k / 3 % 3 - 1, z + k / 9 - 1}) != 0;
                if (deep) req.seeds.push_back({{double(x), double(y), double(z)}, 1.0});
            }
    ASSERT_GE(req.seeds.size(), 10u);
    req.roi = &brain;
    // The documented BrainWeb window: 94 ± 22 in the T1's units (inside-mask percentiles map it).
    req.mu_raw = 94.0;
    req.epsilon_raw = 22.0;
    req.alpha = 0.1;
    req.n = 4.0;
    const SegmentOutcome out = segment_image(t1, req);
    EXPECT_EQ(out.result.reason, StopReason::kConverged) << out.result.iterations;
    const OverlapMetrics m = compare_overlap(out.mask, gm);
    RecordProperty("dice", std::to_string(m.dice));
    std::printf("BrainWeb slab: dice %.4f, volume difference %+.3f, %d iterations\n", m.dice, m.volume_difference, out.result.iterations);
    EXPECT_GE(m.dice, 0.90) << "iterations " << out.result.iterations;
    EXPECT_LT(std::abs(m.volume_difference), 0.10);
}
