// The incremental global step against the full-band reference: bitwise-equal φ and statuses, the
// same change report (equal to a brute-force diff), after hundreds of steps interleaved with local
// edits and undo, on 1 and 2 threads, with the invariants checked after every step.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "levelset_test_util.hpp"
#include "liveset/levelset/curvature_flow.hpp"
#include "liveset/levelset/shapes.hpp"

using namespace liveset;
using namespace liveset::testing;

namespace {

StepOptions mode(StepMode m) {
    StepOptions o;
    o.mode = m;
    o.parallel_band_min = 0;  // small fields too: the 2-thread runs go through the parallel loops
    return o;
}

// The incremental step that only propagates changes (never re-layers the whole band), and the
// default one that re-layers whole when most of a small front moves.
StepOptions propagating() {
    StepOptions o = mode(StepMode::kIncremental);
    o.dense_front_max = 0;
    return o;
}

// Steps `reference` (full band) and `fast` (incremental, `fast_options`) side by side; every
// `edit_every` steps a random local edit is applied to both, and every `undo_every` steps the last
// step is undone on both with restore(). Fails at the first difference.
// Counts in `whole_band` (when given) the fast steps that re-layered the whole band, and in
// `value_pass` those of them that did it by changes of layer and a value pass.
void run_side_by_side(SparseField& reference, SparseField& fast, const Speed& speed, int steps, int edit_every,
                      int undo_every, std::uint32_t seed, const StepOptions& fast_options = propagating(),
                      int* whole_band = nullptr, int* value_pass = nullptr) {
    std::mt19937 rng(seed);
    for (int s = 1; s <= steps; ++s) {
        const SparseField before = fast;
        const StepResult r = reference.step(speed, mode(StepMode::kFullBand));
        const StepResult f = fast.step(speed, fast_options);
        if (whole_band != nullptr && f.whole_band) ++*whole_band;
        if (value_pass != nullptr && f.value_pass) ++*value_pass;
        ASSERT_TRUE(f.whole_band || !f.value_pass) << "step " << s;
        ASSERT_FALSE(r.value_pass) << "step " << s;
        ASSERT_TRUE(r.whole_band) << "step " << s;
        ASSERT_TRUE(fast_options.dense_front_max > 0 || !f.whole_band) << "step " << s;
        ASSERT_EQ(r.dt, f.dt) << "step " << s;
        ASSERT_EQ(r.zero_layer, f.zero_layer) << "step " << s;
        ASSERT_TRUE(same_state(reference, fast)) << "step " << s;
        ASSERT_EQ(sorted(f.changed.points), brute_force_changes(before, fast)) << "step " << s;
        ASSERT_EQ(sorted(r.changed.points), sorted(f.changed.points)) << "step " << s;
        const InvariantReport inv = check_invariants(fast);
        ASSERT_TRUE(inv.ok()) << "step " << s << ": " << inv.summary();
        if (undo_every > 0 && s % undo_every == 0) {
            const auto states = states_at(before, f.changed.points);
            reference.restore(states);
            fast.restore(states);
            ASSERT_TRUE(same_state(fast, before)) << "undo after step " << s;
            ASSERT_TRUE(same_state(reference, fast)) << "undo after step " << s;
        }
        if (edit_every > 0 && s % edit_every == 0) {
            const auto edits = random_edit(fast, rng);
            reference.apply_edits(edits, RepairScope::kLocal);
            fast.apply_edits(edits, RepairScope::kLocal);
            ASSERT_TRUE(same_state(reference, fast)) << "edit after step " << s;
        }
    }
}

// The paper's box, small: 16 points in a 32-point lattice.
SparseField small_box(int layers) {
    BoxFlowOptions o;
    o.lattice = 32;
    o.box = 16;
    o.layers = layers;
    return make_box_field(o);
}

SparseField blob_seed(int n = 40, double radius = 4.0) {
    SparseField f(Lattice({n, n, n}), 2);
    const double c = (n - 1) / 2.0;
    f.init_from_sdf(shapes::Sphere({c + 1.0, c + 1.0, c - 2.0}, radius));
    return f;
}

}  // namespace

TEST(IncrementalStep, GrowingAndStallingFrontEqualsTheFullBandStepBitwise) {
    // Growth from a seed until the front stalls and oscillates at the blob's wavy edge (≈ 60
    // steps), then hundreds of steps of the stalled regime, with edits and undo in between, by
    // change propagation only. Two cases: the whole front moves (about 2/3 of the zero layer
    // changes each step, so the propagation reaches most of the band) and only a cap moves
    // (x ≥ 28, about 1/3: the repair stays local).
    for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            SparseField reference = blob_seed();
            SparseField fast = reference;
            const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0);
            run_side_by_side(reference, fast, speed, 400, 7, 23, 5u + static_cast<std::uint32_t>(threads));
        });
        arena.execute([&] {
            SparseField reference = blob_seed(40, 9.0);
            SparseField fast = reference;
            const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0, 0.05f, 28);
            run_side_by_side(reference, fast, speed, 300, 9, 17, 9u + static_cast<std::uint32_t>(threads));
        });
    }
}

// The default incremental step switches between whole-band re-layering (most of the front moves)
// and change propagation (a cap moves, or the front stalls) from step to step: still the
// reference's bits, reports and invariants.
TEST(IncrementalStep, SwitchingToTheWholeBandWhenMostOfTheFrontMovesKeepsTheBits) {
    for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        int whole_band = 0;  // of 300 + 200 steps
        arena.execute([&] {
            SparseField reference = blob_seed();
            SparseField fast = reference;
            const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0);
            run_side_by_side(reference, fast, speed, 300, 7, 23, 15u + static_cast<std::uint32_t>(threads),
                             mode(StepMode::kIncremental), &whole_band);
        });
        arena.execute([&] {
            SparseField reference = blob_seed(40, 9.0);
            SparseField fast = reference;
            const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0, 0.05f, 28);
            run_side_by_side(reference, fast, speed, 200, 9, 17, 19u + static_cast<std::uint32_t>(threads),
                             mode(StepMode::kIncremental), &whole_band);
        });
        // Both repairs ran, many times each (the growth is dense, the stalled fronts are not).
        EXPECT_GE(whole_band, 50) << threads << " threads";
        EXPECT_LE(whole_band, 450) << threads << " threads";
    }
}

TEST(IncrementalStep, DenseFrontMaxIsValidated) {
    StepOptions o = mode(StepMode::kIncremental);
    o.dense_front_max = 1'000'000'001;
    try {
        validate(o);
        FAIL() << "accepted 1 000 000 001";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("re-layered whole"), std::string::npos) << e.what();
    }
    o.dense_front_max = 0;
    EXPECT_NO_THROW(validate(o));
    o.dense_front_max = 1'000'000'000;
    EXPECT_NO_THROW(validate(o));
}

TEST(IncrementalStep, MeanCurvatureFlowOfTheBoxEqualsTheFullBandStepBitwise) {
    for (int layers : {1, 2, 3}) {
        SparseField reference = small_box(layers);
        SparseField fast = reference;
        const CurvatureSpeed speed;
        run_side_by_side(reference, fast, speed, 250, 11, 0, 40u + static_cast<std::uint32_t>(layers));
    }
}

// A curvature flow changes the layer of few points per step, so the default incremental step
// re-layers its band by changes of layer and a value pass over the lists (repair_dense): the
// reference's bits, reports and invariants after hundreds of steps with edits and undo, on 1 and
// 2 threads, for 1-3 layers; as the small box rounds and shrinks, more points change layer per
// step, and the repair switches to the push sweep and back.
TEST(IncrementalStep, TheValuePassOfADenseStepEqualsTheFullBandStepBitwise) {
    for (int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        arena.execute([&] {
            for (int layers : {1, 2, 3}) {
                SparseField reference = small_box(layers);
                SparseField fast = reference;
                int whole_band = 0, value_pass = 0;
                run_side_by_side(reference, fast, CurvatureSpeed(), 250, 11, 13, 60u + static_cast<std::uint32_t>(layers),
                                 mode(StepMode::kIncremental), &whole_band, &value_pass);
                // Both whole-band repairs ran, many times each.
                EXPECT_GE(value_pass, 30) << layers << " layers, " << threads << " threads";
                EXPECT_GE(whole_band - value_pass, 30) << layers << " layers, " << threads << " threads";
            }
        });
    }
}

// The value pass over lists of several 4 096-point chunks (read in chunks on two threads, then
// written): the same bits, reports and list order on 1 thread and 2.
TEST(IncrementalStep, OneAndTwoThreadsAgreeOnTheValuePassOfALargeFlow) {
    auto run = [](int threads, std::vector<std::vector<PointIndex>>& reports, int& value_pass) {
        tbb::task_arena arena(threads);
        BoxFlowOptions o;
        o.lattice = 64;
        o.box = 44;  // the lists of layers ±1 and ±2 hold about 11 000 points each
        SparseField f = make_box_field(o);
        arena.execute([&] {
            for (int s = 0; s < 120; ++s) {
                const StepResult r = f.step(CurvatureSpeed(), mode(StepMode::kIncremental));
                value_pass += r.value_pass ? 1 : 0;
                reports.push_back(r.changed.points);
            }
        });
        return f;
    };
    std::vector<std::vector<PointIndex>> r1, r2;
    int pass1 = 0, pass2 = 0;
    const SparseField a = run(1, r1, pass1);
    const SparseField b = run(2, r2, pass2);
    EXPECT_TRUE(same_state(a, b));
    EXPECT_EQ(r1, r2);
    expect_same_list_order(a, b);
    EXPECT_GE(pass1, 100);
    EXPECT_EQ(pass1, pass2);
    const InvariantReport inv = check_invariants(b);
    EXPECT_TRUE(inv.ok()) << inv.summary();
}

TEST(IncrementalStep, OneAndTwoThreadsGiveTheSameStateReportsAndListOrder) {
    // Change propagation only, and the default step (which re-layers the whole band on dense steps).
    for (const StepOptions& options : {propagating(), mode(StepMode::kIncremental)}) {
        auto run = [&](int threads, std::vector<std::vector<PointIndex>>& reports) {
            tbb::task_arena arena(threads);
            SparseField f = blob_seed();
            arena.execute([&] {
                const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0);
                std::mt19937 rng(3);
                for (int s = 0; s < 200; ++s) {
                    reports.push_back(f.step(speed, options).changed.points);
                    if (s % 13 == 0) reports.push_back(f.apply_edits(random_edit(f, rng)).points);
                }
            });
            return f;
        };
        std::vector<std::vector<PointIndex>> r1, r2;
        const SparseField a = run(1, r1);
        const SparseField b = run(2, r2);
        EXPECT_TRUE(same_state(a, b));
        EXPECT_EQ(r1, r2);
        expect_same_list_order(a, b);
    }
}

// The same with sleeping on a front of several 4 096-point chunks (the rate pass joins per-chunk
// arrays of awake points in chunk order): the same bits, reports and list order on 1 thread (one
// chunk) and 2 (several).
TEST(IncrementalStep, OneAndTwoThreadsAgreeWhenSleepingOnAFrontOfSeveralChunks) {
    auto run = [](int threads, std::vector<std::vector<PointIndex>>& reports, std::size_t& largest) {
        tbb::task_arena arena(threads);
        SparseField f = blob_seed(72, 8.0);
        arena.execute([&] {
            const BlobSpeed speed({35.5, 35.5, 35.5}, 26.0);
            StepOptions o = propagating();
            o.sleep_after = 5;
            for (int s = 0; s < 160; ++s) {
                const StepResult r = f.step(speed, o);
                reports.push_back(r.changed.points);
                largest = std::max(largest, r.zero_layer);
            }
        });
        return f;
    };
    std::vector<std::vector<PointIndex>> r1, r2;
    std::size_t largest1 = 0, largest2 = 0;
    const SparseField a = run(1, r1, largest1);
    const SparseField b = run(2, r2, largest2);
    EXPECT_GT(largest1, 2u * 4096u) << "the front should span several chunks";
    EXPECT_TRUE(same_state(a, b));
    EXPECT_EQ(r1, r2);
    expect_same_list_order(a, b);
}

// A front growing at full speed changes the layer of about half the band every step: the
// re-layering's write-back, the settling pass and the list moves (one task per list from 4 096
// moves) run in parallel. Both modes give the same bits, reports and sign changes (equal to a
// brute-force diff), and 1 and 2 threads the same state, reports and list order, with the
// invariants (lists against statuses; a wrong slot would show as a wrong removal) every step.
TEST(IncrementalStep, OneAndTwoThreadsAgreeWhenManyPointsChangeLayer) {
    auto run = [](int threads, std::vector<std::vector<PointIndex>>& reports, std::size_t& most_moves) {
        tbb::task_arena arena(threads);
        SparseField reference = blob_seed(72, 12.0);
        SparseField fast = reference;
        arena.execute([&] {
            const BlobSpeed speed({35.5, 35.5, 35.5}, 30.0, 0.01f);
            for (int s = 1; s <= 40; ++s) {
                const SparseField before = fast;
                const StepResult r = reference.step(speed, mode(StepMode::kFullBand));
                const StepResult f = fast.step(speed, propagating());  // the propagation's parallel passes
                ASSERT_TRUE(same_state(reference, fast)) << "step " << s;
                ASSERT_EQ(sorted(r.changed.points), sorted(f.changed.points)) << "step " << s;
                ASSERT_EQ(sorted(f.changed.points), brute_force_changes(before, fast)) << "step " << s;
                std::size_t moves = 0;  // points whose layer changed, by brute force
                std::vector<PointIndex> signs;
                for (const PointIndex i : f.changed.points) {
                    moves += before.status()[i] != fast.status()[i];
                    if ((before.phi()[i] < 0.0f) != (fast.phi()[i] < 0.0f)) signs.push_back(i);
                }
                most_moves = std::max(most_moves, moves);
                ASSERT_TRUE(f.changed.sign_changes && r.changed.sign_changes) << "step " << s;
                ASSERT_EQ(sorted(*f.changed.sign_changes), sorted(signs)) << "step " << s;
                ASSERT_EQ(sorted(*r.changed.sign_changes), sorted(signs)) << "step " << s;
                expect_valid(fast, "after a step");
                reports.push_back(f.changed.points);
                reports.push_back(r.changed.points);
                reports.push_back(*f.changed.sign_changes);
            }
        });
        return fast;
    };
    std::vector<std::vector<PointIndex>> r1, r2;
    std::size_t moves1 = 0, moves2 = 0;
    const SparseField a = run(1, r1, moves1);
    const SparseField b = run(2, r2, moves2);
    EXPECT_GT(moves1, 2u * 4096u) << "the steps should move many points between the lists";
    EXPECT_EQ(moves1, moves2);
    EXPECT_TRUE(same_state(a, b));
    EXPECT_EQ(r1, r2);
    expect_same_list_order(a, b);
}

// A front of more than 16 384 points: the propagation's claims and the full-band step's push sweep
// split at a plane, the two sides at once and the seam after (plane_split.hpp). Still
// the reference's bits, both steps' invariants and reports (against a brute-force diff), and on 1
// and 2 threads the same states, reports and list orders.
TEST(IncrementalStep, OneAndTwoThreadsAgreeWhenALargeFrontsClaimsSplit) {
    auto run = [](int threads, std::vector<std::vector<PointIndex>>& reports, std::size_t& smallest, SparseField& full) {
        tbb::task_arena arena(threads);
        SparseField reference = blob_seed(112, 44.0);
        SparseField fast = reference;
        arena.execute([&] {
            const BlobSpeed speed({55.5, 55.5, 55.5}, 49.0, 0.02f);
            std::mt19937 rng(11);
            for (int s = 1; s <= 16; ++s) {
                const SparseField before = fast;
                const StepResult r = reference.step(speed, mode(StepMode::kFullBand));
                const StepResult f = fast.step(speed, propagating());
                smallest = std::min(smallest, f.changed.size());
                ASSERT_GT(r.zero_layer, 16384u) << "step " << s << ": the push sweep should split its first level";
                ASSERT_TRUE(same_state(reference, fast)) << "step " << s;
                ASSERT_EQ(sorted(r.changed.points), sorted(f.changed.points)) << "step " << s;
                ASSERT_EQ(sorted(f.changed.points), brute_force_changes(before, fast)) << "step " << s;
                expect_valid(reference, "after a full-band step");
                expect_valid(fast, "after a step");
                reports.push_back(f.changed.points);
                reports.push_back(r.changed.points);
                if (s % 5 == 0) {
                    const auto edits = random_edit(fast, rng);
                    reference.apply_edits(edits, RepairScope::kLocal);
                    reports.push_back(fast.apply_edits(edits, RepairScope::kLocal).points);
                    ASSERT_TRUE(same_state(reference, fast)) << "edit after step " << s;
                }
            }
        });
        full = reference;
        return fast;
    };
    std::vector<std::vector<PointIndex>> r1, r2;
    std::size_t smallest1 = SIZE_MAX, smallest2 = SIZE_MAX;
    SparseField full1(Lattice({1, 1, 1})), full2(Lattice({1, 1, 1}));
    const SparseField a = run(1, r1, smallest1, full1);
    const SparseField b = run(2, r2, smallest2, full2);
    // The level-1 claims' sources are the zero layer's changes: more than the split's threshold.
    EXPECT_GT(smallest1, 4u * 16384u) << "every step should change enough points for its claims to split";
    EXPECT_TRUE(same_state(a, b));
    EXPECT_TRUE(same_state(full1, full2));
    EXPECT_EQ(r1, r2);
    expect_same_list_order(a, b);
    expect_same_list_order(full1, full2);
}

TEST(IncrementalStep, BadOptionsThrowOneLineMessages) {
    SparseField f = blob_seed(16);
    const CurvatureSpeed speed;
    StepOptions bad;
    bad.mode = static_cast<StepMode>(7);
    EXPECT_THROW(f.step(speed, bad), std::invalid_argument);
    bad = {};
    bad.cfl = 0.0f;
    EXPECT_THROW(validate(bad), std::invalid_argument);
    bad = {};
    bad.max_dt = -1.0f;
    EXPECT_THROW(validate(bad), std::invalid_argument);
    EXPECT_NO_THROW(validate(StepOptions{}));
}

// Every eighth full-band step starts by putting the layer lists back into lattice order (a radix
// sort over the bytes the indices use). Step 16 here moves nothing (zero speed), so its sorted
// lists survive it: each must be ascending and hold exactly the points of its layer (the
// invariant checker also checks the slots).
TEST(IncrementalStep, TheFullBandStepSortsTheLayerListsEveryEighthStep) {
    SparseField f(Lattice({70, 66, 64}), 2);  // indices up to 295 680: three bytes
    f.init_from_sdf(shapes::Sphere({34.2, 33.1, 31.7}, 24.0));
    for (int s = 1; s <= 15; ++s) f.step(CurvatureSpeed(1.0f), mode(StepMode::kFullBand));
    EXPECT_TRUE(f.step(CurvatureSpeed(0.0f), mode(StepMode::kFullBand)).changed.empty());
    for (int k = -2; k <= 2; ++k) {
        const auto list = f.layer(k);
        ASSERT_GT(list.size(), 256u) << "layer " << k << " too small to take the radix path";
        EXPECT_TRUE(std::is_sorted(list.begin(), list.end())) << "layer " << k;
        std::vector<PointIndex> brute;
        for (std::size_t i = 0; i < f.status().size(); ++i)
            if (f.status()[static_cast<PointIndex>(i)] == k) brute.push_back(static_cast<PointIndex>(i));
        EXPECT_EQ(std::vector<PointIndex>(list.begin(), list.end()), brute) << "layer " << k;
    }
    expect_valid(f, "after the sort");
}
