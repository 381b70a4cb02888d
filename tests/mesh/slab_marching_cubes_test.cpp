// The slab-parallel whole-volume marching cubes against the naive reference: the same vertices
// (bit for bit) and the same triangles in the same order, for any slab size and thread count,
// on random fields (with exact zeros, multi-word rows, odd sizes) and analytic shapes.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <limits>
#include <stdexcept>

#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/mesh/slab_marching_cubes.hpp"
#include "mesh/mesh_test_fields.hpp"

namespace liveset {
namespace {

using testing::random_field;
using testing::sphere_field;
using testing::torus_field;

using testing::expect_identical;

void check_all_settings(const Grid<float>& phi) {
    const Mesh ref = marching_cubes_naive(phi);
    for (int threads : {1, 2}) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
        for (int layers : {1, 2, 3, 7, 16, 1000}) {
            SCOPED_TRACE(::testing::Message() << "threads " << threads << ", slab_layers " << layers);
            expect_identical(marching_cubes_slabs(phi, {layers}), ref);
        }
    }
}

TEST(SlabMarchingCubes, RandomFieldsEqualNaiveExactly) {
    const Vec3i dims[] = {{9, 10, 11}, {2, 2, 2}, {70, 5, 6}, {129, 4, 9}, {64, 3, 5}, {65, 7, 3}};
    std::uint32_t seed = 1;
    for (const Vec3i& d : dims)
        for (bool border : {false, true})
            for (bool zeros : {false, true}) {
                SCOPED_TRACE(::testing::Message() << "dims " << d << " seed " << seed);
                const Grid<float> phi = random_field(d, seed++, border, zeros);
                if (!(border && d.x == 2)) {  // a 2³ lattice is all border: no surface
                    ASSERT_GT(marching_cubes_naive(phi).triangle_count(), 0u);
                }
                check_all_settings(phi);
            }
}

TEST(SlabMarchingCubes, AnalyticShapesEqualNaiveAndBand) {
    const Grid<float> sphere = sphere_field({40, 37, 45}, {19.3, 18.1, 22.7}, 14.2);
    check_all_settings(sphere);
    const Grid<float> torus = torus_field({48, 48, 30}, {23.5, 23.5, 14.5}, 14.0, 5.0);
    check_all_settings(torus);
    // The slab mesh is a closed sphere: Euler characteristic 2 once welded (it is already shared).
    const Mesh m = marching_cubes_slabs(sphere, {3});
    EXPECT_EQ(euler_characteristic(m), 2);
    EXPECT_EQ(canonical_triangles(m), canonical_triangles(marching_cubes_band(sphere, zero_crossing_points(sphere))));
}

TEST(SlabMarchingCubes, SignBitsMatchIsInside) {
    Grid<float> phi = random_field({67, 3, 2}, 99, false, true);
    phi({1, 0, 0}) = -0.0f;
    phi({2, 0, 0}) = std::numeric_limits<float>::quiet_NaN();
    phi({3, 0, 0}) = -std::numeric_limits<float>::infinity();
    const SignBits s = sign_bits(phi);
    ASSERT_EQ(s.words_per_row, 2u);
    for (int z = 0; z < 2; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 128; ++x) {
                const bool bit = (s.row(y, z)[x / 64] >> (x % 64)) & 1u;
                EXPECT_EQ(bit, x < 67 && is_inside(phi({x, y, z}))) << x << "," << y << "," << z;
            }
}

TEST(SlabMarchingCubes, FlatLatticesAndBadOptions) {
    EXPECT_EQ(marching_cubes_slabs(random_field({1, 5, 5}, 3, false)).triangle_count(), 0u);
    EXPECT_EQ(marching_cubes_slabs(random_field({5, 5, 1}, 3, false)).triangle_count(), 0u);
    EXPECT_THROW(marching_cubes_slabs(random_field({4, 4, 4}, 3, false), {0}), std::invalid_argument);
}

}  // namespace
}  // namespace liveset
