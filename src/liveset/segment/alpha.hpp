// The automatic regularisation of the threshold speed: the curvature weight α - as much smoothing
// as the image's noise needs, less on voxels much longer along one axis than another - and, on a
// noisy scan, a slight Gaussian blur of the image the data term reads (smoothing.hpp).
#pragma once

#include <limits>

#include "liveset/grid/vec3.hpp"
#include "liveset/segment/tissue_model.hpp"

namespace liveset {

// What α a segmentation ran with, and why.
struct AlphaChoice {
    double alpha = 0.1;
    bool automatic = false;
    // The larger σ of the window's tissue class and of the class with the nearest mean, over the
    // distance between the two means (raw units; the tissue model's fit); NaN when no usable model
    // was fitted.
    double noise_ratio = std::numeric_limits<double>::quiet_NaN();
    int tissue_class = -1;   // the window's class (see automatic_alpha); -1 without a ratio
    double anisotropy = 1.0;  // longest over shortest voxel side
    // σ (mm) of the pre-smoothing (ThresholdParams::smooth_mm): kSmoothVoxels × the finest voxel
    // side when the noise ratio exceeds kAlphaNoiseFloor, else 0 (also without a ratio); at least
    // the model's own smooth_mm when it was fitted on the blurred image (window.hpp: the noise ratio
    // and α then come from that model's narrower spreads).
    double smooth_mm = 0.0;
};

// The rule (docs/ARCHITECTURE.md, "The automatic curvature weight"):
//   α = clamp((noise_ratio − kAlphaNoiseFloor) × kAlphaPerNoise, 0, kAlphaMax) × (h_min / h_max)³,
// with kFallbackAlpha in place of the first factor when the model is absent or unusable. The
// curvature only pays where noise scatters single voxels across the window's edges (a clean scan
// segments best without it; docs/BENCHMARKS.md, session 50), and on thick slices it costs the most.
// Above the same noise floor the image is blurred by σ = kSmoothVoxels finest voxel sides before D
// is tabulated (docs/BENCHMARKS.md, session 54): single noisy voxels no longer cut the front off.
inline constexpr double kAlphaNoiseFloor = 0.2;
inline constexpr double kAlphaPerNoise = 0.5;
inline constexpr double kAlphaMax = 0.15;
inline constexpr double kFallbackAlpha = 0.1;

// `model` may be null or unusable (then the fallback). The class is `window_class` where the window came from the model (its seeds'
// class), else the one whose mean lies nearest `window_centre_raw` (a tie: the darker). `spacing`
// is the voxel size in mm as float (Lattice::spacing_float(): a NIfTI's float and a MINC's double
// voxel sizes give the same α, as they give the same curvature).
AlphaChoice automatic_alpha(const TissueModel* model, double window_centre_raw, Vec3f spacing, int window_class = -1);

}  // namespace liveset
