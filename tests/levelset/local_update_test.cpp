// Local updates: equal to the global repair bitwise, report exactly the changed points, stay local,
// and reject bad edits without changing anything.
#include <gtest/gtest.h>

#include <random>

#include "levelset_test_util.hpp"
#include "liveset/levelset/shapes.hpp"

using namespace liveset;
using namespace liveset::testing;

namespace {
SparseField sphere_field(int n = 40, double r = 12.0, int layers = 2) {
    SparseField f(Lattice({n, n, n}), layers);
    const double c = (n - 1) / 2.0;
    f.init_from_sdf(shapes::Sphere({c, c, c}, r));
    return f;
}
}  // namespace

TEST(LocalUpdate, RandomEditSequencesEqualTheGlobalRepairBitwise) {
    for (int layers : {1, 2, 3}) {
        SparseField local = sphere_field(40, 12.0, layers);
        SparseField global = local;
        std::mt19937 rng(1234 + layers);
        for (int e = 0; e < 300; ++e) {
            const auto edits = random_edit(local, rng);
            const SparseField before = local;
            const ChangedPoints xl = local.apply_edits(edits, RepairScope::kLocal);
            const ChangedPoints xg = global.apply_edits(edits, RepairScope::kGlobal);
            ASSERT_TRUE(same_state(local, global)) << "layers " << layers << " edit " << e;
            // X is exactly the set of points whose φ or status changed.
            ASSERT_EQ(sorted(xl.points), brute_force_changes(before, local)) << "edit " << e;
            ASSERT_EQ(sorted(xg.points), sorted(xl.points)) << "edit " << e;
            ASSERT_TRUE(reports_sign_changes(xl, before, local)) << "edit " << e;
            ASSERT_TRUE(reports_sign_changes(xg, before, global)) << "edit " << e;
            if (e % 25 == 0) expect_valid(local, "random edits");
        }
        expect_valid(local, "after random edits");
    }
}

TEST(LocalUpdate, GlobalStepEqualsItsDeltasAppliedLocally) {
    SparseField a = sphere_field();
    SparseField b = a;
    const CurvatureSpeed speed;
    std::mt19937 rng(7);
    for (int s = 0; s < 60; ++s) {
        double dt = 0.0;
        const auto deltas = b.compute_step(speed, {}, &dt);
        a.step(speed);
        b.apply_edits(deltas, RepairScope::kLocal);
        ASSERT_TRUE(same_state(a, b)) << "step " << s;
        // Interleave local edits so the two paths see irregular fronts.
        const auto edits = random_edit(a, rng);
        a.apply_edits(edits, RepairScope::kGlobal);
        b.apply_edits(edits, RepairScope::kLocal);
        ASSERT_TRUE(same_state(a, b)) << "edit after step " << s;
    }
    expect_valid(a, "steps and edits");
}

TEST(LocalUpdate, RepeatedPushesMoveTheFrontAndStayValid) {
    // Push the same spot outwards many times: the front must travel several voxels.
    SparseField f = sphere_field(48, 10.0);
    const Vec3i tip{34, 23, 23};  // just outside the sphere along +x (centre 23.5, r 10)
    for (int k = 0; k < 40; ++k) {
        f.apply_in_box(tip - Vec3i{14, 3, 3}, tip + Vec3i{6, 3, 3}, [&](Vec3i p, float) {
            return (std::abs(p.y - tip.y) <= 2 && std::abs(p.z - tip.z) <= 2) ? -0.5f : 0.0f;
        });
    }
    expect_valid(f, "pushed");
    EXPECT_LT(f.phi()({36, 23, 23}), 0.0f);  // the front passed x = 36
    EXPECT_GT(f.phi()({23, 23, 40}), 0.0f);  // far side untouched: still outside
}

TEST(LocalUpdate, ChangesStayNearTheEdit) {
    SparseField f = sphere_field();
    const SparseField before = f;
    const PointIndex seed = f.zero_layer()[0];
    const Vec3i c = f.lattice().coord(seed);
    const ChangedPoints x = f.apply_edits(std::vector<ZeroLayerEdit>{{seed, 0.5f}});
    ASSERT_FALSE(x.empty());
    for (PointIndex i : x.points) {
        const Vec3i d = f.lattice().coord(i) - c;
        EXPECT_LE(std::abs(d.x) + std::abs(d.y) + std::abs(d.z), f.layers() + 1);
    }
}

TEST(LocalUpdate, BadEditsThrowAndChangeNothing) {
    SparseField f = sphere_field();
    const SparseField before = f;
    const PointIndex z = f.zero_layer()[0];
    const PointIndex far = f.lattice().index({0, 0, 0});
    EXPECT_THROW(f.apply_edits(std::vector<ZeroLayerEdit>{{z, 0.1f}, {far, 0.1f}}), std::invalid_argument);
    EXPECT_THROW(f.apply_edits(std::vector<ZeroLayerEdit>{{z, NAN}}), std::invalid_argument);
    EXPECT_THROW(f.apply_edits(std::vector<ZeroLayerEdit>{{static_cast<PointIndex>(f.lattice().size()), 0.1f}}),
                 std::invalid_argument);
    EXPECT_TRUE(same_state(f, before));
    EXPECT_TRUE(f.apply_edits({}).empty());
}

TEST(LocalUpdate, DuplicateEditsAreSummedAndClamped) {
    SparseField a = sphere_field();
    SparseField b = a;
    const PointIndex z = a.zero_layer()[3];
    a.apply_edits(std::vector<ZeroLayerEdit>{{z, 0.1f}, {z, 0.15f}});
    b.apply_edits(std::vector<ZeroLayerEdit>{{z, 0.25f}});
    EXPECT_TRUE(same_state(a, b));
    SparseField c = a, d = a;
    const PointIndex y = c.zero_layer()[5];
    c.apply_edits(std::vector<ZeroLayerEdit>{{y, 7.0f}});
    d.apply_edits(std::vector<ZeroLayerEdit>{{y, 0.5f}});
    EXPECT_TRUE(same_state(c, d));
}
