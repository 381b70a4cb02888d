// Mean curvature flow: a sphere follows r(t)² = r0² − 4t; the paper's box shrinks monotonically
// and vanishes with a valid band at every step.
#include <gtest/gtest.h>

#include <cmath>

#include "levelset_test_util.hpp"
#include "liveset/levelset/curvature_flow.hpp"
#include "liveset/levelset/shapes.hpp"

using namespace liveset;
using liveset::testing::expect_valid;

TEST(MeanCurvatureFlow, SphereRadiusFollowsTheAnalyticLaw) {
    const double r0 = 20.0;
    SparseField f(Lattice({64, 64, 64}), 2);
    f.init_from_sdf(shapes::Sphere({31.5, 31.5, 31.5}, r0));
    const CurvatureSpeed speed;
    double t = 0.0;
    int checked = 0;
    double next_check = 10.0;
    for (int step = 0; step < 20000 && !f.zero_layer().empty(); ++step) {
        const StepResult s = f.step(speed);
        t += s.dt;
        if (t < next_check) continue;
        const double r2 = r0 * r0 - 4.0 * t;
        if (r2 < 25.0) break;  // until r ≈ 5
        const double expected = std::sqrt(r2);
        const double measured = equivalent_radius(f);
        // Whitaker's first-order outer-layer values bias κ by ~+5 % (layer_value.hpp): r² drifts
        // by ~4 % of 4t, which stays within 3 % of r down to r ≈ 8 and reaches ~5 % at r ≈ 6.
        const double tolerance = expected >= 8.0 ? 0.03 : 0.06;
        EXPECT_NEAR(measured / expected, 1.0, tolerance) << "t=" << t << " r=" << measured << " expected " << expected;
        EXPECT_LT(measured, expected) << "curvature bias should only speed the flow up";
        expect_valid(f, "sphere flow");
        ++checked;
        next_check += 10.0;
    }
    EXPECT_GE(checked, 8);
}

TEST(MeanCurvatureFlow, SmallBoxValidAtEveryStepAndVanishes) {
    BoxFlowOptions o;
    o.lattice = 36;
    o.box = 18;
    SparseField f = make_box_field(o);
    double last_volume = enclosed_volume(f);
    int steps = 0;
    const BoxFlowReport rep = run_curvature_flow(f, 5000, 0.5f, [&](const SparseField& fs, const StepResult&, const FlowStepRecord&) {
        ++steps;
        expect_valid(fs, "box step");
        const double v = enclosed_volume(fs);
        EXPECT_LE(v, last_volume + 1e-9) << "step " << steps;
        last_volume = v;
        return !::testing::Test::HasFailure();
    });
    EXPECT_TRUE(rep.vanished);
    EXPECT_LT(last_volume, 1.0);
}

TEST(MeanCurvatureFlow, PaperBoxVanishesNearTheExpectedTime) {
    // 50³ box in 100³: other implementations report t ≈ 236 (κ = k1 + k2) until it vanishes.
    SparseField f = make_box_field({});
    double last_volume = enclosed_volume(f);
    const BoxFlowReport rep = run_curvature_flow(f, 5000, 0.5f, [&](const SparseField& fs, const StepResult&, const FlowStepRecord& r) {
        if (r.step % 100 == 0) {
            expect_valid(fs, "paper box");
            const double v = enclosed_volume(fs);
            EXPECT_LT(v, last_volume);
            last_volume = v;
        }
        return true;
    });
    ASSERT_TRUE(rep.vanished);
    EXPECT_NEAR(rep.steps.back().time, 236.0, 0.05 * 236.0);
}
