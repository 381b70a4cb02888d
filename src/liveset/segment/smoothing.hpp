// The Gaussian pre-smoothing of the threshold speed's image: a noisy scan's data term sees a
// slightly blurred image (docs/ARCHITECTURE.md, "The automatic regularisation").
#pragma once

#include "liveset/grid/grid.hpp"

namespace liveset {

// The automatic choice blurs by kSmoothVoxels of the finest voxel side (σ in mm, the same along every
// axis) when the noise ratio exceeds kAlphaNoiseFloor (alpha.hpp), else not at all.
inline constexpr double kSmoothVoxels = 0.5;
// Largest σ accepted: in mm, and in voxels along any axis (kernels stay at most 4·kMaxSmoothVoxels
// taps each side on any lattice the reader accepts).
inline constexpr double kMaxSmoothMm = 10.0;
inline constexpr double kMaxSmoothVoxels = 50.0;

// `image` convolved with a Gaussian of standard deviation `sigma_mm` (physical units: σ / spacing
// voxels along each axis, the spacing taken as float - Lattice::spacing_float() - and the quotient
// rounded to 1e-4 voxel, so that one scan stored as NIfTI and as MINC gets the same kernels), sampled and truncated at 4σ (scipy.ndimage's default), weights
// normalised to 1, the border replicated. Along an axis whose σ is under kNegligibleSigma voxels
// the image is not filtered (its side weights would be below 1e-9). σ = 0 returns a copy.
// Deterministic: each voxel's sum runs in a fixed order whatever the thread count.
// Throws std::invalid_argument for σ outside [0, kMaxSmoothMm] or not finite, or over
// kMaxSmoothVoxels voxels along an axis.
inline constexpr double kNegligibleSigma = 0.15;
Grid<float> gaussian_smooth(const Grid<float>& image, double sigma_mm);

// Throws std::invalid_argument "the smoothing sigma must be in [0, 10] mm, not S" for σ outside
// [0, kMaxSmoothMm] or not finite (gaussian_smooth's and ThresholdParams' one range check).
void check_smooth_mm(double sigma_mm);

// The automatic pre-smoothing's σ (mm) for voxels of `spacing` (as float, Lattice::spacing_float()):
// kSmoothVoxels × the finest side, at most kMaxSmoothMm.
double presmoothing_mm(Vec3f spacing);

}  // namespace liveset
