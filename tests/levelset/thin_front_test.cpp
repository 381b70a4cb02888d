// The thin-front rule (StepOptions::thin_fronts, docs/ARCHITECTURE.md "Thin fronts"): a front
// carries into structures one and two voxels across to their end, as it does into three, growing
// or (mirrored) shrinking; both steps give the same bits and keep the invariants on the way.
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "levelset_test_util.hpp"
#include "liveset/levelset/shapes.hpp"

using namespace liveset;
using namespace liveset::testing;

namespace {

// A 7-voxel cube (x 2-8) joined to a 52-voxel (x 8-59) tube of `width` × `width` voxels or sheet
// of `span` × `width` voxels (scripts/thin_structures.sh's shapes at span 16), in a 64 × (span + 8)
// × 24 lattice.
struct Thin {
    int width;
    bool sheet;
    int span = 16;
    Vec3i dims() const { return {64, span + 8, 24}; }
    bool contains(Vec3i p) const {
        if (sheet) {
            const bool cube = p.x >= 2 && p.x < 9 && p.y >= 4 && p.y < 4 + span && p.z >= 8 && p.z < 15;
            return cube || (p.x >= 8 && p.x < 60 && p.y >= 4 && p.y < 4 + span && p.z >= 12 && p.z < 12 + width);
        }
        const int lo = 12 - width / 2;
        const bool cube = p.x >= 2 && p.x < 9 && p.y >= 8 && p.y < 15 && p.z >= 8 && p.z < 15;
        return cube || (p.x >= 8 && p.x < 60 && p.y >= lo && p.y < lo + width && p.z >= lo && p.z < lo + width);
    }
    std::string name() const { return (sheet ? "sheet " : "tube ") + std::to_string(width); }
};

// The threshold speed's regime at α 0: the front expands inside the structure and contracts
// outside; mirrored, the outside grows into the structure (the rule's L-1 side).
class ThinSpeed final : public Speed {
public:
    ThinSpeed(Thin s, bool mirrored) : s_(s), sign_(mirrored ? -1.0f : 1.0f) {}
    SpeedSample at(const Grid<float>&, Vec3i p) const override { return {sign_ * (s_.contains(p) ? -1.0f : 1.0f), 0.0f}; }
    float curvature_weight() const override { return 0.0f; }

private:
    Thin s_;
    float sign_;
};

// A ball of radius 2 in the cube inside the front (mirrored: outside it, all else inside).
SparseField seeded(const Thin& s, bool mirrored) {
    SparseField f(Lattice(s.dims()), 2);
    const shapes::Sphere ball({5.0, 11.0, 11.0}, 2.0);
    f.init_from_sdf([&](Vec3d p) { return mirrored ? -ball(p) : ball(p); });
    return f;
}

// Points on the seed's side of the front (φ < 0; mirrored φ > 0) in and out of the structure.
std::pair<int, int> reached(const SparseField& f, const Thin& s, bool mirrored) {
    int in = 0, out = 0;
    const Vec3i d = s.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                if ((f.phi()({x, y, z}) < 0.0f) != mirrored) ++(s.contains({x, y, z}) ? in : out);
    return {in, out};
}

int structure_size(const Thin& s) {
    int n = 0;
    const Vec3i d = s.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) n += s.contains({x, y, z}) ? 1 : 0;
    return n;
}

StepOptions thin_options(StepMode mode, bool thin = true, int sleep_after = 0, std::size_t dense_front_max = 150'000) {
    StepOptions o;
    o.mode = mode;
    o.sleep_after = sleep_after;
    o.dense_front_max = dense_front_max;
    o.parallel_band_min = 0;  // the 2-thread runs go through the parallel loops
    o.thin_fronts = thin;
    return o;
}

const Thin kThin[] = {{1, false}, {2, false}, {3, false}, {1, true}, {2, true}, {3, true}};

}  // namespace

// The front fills each structure, and nothing outside it, within 400 steps (the ideal front, a voxel
// per two steps at the CFL bound, needs about 110), growing and mirrored, either step; without the
// rule one and two voxels across it stops after 1-7 voxels (docs/BENCHMARKS.md, session 70).
TEST(ThinFront, CarriesToTheEndOfTubesAndSheetsOneAndTwoVoxelsAcross) {
    for (const bool mirrored : {false, true})
        for (const Thin& s : kThin)
            for (const StepOptions& o : {thin_options(StepMode::kFullBand), thin_options(StepMode::kIncremental, true, 20),
                                         thin_options(StepMode::kIncremental, false, 20)}) {
                SCOPED_TRACE(s.name() + (mirrored ? ", mirrored" : "") + (o.mode == StepMode::kFullBand ? ", full band" : ", incremental") +
                             (o.thin_fronts ? "" : ", without the rule"));
                const ThinSpeed speed(s, mirrored);
                SparseField f = seeded(s, mirrored);
                for (int k = 0; k < 400; ++k) {
                    f.step(speed, o);
                    if (k % 25 == 0) expect_valid(f, "thin front");
                }
                const auto [in, out] = reached(f, s, mirrored);
                EXPECT_EQ(out, 0);
                if (o.thin_fronts || s.width == 3) {
                    EXPECT_EQ(in, structure_size(s));
                } else {
                    EXPECT_LT(in, structure_size(s) - 40 * s.width) << "the front stops in the structure without the rule";
                }
                expect_valid(f, "thin front, end");
            }
}

// Both steps apply the rule alike: the same bits, change reports equal to a brute-force diff with
// their sign changes, on 1 and 2 threads, growing and mirrored, the invariants after every step;
// the incremental step takes its local repair and its whole-band push sweep on steps where points
// enter by the rule.
TEST(ThinFront, TheIncrementalStepEqualsTheFullBandStepBitwise) {
    for (int threads : {1, 2})
        for (const bool mirrored : {false, true})
            for (const Thin& s : {Thin{1, false}, Thin{2, true}})
                for (std::size_t dense_max : {std::size_t{0}, std::size_t{150'000}}) {
                    SCOPED_TRACE(s.name() + (mirrored ? ", mirrored" : "") + ", threads " + std::to_string(threads) + ", dense " +
                                 std::to_string(dense_max));
                    tbb::task_arena arena(threads);
                    arena.execute([&] {
                        const ThinSpeed speed(s, mirrored);
                        SparseField reference = seeded(s, mirrored);
                        SparseField fast = reference;
                        SparseField without = reference;  // the same steps without the rule
                        int local = 0, sweep = 0, pass = 0;
                        for (int k = 1; k <= 150; ++k) {
                            const SparseField before = fast;
                            const StepResult r = reference.step(speed, thin_options(StepMode::kFullBand));
                            const StepResult f = fast.step(speed, thin_options(StepMode::kIncremental, true, 0, dense_max));
                            ASSERT_TRUE(same_state(reference, fast)) << "step " << k;
                            ASSERT_EQ(sorted(f.changed.points), brute_force_changes(before, fast)) << "step " << k;
                            ASSERT_EQ(sorted(r.changed.points), sorted(f.changed.points)) << "step " << k;
                            ASSERT_TRUE(reports_sign_changes(f.changed, before, fast)) << "step " << k;
                            ASSERT_TRUE(reports_sign_changes(r.changed, before, reference)) << "step " << k;
                            const InvariantReport inv = check_invariants(fast);
                            ASSERT_TRUE(inv.ok()) << "step " << k << ": " << inv.summary();
                            // Where the rule took points in, the same step without it differs.
                            without = before;
                            without.step(speed, thin_options(StepMode::kIncremental, false, 0, dense_max));
                            if (same_state(without, fast)) continue;
                            ++(f.value_pass ? pass : f.whole_band ? sweep : local);
                        }
                        EXPECT_GT(local + sweep + pass, 20);
                        if (dense_max == 0) {
                            EXPECT_EQ(sweep + pass, 0);
                        } else {
                            EXPECT_GT(sweep, 0);  // (the value pass is taken where few points change layer: not here)
                        }
                    });
                }
}

// The value pass (repair_dense where the last whole-band repair changed few layers) on steps where
// the rule takes points in: a large ball creeping outwards at a hundredth of the speed (every one of
// its zero-layer points moves each step, few change layer) keeps the steps dense while the front
// runs down a tube one voxel across (whose outside contracts at a twentieth: at full speed its
// converged faces change the layer of a tenth of the band every step, and no value pass is taken). The same bits as the full-band step, reports equal to a
// brute-force diff with their sign changes, the invariants every step, on 1 and 2 threads.
TEST(ThinFront, TheValuePassTakesTheRulesEntriesAsTheFullBandStep) {
    class TubeAndSlowBall final : public Speed {
    public:
        SpeedSample at(const Grid<float>&, Vec3i p) const override {
            if (p.z >= 28) return {-0.01f, 0.0f};  // the ball's half: it creeps outwards
            return {tube_.contains(p) ? -1.0f : 0.05f, 0.0f};
        }
        float curvature_weight() const override { return 0.0f; }

    private:
        Thin tube_{1, false};
    };
    const TubeAndSlowBall speed;
    const shapes::Sphere seed({5.0, 11.0, 11.0}, 2.0), ball({32.0, 16.0, 44.0}, 10.0);
    for (int threads : {1, 2}) {
        SCOPED_TRACE("threads " + std::to_string(threads));
        tbb::task_arena(threads).execute([&] {
            SparseField reference(Lattice({64, 32, 64}), 2);
            reference.init_from_sdf([&](Vec3d p) { return std::min(seed(p), ball(p)); });
            SparseField fast = reference;
            SparseField without = reference;
            int pass = 0;
            for (int k = 1; k <= 160; ++k) {
                const SparseField before = fast;
                const StepResult r = reference.step(speed, thin_options(StepMode::kFullBand));
                const StepResult f = fast.step(speed, thin_options(StepMode::kIncremental));
                ASSERT_TRUE(same_state(reference, fast)) << "step " << k;
                ASSERT_EQ(sorted(f.changed.points), brute_force_changes(before, fast)) << "step " << k;
                ASSERT_EQ(sorted(r.changed.points), sorted(f.changed.points)) << "step " << k;
                ASSERT_TRUE(reports_sign_changes(f.changed, before, fast)) << "step " << k;
                const InvariantReport inv = check_invariants(fast);
                ASSERT_TRUE(inv.ok()) << "step " << k << ": " << inv.summary();
                without = before;
                without.step(speed, thin_options(StepMode::kIncremental, false));
                pass += f.value_pass && !same_state(without, fast) ? 1 : 0;
            }
            EXPECT_GT(pass, 20) << "value-pass steps where the rule took points in";
            EXPECT_LT(fast.phi()({40, 12, 12}), 0.0f) << "the front runs down the tube";
        });
    }
}

// The same φ and statuses on 1 and 2 threads, either step, where the rule runs every step on a
// front of over 8 192 points (the rule's passes split into chunks on 2 threads).
TEST(ThinFront, OneAndTwoThreadsAgree) {
    const Thin s{1, true, 180};
    const ThinSpeed speed(s, false);
    for (const StepMode mode : {StepMode::kFullBand, StepMode::kIncremental}) {
        SparseField one(Lattice(s.dims()), 2);  // the whole cube inside to begin with
        one.init_from_sdf(shapes::Box({5.0, 3.5 + s.span / 2.0, 11.0}, {3.0, s.span / 2.0 - 0.5, 3.0}));
        SparseField two = one;
        std::size_t largest = 0;
        tbb::task_arena(1).execute([&] {
            for (int k = 0; k < 400; ++k) largest = std::max(largest, one.step(speed, thin_options(mode)).zero_layer);
        });
        tbb::task_arena(2).execute([&] {
            for (int k = 0; k < 400; ++k) two.step(speed, thin_options(mode));
        });
        EXPECT_GT(largest, std::size_t{8192});
        EXPECT_TRUE(same_state(one, two)) << (mode == StepMode::kFullBand ? "full band" : "incremental");
        const auto [in, out] = reached(one, s, false);
        EXPECT_EQ(in, structure_size(s));  // without the rule the sheet stops a row or two in
        EXPECT_EQ(out, 0);
    }
}

// A speed that throws when asked for a rate beside the zero layer (the rule's call), or for the
// propagation's signs there (the rule's test before it), leaves the field as it was before the
// step: no value moved, no point entered.
TEST(ThinFront, ASpeedThatThrowsInTheRuleLeavesTheFieldAsItWas) {
    class Throwing final : public Speed {
    public:
        Throwing(const Speed& inner, const SparseField& f, bool in_signs) : inner_(inner), f_(f), in_signs_(in_signs) {}
        SpeedSample at(const Grid<float>& phi, Vec3i p) const override { return inner_.at(phi, p); }
        void rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const override {
            if (!in_signs_) off_the_zero_layer(points);
            inner_.rates(phi, points, out);
        }
        void propagation_signs(const Grid<float>& phi, std::span<const PointIndex> points, std::span<std::int8_t> out) const override {
            if (in_signs_) off_the_zero_layer(points);
            inner_.propagation_signs(phi, points, out);
        }
        float curvature_weight() const override { return inner_.curvature_weight(); }

    private:
        void off_the_zero_layer(std::span<const PointIndex> points) const {
            for (PointIndex i : points)
                if (f_.status()[i] != 0) throw std::runtime_error("nothing asked off the zero layer");
        }
        const Speed& inner_;
        const SparseField& f_;
        bool in_signs_;
    };
    const Thin s{1, false};
    const ThinSpeed speed(s, false);
    for (const bool in_signs : {false, true})
        for (const StepMode mode : {StepMode::kFullBand, StepMode::kIncremental}) {
            SparseField f = seeded(s, false);
            int thrown = 0;
            for (int k = 0; k < 120; ++k) {
                SparseField trial = f;
                const Throwing on_trial(speed, trial, in_signs);
                try {
                    trial.step(on_trial, thin_options(mode));
                } catch (const std::runtime_error&) {
                    ++thrown;
                    ASSERT_TRUE(same_state(trial, f)) << "step " << k << (in_signs ? ", in the signs" : ", in the rates");
                    expect_valid(trial, "after the throw");
                }
                f.step(speed, thin_options(mode));
            }
            EXPECT_GT(thrown, 20) << (in_signs ? "in the signs" : "in the rates");
        }
}
