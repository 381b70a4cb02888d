// Thread-count independence: 1 and 2 threads give bitwise-identical states and change lists.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <random>

#include "levelset_test_util.hpp"
#include "liveset/levelset/curvature_flow.hpp"

using namespace liveset;
using namespace liveset::testing;

namespace {
SparseField run(int threads, std::vector<std::size_t>& changes) {
    tbb::task_arena arena(threads);
    SparseField f = make_box_field({});
    arena.execute([&] {
        const CurvatureSpeed speed;
        std::mt19937 rng(99);
        for (int s = 0; s < 150; ++s) {
            changes.push_back(f.step(speed).changed.size());
            if (s % 10 == 0) changes.push_back(f.apply_edits(random_edit(f, rng)).size());
        }
    });
    return f;
}
}  // namespace

TEST(Determinism, OneAndTwoThreadsGiveIdenticalResults) {
    std::vector<std::size_t> c1, c2;
    const SparseField a = run(1, c1);
    const SparseField b = run(2, c2);
    EXPECT_TRUE(same_state(a, b));
    EXPECT_EQ(c1, c2);
    expect_same_list_order(a, b);
}
