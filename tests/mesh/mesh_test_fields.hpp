// Shared φ fields for the mesh tests: exact sphere and torus signed distances and seeded random
// grids (φ < 0 inside); and the bit-for-bit mesh comparison.
#pragma once

#include <cmath>
#include <cstdint>
#include <random>

#include <gtest/gtest.h>

#include "liveset/grid/grid.hpp"
#include "liveset/mesh/mesh.hpp"

namespace liveset::testing {

inline Grid<float> sphere_field(Vec3i dims, Vec3d center, double radius) {
    Grid<float> g{Lattice(dims)};
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x)
                g({x, y, z}) = static_cast<float>(norm(Vec3d{double(x), double(y), double(z)} - center) - radius);
    return g;
}

// Torus around the z axis through `center`: major radius R, minor radius r.
inline Grid<float> torus_field(Vec3i dims, Vec3d center, double R, double r) {
    Grid<float> g{Lattice(dims)};
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x) {
                const Vec3d p = Vec3d{double(x), double(y), double(z)} - center;
                const double q = std::hypot(p.x, p.y) - R;
                g({x, y, z}) = static_cast<float>(std::hypot(q, p.z) - r);
            }
    return g;
}

// Uniform values in [-1, 1]; with outside_border the lattice border is set to +1 so the level set
// is closed. With zeros, about a third of the values are exactly 0 (and the rest ±1).
inline Grid<float> random_field(Vec3i dims, std::uint32_t seed, bool outside_border, bool zeros = false) {
    Grid<float> g{Lattice(dims)};
    std::mt19937 rng(seed);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    std::uniform_int_distribution<int> tri(-1, 1);
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y)
            for (int x = 0; x < dims.x; ++x) {
                const bool border = x == 0 || y == 0 || z == 0 || x == dims.x - 1 || y == dims.y - 1 || z == dims.z - 1;
                float v = zeros ? static_cast<float>(tri(rng)) : u(rng);
                if (outside_border && border) v = 1.0f;
                g({x, y, z}) = v;
            }
    return g;
}

// The same vertices (positions and normals, bit for bit) and the same triangles in the same order.
inline void expect_identical(const Mesh& a, const Mesh& b) {
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    ASSERT_EQ(a.indices, b.indices);
    for (std::size_t i = 0; i < a.vertices.size(); ++i)
        for (int k = 0; k < 3; ++k) {
            ASSERT_EQ(a.vertices[i].position[k], b.vertices[i].position[k]) << "vertex " << i;
            ASSERT_EQ(a.vertices[i].normal[k], b.vertices[i].normal[k]) << "vertex " << i;
        }
}

}  // namespace liveset::testing
