// 3D view drawing: shaders and passes.
#include "liveset/render/scene_renderer.hpp"

#include <cmath>

namespace liveset::render {

namespace {

constexpr const char* kSurfaceVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model_view;
uniform mat4 u_projection;
uniform mat3 u_normal_matrix;
out vec3 v_normal;
out vec3 v_eye;
void main() {
    vec4 p = u_model_view * vec4(a_position, 1.0);
    v_eye = p.xyz;
    v_normal = u_normal_matrix * a_normal;
    gl_Position = u_projection * p;
}
)";

// Phong: a headlight plus a key light from the upper left, a soft specular on the outside only,
// and a mild darkening with depth across the object (a depth cue for folded surfaces).
constexpr const char* kSurfaceFragment = R"(#version 330 core
in vec3 v_normal;
in vec3 v_eye;
uniform vec3 u_outside;
uniform vec3 u_inside;
uniform bool u_front_is_ccw;
uniform vec2 u_depth_range;
out vec4 colour;
void main() {
    vec3 n = normalize(v_normal);
    bool outside = gl_FrontFacing == u_front_is_ccw;
    if (!outside) n = -n;
    vec3 v = normalize(-v_eye);
    vec3 key = normalize(vec3(-0.45, 0.6, 0.65));
    vec3 base = outside ? u_outside : u_inside;
    float diffuse = 0.55 * max(dot(n, v), 0.0) + 0.35 * max(dot(n, key), 0.0);
    float specular = outside ? 0.12 * pow(max(dot(n, normalize(key + v)), 0.0), 20.0) : 0.0;
    float depth = clamp((-v_eye.z - u_depth_range.x) / max(u_depth_range.y - u_depth_range.x, 1e-3), 0.0, 1.0);
    colour = vec4((base * (0.25 + diffuse) + vec3(specular)) * (1.0 - 0.25 * depth), 1.0);
}
)";

constexpr const char* kSpriteVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_model_view;
uniform mat4 u_projection;
uniform float u_pixels_per_mm_at_unit_depth;
uniform float u_radius_mm;
void main() {
    vec4 p = u_model_view * vec4(a_position, 1.0);
    gl_Position = u_projection * p;
    gl_PointSize = max(2.0, 2.0 * u_radius_mm * u_pixels_per_mm_at_unit_depth / max(-p.z, 1e-3));
}
)";

constexpr const char* kSpriteFragment = R"(#version 330 core
uniform vec3 u_colour;
uniform float u_alpha;
out vec4 colour;
void main() {
    vec2 d = gl_PointCoord * 2.0 - 1.0;
    float r2 = dot(d, d);
    if (r2 > 1.0) discard;
    vec3 n = vec3(d.x, -d.y, sqrt(1.0 - r2));
    float light = 0.35 + 0.65 * max(dot(n, normalize(vec3(-0.4, 0.5, 0.75))), 0.0);
    colour = vec4(u_colour * light + vec3(0.25 * pow(n.z, 30.0)), u_alpha);
}
)";

constexpr const char* kLineVertex = R"(#version 330 core
layout(location = 0) in vec3 a_position;
uniform mat4 u_view_projection;
void main() { gl_Position = u_view_projection * vec4(a_position, 1.0); }
)";

constexpr const char* kLineFragment = R"(#version 330 core
uniform vec4 u_colour;
out vec4 colour;
void main() { colour = u_colour; }
)";

void make_point_buffer(GLuint& vao, GLuint& vbo) {
    glGenVertexArrays(1, &vao);
    glGenBuffers(1, &vbo);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, sizeof(glm::vec3), nullptr);
    glBindVertexArray(0);
}

}  // namespace

SceneRenderer::SceneRenderer()
    : surface_(kSurfaceVertex, kSurfaceFragment), sprites_(kSpriteVertex, kSpriteFragment), lines_(kLineVertex, kLineFragment) {
    make_point_buffer(point_vao_, point_vbo_);
    make_point_buffer(line_vao_, line_vbo_);
}

SceneRenderer::~SceneRenderer() {
    glDeleteVertexArrays(1, &point_vao_);
    glDeleteBuffers(1, &point_vbo_);
    glDeleteVertexArrays(1, &line_vao_);
    glDeleteBuffers(1, &line_vbo_);
}

void SceneRenderer::draw_sprites(std::span<const glm::vec3> points, float radius_mm, const glm::vec3& colour, float alpha,
                                 const glm::mat4& model, const glm::mat4& view, const glm::mat4& projection, int height) {
    if (points.empty()) return;
    sprites_.use();
    sprites_.set("u_model_view", view * model);
    sprites_.set("u_projection", projection);
    sprites_.set("u_pixels_per_mm_at_unit_depth", 0.5f * projection[1][1] * static_cast<float>(height));
    sprites_.set("u_radius_mm", radius_mm);
    sprites_.set("u_colour", colour);
    sprites_.set("u_alpha", alpha);
    glBindVertexArray(point_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, point_vbo_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(points.size_bytes()), points.data(), GL_STREAM_DRAW);
    glDrawArrays(GL_POINTS, 0, static_cast<GLsizei>(points.size()));
    glBindVertexArray(0);
}

void SceneRenderer::draw_see_through(std::span<const glm::vec3> points, float radius_mm, const glm::vec3& colour, const glm::mat4& model,
                                     const glm::mat4& view, const glm::mat4& projection, int height) {
    if (points.empty()) return;
    draw_sprites(points, radius_mm, colour, 1.0f, model, view, projection, height);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    draw_sprites(points, radius_mm, colour, 0.45f, model, view, projection, height);
    glDisable(GL_BLEND);
    glEnable(GL_DEPTH_TEST);
}

void SceneRenderer::draw_lines(std::span<const glm::vec3> world_points, const glm::vec4& colour, const glm::mat4& view_projection) {
    if (world_points.empty()) return;
    lines_.use();
    lines_.set("u_view_projection", view_projection);
    lines_.set("u_colour", colour);
    glBindVertexArray(line_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(world_points.size_bytes()), world_points.data(), GL_STREAM_DRAW);
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(world_points.size()));
    glBindVertexArray(0);
}

void SceneRenderer::render(const Framebuffer& target, const OrbitCamera& camera, const SceneContent& content,
                           const SceneStyle& style) {
    target.bind();
    glClearColor(style.background.r, style.background.g, style.background.b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    if (content.lattice == nullptr) return;
    const glm::dmat4 model_d = index_to_world(*content.lattice);
    const glm::mat4 model(model_d);
    const glm::mat4 view = camera.view();
    const glm::mat4 projection = camera.projection(static_cast<double>(target.width()) / target.height());
    const glm::mat4 view_projection = projection * view;
    glEnable(GL_DEPTH_TEST);
    glDepthFunc(GL_LESS);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);

    if (content.surface != nullptr && content.surface->triangle_count() > 0) {
        surface_.use();
        // A coarser grid's vertices are in its own index space: scale and shift them to the lattice's.
        glm::mat4 surface_to_index(glm::mat3(content.surface_scale));
        surface_to_index[3] = glm::vec4(glm::vec3(content.surface_offset), 1.0f);
        const glm::mat4 model_view = view * model * surface_to_index;
        surface_.set("u_model_view", model_view);
        surface_.set("u_projection", projection);
        surface_.set("u_normal_matrix", glm::mat3(glm::transpose(glm::inverse(model_view))));
        surface_.set("u_outside", style.outside);
        surface_.set("u_inside", style.inside);
        const glm::dvec2 range = camera.depth_range();
        surface_.set("u_depth_range", glm::vec2(range));
        // Triangles are counter-clockwise seen from outside in index space; a mirroring
        // index -> world map (negative determinant) turns them clockwise.
        surface_.set("u_front_is_ccw", glm::determinant(glm::dmat3(model_d)) > 0.0 ? 1 : 0);
        content.surface->draw();
    }

    glEnable(GL_PROGRAM_POINT_SIZE);
    draw_sprites(content.agents, style.agent_radius_mm, style.agents, 1.0f, model, view, projection, target.height());

    if (style.bounding_box) {
        const Vec3i d = content.lattice->dims();
        std::vector<glm::vec3> box;
        for (int e = 0; e < 12; ++e) {
            const int axis = e / 4, a = (axis + 1) % 3, b = (axis + 2) % 3;
            glm::dvec3 p0(0.0), p1(0.0);
            const double extent[3] = {d.x - 1.0, d.y - 1.0, d.z - 1.0};
            p0[a] = p1[a] = (e & 1) ? extent[a] : 0.0;
            p0[b] = p1[b] = (e & 2) ? extent[b] : 0.0;
            p1[axis] = extent[axis];
            box.emplace_back(model_d * glm::dvec4(p0, 1.0));
            box.emplace_back(model_d * glm::dvec4(p1, 1.0));
        }
        draw_lines(box, glm::vec4(0.45f, 0.47f, 0.52f, 1.0f), view_projection);
    }

    draw_see_through(content.markers, style.marker_radius_mm, style.markers, model, view, projection, target.height());
    if (content.selected_marker) {
        const glm::vec3 m = *content.selected_marker;
        draw_see_through({&m, 1}, style.marker_radius_mm * 1.4f, style.selected_marker, model, view, projection, target.height());
    }
    if (content.target) {
        const glm::vec3 t = *content.target;
        draw_see_through({&t, 1}, style.target_radius_mm, style.target, model, view, projection, target.height());
    }

    if (style.cursor && content.cursor) {
        const glm::dvec3 c = model_d * glm::dvec4(glm::dvec3(*content.cursor), 1.0);
        const double half = 0.06 * world_bounds(*content.lattice).radius;
        glDisable(GL_DEPTH_TEST);
        const glm::vec4 colours[3] = {{0.95f, 0.3f, 0.3f, 1.0f}, {0.3f, 0.9f, 0.3f, 1.0f}, {0.35f, 0.55f, 1.0f, 1.0f}};
        for (int axis = 0; axis < 3; ++axis) {
            glm::dvec3 u(0.0);
            u[axis] = half;
            const glm::vec3 seg[2] = {glm::vec3(c - u), glm::vec3(c + u)};
            draw_lines(seg, colours[axis], view_projection);
        }
        glEnable(GL_DEPTH_TEST);
    }
    glDisable(GL_PROGRAM_POINT_SIZE);
}

}  // namespace liveset::render
