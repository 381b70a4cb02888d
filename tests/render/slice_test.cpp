// Slice views: ITK-SNAP's radiological orientation from the direction cosines, pixel <-> voxel
// mapping with square millimetres, texels, and the zero contour of φ on a slice.
#include <gtest/gtest.h>

#include "liveset/render/slice_geometry.hpp"

namespace liveset {
namespace {

using render::SliceAxis;

TEST(SliceGeometry, AxialCoronalSagittalOfAnLpsImage) {
    const Lattice lat({30, 40, 20}, {1.0, 1.0, 2.5});
    const auto ax = render::slice_geometry(lat, SliceAxis::kAxial);
    EXPECT_EQ(ax.normal_axis, 2);
    EXPECT_EQ(ax.u_axis, 0);
    EXPECT_FALSE(ax.u_flip);  // +x (patient left) to the screen's right: radiological
    EXPECT_EQ(ax.v_axis, 1);
    EXPECT_TRUE(ax.v_flip);   // anterior (-y) up
    const auto co = render::slice_geometry(lat, SliceAxis::kCoronal);
    EXPECT_EQ(co.normal_axis, 1);
    EXPECT_EQ(co.v_axis, 2);
    EXPECT_FALSE(co.v_flip);  // superior up
    EXPECT_DOUBLE_EQ(co.v_mm, 2.5);
    const auto sa = render::slice_geometry(lat, SliceAxis::kSagittal);
    EXPECT_EQ(sa.normal_axis, 0);
    EXPECT_EQ(sa.u_axis, 1);
    EXPECT_FALSE(sa.u_flip);  // posterior to the right, anterior left
    EXPECT_EQ(sa.slices, 30);
}

TEST(SliceGeometry, ASagittallyStoredImageStillShowsUpright) {
    // Lattice axes: i along -y (anterior), j along +z... stored as sagittal slices along x.
    const Mat3d dir{0, 0, 1, -1, 0, 0, 0, 1, 0};  // columns: i -> -y, j -> +z, k -> +x
    const Lattice lat({50, 60, 40}, {1, 1, 1}, {0, 0, 0}, dir);
    const auto ax = render::slice_geometry(lat, SliceAxis::kAxial);
    EXPECT_EQ(ax.normal_axis, 1);  // j runs along z
    EXPECT_EQ(ax.u_axis, 2);       // k along x
    EXPECT_EQ(ax.v_axis, 0);       // i along -y: anterior up without a flip
    EXPECT_FALSE(ax.v_flip);
    // Round trip voxel -> texel -> voxel.
    const Vec3d p{12, 7, 33};
    const Vec3d q = ax.to_index(ax.to_uv(p), 7);
    EXPECT_NEAR(q.x, p.x, 1e-12);
    EXPECT_NEAR(q.z, p.z, 1e-12);
    EXPECT_EQ(ax.slice_of(p), 7);
    EXPECT_EQ(ax.voxel(0, 0, 7), (Vec3i{0, 7, 0}));
}

TEST(SliceGeometry, ViewportKeepsMillimetresSquare) {
    const Lattice lat({40, 40, 10}, {1.0, 1.0, 4.0});
    const auto g = render::slice_geometry(lat, SliceAxis::kCoronal);  // 40 x 10 texels of 1 x 4 mm
    const auto vp = render::SliceViewport::fit(g, 400, 400);
    const glm::dvec2 a = vp.to_pixel({0, 0}), b = vp.to_pixel({40, 10});
    EXPECT_NEAR(std::abs(b.x - a.x), std::abs(b.y - a.y), 1e-9);  // 40 mm by 40 mm
    const glm::dvec2 uv = vp.to_uv(vp.to_pixel({13.25, 4.5}));
    EXPECT_NEAR(uv.x, 13.25, 1e-9);
    EXPECT_NEAR(uv.y, 4.5, 1e-9);
    EXPECT_LT(a.y, 400.0);
    EXPECT_GT(a.y, b.y);  // texel row 0 at the bottom of the pane
}

TEST(SliceGeometry, ZeroContourOfADiscLiesOnTheCircle) {
    const Lattice lat({41, 41, 5});
    Grid<float> phi(lat);
    for (int z = 0; z < 5; ++z)
        for (int y = 0; y < 41; ++y)
            for (int x = 0; x < 41; ++x) phi({x, y, z}) = static_cast<float>(std::hypot(x - 20.0, y - 20.0) - 12.0);
    const auto g = render::slice_geometry(lat, SliceAxis::kAxial);
    const auto seg = render::zero_contour(phi, g, 2);
    ASSERT_GT(seg.size(), 100u);
    ASSERT_EQ(seg.size() % 2, 0u);
    for (const glm::dvec2& p : seg) {
        const Vec3d q = g.to_index(p, 2);
        EXPECT_NEAR(std::hypot(q.x - 20.0, q.y - 20.0), 12.0, 0.1);
    }
    Grid<float> unit(lat, 0.5f);
    unit({3, 4, 2}) = 1.0f;
    const auto tex = render::slice_texels(unit, g, 2);
    ASSERT_EQ(tex.size(), 41u * 41u);
    // Voxel (3, 4) is texel column 3, row 40 - 4 (anterior up).
    EXPECT_EQ(tex[static_cast<std::size_t>(40 - 4) * 41 + 3], 255);
    EXPECT_EQ(tex[0], 128);
}

}  // namespace
}  // namespace liveset
