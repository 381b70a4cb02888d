// Mean curvature by difference of normals against analytic shapes: sphere 2/r, cylinder 1/r, plane 0,
// in 1/mm on anisotropic lattices too.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "liveset/levelset/shapes.hpp"
#include "liveset/levelset/speed.hpp"

using namespace liveset;

namespace {
template <class F>
Grid<float> sample(int n, F f) {
    Grid<float> g(Lattice({n, n, n}));
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) g({x, y, z}) = static_cast<float>(f(Vec3d{double(x), double(y), double(z)}));
    return g;
}
}  // namespace

TEST(Curvature, SphereIsTwoOverR) {
    for (double r : {6.0, 10.0, 20.0}) {
        const Vec3d c{31.5, 31.5, 31.5};
        const Grid<float> g = sample(64, shapes::Sphere(c, r));
        // Points near the surface in several directions.
        for (Vec3d dir : {Vec3d{1, 0, 0}, Vec3d{0, 1, 0}, Vec3d{1, 1, 0}, Vec3d{1, 1, 1}, Vec3d{-1, 2, 0.5}}) {
            const Vec3d u = dir / norm(dir);
            const Vec3d p = c + u * r;
            const Vec3i q{int(std::lround(p.x)), int(std::lround(p.y)), int(std::lround(p.z))};
            const double at = norm(q.cast<double>() - c);  // curvature of the level set through q
            EXPECT_NEAR(mean_curvature(g, q), 2.0 / at, 0.06 * 2.0 / at) << "r=" << r;
        }
    }
}

// κ is per millimetre: a sphere of radius r mm sampled on grids of other voxel sizes, anisotropic
// ones included, gives 2/r (the index-unit curvature gave 2/r only at 1 mm, and on a 1 x 1 x 2 mm
// grid a value that depends on the direction: the sphere is an ellipsoid in index space).
TEST(Curvature, SphereIsTwoOverRInMillimetresOnAnyGrid) {
    for (const Vec3d h : {Vec3d{2, 2, 2}, Vec3d{0.8, 0.8, 0.8}, Vec3d{1, 1, 2}, Vec3d{0.9375, 0.9375, 1.2}, Vec3d{1.5, 1, 0.7}}) {
        const Vec3i dims{int(std::ceil(60.0 / h.x)), int(std::ceil(60.0 / h.y)), int(std::ceil(60.0 / h.z))};
        Grid<float> g(Lattice(dims, h));
        const Vec3d c{30.3, 29.6, 30.1};  // mm
        const double r = 18.0;
        for (int z = 0; z < dims.z; ++z)
            for (int y = 0; y < dims.y; ++y)
                for (int x = 0; x < dims.x; ++x) g({x, y, z}) = static_cast<float>(norm(Vec3d{x * h.x, y * h.y, z * h.z} - c) - r);
        for (Vec3d dir : {Vec3d{1, 0, 0}, Vec3d{0, 1, 0}, Vec3d{0, 0, 1}, Vec3d{1, 1, 0}, Vec3d{1, 1, 1}, Vec3d{-1, 2, 0.5}}) {
            const Vec3d p = c + dir / norm(dir) * r;  // mm
            const Vec3i q{int(std::lround(p.x / h.x)), int(std::lround(p.y / h.y)), int(std::lround(p.z / h.z))};
            const double at = norm(Vec3d{q.x * h.x, q.y * h.y, q.z * h.z} - c);  // the level set through q
            EXPECT_NEAR(mean_curvature(g, q), 2.0 / at, 0.06 * 2.0 / at) << "spacing " << h.x << "x" << h.y << "x" << h.z;
        }
    }
}

TEST(Curvature, CylinderAndPlane) {
    const Grid<float> cyl = sample(40, [](Vec3d p) { return std::hypot(p.x - 19.5, p.y - 19.5) - 8.0; });
    EXPECT_NEAR(mean_curvature(cyl, {27, 20, 20}), 1.0 / std::hypot(7.5, 0.5), 0.05);
    const Grid<float> plane = sample(20, [](Vec3d p) { return 0.6 * p.x + 0.8 * p.y - 12.0; });
    EXPECT_NEAR(mean_curvature(plane, {10, 8, 10}), 0.0, 1e-5);
}

TEST(Curvature, SpeedRejectsBadWeight) {
    EXPECT_THROW(CurvatureSpeed(-1.0f), std::invalid_argument);
    EXPECT_THROW(CurvatureSpeed(NAN), std::invalid_argument);
}

namespace {
// The reference multiplies by the inverse voxel sizes (as float, speed.cpp) only when `scaled`: on a
// 1 mm lattice it is called unscaled, the index-unit formula of before the curvature was per mm, so
// that 1 mm keeps those bits.
void check_fast_path_against_reference(const Grid<float>& phi, bool scaled) {
    const liveset::Vec3d h = phi.lattice().spacing();
    const float inv[3] = {1.0f / static_cast<float>(h.x), 1.0f / static_cast<float>(h.y), 1.0f / static_cast<float>(h.z)};
    const float h_min = std::min({static_cast<float>(h.x), static_cast<float>(h.y), static_cast<float>(h.z)});
    const float finest[3] = {h_min / static_cast<float>(h.x), h_min / static_cast<float>(h.y), h_min / static_cast<float>(h.z)};
    const auto reference = [&](liveset::Vec3i p) {
        float k = 0.0f;
        for (int a = 0; a < 3; ++a) {
            float n_dir[2] = {0.0f, 0.0f};
            for (int dir : {+1, -1}) {
                const int b = (a + 1) % 3, c = (a + 2) % 3;
                liveset::Vec3i q = p, eb{0, 0, 0}, ec{0, 0, 0};
                q[a] += dir;
                eb[b] = 1;
                ec[c] = 1;
                float ga = static_cast<float>(dir) * (phi.clamped(q) - phi.clamped(p));
                float gb = 0.25f * (phi.clamped(p + eb) + phi.clamped(q + eb) - phi.clamped(p - eb) - phi.clamped(q - eb));
                float gc = 0.25f * (phi.clamped(p + ec) + phi.clamped(q + ec) - phi.clamped(p - ec) - phi.clamped(q - ec));
                if (scaled) {
                    ga *= inv[a];
                    gb *= inv[b];
                    gc *= inv[c];
                }
                const float len = std::sqrt(ga * ga + gb * gb + gc * gc);
                n_dir[dir > 0 ? 0 : 1] = len > 1e-6f ? ga / len : 0.0f;
            }
            k += scaled ? (n_dir[0] - n_dir[1]) * inv[a] : n_dir[0] - n_dir[1];
        }
        return k;
    };
    // central_gradient's norm (per finest voxel where `scaled`), written out with clamped reads
    // (one-sided at the border).
    const auto reference_gradient_norm = [&](liveset::Vec3i p) {
        float g[3];
        for (int a = 0; a < 3; ++a) {
            liveset::Vec3i lo = p, hi = p;
            lo[a] = std::max(p[a] - 1, 0);
            hi[a] = std::min(p[a] + 1, phi.dims()[a] - 1);
            g[a] = (phi(hi) - phi(lo)) / static_cast<float>(hi[a] - lo[a]);
            if (scaled) g[a] *= finest[a];  // per finest voxel
        }
        return std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    };
    std::vector<liveset::PointIndex> points;
    for (int z = 0; z < 7; ++z)
        for (int y = 0; y < 8; ++y)
            for (int x = 0; x < 9; ++x) {
                const liveset::Vec3i p{x, y, z};
                const float got = liveset::mean_curvature(phi, p), want = reference(p);
                ASSERT_EQ(std::bit_cast<std::uint32_t>(got), std::bit_cast<std::uint32_t>(want)) << x << "," << y << "," << z;
                points.push_back(phi.lattice().index(p));
            }
    // The batched form (four stencils per pass), over every point in a scrambled order and over
    // a count that leaves a partial last batch.
    for (std::size_t n = 0; n < points.size(); ++n) std::swap(points[n], points[(n * 7919) % points.size()]);
    points.pop_back();
    std::vector<liveset::CurvatureAndGradient> batch(points.size());
    liveset::mean_curvature_and_gradient(phi, points, batch);
    for (std::size_t n = 0; n < points.size(); ++n) {
        const liveset::Vec3i p = phi.lattice().coord(points[n]);
        ASSERT_EQ(std::bit_cast<std::uint32_t>(batch[n].kappa), std::bit_cast<std::uint32_t>(reference(p))) << p.x << "," << p.y << "," << p.z;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(batch[n].gradient_norm), std::bit_cast<std::uint32_t>(reference_gradient_norm(p)))
            << p.x << "," << p.y << "," << p.z;
    }
    // CurvatureSpeed's batched rates against Speed's formula, sample by sample.
    const liveset::CurvatureSpeed speed(0.7f);
    std::vector<double> rates(points.size());
    speed.rates(phi, points, rates);
    for (std::size_t n = 0; n < points.size(); ++n) {
        const liveset::Vec3i p = phi.lattice().coord(points[n]);
        const double want = liveset::rate_of(speed.at(phi, p), phi, p);
        ASSERT_EQ(std::bit_cast<std::uint64_t>(rates[n]), std::bit_cast<std::uint64_t>(want)) << p.x << "," << p.y << "," << p.z;
    }
}
}  // namespace

// The difference-of-normals formula written out with clamped, scalar reads everywhere (the
// reference); mean_curvature's unclamped interior fast path, the batched curvature and central
// |∇φ|, and CurvatureSpeed's batched rates must agree with it (and rate_of) bit for bit: on random values, and on plateaus with steps of 1e-7 to 1e-5, where half-point normals
// are exactly 0 or straddle the 1e-6 length below which a normal counts as 0.
// On a 1 mm lattice against the index-unit formula (unscaled), on others against the per-mm one.
TEST(Curvature, InteriorFastPathIsBitIdenticalToClampedFormula) {
    for (const bool plateaus : {false, true})
    for (const liveset::Vec3d h : {liveset::Vec3d{1, 1, 1}, liveset::Vec3d{0.9375, 0.9375, 1.2}, liveset::Vec3d{2, 1, 3}}) {
        SCOPED_TRACE(plateaus ? "plateaus" : "random");
        SCOPED_TRACE(h.z);
        const liveset::Lattice lat({9, 8, 7}, h);
        liveset::Grid<float> phi(lat);
        std::uint32_t state = 99;
        for (float& v : phi.values()) {
            state = state * 1664525u + 1013904223u;
            const float u = static_cast<float>(state >> 8) / static_cast<float>(1u << 24);
            if (!plateaus) {
                v = u * 4.0f - 2.0f;
            } else {
                const float steps[] = {0.0f, 0.0f, 0.0f, 1e-7f, 5e-7f, 1e-6f, 2e-6f, 1e-5f};
                v = 0.5f + steps[(state >> 4) % 8] * (u < 0.5f ? -1.0f : 1.0f);
            }
        }
        check_fast_path_against_reference(phi, !(h.x == 1.0 && h.y == 1.0 && h.z == 1.0));
    }
}
