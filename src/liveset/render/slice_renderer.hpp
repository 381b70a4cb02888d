// One slice pane: the image slice as a texture, an RGBA overlay texture (label fill, ROI, speed
// preview: slice_display.hpp) blended over it, the zero contour of φ, the crosshair linked to the
// 3D view, the seeds (circles where their balls cut the slice), the swarm's target and markers
// (hole candidates: a ring with its rank), drawn into the pane's framebuffer in pane pixels
// (SliceViewport).
#pragma once

#include <glm/glm.hpp>
#include <optional>
#include <span>
#include <vector>

#include "liveset/render/framebuffer.hpp"
#include "liveset/render/shader_program.hpp"
#include "liveset/render/slice_geometry.hpp"

namespace liveset::render {

struct SliceCircle {
    glm::dvec2 centre_uv{0.0};
    double radius_mm = 1.0;
};

// A numbered marker (a hole candidate's site): a ring of kMarkerRadiusPx pixels with `label` at its
// upper right; `selected` adds an outer ring in the highlight colour; off the slice (a site on a
// nearby slice) the ring is dashed and faint.
struct SliceMarker {
    glm::dvec2 centre_uv{0.0};
    int label = 0;
    bool selected = false;
    bool on_slice = true;
};
inline constexpr float kMarkerRadiusPx = 7.0f;

struct SliceOverlay {
    std::span<const glm::dvec2> contour;  // segment end points, texel space
    std::optional<glm::dvec2> cursor;     // crosshair, texel space
    std::vector<SliceCircle> seeds;
    std::optional<glm::dvec2> target;
    std::vector<SliceMarker> markers;
    bool layer = false;  // blend the RGBA overlay texture (set_overlay) over the image
};

struct SliceStyle {
    glm::vec3 background{0.0f};
    glm::vec4 contour{1.0f, 0.25f, 0.2f, 1.0f};
    glm::vec4 cursor{0.35f, 0.55f, 1.0f, 0.85f};
    glm::vec4 seeds{0.2f, 1.0f, 0.3f, 1.0f};
    glm::vec4 target{1.0f, 0.85f, 0.1f, 1.0f};
    glm::vec4 marker{1.0f, 0.5f, 0.0f, 1.0f};
    glm::vec4 marker_selected{1.0f, 0.25f, 1.0f, 1.0f};
};

class SliceRenderer {
public:
    SliceRenderer();  // needs a current OpenGL 3.3 context
    ~SliceRenderer();
    SliceRenderer(const SliceRenderer&) = delete;
    SliceRenderer& operator=(const SliceRenderer&) = delete;

    // Uploads the slice's grey texels (slice_texels()).
    void set_texels(int width, int height, std::span<const std::uint8_t> texels);
    // Uploads the RGBA overlay texels (overlay_texels(), straight alpha), same size as the slice.
    void set_overlay(int width, int height, std::span<const std::uint8_t> rgba);
    void render(const Framebuffer& target, const SliceViewport& viewport, const SliceOverlay& overlay, const SliceStyle& style);

private:
    void draw_lines(std::span<const glm::vec2> pixels, const glm::vec4& colour, const glm::mat4& projection);
    void draw_markers(const SliceViewport& viewport, std::span<const SliceMarker> markers, const SliceStyle& style,
                      const glm::mat4& projection);

    ShaderProgram image_, lines_;
    GLuint texture_ = 0, overlay_ = 0;
    GLuint quad_vao_ = 0, quad_vbo_ = 0;
    GLuint line_vao_ = 0, line_vbo_ = 0;
};

}  // namespace liveset::render
