// Headless rendering: the phantom's surface renders (EGL surfaceless, offscreen framebuffer) to an
// image matching the stored reference within a small per-pixel tolerance and is not blank;
// re-uploading only the fragments the mesher reports gives the same picture as uploading all;
// so does the EGL device platform; the camera's named views and the PNG writer behave.
#include <gtest/gtest.h>

#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <thread>

#include "liveset/render/orbit_camera.hpp"
#include "liveset/render/png_writer.hpp"
#include "liveset/render/scene_renderer.hpp"
#include "liveset/render/surface_buffers.hpp"
#include "render/render_test_util.hpp"
#include "scratch_dir.hpp"

namespace liveset {
namespace {

namespace fs = std::filesystem;
using testing::compare;
using testing::covered_fraction;
using testing::gl_context;

const std::string kReference = std::string(LIVESET_TEST_DATA) + "/render/phantom64_truth_superior.png";

Vec3d phantom_seed() { return testing::phantom64().seeds.front().cast<double>(); }

render::Image render_scene(const Session& s, render::SurfaceBuffers& buffers, const char* view, int w, int h) {
    render::Framebuffer fb(w, h);
    render::SceneRenderer renderer;
    render::OrbitCamera camera;
    render::CameraPose pose;
    EXPECT_TRUE(render::OrbitCamera::named_pose(view, pose));
    camera.frame(render::surface_bounds(s.mesher()), pose);
    render::SceneContent content;
    content.lattice = &s.lattice();
    content.surface = &buffers;
    renderer.render(fb, camera, content, render::SceneStyle{});
    glFinish();
    return fb.read_color();
}

TEST(HeadlessRender, PhantomSurfaceMatchesTheReferenceImage) {
    gl_context();
    auto s = testing::truth_session();
    render::SurfaceBuffers buffers;
    buffers.upload(s->mesher(), s->take_dirty_fragments());
    EXPECT_EQ(buffers.triangle_count(), s->mesher().triangle_count());
    const render::Image img = render_scene(*s, buffers, "superior", 320, 240);
    // Not blank: the cortex covers a good part of the frame, and lit pixels vary.
    EXPECT_GT(covered_fraction(img), 0.25);
    if (std::getenv("LIVESET_UPDATE_REFERENCE")) render::write_png(kReference, img);
    const render::Image ref = render::read_png(kReference);
    const auto d = compare(img, ref, 16);
    // Headless llvmpipe output is byte-identical run to run; other CPUs / Xvfb may differ by a
    // little at a few pixels.
    EXPECT_LT(d.mean_abs, 1.0) << "max " << d.max_abs;
    EXPECT_LT(d.fraction_over, 0.005) << "max " << d.max_abs;
}

// The EGL device platform (how a headless NVIDIA server gives a context) draws the same picture:
// here Mesa's software device, on a thread of its own so that the shared context stays untouched.
TEST(HeadlessRender, TheDevicePlatformDrawsTheReferenceToo) {
    std::string platform, error;
    render::Image img;
    std::thread([&] {
        try {
            render::HeadlessContext context(render::EglPlatform::kDevice);
            platform = context.platform();
            auto s = testing::truth_session();
            render::SurfaceBuffers buffers;
            buffers.upload_all(s->mesher());
            img = render_scene(*s, buffers, "superior", 320, 240);
        } catch (const std::exception& e) {
            error = e.what();
        }
    }).join();
    ASSERT_EQ(error, "");
    EXPECT_EQ(platform, "device");
    const auto d = compare(img, render::read_png(kReference), 16);
    EXPECT_LT(d.mean_abs, 1.0) << "max " << d.max_abs;
    EXPECT_LT(d.fraction_over, 0.005) << "max " << d.max_abs;
}

TEST(HeadlessRender, ADifferentViewDoesNotMatchTheReference) {
    gl_context();
    auto s = testing::truth_session();
    render::SurfaceBuffers buffers;
    buffers.upload_all(s->mesher());
    const render::Image img = render_scene(*s, buffers, "anterior", 320, 240);
    const auto d = compare(img, render::read_png(kReference), 16);
    EXPECT_GT(d.fraction_over, 0.05);  // the comparison above can fail
}

TEST(HeadlessRender, ReuploadingOnlyTheRebuiltFragmentsEqualsUploadingAll) {
    gl_context();
    auto s = std::make_unique<Session>(testing::phantom64().image, SessionOptions{});
    render::SurfaceBuffers incremental;
    incremental.upload(s->mesher(), s->take_dirty_fragments());
    // Grow a seed for a few steps, re-uploading after each only the fragments the session reports.
    s->add_seed({phantom_seed(), 2.0});
    incremental.upload(s->mesher(), s->take_dirty_fragments());
    std::size_t rebuilt = 0, vertices_only = 0;
    for (int i = 0; i < 40; ++i) {
        rebuilt += s->segment_step().fragments.size();
        if (i % 3 == 0 || i >= 30) vertices_only += incremental.upload(s->mesher(), s->take_dirty_fragments()).vertices_only;
    }
    ASSERT_GT(rebuilt, 0u);
    EXPECT_GT(vertices_only, 0u);  // fragments whose T did not change got only their vertices, in place
    const auto dirty = s->take_dirty_fragments();
    ASSERT_LT(dirty.size(), s->mesher().fragment_count());
    incremental.upload(s->mesher(), dirty);
    render::SurfaceBuffers fresh;
    fresh.upload_all(s->mesher());
    EXPECT_EQ(incremental.triangle_count(), fresh.triangle_count());
    const render::Image a = render_scene(*s, incremental, "superior", 256, 192);
    const render::Image b = render_scene(*s, fresh, "superior", 256, 192);
    EXPECT_EQ(a.rgba, b.rgba);
    // And the edit is visible: the stale buffers would differ.
    render::SurfaceBuffers stale;
    auto before = std::make_unique<Session>(testing::phantom64().image, SessionOptions{});
    before->add_seed({phantom_seed(), 2.0});
    before->segment_step();
    stale.upload_all(before->mesher());
    EXPECT_NE(render_scene(*s, stale, "superior", 256, 192).rgba, a.rgba);
}

TEST(OrbitCamera, NamedViewsLookFromWhereTheySay) {
    render::OrbitCamera c;
    render::Bounds b;
    b.centre = {1, 2, 3};
    b.radius = 50;
    render::CameraPose p;
    ASSERT_TRUE(render::OrbitCamera::named_pose("superior", p));
    c.frame(b, p);
    const glm::dvec3 to_eye = glm::normalize(c.eye() - c.centre());
    EXPECT_NEAR(to_eye.z, 1.0, 1e-9);     // above the head (+z superior)
    EXPECT_NEAR(c.up().y, -1.0, 1e-9);    // anterior (-y) at the top of the screen
    ASSERT_TRUE(render::OrbitCamera::named_pose("left", p));
    c.set_pose(p);
    EXPECT_NEAR(glm::normalize(c.eye() - c.centre()).x, 1.0, 1e-9);  // +x is the patient's left in LPS
    c.rotate(100, 0);
    EXPECT_NE(c.pose().yaw_deg, p.yaw_deg);
    c.reset();
    EXPECT_EQ(c.pose().yaw_deg, 180.0);  // back to the framed home pose (superior)
    EXPECT_FALSE(render::OrbitCamera::named_pose("sideways", p));
    // The volume's core fits: every corner of the cube inscribed in 0.7 of the bounding sphere
    // projects inside the frame.
    c.frame(b);
    const glm::mat4 vp = c.projection(1.0) * c.view();
    for (int k = 0; k < 8; ++k) {
        const glm::dvec3 corner = b.centre + glm::dvec3((k & 1) ? 20 : -20, (k & 2) ? 20 : -20, (k & 4) ? 20 : -20);
        const glm::vec4 clip = vp * glm::vec4(glm::vec3(corner), 1.0f);
        EXPECT_LT(std::abs(clip.x / clip.w), 1.0f);
        EXPECT_LT(std::abs(clip.y / clip.w), 1.0f);
        EXPECT_LT(std::abs(clip.z / clip.w), 1.0f);
    }
}

TEST(PngWriter, WritesAtomicallyAndRoundTrips) {
    const fs::path dir = testing::scratch_dir("png");
    render::Image img{3, 2, {255, 0, 0, 255, 0, 255, 0, 255, 0, 0, 255, 255, 1, 2, 3, 255, 4, 5, 6, 255, 7, 8, 9, 255}};
    render::write_png((dir / "a.png").string(), img);
    EXPECT_EQ(render::read_png((dir / "a.png").string()).rgba, img.rgba);
    EXPECT_THROW(render::write_png((dir / "missing" / "b.png").string(), img), std::runtime_error);
    EXPECT_THROW(render::read_png((dir / "nothing.png").string()), std::runtime_error);
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : fs::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 1u);  // no temporary left behind
    const render::Image half = render::downsample(render::Image{2, 2, std::vector<std::uint8_t>(16, 100)}, 2);
    EXPECT_EQ(half.width, 1);
    EXPECT_EQ(half.rgba[0], 100);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace liveset
