// The 3D view: the surface from the per-fragment buffers with Phong lighting from the ∇φ vertex
// normals (outside and inside faces in different colours, so holes show), the agents as small
// shaded spheres (point sprites), the user's target as a marker that stays visible through the
// surface, markers (hole candidates; the selected one highlighted) drawn the same way, the
// crosshair cursor as three axis lines and the volume's bounding box.
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <span>
#include <vector>

#include "liveset/render/framebuffer.hpp"
#include "liveset/render/orbit_camera.hpp"
#include "liveset/render/shader_program.hpp"
#include "liveset/render/surface_buffers.hpp"

namespace liveset::render {

struct SceneStyle {
    glm::vec3 background{0.10f, 0.11f, 0.13f};
    glm::vec3 outside{0.93f, 0.82f, 0.72f};  // cortex-like
    glm::vec3 inside{0.62f, 0.22f, 0.20f};   // back faces: seen through holes
    glm::vec3 agents{0.15f, 0.75f, 0.95f};
    glm::vec3 target{1.00f, 0.85f, 0.10f};
    float agent_radius_mm = 0.6f;
    float target_radius_mm = 2.5f;
    glm::vec3 markers{1.0f, 0.5f, 0.0f};
    glm::vec3 selected_marker{1.0f, 0.25f, 1.0f};
    float marker_radius_mm = 2.0f;
    bool bounding_box = true;
    bool cursor = true;
};

struct SceneContent {
    const Lattice* lattice = nullptr;          // index -> world of everything below
    const SurfaceBuffers* surface = nullptr;
    float surface_scale = 1.0f;                // surface index = this x buffer position (2: LodMesher's)
    float surface_offset = 0.0f;               // + this on each axis (0.5: a coarse start's grid of 2x2x2 blocks)
    std::span<const glm::vec3> agents;         // index space
    std::optional<glm::vec3> target;           // index space
    std::optional<glm::vec3> cursor;           // index space
    std::span<const glm::vec3> markers;        // index space
    std::optional<glm::vec3> selected_marker;  // index space
};

class SceneRenderer {
public:
    SceneRenderer();  // compiles the shaders (a current OpenGL 3.3 context is needed)
    ~SceneRenderer();
    SceneRenderer(const SceneRenderer&) = delete;
    SceneRenderer& operator=(const SceneRenderer&) = delete;

    // Clears and draws into `target` (bound here) as seen by `camera`.
    void render(const Framebuffer& target, const OrbitCamera& camera, const SceneContent& content, const SceneStyle& style);

private:
    void draw_sprites(std::span<const glm::vec3> points, float radius_mm, const glm::vec3& colour, float alpha,
                      const glm::mat4& model, const glm::mat4& view, const glm::mat4& projection, int height);
    // Points seen through the surface as well: opaque where visible, translucent on top.
    void draw_see_through(std::span<const glm::vec3> points, float radius_mm, const glm::vec3& colour, const glm::mat4& model,
                          const glm::mat4& view, const glm::mat4& projection, int height);
    void draw_lines(std::span<const glm::vec3> world_points, const glm::vec4& colour, const glm::mat4& view_projection);

    ShaderProgram surface_, sprites_, lines_;
    GLuint point_vao_ = 0, point_vbo_ = 0;
    GLuint line_vao_ = 0, line_vbo_ = 0;
};

}  // namespace liveset::render
