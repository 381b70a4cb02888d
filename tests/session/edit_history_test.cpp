// EditHistory + SparseField::restore: undoing an action gives back φ and status bit for bit as they
// were before it, redoing gives the state after it, across many actions of random local edits, and
// an action's memory grows with the points it changed, not with the lattice.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <random>
#include <vector>

#include "liveset/levelset/invariants.hpp"
#include "liveset/session/edit_history.hpp"

namespace liveset {
namespace {

struct Snapshot {
    std::vector<std::uint32_t> phi_bits;
    std::vector<std::int8_t> status;
    std::vector<std::vector<PointIndex>> layers;  // sorted point sets per layer
};

Snapshot snapshot(const SparseField& f) {
    Snapshot s;
    for (float v : f.phi().values()) s.phi_bits.push_back(std::bit_cast<std::uint32_t>(v));
    s.status.assign(f.status().values().begin(), f.status().values().end());
    for (int k = -f.layers(); k <= f.layers(); ++k) {
        std::vector<PointIndex> l(f.layer(k).begin(), f.layer(k).end());
        std::sort(l.begin(), l.end());
        s.layers.push_back(std::move(l));
    }
    return s;
}

void expect_same(const Snapshot& a, const Snapshot& b, const char* what, int action) {
    ASSERT_EQ(a.phi_bits, b.phi_bits) << what << " φ differs after action " << action;
    ASSERT_EQ(a.status, b.status) << what << " status differs after action " << action;
    ASSERT_EQ(a.layers, b.layers) << what << " layer lists differ after action " << action;
}

// Random ±0.35 edits on a tenth of the zero layer within a box: the front moves, points enter and
// leave every layer, far points join the band and band points go far.
ChangedPoints random_edits(SparseField& f, std::mt19937& rng, Vec3i lo, Vec3i hi) {
    std::uniform_real_distribution<float> u(-0.35f, 0.35f);
    std::uniform_int_distribution<int> pick(0, 9);
    return f.apply_in_box(lo, hi, [&](Vec3i, float) { return pick(rng) == 0 ? u(rng) : 0.0f; });
}

TEST(EditHistory, UndoAndRedoAreBitIdenticalOverManyActions) {
    const Lattice lat({40, 36, 32});
    SparseField f(lat, 2);
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{20, 18, 16}) - 10.0; });
    EditHistory h(f, 32);
    std::mt19937 rng(7);
    std::vector<Snapshot> states{snapshot(f)};
    const int actions = 12;
    for (int a = 0; a < actions; ++a) {
        h.begin("edits", {});
        const Vec3i lo{(a * 5) % 20, 4, 4}, hi{(a * 5) % 20 + 18, 30, 26};
        for (int k = 0; k < 6; ++k) h.record(random_edits(f, rng, lo, hi));  // several updates per action
        ASSERT_TRUE(h.commit(f, {}));
        states.push_back(snapshot(f));
    }
    ASSERT_EQ(h.undo_depth(), static_cast<std::size_t>(actions));
    for (int a = actions; a > 0; --a) {
        h.undo(f);
        expect_same(snapshot(f), states[static_cast<std::size_t>(a - 1)], "undo", a);
        ASSERT_TRUE(check_invariants(f).ok()) << check_invariants(f).summary();
    }
    EXPECT_FALSE(h.can_undo());
    for (int a = 1; a <= actions; ++a) {
        h.redo(f);
        expect_same(snapshot(f), states[static_cast<std::size_t>(a)], "redo", a);
    }
    EXPECT_FALSE(h.can_redo());
    // Undo half, edit again: the redo list is dropped, and undo still reaches the older states.
    for (int a = 0; a < 4; ++a) h.undo(f);
    h.begin("more", {});
    h.record(random_edits(f, rng, {0, 0, 0}, {39, 35, 31}));
    ASSERT_TRUE(h.commit(f, {}));
    EXPECT_FALSE(h.can_redo());
    h.undo(f);
    expect_same(snapshot(f), states[actions - 4], "undo after a new action", actions - 4);
    for (int a = actions - 4; a > 0; --a) h.undo(f);
    expect_same(snapshot(f), states[0], "undo to the start", 0);
}

TEST(EditHistory, RestoreReportsExactlyThePointsItChanges) {
    const Lattice lat({30, 30, 30});
    SparseField f(lat, 2);
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{15, 15, 15}) - 8.0; });
    EditHistory h(f, 32);
    std::mt19937 rng(3);
    const Snapshot before = snapshot(f);
    h.begin("edits", {});
    h.record(random_edits(f, rng, {0, 0, 0}, {29, 29, 29}));
    h.commit(f, {});
    const Snapshot after = snapshot(f);
    // Restore through the field's own API with the history's answer: X = the differing points.
    const HistoryStep step = h.undo(f);
    std::vector<PointIndex> differing;
    for (std::size_t i = 0; i < before.status.size(); ++i)
        if (before.status[i] != after.status[i] || before.phi_bits[i] != after.phi_bits[i])
            differing.push_back(static_cast<PointIndex>(i));
    std::vector<PointIndex> got = step.changed.points;
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, differing);
    EXPECT_FALSE(differing.empty());
}

TEST(EditHistory, MemoryGrowsWithTheChangedPointsNotTheLattice) {
    for (int n : {48, 96}) {
        const Lattice lat({n, n, n});
        SparseField f(lat, 2);
        f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{20, 20, 20}) - 8.0; });
        EditHistory h(f, 32);
        h.begin("one edit", {});
        const PointIndex p = f.zero_layer().front();
        const ZeroLayerEdit e{p, f.phi()[p] < 0 ? 0.4f : -0.4f};
        const ChangedPoints x = f.apply_edits({&e, 1});
        h.record(x);
        ASSERT_TRUE(h.commit(f, {}));
        EXPECT_LE(h.bytes(), 4096u + 64 * x.size()) << n;  // a few dozen points, whatever the lattice
    }
}

TEST(EditHistory, RestoreRejectsBadStatesBeforeChangingAnything) {
    SparseField f(Lattice({10, 10, 10}), 2);
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{5, 5, 5}) - 3.0; });
    const Snapshot s = snapshot(f);
    const std::vector<PointState> bad{{0, -3.0f, -3}, {1, 0.0f, 9}};
    EXPECT_THROW(f.restore(bad), std::invalid_argument);
    const std::vector<PointState> outside{{0, 1.0f, 1}, {5000, 0.0f, 0}};
    EXPECT_THROW(f.restore(outside), std::invalid_argument);
    expect_same(snapshot(f), s, "rejected restore", 0);
}

TEST(EditHistory, KeepsAtMostItsLimitAndDropsEmptyActions) {
    SparseField f(Lattice({24, 24, 24}), 2);
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{12, 12, 12}) - 6.0; });
    EditHistory h(f, 20);
    h.begin("nothing", {});
    EXPECT_FALSE(h.commit(f, {}));  // no point, no mark changed
    std::mt19937 rng(5);
    for (int a = 0; a < 25; ++a) {
        h.begin("edit", {});
        h.record(random_edits(f, rng, {0, 0, 0}, {23, 23, 23}));
        h.commit(f, {});
    }
    EXPECT_EQ(h.undo_depth(), 20u);
    for (int a = 0; a < 20; ++a) h.undo(f);
    EXPECT_FALSE(h.can_undo());
    EXPECT_THROW(h.undo(f), std::logic_error);
}

}  // namespace
}  // namespace liveset

namespace liveset {
namespace {

// Brute force: the points whose φ bits or status differ from `start`, or that `also` marks, in
// index order.
std::vector<PointIndex> differing(const SparseField& f, const Snapshot& start, const std::vector<std::uint8_t>* also = nullptr) {
    std::vector<PointIndex> out;
    for (std::size_t i = 0; i < f.lattice().size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if ((also && (*also)[i]) || std::bit_cast<std::uint32_t>(f.phi()[p]) != start.phi_bits[i] || f.status()[p] != start.status[i])
            out.push_back(p);
    }
    return out;
}

// record_differences after a whole-state replacement within an action that already recorded local
// edits: X is exactly the points whose state differs from the action's start or that were recorded
// earlier (brute force, index order), its sign changes hold every point whose sign differs from
// the state just before the replacement, and undo gives back the action's start bit for bit.
TEST(EditHistory, RecordDifferencesIsTheBruteForceDifferenceWithItsSignChanges) {
    const Lattice lat({40, 36, 32});
    SparseField f(lat, 2);
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{20, 18, 16}) - 10.0; });
    EditHistory h(f, 32);
    const Snapshot start = snapshot(f);
    std::mt19937 rng(11);
    h.begin("whole", {});
    h.record(random_edits(f, rng, {4, 4, 4}, {30, 30, 26}));
    std::vector<std::uint8_t> recorded(lat.size(), 0);
    for (PointIndex p : differing(f, start)) recorded[p] = 1;
    const Grid<float> before = f.phi();
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{22, 17, 15}) - 9.0; });  // the whole state replaced
    const ChangedPoints x = h.record_differences(f);
    const std::vector<PointIndex> expected = differing(f, start, &recorded);
    EXPECT_EQ(x.points, expected);
    ASSERT_TRUE(x.sign_changes.has_value());
    std::vector<std::uint8_t> listed(lat.size(), 0);
    for (PointIndex p : *x.sign_changes) listed[p] = 1;
    std::size_t flips = 0;
    for (std::size_t i = 0; i < lat.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if ((before[p] < 0.0f) != (f.phi()[p] < 0.0f)) {
            ++flips;
            ASSERT_TRUE(listed[i]) << "point " << i << " changed sign but is not listed";
        }
    }
    EXPECT_GT(flips, 100u);
    h.commit(f, {});
    h.undo(f);
    expect_same(snapshot(f), start, "undone", 0);
}

// A whole-state replacement large enough for the commit's parallel parts (some 130 000 recorded
// points, several parts of the list): X is the brute-force difference in index order, undo gives
// back the start and redo the replacement bit for bit, and a point brought back to its old state
// before the commit is left out of the action (its memory: only the points that changed).
TEST(EditHistory, ALargeWholeStateActionIsExactInEveryPartOfItsLists) {
    const Lattice lat({100, 90, 80});
    SparseField f(lat, 2);
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{30, 45, 40}) - 25.0; });
    EditHistory h(f, 32);
    const Snapshot start = snapshot(f);
    h.begin("whole", {});
    f.init_from_sdf([](Vec3d p) { return norm(p - Vec3d{70, 45, 40}) - 25.0; });
    const ChangedPoints x = h.record_differences(f);
    const std::vector<PointIndex> expected = differing(f, start);
    ASSERT_GT(expected.size(), 100000u);
    EXPECT_EQ(x.points, expected);
    // One recorded point put back as it was: the commit leaves it out.
    const PointIndex back = expected[expected.size() / 3];
    f.restore(std::vector<PointState>{{back, std::bit_cast<float>(start.phi_bits[back]), start.status[back]}});
    const Snapshot end = snapshot(f);
    ASSERT_TRUE(h.commit(f, {}));
    EXPECT_LT(h.bytes(), 2 * expected.size() * sizeof(PointState) + 4096);
    EXPECT_GE(h.bytes(), 2 * (expected.size() - 1) * sizeof(PointState));
    h.undo(f);
    expect_same(snapshot(f), start, "undone", 0);
    h.redo(f);
    expect_same(snapshot(f), end, "redone", 0);
}

}  // namespace
}  // namespace liveset
