// PlaneSplit against its contract, by brute force: the three parts hold every source once, each in
// source order; the parts below and above touch disjoint planes (a source reaches its own plane and
// the two next to it); neither holds more than half the sources; and the two tasks plus the seam
// run every source once, on one thread and on two.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <atomic>
#include <random>
#include <vector>

#include "liveset/grid/index_decoder.hpp"
#include "liveset/levelset/plane_split.hpp"

using namespace liveset;
using liveset::detail::PlaneSplit;

namespace {

void expect_contract(const Lattice& lat, const std::vector<PointIndex>& sources, PlaneSplit& split) {
    const IndexDecoder decoder(lat);
    split.split(sources, decoder, lat.dims().z);
    const auto below = split.part(PlaneSplit::kBelow), above = split.part(PlaneSplit::kAbove),
               seam = split.part(PlaneSplit::kSeam);
    ASSERT_EQ(below.size() + above.size() + seam.size(), sources.size());
    // Each part is the subsequence of the sources on its planes: merging them back by source
    // position gives the sources (positions are unique as the sources are distinct here).
    std::vector<std::size_t> position(lat.size(), SIZE_MAX);
    for (std::size_t m = 0; m < sources.size(); ++m) position[sources[m]] = m;
    for (const auto part : {below, above, seam})
        for (std::size_t m = 1; m < part.size(); ++m) EXPECT_LT(position[part[m - 1]], position[part[m]]);
    const auto z = [&](PointIndex i) { return lat.coord(i).z; };
    int top_below = -10, bottom_above = 1 << 30;
    for (const PointIndex i : below) top_below = std::max(top_below, z(i));
    for (const PointIndex i : above) bottom_above = std::min(bottom_above, z(i));
    EXPECT_GT(bottom_above - 1, top_below + 1) << "the planes the two tasks touch must not meet";
    int seam_lo = 1 << 30, seam_hi = -1;
    for (const PointIndex i : seam) {
        EXPECT_GT(z(i), top_below);
        EXPECT_LT(z(i), bottom_above);
        seam_lo = std::min(seam_lo, z(i));
        seam_hi = std::max(seam_hi, z(i));
    }
    if (!seam.empty()) {
        EXPECT_LE(seam_hi - seam_lo, 2) << "the seam is at most three planes";
    }
    EXPECT_LE(2 * below.size(), sources.size());
    EXPECT_LE(2 * above.size(), sources.size());
    for (const int threads : {1, 2}) {
        std::vector<std::atomic<int>> runs(lat.size());
        std::atomic<int> seam_before_tasks{0};
        std::atomic<int> tasks_done{0};
        tbb::task_arena(threads).execute([&] {
            split.run([&](std::span<const PointIndex> part, int p) {
                if (p == PlaneSplit::kSeam && tasks_done.load() != 2) ++seam_before_tasks;
                for (const PointIndex i : part) ++runs[i];
                if (p != PlaneSplit::kSeam) ++tasks_done;
            });
        });
        EXPECT_EQ(seam_before_tasks.load(), 0) << "the seam runs after both tasks";
        for (const PointIndex i : sources) EXPECT_EQ(runs[i].load(), 1);
    }
}

}  // namespace

TEST(PlaneSplit, PartsKeepTheSourcesOrderAndTouchDisjointPlanes) {
    const Lattice lat({12, 9, 40});
    std::mt19937 rng(7);
    PlaneSplit split;
    // A sphere-like shell in lattice order, the same shuffled, a slab of three planes (all seam),
    // one plane, and a front crowded at the bottom.
    std::vector<PointIndex> shell;
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const Vec3i c = lat.coord(i);
        const double r = std::hypot(c.x - 5.5, c.y - 4.0, (c.z - 20.0) / 3.0);
        if (std::abs(r - 4.0) < 0.7) shell.push_back(i);
    }
    expect_contract(lat, shell, split);
    std::vector<PointIndex> shuffled = shell;
    std::shuffle(shuffled.begin(), shuffled.end(), rng);
    expect_contract(lat, shuffled, split);
    std::vector<PointIndex> slab, plane, crowded;
    for (PointIndex i = 0; i < lat.size(); ++i) {
        const int z = lat.coord(i).z;
        if (z >= 10 && z <= 12) slab.push_back(i);
        if (z == 30) plane.push_back(i);
        if (z < 3 || (z == 39 && i % 5 == 0)) crowded.push_back(i);
    }
    expect_contract(lat, slab, split);
    EXPECT_EQ(split.part(PlaneSplit::kSeam).size(), slab.size()) << "three planes around the median are all seam";
    expect_contract(lat, plane, split);
    expect_contract(lat, crowded, split);
    expect_contract(lat, {}, split);
}
