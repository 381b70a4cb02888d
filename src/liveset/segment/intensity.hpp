// Intensity handling for threshold segmentation: the robust normalisation of a raw MR image to
// [0, 1] (paper Eq. 3 assumes I(p) ∈ [0, 1]) and the estimate of the threshold window (µ, ε) from
// the intensities around the user's seeds.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

// Linear map raw -> unit: u = clamp((raw - low) / (high - low), 0, 1), with low/high robust
// percentiles of the image (or of the region of interest), so a few hot or dark voxels do not
// squash the tissue contrast.
struct IntensityScale {
    double low = 0.0;
    double high = 1.0;
    double to_unit(double raw) const;   // clamped to [0, 1]
    double to_raw(double unit) const;   // inverse (unclamped)
    double unit_length(double raw_length) const { return raw_length / (high - low); }
    double raw_length(double unit_length) const { return unit_length * (high - low); }
};

struct ScaleOptions {
    double low_percentile = 0.5;    // in percent
    double high_percentile = 99.5;  // in percent
};

// Percentiles over the voxels of `image` (inside `roi` when given: non-zero voxels; same
// dimensions). Throws std::invalid_argument on bad percentiles, a ROI of other dimensions or with
// no voxel, non-finite voxels, or a flat image (high == low).
IntensityScale robust_scale(const Grid<float>& image, const Grid<std::uint8_t>* roi = nullptr,
                            const ScaleOptions& options = {});

// The image mapped to [0, 1] with `scale`.
Grid<float> normalise(const Grid<float>& image, const IntensityScale& scale);

// The value a masked image's outside is given so that it lies below every value in [lo, hi]:
// 1 % of the range below lo (1 below when the range is empty).
float value_below(float lo, float hi);

// The voxels of `where` (non-zero; same dims) set to value_below(the other voxels' range): a masked
// outside read as a skull-stripped image's dark background. Nothing changes when `where` holds every
// voxel or none.
void lower_voxels(Grid<float>& image, const Grid<std::uint8_t>& where);

// A masked image's "no data" (NaN voxels: SPM's masked images, fslmaths -nan, read with
// NanVoxels::keep) made its lowest values: every NaN voxel set to value_below(the others' range),
// so the brain mask finds them as a skull-stripped brain's dark outside and no threshold window
// around a tissue holds them. Returns where they were (none: no NaN). Throws
// std::invalid_argument when every voxel is NaN or any is infinite.
std::optional<Grid<std::uint8_t>> lower_no_data(Grid<float>& image);

// A seed: a ball in index coordinates (voxels).
struct SeedBall {
    Vec3d center;
    double radius = 2.0;
};

struct SeedStatistics {
    std::size_t voxels = 0;
    double mean = 0.0;
    double median = 0.0;
    double stddev = 0.0;
    double mad_sigma = 0.0;  // 1.4826 × median absolute deviation (robust σ)
};

// Values of `image` at the lattice points inside the seed balls (inside `roi` when given), seed by
// seed. Throws std::invalid_argument when a seed centre lies outside the lattice, a radius is bad
// or no voxel is covered.
std::vector<float> seed_values(const Grid<float>& image, std::span<const SeedBall> seeds,
                               const Grid<std::uint8_t>* roi = nullptr);

// Whether a lattice point of the seed's ball, as seed_values reads it (within max(radius, 0.5) of
// the centre, index space), lies in `mask` (non-zero).
bool ball_touches(const Grid<std::uint8_t>& mask, const SeedBall& seed);

// Statistics of seed_values().
SeedStatistics seed_statistics(const Grid<float>& image, std::span<const SeedBall> seeds,
                               const Grid<std::uint8_t>* roi = nullptr);
// Statistics of a sample (not empty).
SeedStatistics seed_statistics_of(std::vector<float> values);

}  // namespace liveset
