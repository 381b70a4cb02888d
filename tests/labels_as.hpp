// BrainWeb's labels in another contrast (a T2, a PD): the image the contrast tests build from them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/smoothing.hpp"

namespace liveset::testing {

// Each label's value (labels above 9 as 9), blurred by 0.7 mm, with Gaussian noise σ 4 as magnitude
// or (rician > 0) Rician noise of that σ, drawn from std::mt19937(seed).
inline Grid<float> labels_as(const Grid<std::uint8_t>& labels, const float (&value)[10], float rician = 0.0f, unsigned seed = 7) {
    Grid<float> image(labels.lattice());
    for (PointIndex i = 0; i < image.size(); ++i) image[i] = value[std::min<int>(labels[i], 9)];
    image = gaussian_smooth(image, 0.7);
    std::mt19937 rng(seed);
    std::normal_distribution<float> noise(0.0f, rician > 0.0f ? rician : 4.0f);
    for (float& v : image.values()) v = rician > 0.0f ? std::hypot(v + noise(rng), noise(rng)) : std::abs(v + noise(rng));
    return image;
}

}  // namespace liveset::testing
