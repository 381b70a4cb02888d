// SparseField::unite_in_box (a seed ball added where the user clicks) against the whole-lattice
// re-initialisation init_from_sdf(min(φ, ball)) it replaces: the same φ and statuses bit for bit,
// X exactly the points that changed, valid layers — for balls inside the front, across it, far
// from it, at the lattice's edge, and one after another; and a refusal that changes nothing.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "levelset_test_util.hpp"
#include "liveset/levelset/shapes.hpp"

using namespace liveset;
using liveset::testing::brute_force_changes;
using liveset::testing::expect_valid;
using liveset::testing::same_state;
using liveset::testing::sorted;

namespace {

// The whole-lattice re-initialisation also re-snaps, anywhere in the band, a point off the zero
// layer whose φ is exactly ±0.5; the local union only touches the ball's neighbourhood. The two
// agree bit for bit when the field has no such point (checked, so the comparison is exact).
bool has_exact_half_off_zero(const SparseField& f) {
    for (std::size_t n = 0; n < f.phi().size(); ++n) {
        const auto i = static_cast<PointIndex>(n);
        if (f.status()[i] != 0 && std::abs(f.phi()[i]) == 0.5f) return true;
    }
    return false;
}

Vec3i floor3(Vec3d p) {
    return {static_cast<int>(std::floor(p.x)), static_cast<int>(std::floor(p.y)), static_cast<int>(std::floor(p.z))};
}
Vec3i ceil3(Vec3d p) { return {static_cast<int>(std::ceil(p.x)), static_cast<int>(std::ceil(p.y)), static_cast<int>(std::ceil(p.z))}; }

// One ball both ways from `field`; returns the locally updated field.
SparseField unite_both_ways(const SparseField& field, const shapes::Sphere& ball, const std::string& what) {
    SCOPED_TRACE(what);
    SparseField global = field;
    const Grid<float>& phi = field.phi();
    const Lattice& lat = field.lattice();
    global.init_from_sdf([&](Vec3d p) { return std::min(static_cast<double>(phi[lat.index(p.cast<int>())]), ball(p)); });
    SparseField local = field;
    const double reach = ball.radius + field.layers() + 1.0;
    const Vec3d r{reach, reach, reach};
    const ChangedPoints x = local.unite_in_box(floor3(ball.center - r), ceil3(ball.center + r), ball);
    EXPECT_TRUE(same_state(local, global));
    EXPECT_EQ(sorted(x.points), brute_force_changes(field, local));
    EXPECT_TRUE(liveset::testing::reports_sign_changes(x, field, local));
    expect_valid(local, what.c_str());
    return local;
}

}  // namespace

TEST(SparseFieldUnite, EqualsTheWholeLatticeReinitialisationBallAfterBall) {
    const Lattice lat({40, 36, 32});
    SparseField f(lat, 2);
    f.init_from_sdf(shapes::Sphere({19.3, 17.6, 15.2}, 7.7));
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    int compared = 0;
    for (int k = 0; k < 40; ++k) {
        // Centres anywhere, edges included; radii from the session's minimum seed (0.5) up.
        const Vec3d c{u(rng) * 39.0, u(rng) * 35.0, u(rng) * 31.0};
        const shapes::Sphere ball(c, 0.5 + 4.0 * u(rng));
        if (has_exact_half_off_zero(f)) {  // the global path would re-snap far away: compare near the ball only
            SparseField local = f;
            const double reach = ball.radius + f.layers() + 1.0;
            const Vec3d r{reach, reach, reach};
            local.unite_in_box(floor3(c - r), ceil3(c + r), ball);
            expect_valid(local, ("ball " + std::to_string(k)).c_str());
            f = std::move(local);
            continue;
        }
        f = unite_both_ways(f, ball, "ball " + std::to_string(k));
        ++compared;
    }
    EXPECT_GE(compared, 30) << "too few balls compared bit for bit";
}

TEST(SparseFieldUnite, InsideAcrossFarAndEmpty) {
    const Lattice lat({32, 32, 32});
    SparseField f(lat, 2);
    f.init_from_sdf(shapes::Sphere({15.4, 16.1, 15.7}, 6.3));
    ASSERT_FALSE(has_exact_half_off_zero(f));
    unite_both_ways(f, shapes::Sphere({15.4, 16.1, 15.7}, 2.0), "deep inside: nothing changes");
    unite_both_ways(f, shapes::Sphere({21.9, 16.0, 15.5}, 2.5), "across the front");
    unite_both_ways(f, shapes::Sphere({4.2, 27.8, 5.1}, 1.5), "far away: a new piece");
    unite_both_ways(f, shapes::Sphere({0.0, 31.0, 0.0}, 3.0), "on the lattice's corner");
    SparseField empty(lat, 2);
    empty.init_from_sdf([](Vec3d) { return 3.0; });
    unite_both_ways(empty, shapes::Sphere({10.3, 12.7, 9.9}, 2.2), "the first seed in an empty field");
}

TEST(SparseFieldUnite, AStepShapeIsPulledOntoTheZeroLayerAsByTheReinitialisation) {
    // Not a distance: -10 inside a box, +10 outside. init_from_sdf pulls both sides of every such
    // sign change onto the zero layer; so must the local union.
    const Lattice lat({28, 28, 28});
    SparseField f(lat, 2);
    f.init_from_sdf(shapes::Sphere({8.3, 8.6, 9.1}, 4.4));
    ASSERT_FALSE(has_exact_half_off_zero(f));
    const auto step = [](Vec3d p) {
        const bool in = p.x >= 15 && p.x <= 19 && p.y >= 14 && p.y <= 20 && p.z >= 13 && p.z <= 18;
        return in ? -10.0 : 10.0;
    };
    SparseField global = f;
    const Grid<float>& phi = f.phi();
    global.init_from_sdf([&](Vec3d p) { return std::min(static_cast<double>(phi[lat.index(p.cast<int>())]), step(p)); });
    SparseField local = f;
    const ChangedPoints x = local.unite_in_box({14, 13, 12}, {20, 21, 19}, step);
    EXPECT_TRUE(same_state(local, global));
    EXPECT_EQ(sorted(x.points), brute_force_changes(f, local));
    EXPECT_EQ(local.status()({15, 16, 15}), 0);  // a pulled point: on the zero layer
    expect_valid(local, "step shape");
}

TEST(SparseFieldUnite, AShapeThatIsNotFiniteChangesNothing) {
    const Lattice lat({24, 24, 24});
    SparseField f(lat, 2);
    f.init_from_sdf(shapes::Sphere({12, 12, 12}, 5));
    const SparseField before = f;
    EXPECT_THROW(f.unite_in_box({0, 0, 0}, {23, 23, 23}, [](Vec3d p) { return p.x > 20 ? NAN : p.x - 30.0; }),
                 std::invalid_argument);
    EXPECT_TRUE(same_state(f, before));
    expect_valid(f, "after the refusal");
}
