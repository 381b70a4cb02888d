// Rings and seven-segment numbers as line pairs (marker_glyphs.hpp).
#include "liveset/render/marker_glyphs.hpp"

#include <cmath>
#include <string>

namespace liveset::render {

unsigned seven_segment_bits(int digit) {
    //                                   0     1     2     3     4     5     6     7     8     9
    static constexpr unsigned kBits[10] = {0x3F, 0x06, 0x5B, 0x4F, 0x66, 0x6D, 0x7D, 0x07, 0x7F, 0x6F};
    return digit >= 0 && digit <= 9 ? kBits[digit] : 0u;
}

std::vector<glm::vec2> number_lines(int value, glm::vec2 top_left, float height) {
    std::vector<glm::vec2> out;
    if (value < 0) return out;
    const float w = height * 0.5f, h2 = height * 0.5f;
    float x = top_left.x;
    const float y = top_left.y;
    for (const char c : std::to_string(value)) {
        const unsigned bits = seven_segment_bits(c - '0');
        // a, b, c, d, e, f, g: (from, to) in the digit's box
        const glm::vec2 seg[7][2] = {{{0, 0}, {w, 0}},   {{w, 0}, {w, h2}},  {{w, h2}, {w, height}}, {{0, height}, {w, height}},
                                     {{0, h2}, {0, height}}, {{0, 0}, {0, h2}}, {{0, h2}, {w, h2}}};
        for (int s = 0; s < 7; ++s)
            if (bits & (1u << s)) {
                out.push_back(glm::vec2(x, y) + seg[s][0]);
                out.push_back(glm::vec2(x, y) + seg[s][1]);
            }
        x += w + height * 0.25f;
    }
    return out;
}

float number_width(int value, float height) {
    const auto digits = static_cast<float>(std::to_string(value < 0 ? 0 : value).size());
    return digits * height * 0.5f + (digits - 1.0f) * height * 0.25f;
}

std::vector<glm::vec2> ring_lines(glm::vec2 centre, float radius, int segments, bool dashed) {
    std::vector<glm::vec2> out;
    for (int k = 0; k < segments; k += dashed ? 2 : 1)
        for (int e = 0; e < 2; ++e) {
            const double a = 2.0 * 3.14159265358979 * (k + e) / segments;
            out.emplace_back(centre.x + radius * static_cast<float>(std::cos(a)), centre.y + radius * static_cast<float>(std::sin(a)));
        }
    return out;
}

}  // namespace liveset::render
