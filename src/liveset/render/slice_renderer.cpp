// Slice pane drawing.
#include "liveset/render/slice_renderer.hpp"

#include <cmath>
#include <glm/gtc/matrix_transform.hpp>

#include "liveset/render/marker_glyphs.hpp"

namespace liveset::render {

namespace {

constexpr const char* kImageVertex = R"(#version 330 core
layout(location = 0) in vec2 a_pixel;
layout(location = 1) in vec2 a_texcoord;
uniform mat4 u_projection;
out vec2 v_texcoord;
void main() { v_texcoord = a_texcoord; gl_Position = u_projection * vec4(a_pixel, 0.0, 1.0); }
)";

constexpr const char* kImageFragment = R"(#version 330 core
in vec2 v_texcoord;
uniform sampler2D u_image;
uniform int u_rgba;  // 0: grey texels (R8), 1: straight-alpha RGBA overlay
out vec4 colour;
void main() {
    vec4 t = texture(u_image, v_texcoord);
    colour = u_rgba == 1 ? t : vec4(t.r, t.r, t.r, 1.0);
}
)";

constexpr const char* kLineVertex = R"(#version 330 core
layout(location = 0) in vec2 a_pixel;
uniform mat4 u_projection;
void main() { gl_Position = u_projection * vec4(a_pixel, 0.0, 1.0); }
)";

constexpr const char* kLineFragment = R"(#version 330 core
uniform vec4 u_colour;
out vec4 colour;
void main() { colour = u_colour; }
)";

}  // namespace

SliceRenderer::SliceRenderer() : image_(kImageVertex, kImageFragment), lines_(kLineVertex, kLineFragment) {
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glGenTextures(1, &overlay_);
    glBindTexture(GL_TEXTURE_2D, overlay_);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    glGenVertexArrays(1, &quad_vao_);
    glGenBuffers(1, &quad_vbo_);
    glBindVertexArray(quad_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, quad_vbo_);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), nullptr);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 2, GL_FLOAT, GL_FALSE, 4 * sizeof(float), reinterpret_cast<void*>(2 * sizeof(float)));
    glGenVertexArrays(1, &line_vao_);
    glGenBuffers(1, &line_vbo_);
    glBindVertexArray(line_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(glm::vec2), nullptr);
    glBindVertexArray(0);
}

SliceRenderer::~SliceRenderer() {
    glDeleteTextures(1, &texture_);
    glDeleteTextures(1, &overlay_);
    glDeleteVertexArrays(1, &quad_vao_);
    glDeleteBuffers(1, &quad_vbo_);
    glDeleteVertexArrays(1, &line_vao_);
    glDeleteBuffers(1, &line_vbo_);
}

void SliceRenderer::set_texels(int width, int height, std::span<const std::uint8_t> texels) {
    glBindTexture(GL_TEXTURE_2D, texture_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_R8, width, height, 0, GL_RED, GL_UNSIGNED_BYTE, texels.data());
}

void SliceRenderer::set_overlay(int width, int height, std::span<const std::uint8_t> rgba) {
    glBindTexture(GL_TEXTURE_2D, overlay_);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
}

void SliceRenderer::draw_lines(std::span<const glm::vec2> pixels, const glm::vec4& colour, const glm::mat4& projection) {
    if (pixels.empty()) return;
    lines_.use();
    lines_.set("u_projection", projection);
    lines_.set("u_colour", colour);
    glBindVertexArray(line_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, line_vbo_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(pixels.size_bytes()), pixels.data(), GL_STREAM_DRAW);
    glDrawArrays(GL_LINES, 0, static_cast<GLsizei>(pixels.size()));
    glBindVertexArray(0);
}

void SliceRenderer::render(const Framebuffer& target, const SliceViewport& vp, const SliceOverlay& overlay,
                           const SliceStyle& style) {
    target.bind();
    glClearColor(style.background.r, style.background.g, style.background.b, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    // Pane pixels, top-left origin.
    const glm::mat4 projection = glm::ortho(0.0f, static_cast<float>(vp.pane_width), static_cast<float>(vp.pane_height), 0.0f);
    const SliceGeometry& g = vp.geometry;
    const glm::dvec2 lo = vp.to_pixel({0.0, 0.0}), hi = vp.to_pixel({static_cast<double>(g.width), static_cast<double>(g.height)});
    const float quad[] = {
        float(lo.x), float(lo.y), 0.0f, 0.0f,  float(hi.x), float(lo.y), 1.0f, 0.0f, float(hi.x), float(hi.y), 1.0f, 1.0f,
        float(lo.x), float(lo.y), 0.0f, 0.0f,  float(hi.x), float(hi.y), 1.0f, 1.0f, float(lo.x), float(hi.y), 0.0f, 1.0f,
    };
    image_.use();
    image_.set("u_projection", projection);
    image_.set("u_image", 0);
    image_.set("u_rgba", 0);
    glActiveTexture(GL_TEXTURE0);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glBindVertexArray(quad_vao_);
    glBindBuffer(GL_ARRAY_BUFFER, quad_vbo_);
    glBufferData(GL_ARRAY_BUFFER, sizeof(quad), quad, GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, 6);

    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    if (overlay.layer) {
        image_.set("u_rgba", 1);
        glBindTexture(GL_TEXTURE_2D, overlay_);
        glDrawArrays(GL_TRIANGLES, 0, 6);
    }
    glBindVertexArray(0);
    std::vector<glm::vec2> px;
    if (overlay.cursor) {  // ITK-SNAP's crosshair: full-width lines, a gap at the centre
        const glm::dvec2 c = vp.to_pixel(*overlay.cursor);
        const float gap = 6.0f;
        const auto x = static_cast<float>(c.x), y = static_cast<float>(c.y);
        px = {{0.0f, y}, {x - gap, y}, {x + gap, y}, {static_cast<float>(vp.pane_width), y},
              {x, 0.0f}, {x, y - gap}, {x, y + gap}, {x, static_cast<float>(vp.pane_height)}};
        draw_lines(px, style.cursor, projection);
    }
    px.clear();
    for (const glm::dvec2& p : overlay.contour) px.emplace_back(vp.to_pixel(p));
    draw_lines(px, style.contour, projection);

    const auto circle = [&](glm::dvec2 centre_uv, double radius_mm, const glm::vec4& colour) {
        std::vector<glm::vec2> ring;
        const glm::dvec2 c = vp.to_pixel(centre_uv);
        const double r = std::max(radius_mm * vp.pixels_per_mm(), 3.0);
        for (int k = 0; k < 32; ++k)
            for (int e = 0; e < 2; ++e) {
                const double a = 2.0 * 3.14159265358979 * (k + e) / 32.0;
                ring.emplace_back(c.x + r * std::cos(a), c.y + r * std::sin(a));
            }
        draw_lines(ring, colour, projection);
    };
    for (const SliceCircle& s : overlay.seeds) circle(s.centre_uv, s.radius_mm, style.seeds);
    if (overlay.target) {
        circle(*overlay.target, 2.5, style.target);
        const glm::dvec2 c = vp.to_pixel(*overlay.target);
        const std::vector<glm::vec2> cross{{c.x - 7, c.y}, {c.x + 7, c.y}, {c.x, c.y - 7}, {c.x, c.y + 7}};
        draw_lines(cross, style.target, projection);
    }
    draw_markers(vp, overlay.markers, style, projection);
    glDisable(GL_BLEND);
}

// Rings with their numbers (bold: drawn twice, a pixel apart); the selected one last, on top.
void SliceRenderer::draw_markers(const SliceViewport& vp, std::span<const SliceMarker> markers, const SliceStyle& style,
                                 const glm::mat4& projection) {
    for (int pass = 0; pass < 2; ++pass)
        for (const SliceMarker& m : markers) {
            if (m.selected != (pass == 1)) continue;
            const glm::vec2 c(vp.to_pixel(m.centre_uv));
            glm::vec4 colour = m.selected ? style.marker_selected : style.marker;
            if (!m.on_slice) colour.a *= 0.55f;
            std::vector<glm::vec2> px = ring_lines(c, kMarkerRadiusPx, 24, !m.on_slice);
            if (m.selected) {
                const std::vector<glm::vec2> outer = ring_lines(c, kMarkerRadiusPx + 3.0f, 24, !m.on_slice);
                px.insert(px.end(), outer.begin(), outer.end());
            }
            const float h = 9.0f;
            const std::vector<glm::vec2> digits = number_lines(m.label, c + glm::vec2(kMarkerRadiusPx + 2.0f, -kMarkerRadiusPx - h + 2.0f), h);
            for (const glm::vec2& d : digits) px.push_back(d);
            for (const glm::vec2& d : digits) px.push_back(d + glm::vec2(1.0f, 0.0f));
            draw_lines(px, colour, projection);
        }
}

}  // namespace liveset::render
