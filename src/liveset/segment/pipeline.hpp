// One call from a raw image and seeds to a segmentation: normalise the intensities, estimate the
// threshold window from the seeds when it is not given, initialise the level set (seed balls or an
// initial mask), run the threshold speed to convergence, and return φ, the mask and the numbers a
// report needs. Shared by `liveset segment`, the demo and the viewer.
#pragma once

#include <atomic>
#include <memory>
#include <optional>
#include <vector>

#include "liveset/levelset/sparse_field.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/threshold_speed.hpp"

namespace liveset {

struct SegmentRequest {
    std::vector<SeedBall> seeds;                   // index space; or
    const Grid<std::uint8_t>* initial_mask = nullptr;  // an initial region (non-zero inside)
    const Grid<std::uint8_t>* roi = nullptr;       // region the front may not leave
    // Threshold window in normalised units; estimated from the seeds when absent:
    // µ = median of the seed-ball intensities, ε = epsilon_sigmas × their robust σ (at least
    // min_epsilon).
    std::optional<double> mu, epsilon;
    // The same in the image's own units (mapped through the intensity scale; not with mu/epsilon).
    std::optional<double> mu_raw, epsilon_raw;
    double epsilon_sigmas = 5.0;
    double min_epsilon = 0.05;
    double n = 4.0;
    double alpha = 0.1;
    ScaleOptions scale;
    SegmentationOptions loop;
    int layers = 2;
};

struct SegmentOutcome {
    IntensityScale scale;
    ThresholdParams params;
    std::optional<SeedStatistics> seed_stats;  // when the window was estimated
    SegmentationResult result;
    std::unique_ptr<SparseField> field;
    Grid<std::uint8_t> mask;  // φ < 0 within the ROI
};

// The window estimated from the seed balls' statistics (normalised units), as segment_image does
// it: µ = median, ε = max(min_epsilon, epsilon_sigmas × robust σ). Sets params.mu and params.epsilon.
void estimate_window(const SeedStatistics& stats, double epsilon_sigmas, double min_epsilon, ThresholdParams& params);

// Throws std::invalid_argument with a one-line message on bad requests (no seeds and no initial
// mask, seeds outside the image, masks of other dimensions, bad parameters, empty initial mask).
SegmentOutcome segment_image(const Grid<float>& image, const SegmentRequest& request, const SegmentationHook& hook = {},
                             const std::atomic<bool>* interrupt = nullptr);

}  // namespace liveset
