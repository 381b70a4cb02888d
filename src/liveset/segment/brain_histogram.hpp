// Histogram helpers of the automatic brain mask (brain_mask.cpp) and its reading of the deep head's
// contrast (T1, or grey matter brighter than white: T2, PD). Internal to the segment library.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/brain_mask.hpp"

namespace liveset::brain_detail {

using Mask = Grid<std::uint8_t>;

constexpr int kBins = 128;

// The value at fraction q in [0, 1] of the sorted values of `image` inside `mask` (all voxels when
// null) that lie above `above` (element floor(q·(n − 1)), as std::nth_element places it), or
// nullopt when there is none. Two passes, no copy of the image.
std::optional<float> quantile_above(const Grid<float>& image, const Mask* mask, double above, double q);
// quantile_above for several fractions in the same two passes (each value as quantile_above gives
// it), in their order; empty when no voxel is kept. At most 255 distinct histogram bins among them.
std::vector<float> quantiles_above(const Grid<float>& image, const Mask* mask, double above, std::span<const double> fractions);

// A kBins-bin histogram over [lo, hi] of the image's voxels inside `mask` (values outside the range
// and NaN are not counted).
struct Histogram {
    double lo = 0, width = 1;
    std::vector<double> counts = std::vector<double>(kBins, 0.0);
    double centre(int bin) const { return lo + (bin + 0.5) * width; }
};
Histogram histogram(const Grid<float>& image, const Mask& mask, double lo, double hi);

// Counts smoothed by a Gaussian of sigma_bins bins (the ends repeated).
std::vector<double> smoothed(const std::vector<double>& c, double sigma_bins);

// Three-class Otsu (tissue_model.hpp) on a histogram: the first bins of the middle and upper classes.
std::pair<int, int> otsu3(const std::vector<double>& h, const Histogram& geom);

// The tallest bin of a smoothed histogram and the bins, on either side, where it first falls to half.
struct Peak { int bin = 0, low = 0, high = 0; };
Peak tallest(const std::vector<double>& s);

// White-matter peak and widths from the deepest half of `head` by `depth` (mm; T1: mostly white
// matter: its histogram's tallest peak), and that half's skew and shares about the peak
// (BrainMaskReport::deep_skew, deep_above, deep_below), all of it over r.background_threshold. Skewed
// bright with two prominent peaks (≥ 5 % of the tallest bin), the darker is taken as white matter's
// and the brighter as grey matter's (deep_grey_peak) where at least 10 % of the half lies 3 σ above
// that white matter, over twice as much as below, and it stands 3 σ clear of the background. Returns
// the head's 99.5th percentile above the background (the histograms' top). `grey_brighter`: known so
// (read before N4, brain_contrast): two such peaks are read so without the share tests. Throws
// std::invalid_argument where nothing lies above the background, or all of it at one value.
// `swamped_share` < 1 (BrainMaskOptions::swamped_share, not with `grey_brighter`): where over that
// share of the deep half lies 3 σ above the tallest peak and the half is skewed dark (deep_skew < 0,
// as a T1's: a T2's or PD's brightest peak is its CSF), white matter is taken at the brightest
// prominent peak above it instead (r.wm_swamped), and the grey-brighter and FLAIR reads are skipped
// (a T1 whose ventricles' CSF outnumbers its deep white matter: CSF darkest, white matter brightest).
double white_matter_peak(const Grid<float>& image, const Mask& head, const Grid<float>& depth, BrainMaskReport& r,
                         bool grey_brighter = false, double swamped_share = 1.0);

// White matter's lower edge on `smooth`, the smoothed image the brain-tissue window is applied to:
// its peak there (the local maximum of the deep half's smoothed histogram climbed to from r.wm_peak,
// within 2 σ of it) less 3 of its lower σ, and never below r.wm_peak − 3·r.wm_low_sigma (the raw
// image's). Smoothing narrows the noise the raw σ holds (a T2 under Rician σ 9: raw lower edge 41.9,
// smoothed 63.5, its muscle 45-60).
double smoothed_white_floor(const Grid<float>& smooth, const Mask& head, const Grid<float>& depth, const BrainMaskReport& r, double top);
// The contrast of a deep head (or brain) from white_matter_peak's figures. Grey matter brighter than
// white (a T2, a PD): the deep part skewed bright, with a grey-matter peak (deep_grey_peak) or at
// least a quarter of it 3 σ above the white-matter peak and over 4 times as much as 3 σ below, and -
// in a head (`in_head`) - that peak 3 σ clear of the background threshold (not the air's noise cut
// off there). Else a T1. What each part keeps out (a child's neck, noisy heads, the phantom's bias, a
// noisy field of view) and the measured margins: docs/ARCHITECTURE.md.
TissueContrast deep_contrast(const BrainMaskReport& r, bool in_head);

}  // namespace liveset::brain_detail
