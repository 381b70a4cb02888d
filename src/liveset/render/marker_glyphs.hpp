// Line-drawn marks for the slice panes, in pane pixels (top-left origin), as GL_LINES end-point
// pairs: rings and seven-segment numbers (the rank of a hole candidate next to its ring).
#pragma once

#include <glm/glm.hpp>
#include <vector>

namespace liveset::render {

// Segments a..g of each decimal digit (bit 0 = a, the top bar, clockwise to f; bit 6 = g, the
// middle bar), as a seven-segment display lights them.
unsigned seven_segment_bits(int digit);

// The digits of `value` (>= 0) as seven-segment line pairs, each digit `height` pixels tall and
// height / 2 wide, a quarter height apart, the first digit's top-left corner at `top_left`.
std::vector<glm::vec2> number_lines(int value, glm::vec2 top_left, float height);
float number_width(int value, float height);  // of number_lines' box

// A ring of `segments` chords about `centre`; with `dashed`, every other chord only.
std::vector<glm::vec2> ring_lines(glm::vec2 centre, float radius, int segments = 24, bool dashed = false);

}  // namespace liveset::render
