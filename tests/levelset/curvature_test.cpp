// Mean curvature by difference of normals against analytic shapes: sphere 2/r, cylinder 1/r, plane 0.
#include <gtest/gtest.h>

#include <cmath>

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
