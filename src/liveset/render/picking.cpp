// Depth read-back and unprojection.
#include "liveset/render/picking.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include "liveset/render/volume_transform.hpp"

namespace liveset::render {

std::optional<Pick> unproject(double x, double y, float depth, int width, int height, const OrbitCamera& camera,
                              const Lattice& lattice) {
    if (!(depth < 1.0f) || width < 1 || height < 1) return std::nullopt;
    const glm::dmat4 view(camera.view());
    const glm::dmat4 projection(camera.projection(static_cast<double>(width) / height));
    // Pixel centres: OpenGL window coordinates run bottom-up.
    const glm::dvec3 window(x + 0.5, static_cast<double>(height) - (y + 0.5), static_cast<double>(depth));
    Pick p;
    p.depth = depth;
    p.world = glm::unProject(window, view, projection, glm::dvec4(0.0, 0.0, width, height));
    p.index = glm::dvec3(world_to_index(lattice) * glm::dvec4(p.world, 1.0));
    return p;
}

std::optional<Pick> pick(const Framebuffer& view, int x, int y, const OrbitCamera& camera, const Lattice& lattice) {
    if (x < 0 || y < 0 || x >= view.width() || y >= view.height()) return std::nullopt;
    const float depth = view.read_depth(x, view.height() - 1 - y);
    return unproject(x, y, depth, view.width(), view.height(), camera, lattice);
}

}  // namespace liveset::render
