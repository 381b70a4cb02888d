// One-off surface pictures (see surface_picture.hpp).
#include "liveset/render/surface_picture.hpp"

#include <stdexcept>

#include "liveset/render/framebuffer.hpp"
#include "liveset/render/headless_context.hpp"
#include "liveset/render/orbit_camera.hpp"
#include "liveset/render/png_writer.hpp"
#include "liveset/render/scene_renderer.hpp"
#include "liveset/render/surface_buffers.hpp"

namespace liveset::render {

void render_surface_png(const FragmentMesher& mesher, const std::string& path, const std::string& view, int width,
                        int height, int supersample) {
    CameraPose pose;
    if (!OrbitCamera::named_pose(view, pose)) throw std::invalid_argument("unknown view " + view);
    const HeadlessContext context;
    SurfaceBuffers buffers;
    buffers.upload_all(mesher);
    OrbitCamera camera;
    camera.frame(surface_bounds(mesher), pose);
    SceneRenderer renderer;
    Framebuffer fb(width * supersample, height * supersample);
    SceneContent content;
    content.lattice = &mesher.lattice();
    content.surface = &buffers;
    SceneStyle style;
    style.bounding_box = false;
    renderer.render(fb, camera, content, style);
    write_png(path, downsample(fb.read_color(), supersample));
}

}  // namespace liveset::render
