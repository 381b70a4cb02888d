// Depth-buffer picking: a clicked pixel unprojects to a point within half a voxel of the zero level
// set (trilinear φ), on the phantom and on an anisotropic, mirrored lattice; background pixels
// pick nothing; unproject inverts the camera's projection exactly.
#include <gtest/gtest.h>

#include <glm/gtc/matrix_transform.hpp>

#include "liveset/grid/sampling.hpp"
#include "liveset/render/picking.hpp"
#include "liveset/render/scene_renderer.hpp"
#include "render/render_test_util.hpp"

namespace liveset {
namespace {

using testing::gl_context;

TEST(Picking, UnprojectInvertsTheProjection) {
    render::OrbitCamera camera;
    render::Bounds b;
    b.centre = {10, -5, 30};
    b.radius = 80;
    camera.frame(b, {35.0, 25.0, 1.3, glm::dvec3(3, 0, -2)});
    const Lattice lat({64, 64, 64});
    const int w = 400, h = 300;
    for (const glm::dvec3 world : {glm::dvec3(10, -5, 30), glm::dvec3(40, 20, 0), glm::dvec3(-30, 10, 60)}) {
        const glm::dvec3 win = glm::project(world, glm::dmat4(camera.view()), glm::dmat4(camera.projection(double(w) / h)),
                                            glm::dvec4(0, 0, w, h));
        // Pixel with its centre at the projected point (top-row origin).
        const auto p = render::unproject(win.x - 0.5, h - win.y - 0.5, static_cast<float>(win.z), w, h, camera, lat);
        ASSERT_TRUE(p.has_value());
        EXPECT_LT(glm::length(p->world - world), 1e-3 * b.radius);
    }
    EXPECT_FALSE(render::unproject(10, 10, 1.0f, w, h, camera, lat).has_value());  // background
}

// Renders `field`'s surface and picks every 6th pixel: every hit lies within `tolerance` of the
// zero level set (|trilinear φ|, in voxels); returns the number of hits.
int pick_grid(const Lattice& lat, const Grid<float>& phi, const FragmentMesher& mesher, const char* view, double tolerance) {
    render::SurfaceBuffers buffers;
    buffers.upload_all(mesher);
    render::Framebuffer fb(300, 240);
    render::SceneRenderer renderer;
    render::OrbitCamera camera;
    render::CameraPose pose;
    render::OrbitCamera::named_pose(view, pose);
    pose.yaw_deg += 20.0;
    pose.pitch_deg = std::min(pose.pitch_deg + 15.0, 90.0);
    camera.frame(render::surface_bounds(mesher), pose);
    render::SceneContent content;
    content.lattice = &lat;
    content.surface = &buffers;
    render::SceneStyle style;
    style.bounding_box = false;
    renderer.render(fb, camera, content, style);
    int hits = 0, misses = 0;
    for (int y = 0; y < fb.height(); y += 6)
        for (int x = 0; x < fb.width(); x += 6) {
            const auto p = render::pick(fb, x, y, camera, lat);
            if (!p) {
                ++misses;
                continue;
            }
            ++hits;
            const Vec3d q{p->index.x, p->index.y, p->index.z};
            EXPECT_TRUE(lat.contains(q)) << x << "," << y;
            EXPECT_LE(std::abs(trilinear(phi, q)), tolerance) << "pixel " << x << "," << y;
        }
    EXPECT_GT(misses, 0);  // the background picks nothing (and is there)
    return hits;
}

TEST(Picking, ClickedPixelsLieOnThePhantomSurface) {
    gl_context();
    auto s = testing::truth_session();
    const int hits = pick_grid(s->lattice(), s->field().phi(), s->mesher(), "superior", 0.5);
    EXPECT_GT(hits, 300);
}

TEST(Picking, AnisotropicMirroredLatticePicksInMillimetres) {
    gl_context();
    // 2 mm slices along z, the x axis mirrored, an offset origin: a sphere of 15 mm radius.
    const Mat3d mirror{-1, 0, 0, 0, 1, 0, 0, 0, 1};
    const Lattice lat({48, 48, 24}, {1.0, 1.0, 2.0}, {20.0, -30.0, 5.0}, mirror);
    const Vec3d centre = lat.to_world({23.5, 23.5, 11.5});
    SparseField field(lat, 2);
    field.init_from_sdf([&](Vec3d p) { return (norm(lat.to_world(p) - centre) - 15.0) / 1.5; });
    FragmentMesher mesher(lat, 16);
    mesher.full_rebuild(field.phi(), field.zero_layer());
    const int hits = pick_grid(lat, field.phi(), mesher, "anterior", 0.5);
    EXPECT_GT(hits, 300);
    // In millimetres: on the sphere within tessellation error.
    render::SurfaceBuffers buffers;
    buffers.upload_all(mesher);
    render::Framebuffer fb(200, 200);
    render::SceneRenderer renderer;
    render::OrbitCamera camera;
    camera.frame(render::surface_bounds(mesher));
    render::SceneContent content;
    content.lattice = &lat;
    content.surface = &buffers;
    renderer.render(fb, camera, content, render::SceneStyle{});
    const auto p = render::pick(fb, 100, 100, camera, lat);
    ASSERT_TRUE(p.has_value());
    EXPECT_NEAR(glm::length(p->world - glm::dvec3(centre.x, centre.y, centre.z)), 15.0, 0.3);
}

}  // namespace
}  // namespace liveset
