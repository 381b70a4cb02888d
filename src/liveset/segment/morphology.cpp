// Binary morphology in mm through eval's exact separable distance transform (see morphology.hpp).
#include "liveset/segment/morphology.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "liveset/eval/surface_distance.hpp"
#include "liveset/eval/topology.hpp"

namespace liveset {

namespace {

void check_radius(double r) {
    if (!std::isfinite(r) || r < 0) throw std::invalid_argument("morphology radius must be finite and >= 0 mm");
}

Grid<std::uint8_t> complement(const Grid<std::uint8_t>& mask) {
    Grid<std::uint8_t> out(mask.lattice());
    for (std::size_t i = 0; i < mask.size(); ++i) out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] == 0;
    return out;
}

// 1 where the squared distance (mm²) to the features is above r² (above == true) or at most r².
// Distances equal to r up to rounding count as r: a 4 mm ball at 1 mm spacing holds (0, 0, 4).
Grid<std::uint8_t> threshold_distance(const Grid<std::uint8_t>& features, double r, bool above) {
    const double r2 = r * r * (1 + 1e-9);
    const Grid<double> d2 = squared_distance_transform_mm(features, r2);
    Grid<std::uint8_t> out(features.lattice());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const double v = d2[static_cast<PointIndex>(i)];
        out[static_cast<PointIndex>(i)] = above ? v > r2 : v <= r2;
    }
    return out;
}

Grid<std::uint8_t> binarised(const Grid<std::uint8_t>& mask) {
    Grid<std::uint8_t> out(mask.lattice());
    for (std::size_t i = 0; i < mask.size(); ++i) out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] != 0;
    return out;
}

}  // namespace

Grid<std::uint8_t> erode_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    check_radius(radius_mm);
    if (radius_mm == 0) return binarised(mask);
    Grid<std::uint8_t> out = threshold_distance(complement(mask), radius_mm, true);
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] &= mask[static_cast<PointIndex>(i)] != 0;
    return out;
}

Grid<std::uint8_t> dilate_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    check_radius(radius_mm);
    if (radius_mm == 0) return binarised(mask);
    return threshold_distance(mask, radius_mm, false);
}

Grid<std::uint8_t> close_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    Grid<std::uint8_t> out = erode_mm(dilate_mm(mask, radius_mm), radius_mm);
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] |= mask[static_cast<PointIndex>(i)] != 0;
    return out;
}

Grid<std::uint8_t> largest_component(const Grid<std::uint8_t>& mask) {
    std::size_t count = 0;
    const std::vector<std::uint32_t> labels = label_components(mask, 6, &count);
    Grid<std::uint8_t> out(mask.lattice());
    if (count == 0) return out;
    std::vector<std::size_t> sizes(count + 1, 0);
    for (std::uint32_t l : labels) ++sizes[l];
    std::uint32_t best = 1;
    for (std::uint32_t l = 2; l <= count; ++l)
        if (sizes[l] > sizes[best]) best = l;  // labels follow scan order: strict > keeps the first on ties
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] = labels[i] == best;
    return out;
}

Grid<std::uint8_t> large_components(const Grid<std::uint8_t>& mask, double fraction) {
    if (!(fraction > 0 && fraction <= 1)) throw std::invalid_argument("large_components: fraction must lie in (0, 1]");
    std::size_t count = 0;
    const std::vector<std::uint32_t> labels = label_components(mask, 6, &count);
    std::vector<std::size_t> sizes(count + 1, 0);
    for (std::uint32_t l : labels) ++sizes[l];
    sizes[0] = 0;
    const double largest = static_cast<double>(*std::max_element(sizes.begin(), sizes.end()));
    Grid<std::uint8_t> out(mask.lattice());
    for (std::size_t i = 0; i < out.size(); ++i)
        out[static_cast<PointIndex>(i)] = labels[i] != 0 && static_cast<double>(sizes[labels[i]]) >= fraction * largest;
    return out;
}

Grid<std::uint8_t> fill_holes(const Grid<std::uint8_t>& mask) {
    const Grid<std::uint8_t> outside = complement(mask);
    std::size_t count = 0;
    const std::vector<std::uint32_t> labels = label_components(outside, 6, &count);
    std::vector<std::uint8_t> open(count + 1, 0);  // outside components that reach the border
    const Lattice& lat = mask.lattice();
    const Vec3i d = lat.dims();
    for (std::size_t i = 0; i < labels.size(); ++i) {
        if (labels[i] == 0) continue;
        const Vec3i p = lat.coord(static_cast<PointIndex>(i));
        if (p.x == 0 || p.y == 0 || p.z == 0 || p.x == d.x - 1 || p.y == d.y - 1 || p.z == d.z - 1) open[labels[i]] = 1;
    }
    Grid<std::uint8_t> out(lat);
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] = labels[i] == 0 || !open[labels[i]];
    return out;
}

Grid<float> depth_mm(const Grid<std::uint8_t>& mask) {
    const Grid<double> d2 = squared_distance_transform_mm(complement(mask));
    Grid<float> out(mask.lattice());
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] = static_cast<float>(std::sqrt(d2[static_cast<PointIndex>(i)]));
    return out;
}

}  // namespace liveset
