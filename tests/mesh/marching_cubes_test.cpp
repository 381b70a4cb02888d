// Whole-lattice marching cubes: crack-free on random fields, closed 2-manifolds with the right
// topology and geometry on analytic shapes, naive == band-driven, and the analysis utilities.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <random>
#include <cmath>
#include <numbers>

#include "liveset/mesh/cell_polygoniser.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "mesh/mesh_test_fields.hpp"

namespace liveset {
namespace {

using testing::random_field;
using testing::sphere_field;
using testing::torus_field;

Vec3d pos(const Vertex& v) { return {v.position[0], v.position[1], v.position[2]}; }

bool on_same_border_plane(const Vertex& a, const Vertex& b, Vec3i dims) {
    for (int k = 0; k < 3; ++k) {
        for (float plane : {0.0f, float(dims[k] - 1)})
            if (a.position[k] == plane && b.position[k] == plane) return true;
    }
    return false;
}

using testing::expect_identical;

TEST(MarchingCubes, RandomFieldsAreCrackFreeAndConsistentlyOriented) {
    const Vec3i dims{9, 10, 11};
    for (std::uint32_t seed = 1; seed <= 40; ++seed) {
        const Grid<float> phi = random_field(dims, seed, false);
        const Mesh m = marching_cubes_naive(phi);
        ASSERT_GT(m.triangle_count(), 100u);
        // G shares vertices between cells; welding by position must not merge anything more.
        const Mesh w = weld_vertices(m, 1e-5);
        EXPECT_EQ(w.vertices.size(), m.vertices.size());
        EXPECT_EQ(w.triangle_count(), m.triangle_count());
        for (const auto& e : edges_not_shared_by_two(w))
            EXPECT_TRUE(on_same_border_plane(w.vertices[e[0]], w.vertices[e[1]], dims))
                << "seed " << seed << ": interior edge not shared by 2 triangles";
        const EdgeStats s = edge_stats(w);
        EXPECT_EQ(s.nonmanifold_edges, 0u);
        EXPECT_EQ(s.misoriented_edges, 0u);
        EXPECT_GT(s.boundary_edges, 0u);
        EXPECT_EQ(invalid_normal_count(m), 0u);
    }
}

TEST(MarchingCubes, RandomFieldsWithOutsideBorderAreClosedManifolds) {
    for (std::uint32_t seed = 100; seed < 130; ++seed) {
        for (bool zeros : {false, true}) {
            const Grid<float> phi = random_field({10, 9, 8}, seed, true, zeros);
            const Mesh w = weld_vertices(marching_cubes_naive(phi), 1e-5);
            const EdgeStats s = edge_stats(w);
            EXPECT_TRUE(s.closed_manifold()) << "seed " << seed << " zeros " << zeros << ": boundary "
                                             << s.boundary_edges << " nonmanifold " << s.nonmanifold_edges
                                             << " misoriented " << s.misoriented_edges;
            EXPECT_EQ(nonmanifold_vertices(w), 0u) << "seed " << seed;
            EXPECT_GT(enclosed_volume(w), 0.0) << "seed " << seed;
            // χ is even on a closed orientable surface, 2 per sphere-like component at most.
            const long long chi = euler_characteristic(w);
            EXPECT_EQ(chi % 2, 0);
            EXPECT_LE(chi, 2 * static_cast<long long>(connected_components(w)));
        }
    }
}

void check_sphere(Vec3d c, double r) {
    const Grid<float> phi = sphere_field({64, 64, 64}, c, r);
    const Mesh m = marching_cubes_naive(phi);
    const Mesh w = weld_vertices(m, 1e-5);
    EXPECT_EQ(w.vertices.size(), m.vertices.size());
    EXPECT_TRUE(edge_stats(w).closed_manifold());
    EXPECT_EQ(nonmanifold_vertices(w), 0u);
    EXPECT_EQ(euler_characteristic(w), 2);
    EXPECT_EQ(connected_components(w), 1u);
    const double pi = std::numbers::pi;
    EXPECT_NEAR(surface_area(w), 4 * pi * r * r, 0.01 * 4 * pi * r * r);
    EXPECT_NEAR(enclosed_volume(w), 4.0 / 3.0 * pi * r * r * r, 0.01 * 4.0 / 3.0 * pi * r * r * r);
    EXPECT_EQ(invalid_normal_count(m, 1e-5), 0u);
    EXPECT_EQ(invalid_position_count(m), 0u);
    for (const Vertex& v : m.vertices) {
        const Vec3d d = pos(v) - c;
        ASSERT_NEAR(norm(d), r, 0.05);
        const Vec3d n{v.normal[0], v.normal[1], v.normal[2]};
        ASSERT_GT(dot(n, d / norm(d)), 0.99);
    }
    // Triangle winding: face normals point outwards.
    for (std::size_t t = 0; t < m.indices.size(); t += 3) {
        const Vec3d a = pos(m.vertices[m.indices[t]]), b = pos(m.vertices[m.indices[t + 1]]),
                    cc = pos(m.vertices[m.indices[t + 2]]);
        const Vec3d n = cross(b - a, cc - a);
        if (norm(n) < 1e-6) continue;
        ASSERT_GT(dot(n, (a + b + cc) / 3.0 - c), 0.0);
    }
}

TEST(MarchingCubes, SphereIsClosedWithAnalyticAreaVolumeAndNormals) {
    check_sphere({31.71, 32.23, 31.37}, 20.0);
    // Integer centre: many lattice points have φ exactly 0.
    check_sphere({32, 32, 32}, 20.0);
}

TEST(MarchingCubes, TorusHasGenusOne) {
    const double R = 16, r = 6, pi = std::numbers::pi;
    const Grid<float> phi = torus_field({64, 64, 48}, {31.6, 32.3, 23.8}, R, r);
    const Mesh w = weld_vertices(marching_cubes_naive(phi), 1e-5);
    EXPECT_TRUE(edge_stats(w).closed_manifold());
    EXPECT_EQ(euler_characteristic(w), 0);
    EXPECT_EQ(connected_components(w), 1u);
    EXPECT_NEAR(surface_area(w), 4 * pi * pi * R * r, 0.01 * 4 * pi * pi * R * r);
    EXPECT_NEAR(enclosed_volume(w), 2 * pi * pi * R * r * r, 0.01 * 2 * pi * pi * R * r * r);
}

TEST(MarchingCubes, TwoSpheresGiveTwoComponents) {
    Grid<float> a = sphere_field({40, 24, 24}, {10.3, 11.6, 12.1}, 6);
    const Grid<float> b = sphere_field({40, 24, 24}, {28.4, 11.9, 11.2}, 7);
    for (PointIndex i = 0; i < a.size(); ++i) a[i] = std::min(a[i], b[i]);
    const Mesh w = weld_vertices(marching_cubes_naive(a), 1e-5);
    EXPECT_EQ(connected_components(w), 2u);
    EXPECT_EQ(euler_characteristic(w), 4);
}

TEST(MarchingCubes, BandDrivenEqualsNaive) {
    std::vector<Grid<float>> fields;
    fields.push_back(sphere_field({64, 64, 64}, {31.71, 32.23, 31.37}, 20));
    fields.push_back(torus_field({48, 48, 40}, {23.5, 24.2, 19.7}, 12, 5));
    for (std::uint32_t s = 0; s < 10; ++s) fields.push_back(random_field({12, 13, 9}, s, s % 2 == 0, s % 3 == 0));
    for (const Grid<float>& phi : fields) {
        const Mesh naive = marching_cubes_naive(phi);
        // Minimal zero layer.
        const std::vector<PointIndex> zero = zero_crossing_points(phi);
        expect_identical(marching_cubes_band(phi, zero), naive);
        // A wider band with duplicates and unsorted order.
        std::vector<PointIndex> wide;
        for (PointIndex i = static_cast<PointIndex>(phi.size()); i-- > 0;)
            if (std::abs(phi[i]) < 1.5f) wide.push_back(i);
        wide.insert(wide.end(), zero.begin(), zero.end());
        expect_identical(marching_cubes_band(phi, wide), naive);
        // One side of each crossing edge is enough: keep only the inside points of the zero layer.
        std::vector<PointIndex> inside_only;
        for (PointIndex i : zero)
            if (is_inside(phi[i])) inside_only.push_back(i);
        expect_identical(marching_cubes_band(phi, inside_only), naive);
    }
}

TEST(MarchingCubes, BandDrivenRejectsBadIndices) {
    const Grid<float> phi = random_field({5, 5, 5}, 3, true);
    const std::vector<PointIndex> bad{125};
    EXPECT_THROW(marching_cubes_band(phi, bad), std::out_of_range);
}

TEST(MarchingCubes, EdgeVertexInterpolatesAndKeepsMargin) {
    Grid<float> phi(Lattice(Vec3i{3, 3, 3}), 1.0f);
    phi({1, 1, 1}) = -0.25f;  // crossing to +1 along +x at t = 0.2
    const Vertex v = make_edge_vertex(phi, {1, 1, 1}, 0);
    EXPECT_FLOAT_EQ(v.position[0], 1.2f);
    EXPECT_FLOAT_EQ(v.position[1], 1.0f);
    EXPECT_FLOAT_EQ(v.normal[0], 1.0f);  // gradient at (2,1,1) is 0 on x by one-sided... direction +x
    phi({2, 1, 1}) = 0.0f;  // exact zero at the outside end: clamped off the lattice point
    const Vertex z = make_edge_vertex(phi, {1, 1, 1}, 0);
    EXPECT_NEAR(z.position[0], 2.0f - kEdgeVertexMargin, 1e-6);
    // Flat gradient falls back to the edge direction from inside to outside.
    Grid<float> flat{Lattice(Vec3i{2, 1, 1})};
    flat({0, 0, 0}) = 1.0f;
    flat({1, 0, 0}) = -1.0f;
    const Vertex f = make_edge_vertex(flat, {0, 0, 0}, 0);
    EXPECT_FLOAT_EQ(f.normal[0], -1.0f);
    EXPECT_FLOAT_EQ(f.position[0], 0.5f);
}

// The vertex refresh (four interior edges at a time with SSE where available) gives exactly the
// bits of the scalar make_edge_vertex() for every lattice edge, in an order that mixes interior
// and border edges, on values that hit every branch: exact zeros, equal endpoints (t = 0/0),
// flat neighbourhoods (zero gradient), overflowing differences and tiny (subnormal) values.
TEST(MarchingCubes, RefreshedVerticesEqualTheScalarEdgeVertexBitForBit) {
    Grid<float> phi(Lattice(Vec3i{16, 15, 14}));
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-2.0f, 2.0f);
    std::uniform_int_distribution<int> kind(0, 9);
    for (std::size_t i = 0; i < phi.size(); ++i) {
        const int k = kind(rng);
        float v = u(rng);
        if (k == 0) v = 0.0f;
        if (k == 1) v = 1.0f;  // repeated values: equal endpoints and flat patches
        if (k == 2) v = v < 0.0f ? -3.0e38f : 3.0e38f;
        if (k == 3) v *= 1.0e-40f;
        phi[static_cast<PointIndex>(i)] = v;
    }
    std::vector<CellPolygoniser::EdgeRef> edges;
    const Vec3i d = phi.dims();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x)
                for (int a = 0; a < 3; ++a) {
                    Vec3i q{x, y, z};
                    q[a] += 1;
                    if (phi.lattice().contains(q)) edges.push_back({{x, y, z}, a});
                }
    std::shuffle(edges.begin(), edges.end(), rng);
    std::vector<Vertex> out(edges.size());
    CellPolygoniser poly;
    poly.refresh_vertices(phi, edges, out);
    std::size_t interior_blocks = 0;
    for (std::size_t k = 0; k < edges.size(); ++k) {
        const Vertex want = make_edge_vertex(phi, edges[k].p, edges[k].axis);
        for (int c = 0; c < 3; ++c) {
            ASSERT_EQ(std::bit_cast<std::uint32_t>(out[k].position[c]), std::bit_cast<std::uint32_t>(want.position[c])) << "edge " << k;
            ASSERT_EQ(std::bit_cast<std::uint32_t>(out[k].normal[c]), std::bit_cast<std::uint32_t>(want.normal[c])) << "edge " << k;
        }
    }
    for (std::size_t k = 0; k + 4 <= edges.size(); k += 4) {
        bool all = true;
        for (std::size_t l = k; l < k + 4; ++l) {
            const Vec3i p = edges[l].p, q = p + Vec3i{edges[l].axis == 0, edges[l].axis == 1, edges[l].axis == 2};
            all = all && p.x >= 1 && p.y >= 1 && p.z >= 1 && q.x <= d.x - 2 && q.y <= d.y - 2 && q.z <= d.z - 2;
        }
        interior_blocks += all;
    }
    EXPECT_GT(interior_blocks, 20u);  // the four-at-a-time path did run
}

TEST(MeshAnalysis, CubeBoxHasKnownMeasures) {
    // Unit cube made of 12 triangles, counter-clockwise from outside.
    Mesh m;
    for (int c = 0; c < 8; ++c) m.vertices.push_back({{float(c & 1), float((c >> 1) & 1), float((c >> 2) & 1)}, {1, 0, 0}});
    const std::uint32_t q[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
    for (const auto& f : q) m.indices.insert(m.indices.end(), {f[0], f[1], f[2], f[0], f[2], f[3]});
    EXPECT_DOUBLE_EQ(surface_area(m), 6.0);
    EXPECT_DOUBLE_EQ(enclosed_volume(m), 1.0);
    EXPECT_EQ(euler_characteristic(m), 2);
    EXPECT_TRUE(edge_stats(m).closed_manifold());
    EXPECT_EQ(connected_components(m), 1u);
    // Duplicate every vertex: not welded -> all boundary; welded -> closed again.
    Mesh split;
    for (std::uint32_t i : m.indices) {
        split.indices.push_back(static_cast<std::uint32_t>(split.vertices.size()));
        split.vertices.push_back(m.vertices[i]);
    }
    EXPECT_EQ(edge_stats(split).boundary_edges, 36u);
    EXPECT_EQ(connected_components(split), 12u);
    const Mesh w = weld_vertices(split);
    EXPECT_EQ(w.vertices.size(), 8u);
    EXPECT_TRUE(edge_stats(w).closed_manifold());
    EXPECT_EQ(canonical_triangles(w), canonical_triangles(m));
    // Flip one triangle: misoriented edges detected and volume changes.
    std::swap(m.indices[1], m.indices[2]);
    EXPECT_EQ(edge_stats(m).misoriented_edges, 3u);
    m.vertices[0].normal[0] = std::nanf("");
    m.vertices[1].normal[0] = 0;
    EXPECT_EQ(invalid_normal_count(m), 2u);
}

}  // namespace
}  // namespace liveset
