// Hole-candidate markers in a slice pane (SliceRenderer, marker_glyphs): the seven-segment table
// against the display's segments, the ring's pixels at the projected site in the marker colour
// (the highlight colour and a second ring when selected, dashed and faint off the slice), its
// centre left clear, and the rank's digits at the ring's upper right.
#include <gtest/gtest.h>

#include <bit>
#include <cmath>

#include "liveset/render/marker_glyphs.hpp"
#include "liveset/render/slice_renderer.hpp"
#include "render_test_util.hpp"

namespace liveset {
namespace {

using testing::gl_context;

TEST(MarkerGlyphs, SevenSegmentDigitsAndNumbers) {
    // Segments lit per digit on a seven-segment display: 0:6 1:2 2:5 3:5 4:4 5:5 6:6 7:3 8:7 9:6.
    const int lit[10] = {6, 2, 5, 5, 4, 5, 6, 3, 7, 6};
    for (int d = 0; d < 10; ++d) EXPECT_EQ(std::popcount(render::seven_segment_bits(d)), lit[d]) << d;
    EXPECT_EQ(render::seven_segment_bits(1), 0x06u);  // b and c: the right-hand bars
    EXPECT_EQ(render::seven_segment_bits(10), 0u);
    const std::vector<glm::vec2> l = render::number_lines(17, {10.0f, 20.0f}, 8.0f);
    EXPECT_EQ(l.size(), 2u * (2 + 3));
    const float w = render::number_width(17, 8.0f);
    EXPECT_FLOAT_EQ(w, 2 * 4.0f + 2.0f);
    for (const glm::vec2& p : l) {
        EXPECT_GE(p.x, 10.0f);
        EXPECT_LE(p.x, 10.0f + w);
        EXPECT_GE(p.y, 20.0f);
        EXPECT_LE(p.y, 28.0f);
    }
    const std::vector<glm::vec2> ring = render::ring_lines({0.0f, 0.0f}, 5.0f, 24, false);
    ASSERT_EQ(ring.size(), 48u);
    for (const glm::vec2& p : ring) EXPECT_NEAR(std::hypot(p.x, p.y), 5.0, 1e-5);
    EXPECT_EQ(render::ring_lines({0.0f, 0.0f}, 5.0f, 24, true).size(), 24u);
}

struct Rgb {
    int r = 0, g = 0, b = 0;
};
Rgb at(const render::Image& img, int x, int y) {
    const std::size_t k = 4 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x));
    return {img.rgba[k], img.rgba[k + 1], img.rgba[k + 2]};
}
// Some pixel of the 3x3 block about (x, y) within 30 of `c`.
bool near_colour(const render::Image& img, glm::dvec2 p, glm::vec4 c) {
    for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
            const Rgb v = at(img, static_cast<int>(std::floor(p.x)) + dx, static_cast<int>(std::floor(p.y)) + dy);
            if (std::abs(v.r - c.r * 255) <= 30 && std::abs(v.g - c.g * 255) <= 30 && std::abs(v.b - c.b * 255) <= 30) return true;
        }
    return false;
}

TEST(HoleMarkers, RingsAndRanksAtTheProjectedSites) {
    gl_context();
    const Lattice lat({64, 64, 40}, {1.0, 1.0, 1.0});
    const render::SliceViewport vp = render::SliceViewport::fit(render::slice_geometry(lat, render::SliceAxis::kAxial), 256, 256);
    render::SliceRenderer r;
    const std::vector<std::uint8_t> black(static_cast<std::size_t>(vp.geometry.width * vp.geometry.height), 0);
    r.set_texels(vp.geometry.width, vp.geometry.height, black);
    render::SliceOverlay o;
    const glm::dvec2 a{16.0, 16.0}, b{44.0, 40.0}, c{20.0, 48.0};
    o.markers = {{a, 3, false, true}, {b, 12, true, true}, {c, 5, false, false}};
    render::Framebuffer fb(256, 256);
    const render::SliceStyle style;
    r.render(fb, vp, o, style);
    glFinish();
    const render::Image img = fb.read_color();
    glm::vec4 faint = style.marker * 0.55f;  // off the slice: blended at 0.55 over black
    // Chords of the ring found in `colour` (with `clear_of_digits`, only those outside the upper
    // right quadrant, where the rank is drawn).
    const auto ring = [&](glm::dvec2 uv, float radius, glm::vec4 colour, bool dashed, bool clear_of_digits = false) {
        const glm::dvec2 p = vp.to_pixel(uv);
        int hits = 0;
        const int n = dashed ? 12 : 24;
        for (int k = 0; k < n; ++k) {  // chord midpoints (of the dashes when dashed)
            const double t = 2.0 * 3.14159265358979 * ((dashed ? 2 * k : k) + 0.5) / 24.0;
            if (clear_of_digits && std::cos(t) > 0 && std::sin(t) < 0) continue;
            hits += near_colour(img, p + glm::dvec2(std::cos(t), std::sin(t)) * static_cast<double>(radius), colour);
        }
        return hits;
    };
    EXPECT_EQ(ring(a, render::kMarkerRadiusPx, style.marker, false), 24);
    EXPECT_EQ(ring(b, render::kMarkerRadiusPx, style.marker_selected, false), 24);
    EXPECT_EQ(ring(b, render::kMarkerRadiusPx + 3.0f, style.marker_selected, false), 24);  // the selected one's outer ring
    EXPECT_EQ(ring(a, render::kMarkerRadiusPx + 3.0f, style.marker, false, true), 0);  // not selected: one ring
    EXPECT_EQ(ring(c, render::kMarkerRadiusPx, faint, true), 12);
    EXPECT_EQ(ring(c, render::kMarkerRadiusPx, style.marker, true), 0);  // not at full strength
    // The centre is clear; the rank's digits lie at the upper right (pixels of the marker colour).
    const glm::dvec2 pa = vp.to_pixel(a);
    const Rgb centre = at(img, static_cast<int>(pa.x), static_cast<int>(pa.y));
    EXPECT_EQ(centre.r + centre.g + centre.b, 0);
    int digit = 0;
    for (int y = static_cast<int>(pa.y) - 18; y < static_cast<int>(pa.y) - 5; ++y)
        for (int x = static_cast<int>(pa.x) + 8; x < static_cast<int>(pa.x) + 16; ++x) {
            const Rgb v = at(img, x, y);
            digit += v.r > 200 && v.g > 100 && v.g < 160 && v.b < 40;
        }
    EXPECT_GE(digit, 10);  // "3": three bars and the right side
}

}  // namespace
}  // namespace liveset
