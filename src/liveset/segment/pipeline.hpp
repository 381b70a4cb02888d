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
#include "liveset/segment/alpha.hpp"
#include "liveset/segment/coarse_start.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/threshold_speed.hpp"
#include "liveset/segment/window.hpp"

namespace liveset {

struct SegmentRequest {
    std::vector<SeedBall> seeds;                   // index space; or
    const Grid<std::uint8_t>* initial_mask = nullptr;  // an initial region (non-zero inside)
    const Grid<std::uint8_t>* roi = nullptr;       // region the front may not leave
    // Threshold window in normalised units. When absent it is estimated: by default the tissue
    // model's window for the seeds' class; with estimate = kSeeds (or when the model is not
    // usable, with a warning) µ = median of the seed-ball intensities, ε = epsilon_sigmas × their
    // robust σ (at least min_epsilon).
    std::optional<double> mu, epsilon;
    // The same in the image's own units (mapped through the intensity scale; not with mu/epsilon).
    std::optional<double> mu_raw, epsilon_raw;
    WindowOptions window;  // how the window is estimated (window.hpp)
    // Where the tissue model is fitted: this region, else the ROI, else the image's foreground
    // (voxels above the Otsu threshold between background and the rest).
    const Grid<std::uint8_t>* model_region = nullptr;
    // That region (model_region, else the ROI) is a whole brain - the automatic brain mask - so the
    // model may be fitted through noise that hides a tissue (fit_window_model, window.hpp).
    bool model_region_is_brain = false;
    // The image read as grey brighter than white before N4 (PreparedImage::grey_brighter, apps/common):
    // the model's region is read so on the corrected image too, any region (brain_contrast).
    bool model_region_grey_brighter = false;
    // How to look for the automatic brain mask where no region or ROI is given (model_region,
    // window.hpp): the front ends' brain_mask_options(header).
    BrainMaskOptions brain_mask;
    double n = 4.0;
    // The curvature weight; absent: automatic_alpha() (alpha.hpp) from the tissue model's noise
    // ratio of the window's class and the voxel shape (the fallback 0.1 without a usable model).
    std::optional<double> alpha;
    // With α given: the σ (mm) of the image's pre-smoothing (ThresholdParams::smooth_mm; absent: 0).
    // The automatic α chooses it too (alpha.hpp), so it may not be given without α.
    std::optional<double> smooth_mm;
    ScaleOptions scale;
    SegmentationOptions loop;
    int layers = 2;
    // From seeds on a fine grid (auto: every voxel side ≤ kCoarseStartMaxSpacing mm), the front first
    // converges on 2x2x2-voxel blocks (their mean threshold term) and starts from there (coarse_start.hpp).
    CoarseStart coarse_start = CoarseStart::kAuto;
};

struct SegmentOutcome {
    IntensityScale scale;
    ThresholdParams params;
    StepOptions step;  // the request's (the report says which step and whether the thin-front rule ran)
    WindowSource window_source = WindowSource::kUser;
    AlphaChoice alpha;  // the α and smoothing params holds, and why
    std::optional<SeedStatistics> seed_stats;  // when the window was estimated
    std::optional<TissueModel> model;          // when it could be fitted (seeds given)
    std::optional<ModelWindow> model_window;   // when the window came from the model
    std::vector<std::string> warnings;         // one line each: model fallback, seeds in two classes, ...
    SegmentationResult result;  // the run on the image's grid (after the coarse start's, when there was one)
    std::optional<CoarseStartReport> coarse;  // when the run started coarse
    std::unique_ptr<SparseField> field;
    Grid<std::uint8_t> mask;  // φ < 0 within the ROI
};

// Throws std::invalid_argument with a one-line message on bad requests (no seeds and no initial
// mask, seeds outside the image, masks of other dimensions, bad parameters, empty initial mask).
SegmentOutcome segment_image(const Grid<float>& image, const SegmentRequest& request, const SegmentationHook& hook = {},
                             const std::atomic<bool>* interrupt = nullptr);
// The same, the image handed over: freed (left empty) once the speed's table is built, since the
// evolution never reads it (a 0.5 mm brain's is 226 MB). The same outcome, bit for bit.
SegmentOutcome segment_image(Grid<float>&& image, const SegmentRequest& request, const SegmentationHook& hook = {},
                             const std::atomic<bool>* interrupt = nullptr);

}  // namespace liveset
