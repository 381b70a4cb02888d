// Sleeping stretches of front (StepOptions::sleep_after): a sleeping zero-layer point never moves
// and the awake set is exactly the rule's (replayed by brute force from the history of sign changes,
// edits and undos), X stays exactly the changed points, a new speed wakes everything, and sleeping
// keeps the segmentation of the exact step.
#include <gtest/gtest.h>

#include <bit>
#include <random>

#include "levelset_test_util.hpp"
#include "liveset/levelset/shapes.hpp"

using namespace liveset;
using namespace liveset::testing;

namespace {

StepOptions sleeping(int after) {
    StepOptions o;
    o.mode = StepMode::kIncremental;
    o.sleep_after = after;
    return o;
}

SparseField seed_field(double radius = 4.0) {
    SparseField f(Lattice({40, 40, 40}), 2);
    f.init_from_sdf(shapes::Sphere({20.5, 20.5, 17.5}, radius));
    return f;
}

std::vector<PointIndex> sign_changes(const SparseField& before, const SparseField& after) {
    std::vector<PointIndex> out;
    for (std::size_t i = 0; i < before.phi().size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if ((before.phi()[p] < 0.0f) != (after.phi()[p] < 0.0f)) out.push_back(p);
    }
    return out;
}

// The rule replayed point by point: last[p] is the latest step at which a wake event happened at a
// point w whose 2×2×2 block is within one block of p's (|⌊w/2⌋ − ⌊p/2⌋| ≤ 1 on every axis).
class BruteForceActivity {
public:
    explicit BruteForceActivity(const Lattice& l) : lat_(l), last_(l.size(), -1000000) {}
    void wake(std::span<const PointIndex> points, std::int64_t step) {
        const Vec3i d = lat_.dims();
        for (PointIndex w : points) {
            const Vec3i c = lat_.coord(w);
            for (int z = std::max(0, 2 * (c.z / 2 - 1)); z <= std::min(d.z - 1, 2 * (c.z / 2 + 1) + 1); ++z)
                for (int y = std::max(0, 2 * (c.y / 2 - 1)); y <= std::min(d.y - 1, 2 * (c.y / 2 + 1) + 1); ++y)
                    for (int x = std::max(0, 2 * (c.x / 2 - 1)); x <= std::min(d.x - 1, 2 * (c.x / 2 + 1) + 1); ++x) {
                        auto& v = last_[lat_.index({x, y, z})];
                        v = std::max<std::int64_t>(v, step);
                    }
        }
    }
    bool awake(PointIndex p, std::int64_t step, int after, std::int64_t all_woken_at) const {
        return step - std::max(last_[p], all_woken_at) <= after;
    }

private:
    Lattice lat_;
    std::vector<std::int64_t> last_;
};

}  // namespace

TEST(Activity, SleepingPointsNeverMoveAndTheAwakeSetIsTheRules) {
    constexpr int kAfter = 6;
    SparseField f = seed_field();
    const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0);
    BruteForceActivity brute(f.lattice());
    std::mt19937 rng(21);
    std::size_t slept = 0, edits_applied = 0;
    for (std::int64_t s = 1; s <= 300; ++s) {
        const SparseField before = f;
        const StepResult r = f.step(speed, sleeping(kAfter));
        // Brute force: which zero-layer points were awake, and a sleeping one keeps φ and status.
        std::size_t awake = 0;
        for (PointIndex p : before.zero_layer()) {
            if (brute.awake(p, s, kAfter, 0)) {
                ++awake;
                continue;
            }
            ASSERT_EQ(std::bit_cast<std::uint32_t>(f.phi()[p]), std::bit_cast<std::uint32_t>(before.phi()[p])) << "step " << s;
            ASSERT_EQ(f.status()[p], 0) << "step " << s;
        }
        ASSERT_EQ(r.awake, awake) << "step " << s;
        slept += before.zero_layer().size() - awake;
        ASSERT_EQ(sorted(r.changed.points), brute_force_changes(before, f)) << "step " << s;
        const InvariantReport inv = check_invariants(f);
        ASSERT_TRUE(inv.ok()) << "step " << s << ": " << inv.summary();
        brute.wake(sign_changes(before, f), s);
        if (s % 29 == 0) {  // undo the step: the restored points wake the front around them
            const SparseField stepped = f;
            const ChangedPoints x = f.restore(states_at(before, r.changed.points));
            ASSERT_TRUE(same_state(f, before));
            ASSERT_TRUE(reports_sign_changes(x, stepped, f)) << "step " << s;
            brute.wake(x.points, s);
        }
        if (s % 17 == 0) {  // a local edit wakes the front around it
            const ChangedPoints x = f.apply_edits(random_edit(f, rng));
            brute.wake(x.points, s);
            edits_applied += x.size();
        }
    }
    EXPECT_GT(slept, 100000u);  // the rule did put most of the stalled front to sleep
    EXPECT_GT(edits_applied, 0u);
}

TEST(Activity, ANewSpeedOrANewFrontWakesEverything) {
    SparseField f = seed_field();
    const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0);
    StepResult r;
    for (int s = 0; s < 120; ++s) r = f.step(speed, sleeping(5));
    ASSERT_GT(r.zero_layer, 1000u);
    ASSERT_LT(r.awake, r.zero_layer / 2);  // most of the front sleeps by now
    const BlobSpeed same_again = speed;    // a new speed object, even an equal one
    r = f.step(same_again, sleeping(5));
    EXPECT_EQ(r.awake, r.zero_layer);
    for (int s = 0; s < 60; ++s) r = f.step(same_again, sleeping(5));
    ASSERT_LT(r.awake, r.zero_layer / 2);
    f.init_from_sdf(shapes::Sphere({20.5, 20.5, 17.5}, 6.0));
    r = f.step(same_again, sleeping(5));
    EXPECT_EQ(r.awake, r.zero_layer);
}

TEST(Activity, SleepingKeepsTheSegmentationOfTheExactStep) {
    // Growth, stall and hundreds of steps of flicker: the inside sets agree to Dice ≥ 0.995 and the
    // sleeping run evaluates far fewer points.
    SparseField exact = seed_field(), fast = exact;
    const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0);
    std::size_t evaluated_exact = 0, evaluated_fast = 0;
    for (int s = 0; s < 400; ++s) {
        evaluated_exact += exact.step(speed, sleeping(0)).awake;
        evaluated_fast += fast.step(speed, sleeping(20)).awake;
    }
    std::size_t both = 0, a = 0, b = 0;
    for (std::size_t i = 0; i < exact.phi().size(); ++i) {
        const bool in_a = exact.phi()[static_cast<PointIndex>(i)] < 0, in_b = fast.phi()[static_cast<PointIndex>(i)] < 0;
        both += in_a && in_b;
        a += in_a;
        b += in_b;
    }
    EXPECT_GE(2.0 * double(both) / double(a + b), 0.995);
    EXPECT_LT(evaluated_fast * 2, evaluated_exact);
    expect_valid(fast, "after sleeping steps");
}

TEST(Activity, SleepAfterIsValidated) {
    StepOptions o;
    o.sleep_after = 5;
    EXPECT_THROW(validate(o), std::invalid_argument);  // sleeping needs the incremental step
    o.mode = StepMode::kIncremental;
    EXPECT_NO_THROW(validate(o));
    o.sleep_after = -1;
    EXPECT_THROW(validate(o), std::invalid_argument);
    o.sleep_after = 1'000'001;
    EXPECT_THROW(validate(o), std::invalid_argument);
    o.sleep_after = 1'000'000;
    EXPECT_NO_THROW(validate(o));
}

namespace {

// φ and statuses of `from` written into `to` (as a session loads a saved field).
void load_bits(SparseField& to, const SparseField& from) {
    std::vector<PointState> states;
    for (std::size_t i = 0; i < from.phi().size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if (std::bit_cast<std::uint32_t>(from.phi()[p]) != std::bit_cast<std::uint32_t>(to.phi()[p]) || from.status()[p] != to.status()[p])
            states.push_back({p, from.phi()[p], from.status()[p]});
    }
    to.restore(states);
}

}  // namespace

// A field saved mid-run (φ, statuses and the activity snapshot) and loaded into another field with a
// new speed object of the same parameters continues bit for bit as the uninterrupted run; without the
// snapshot (everything awake again) it does not.
TEST(Activity, ASavedSnapshotContinuesBitForBit) {
    constexpr int kAfter = 6;
    SparseField run = seed_field();
    const BlobSpeed speed({19.5, 19.5, 19.5}, 13.0, 0.05f, 22);  // the front stops at x < 22: it sleeps there
    for (int s = 0; s < 40; ++s) run.step(speed, sleeping(kAfter));
    const ActivitySnapshot snap = run.activity_snapshot(speed.serial());
    EXPECT_TRUE(snap.speed_current);
    EXPECT_EQ(snap.clock, 40);

    SparseField loaded = seed_field(), forgetful = seed_field();
    load_bits(loaded, run);
    load_bits(forgetful, run);
    loaded.restore_activity(snap);
    const BlobSpeed reloaded = speed;  // a copy: another serial, as after reopening
    ASSERT_NE(reloaded.serial(), speed.serial());
    bool forgetful_differs = false;
    for (int s = 0; s < 40; ++s) {
        run.step(speed, sleeping(kAfter));
        loaded.step(reloaded, sleeping(kAfter));
        forgetful.step(reloaded, sleeping(kAfter));
        ASSERT_TRUE(same_state(run, loaded)) << "step " << s + 41;
        forgetful_differs = forgetful_differs || !same_state(run, forgetful);
    }
    EXPECT_TRUE(check_invariants(loaded).ok());
    EXPECT_TRUE(forgetful_differs) << "the test cannot tell a restored activity from a fresh one";

    // Not the speed the stamps were taken under: the next step wakes everything, as it would have.
    const ActivitySnapshot stale = run.activity_snapshot(0);
    EXPECT_FALSE(stale.speed_current);
    // Another lattice is refused.
    SparseField other(Lattice({30, 40, 40}), 2);
    EXPECT_THROW(other.restore_activity(snap), std::invalid_argument);
}

// The stamps are 32-bit offsets from a base that moves up every 2^30 steps: the rule must read the
// same far past 2^31 steps, a snapshot must hold the absolute steps, and a restored snapshot
// (clock included) must continue with the same awake set.
TEST(Activity, StampsKeepTheRuleFarPastThirtyTwoBits) {
    const Lattice l({8, 8, 8});
    constexpr int kAfter = 10;
    constexpr std::uint64_t kSpeed = 7;
    FrontActivity a;
    a.begin_step(l, kSpeed, 1);
    a.wake_near(std::vector<PointIndex>{l.index({7, 7, 7})}, l, 3);
    const PointIndex p = l.index({1, 1, 1});  // block (0, 0, 0): stamp 0
    for (const std::int64_t t : {std::int64_t{1} << 31, (std::int64_t{1} << 33) + 5, (std::int64_t{1} << 40) + 11}) {
        a.begin_step(l, kSpeed, t);  // the same speed: nothing wakes but the point below
        a.wake_near(std::vector<PointIndex>{p}, l, t);
        EXPECT_TRUE(a.awake({1, 1, 1}, t + kAfter, kAfter)) << t;
        EXPECT_TRUE(a.awake({3, 3, 3}, t + kAfter, kAfter)) << t;  // one block over
        EXPECT_FALSE(a.awake({1, 1, 1}, t + kAfter + 1, kAfter)) << t;
        EXPECT_FALSE(a.awake({5, 5, 5}, t, kAfter)) << t;  // two blocks over (woken at step 3 with (7, 7, 7))
        EXPECT_FALSE(a.awake({7, 7, 7}, t, kAfter)) << t;  // woken at step 3, long asleep
        ActivitySnapshot s = a.snapshot(kSpeed);
        ASSERT_EQ(s.stamps.size(), 64u);
        EXPECT_EQ(s.stamps[0], t);
        s.clock = t + 4;
        FrontActivity b;
        b.restore(s, l);
        for (int z = 0; z < 8; ++z)
            for (int y = 0; y < 8; ++y)
                for (int x = 0; x < 8; ++x)
                    for (const std::int64_t now : {t + 4, t + kAfter, t + kAfter + 1})
                        ASSERT_EQ(b.awake({x, y, z}, now, kAfter), a.awake({x, y, z}, now, kAfter)) << t << " " << x << y << z;
    }
}

// The row-cached scan (the step's filter over the zero-layer list) gives the point test's answer at
// every point, in any order of visits: ascending, with jumps back and across rows, on a lattice of
// odd dimensions (a last block of one point per axis), before anything sleeps and after.
TEST(Activity, TheRowScanAgreesWithThePointTest) {
    const Lattice l({7, 9, 5});
    FrontActivity a;
    constexpr std::uint64_t kSpeed = 1;
    constexpr int kAfter = 3;
    std::mt19937 rng(5);
    std::uniform_int_distribution<PointIndex> any(0, static_cast<PointIndex>(l.size() - 1));
    std::vector<PointIndex> order(l.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = static_cast<PointIndex>(i);
    for (std::size_t k = 0; k + 5 < order.size(); k += 11) std::swap(order[k], order[k + 5]);  // back and forth
    for (int k = 0; k < 40; ++k) order.push_back(any(rng));                                // and anywhere
    int sleeping_seen = 0, awake_seen = 0;
    for (std::int64_t t = 1; t <= 12; ++t) {
        a.begin_step(l, kSpeed, t);
        std::vector<PointIndex> woken;
        if (t % 4 != 0)
            for (int k = 0; k < 2; ++k) woken.push_back(any(rng));
        a.wake_near(woken, l, t);
        const FrontActivity::AwakeTest test = a.awake_test(t + 1, kAfter);
        FrontActivity::AwakeScan scan(test, l);
        for (const PointIndex i : order) {
            const bool want = test(l.coord(i));
            ASSERT_EQ(scan(i), want) << "step " << t << " point " << i;
            (want ? awake_seen : sleeping_seen) += 1;
        }
    }
    EXPECT_GT(sleeping_seen, 1000);  // the test saw both answers, many times
    EXPECT_GT(awake_seen, 1000);
}

// wake_near wakes exactly the blocks within one block (each axis) of a woken point's block, on the
// lattice's faces and edges too, whatever the order and repeats of the points (a run along x shares
// its blocks): brute force over every point of a lattice of odd dimensions.
TEST(Activity, WakeNearWakesTheBlocksAroundEachPoint) {
    const Lattice l({13, 10, 9});
    const Vec3i d = l.dims();
    constexpr std::uint64_t kSpeed = 1;
    std::mt19937 rng(11);
    std::uniform_int_distribution<PointIndex> any(0, static_cast<PointIndex>(l.size() - 1));
    FrontActivity a;
    a.begin_step(l, kSpeed, 1);
    for (std::int64_t t = 2; t <= 30; ++t) {
        a.begin_step(l, kSpeed, t);
        std::vector<PointIndex> woken;
        const int n = static_cast<int>(t % 5);
        for (int k = 0; k < n; ++k) {
            const PointIndex p = any(rng);
            woken.push_back(p);
            if (k % 2 == 0 && l.coord(p).x + 1 < d.x) woken.push_back(p + 1);  // a run along x
        }
        if (t == 7) woken.push_back(l.index({0, 0, 0}));                      // corners of the lattice
        if (t == 8) woken.push_back(l.index({d.x - 1, d.y - 1, d.z - 1}));
        a.wake_near(woken, l, t);
        for (int z = 0; z < d.z; ++z)
            for (int y = 0; y < d.y; ++y)
                for (int x = 0; x < d.x; ++x) {
                    bool want = false;  // no speed change since step 1: only wakes count
                    for (const PointIndex q : woken) {
                        const Vec3i c = l.coord(q);
                        want = want || (std::abs((c.x >> 1) - (x >> 1)) <= 1 && std::abs((c.y >> 1) - (y >> 1)) <= 1 &&
                                        std::abs((c.z >> 1) - (z >> 1)) <= 1);
                    }
                    // With a window of 0 steps, awake at t iff woken at t.
                    ASSERT_EQ(a.awake({x, y, z}, t, 0), want) << "step " << t << " point " << x << "," << y << "," << z;
                }
    }
}
