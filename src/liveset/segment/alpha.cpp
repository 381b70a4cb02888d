// automatic_alpha(): the curvature weight and the pre-smoothing from the tissue model's noise ratio
// and the voxel shape.
#include "liveset/segment/alpha.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

#include "liveset/segment/smoothing.hpp"

namespace liveset {

namespace {

// The larger spread (TissueClass::spread: σ, or the narrower peak the histogram shows) of the
// window's class k and of the class j whose mean is nearest k's, over the
// distance between their means; NaN (class −1) without a usable model of at least two classes with
// distinct means.
double noise_ratio(const TissueModel* model, double centre, int window_class, int& tissue_class) {
    tissue_class = -1;
    if (!model || !model->usable() || model->classes.size() < 2) return std::numeric_limits<double>::quiet_NaN();
    const auto& c = model->classes;
    std::size_t k = 0;
    if (window_class >= 0 && static_cast<std::size_t>(window_class) < c.size()) {
        k = static_cast<std::size_t>(window_class);
    } else {
        for (std::size_t i = 1; i < c.size(); ++i)
            if (std::abs(c[i].mean - centre) < std::abs(c[k].mean - centre)) k = i;
    }
    std::size_t j = k == 0 ? 1 : 0;  // the nearest other class: its border with k is the window's nearer edge
    for (std::size_t i = 0; i < c.size(); ++i)
        if (i != k && std::abs(c[i].mean - c[k].mean) < std::abs(c[j].mean - c[k].mean)) j = i;
    const double gap = std::abs(c[j].mean - c[k].mean), sigma = std::max(c[k].spread(), c[j].spread());
    if (!(gap > 0.0) || !std::isfinite(gap) || !std::isfinite(sigma)) return std::numeric_limits<double>::quiet_NaN();
    tissue_class = static_cast<int>(k);
    return sigma / gap;  // both spreads blur that border
}

}  // namespace

AlphaChoice automatic_alpha(const TissueModel* model, double window_centre_raw, Vec3f spacing, int window_class) {
    AlphaChoice a;
    a.automatic = true;
    a.noise_ratio = noise_ratio(model, window_centre_raw, window_class, a.tissue_class);
    const double base = std::isnan(a.noise_ratio)
                            ? kFallbackAlpha
                            : std::clamp((a.noise_ratio - kAlphaNoiseFloor) * kAlphaPerNoise, 0.0, kAlphaMax);
    const double h_min = std::min({spacing.x, spacing.y, spacing.z});  // float -> double: exact
    const double h_max = std::max({spacing.x, spacing.y, spacing.z});
    a.anisotropy = h_max / h_min;
    a.alpha = base / (a.anisotropy * a.anisotropy * a.anisotropy);
    if (a.noise_ratio > kAlphaNoiseFloor) a.smooth_mm = presmoothing_mm(spacing);  // NaN compares false
    // A model fitted on the blurred image (window.cpp): its window holds on that image, so D reads it.
    if (model && model->usable()) a.smooth_mm = std::max(a.smooth_mm, model->smooth_mm);
    return a;
}

}  // namespace liveset
