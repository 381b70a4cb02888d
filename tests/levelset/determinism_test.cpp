// Thread-count independence: 1 and 2 threads give bitwise-identical states and change lists; a
// small band steps on the calling thread alone, with the same bits.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <atomic>
#include <random>
#include <span>
#include <stdexcept>
#include <string>

#include "levelset_test_util.hpp"
#include "liveset/levelset/curvature_flow.hpp"

using namespace liveset;
using namespace liveset::testing;

namespace {

StepOptions parallel_always() {
    StepOptions o;
    o.parallel_band_min = 0;  // the box's small band too: 2 threads run the parallel loops
    return o;
}

SparseField run(int threads, std::vector<std::size_t>& changes) {
    tbb::task_arena arena(threads);
    SparseField f = make_box_field({});
    arena.execute([&] {
        const CurvatureSpeed speed;
        std::mt19937 rng(99);
        for (int s = 0; s < 150; ++s) {
            changes.push_back(f.step(speed, parallel_always()).changed.size());
            if (s % 10 == 0) changes.push_back(f.apply_edits(random_edit(f, rng)).size());
        }
    });
    return f;
}

// Change propagation only (no whole-band sweep), so that each level of the relayer spans thousands
// of points and its decide and write passes run in parallel on two threads.
SparseField run_propagating(int threads, std::vector<PointIndex>& changes) {
    tbb::task_arena arena(threads);
    SparseField f = make_box_field({});
    StepOptions o = parallel_always();
    o.mode = StepMode::kIncremental;
    o.dense_front_max = 0;
    arena.execute([&] {
        const CurvatureSpeed speed;
        for (int s = 0; s < 80; ++s) {
            const StepResult r = f.step(speed, o);
            changes.insert(changes.end(), r.changed.points.begin(), r.changed.points.end());
        }
    });
    return f;
}

// Mean curvature flow that records the most threads its rates were evaluated under.
class ConcurrencyProbe final : public Speed {
public:
    SpeedSample at(const Grid<float>& phi, Vec3i p) const override { return flow_.at(phi, p); }
    void rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const override {
        int seen = most_.load();
        const int now = tbb::this_task_arena::max_concurrency();
        while (now > seen && !most_.compare_exchange_weak(seen, now)) {
        }
        flow_.rates(phi, points, out);
    }
    float curvature_weight() const override { return flow_.curvature_weight(); }
    int most_threads() const { return most_.load(); }

private:
    CurvatureSpeed flow_;
    mutable std::atomic<int> most_{0};
};

}  // namespace

TEST(Determinism, OneAndTwoThreadsGiveIdenticalResults) {
    std::vector<std::size_t> c1, c2;
    const SparseField a = run(1, c1);
    const SparseField b = run(2, c2);
    EXPECT_TRUE(same_state(a, b));
    EXPECT_EQ(c1, c2);
    expect_same_list_order(a, b);
}

// The change report in order (the region's order, which the relayer's joins keep) and the lists too.
TEST(Determinism, ChangePropagationOnOneAndTwoThreadsGivesTheSameOrder) {
    std::vector<PointIndex> c1, c2;
    const SparseField a = run_propagating(1, c1);
    const SparseField b = run_propagating(2, c2);
    EXPECT_TRUE(same_state(a, b));
    EXPECT_GT(c1.size(), 80u * 4096u);  // big enough steps: the relayer's passes ran in parallel
    EXPECT_EQ(c1, c2);
    expect_same_list_order(a, b);
}

// Under two threads, a band below parallel_band_min is stepped by one thread (the speed sees an
// arena of one), a band at or above it by both; the states and change reports (as sets) are the
// same bits, for both step modes. Below it no level is split for two tasks, so the order of the
// lists and of X follows the option (as it follows dense_front_max), and is the same on one thread.
TEST(Determinism, SmallBandStepsOnTheCallingThreadAloneWithTheSameBits) {
    for (StepMode m : {StepMode::kFullBand, StepMode::kIncremental}) {
        tbb::task_arena arena(2), one(1);
        SparseField alone = make_box_field({}), shared = alone, alone_one = alone;
        StepOptions small = parallel_always(), large = parallel_always();
        small.mode = large.mode = m;
        small.parallel_band_min = alone.band_size() * 2;  // the box flow's band only shrinks
        const ConcurrencyProbe probe_alone, probe_shared;
        for (int s = 0; s < 60; ++s) {
            StepResult a, b, c;
            arena.execute([&] {
                a = alone.step(probe_alone, small);
                b = shared.step(probe_shared, large);
            });
            one.execute([&] { c = alone_one.step(probe_alone, small); });
            ASSERT_EQ(sorted(a.changed.points), sorted(b.changed.points)) << "step " << s;
            ASSERT_EQ(a.changed.points, c.changed.points) << "step " << s;
            ASSERT_EQ(a.dt, b.dt) << "step " << s;
        }
        EXPECT_EQ(probe_alone.most_threads(), 1);
        EXPECT_EQ(probe_shared.most_threads(), 2);
        EXPECT_TRUE(same_state(alone, shared));
        EXPECT_TRUE(same_state(alone, alone_one));
        expect_same_list_order(alone, alone_one);
    }
}

TEST(Determinism, ParallelBandMinIsValidated) {
    StepOptions o;
    o.parallel_band_min = 1'000'000'001;
    try {
        validate(o);
        FAIL() << "accepted 1 000 000 001";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("several threads"), std::string::npos) << e.what();
    }
    o.parallel_band_min = 0;
    EXPECT_NO_THROW(validate(o));
    o.parallel_band_min = 1'000'000'000;
    EXPECT_NO_THROW(validate(o));
}
