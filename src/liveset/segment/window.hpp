// The threshold window (µ, ε) a segmentation runs with, and where it came from: the tissue
// model's window for the seeds' class (tissue_model.hpp), or the seeds' own statistics when the
// model cannot be used or is not wanted. Shared by segment_image() (the CLI, the demo) and the
// viewer's Session, so both estimate the same window from the same seeds.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "liveset/segment/brain_mask.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/tissue_model.hpp"

namespace liveset {

// Where a window came from: given by the user, the tissue model, or the seeds' statistics.
enum class WindowSource { kUser, kModel, kSeeds };
const char* to_string(WindowSource source);

struct WindowOptions {
    WindowSource estimate = WindowSource::kModel;  // kModel (falls back to kSeeds) or kSeeds
    TissueModelOptions model;
    double epsilon_sigmas = 5.0;  // seeds' window: ε = epsilon_sigmas × robust σ, at least min_epsilon
    double min_epsilon = 0.05;    // normalised units
    void validate() const;        // std::invalid_argument with a one-line message
};

struct WindowEstimate {
    double mu = 0.5, epsilon = 0.1;  // normalised units
    WindowSource source = WindowSource::kSeeds;
    std::optional<SeedStatistics> seed_stats;  // normalised units
    std::optional<ModelWindow> model_window;   // raw units
    std::vector<std::string> warnings;
};

// The region the tissue model is fitted in: `region` when given, else `roi`, else the automatic
// brain mask (brain_mask.hpp; full-head scans must not mix scalp and muscle into the classes),
// else, when that finds no head, the image's foreground (voxels above the lowest of the Otsu
// thresholds that split the image into background and `classes` tissue classes). `whole_brain`
// (optional) is set when the region is that automatic brain mask, else cleared. `brain` says how
// to look for it: the front ends' brain_mask_options(header), so that a header without
// orientation has the head's top found from the head.
Grid<std::uint8_t> model_region(const Grid<float>& image, const Grid<std::uint8_t>* region,
                                const Grid<std::uint8_t>* roi, int classes, bool* whole_brain = nullptr,
                                const BrainMaskOptions& brain = {});

// Fits the model for estimate_window(). Never throws on data the model cannot describe: returns
// nullopt (or a degenerate model) and says why in `warnings`. `whole_brain`: the region is a whole
// brain (the automatic brain mask), so every class asked for is in it; when noise makes two of
// them overlap on the image, the model is fitted on the image blurred as the threshold term reads
// it (TissueModel::smooth_mm; docs/ARCHITECTURE.md, "Noise that hides a tissue"). A whole brain's
// contrast is read (brain_contrast; TissueModel::contrast); `known_grey_brighter`: the image read as
// grey brighter than white before N4 (PreparedImage, apps/common; any region). A region of such a
// brain is fitted without its voxels darker than white matter (TissueModel::floor), unless that
// leaves under half of it or that fit is unsound where the whole region's is sound.
std::optional<TissueModel> fit_window_model(const Grid<float>& image, const Grid<std::uint8_t>& region,
                                            const TissueModelOptions& options, std::vector<std::string>& warnings,
                                            bool whole_brain = false, bool known_grey_brighter = false);

// The window for `seeds` on the raw `image` (normalised by `scale`): the model's when `model` is
// usable and options.estimate is kModel, else the seeds' statistics (with a warning saying why).
// Throws std::invalid_argument when the seeds cover no voxel (inside `roi`).
WindowEstimate estimate_window(const Grid<float>& image, const IntensityScale& scale, std::span<const SeedBall> seeds,
                               const Grid<std::uint8_t>* roi, const TissueModel* model, const WindowOptions& options);

// One-line warnings about a window [lower, upper] (raw units) given any other way: it holds the
// mean of more than one tissue class.
std::vector<std::string> window_warnings(const TissueModel& model, double lower, double upper);

// Where sheet_window fits its tissue model: as a segmentation fits it (SegmentRequest's
// model_region, model_region_is_brain, model_region_grey_brighter, brain_mask), so that the hole
// finder of a session reads the band from the region the session's window came from.
struct SheetFit {
    const Grid<std::uint8_t>* region = nullptr;  // none: the ROI, else model_region() looks for the brain
    bool region_is_brain = false;      // that region (else the ROI) is a whole brain: the automatic brain mask, or a file that agrees with it
    bool known_grey_brighter = false;  // as fit_window_model's (SessionOptions::model_region_grey_brighter)
    BrainMaskOptions brain;            // how model_region looks for the brain (its header's orientation)
};

// The intensity band of the tissue a segmented sheet is made of (for the hole finder and the sheet
// repair rule): the model window (model_window) of the class most of the mask's voxels (within
// `roi`) fall in, from the tissue model fitted in model_region(image, fit.region, roi, classes).
// nullopt, with the reason in `warnings`, when the model cannot be used or the mask is empty.
// `model` (optional) receives the fitted model. Throws std::invalid_argument when the sizes differ.
std::optional<ModelWindow> sheet_window(const Grid<float>& image, const Grid<std::uint8_t>& mask,
                                        const Grid<std::uint8_t>* roi, const TissueModelOptions& options,
                                        std::vector<std::string>& warnings, TissueModel* model = nullptr,
                                        const SheetFit& fit = {});

}  // namespace liveset
