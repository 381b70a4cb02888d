// Pieces shared by the image commands (segment, eval, repair, demo, bench soak): loading masks
// and level sets that must overlay an image, the segmentation run with its progress line, and the JSON reports.
#pragma once

#include <nlohmann/json.hpp>
#include <atomic>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "liveset/eval/holes.hpp"
#include "cli_support.hpp"
#include "liveset/eval/overlap.hpp"
#include "liveset/eval/surface_distance.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/brain_mask.hpp"
#include "liveset/preprocess/bias_correction.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/segment/window.hpp"
#include "liveset/session/session.hpp"

namespace liveset::cli {

// A scan as the commands read it (segment, holes, repair, view, Python): read_image with
// NanVoxels::keep, then its NaN voxels — a masked image's "no data" — lowered below every other value
// (lower_no_data), so a NaN-masked brain is segmented as a skull-stripped one.
struct Scan {
    Grid<float> image;
    ImageHeader header;
    std::optional<Grid<std::uint8_t>> no_data;  // where the NaN voxels were (none when there were none)
    std::uint64_t no_data_voxels = 0;
    // "N voxels of "<path>" are NaN (no data): ..." — what a command tells the user; empty without NaN.
    std::string note(const std::string& path) const;
    void print_note(const std::string& path) const;  // note() on stderr as "liveset: note: ...", if any
    const Grid<std::uint8_t>* no_data_mask() const { return no_data ? &*no_data : nullptr; }  // prepare_image's
    // `image` (the scan, or its corrected image) with NaN back where the scan had it: what is written out.
    Grid<float> restored(const Grid<float>& image) const;
};
Scan read_scan(const std::string& path);
// An image already read (an array handed to Python) made a scan: NaN voxels lowered as read_scan's.
Scan scan_of(Grid<float> image, ImageHeader header = {});

// Reads a mask/label image and checks that it overlays `reference` (same dims, spacing, origin
// and direction within tolerance); UsageError naming `option` otherwise. Non-zero -> 1.
Grid<std::uint8_t> load_mask_like(const std::string& path, const Lattice& reference, const std::string& option);

// A region of interest given as `--roi MASK` or `--roi auto` (the automatic brain mask of the image),
// or the automatic brain mask chosen by default (no `--roi`, the image a head).
struct Roi {
    Grid<std::uint8_t> mask;
    std::string source;                          // the file, or "auto"
    std::optional<BrainMaskReport> brain_mask;   // what auto_brain_mask found (auto only)
    std::shared_ptr<BrainMaskHead> head;         // the head it was found in (auto only): prepare_image looks again there
    bool by_default = false;                     // "auto" chosen by default, not asked for
    // A mask from a file that is a whole brain: Dice ≥ 0.8 with the automatic brain mask of its head,
    // found by prepare_image for its contrast (PreparedImage::grey_brighter). The tissue model then
    // treats it as the automatic mask: its contrast read off it, and noise that hides a tissue seen
    // through the blur (BrainWeb at Rician σ 18 in its own brain mask: 2 classes, GM Dice 0.695; as a
    // whole brain 0.893; docs/BENCHMARKS.md, session 69). The report's roi.whole_brain.
    bool file_is_brain = false;
};
// `arg` empty, the default: the automatic brain mask when the image is a full head (Roi::by_default),
// else no ROI (a skull-stripped brain has no scalp, muscle or eyes to leak into; but one whose
// masked outside lies within its tissue's range, BrainMaskReport::mid_range_fill, keeps it as the
// default ROI). "none": no ROI. "auto": auto_brain_mask(image) (UsageError "<option> auto: ..." when it
// fails: constant image, no head, empty mask). Otherwise a mask file overlaying the image
// (load_mask_like); files named "auto" or "none" can be given as ./auto, ./none.
// What the default learnt without keeping a ROI: that no head is there, or the automatic brain mask
// of a skull-stripped brain. prepare_image takes it as the fit region instead of looking again
// (the same mask, bit for bit).
// `options` (in) say how to look at this image: brain_mask_options(its header).
struct BrainLookup {
    bool done = false;                       // the default looked and kept no ROI
    std::optional<Grid<std::uint8_t>> mask;  // what it found (none: no head)
    std::shared_ptr<BrainMaskHead> head;     // where it found it
    std::optional<BrainMaskReport> report;   // how (with a mask)
    BrainMaskOptions options;
    // Where the default found a head but no brain in it (NoBrainFound: ventricles over about 250 ml,
    // docs/BENCHMARKS.md session 69): the warning that it segments the whole image (PreparedImage).
    std::string no_brain;
};
// The automatic brain mask's options for an image with this header: where the header gives no
// orientation, the head's top is found from the head (BrainMaskOptions::superior_from_header).
BrainMaskOptions brain_mask_options(const ImageHeader& header);
std::optional<Roi> load_roi(const std::string& arg, const Grid<float>& image, const std::string& option = "--roi",
                            BrainLookup* lookup = nullptr);
// What a seed refused by a ROI chosen by default is told (after the session's own message).
inline constexpr const char* kDefaultRoiHint =
    ": the automatic brain mask bounds the front by default on a head; open the image with --roi none to segment outside the brain";
// auto_brain_mask(image, options, report, head), or nullopt when the image does not look like a head (no error).
// Where the tissue model of an image given with a ROI from a file (`roi`; none: no ROI) is fitted,
// and how it is read, as `segment` reads it: the ROI, grey brighter than white (a T2, a PD) when its
// head reads so (auto_brain_mask's reading; a ROI of any shape is not read itself: a box astride a
// T1's cortex and scalp reads grey brighter), a whole brain when it agrees with the automatic brain
// mask found there (Roi::file_is_brain); both false where no head is found. Without a ROI, nothing
// is looked for here (sheet_window looks for the brain itself with `options`).
SheetFit fit_for_roi(const Grid<float>& image, const Grid<std::uint8_t>* roi, const BrainMaskOptions& options);
std::optional<Grid<std::uint8_t>> try_auto_brain_mask(const Grid<float>& image, BrainMaskHead* head = nullptr,
                                                      const BrainMaskOptions& options = {}, BrainMaskReport* report = nullptr);
// {"source", "voxels", "volume_mm3", "default", "whole_brain"} plus the automatic mask's findings under "auto".
nlohmann::json roi_report(const Roi& roi);
// One line: "  roi          auto brain mask (...): N voxels, V ml".
void print_roi_summary(const Roi& roi);
// What the automatic brain mask found, for people: "full head, tissue window 65.1..171.4" and,
// where the air's noise raised the head threshold, ", noisy air σ 14.8: head threshold 30.5".
std::string brain_mask_summary(const BrainMaskReport& report);

// Whether N4 runs before a segmentation (segment, view, the Python module): on by default, where a
// failure (an image too small for its grid, a mask that leaves no sample) skips it with a warning;
// required when asked for (or when the corrected image is to be written), where it is an error.
enum class BiasCorrection { kOff, kDefault, kRequired };
// The mode of a front end's setting: off unless `correct`, required when `asked` for.
inline BiasCorrection bias_mode(bool correct, bool asked) {
    return !correct ? BiasCorrection::kOff : asked ? BiasCorrection::kRequired : BiasCorrection::kDefault;
}

// An image made ready for the tissue model and the speed: corrected in place, and the region both
// are fitted in.
struct PreparedImage {
    // Without an ROI, the automatic brain mask (when the image is a head): scalp fat and muscle
    // would pull N4's field and the tissue model off the brain.
    std::optional<Grid<std::uint8_t>> fit_region;
    std::optional<BiasCorrectionReport> bias;  // N4's report when it ran
    std::string bias_skipped;                  // why the default correction did not run (a warning)
    std::string no_brain;                      // BrainLookup::no_brain: the default ROI gave up on a head (a warning)
    // The warnings above that were given (bias_skipped, then no_brain).
    std::vector<std::string> warnings() const {
        std::vector<std::string> w;
        for (const std::string* s : {&bias_skipped, &no_brain})
            if (!s->empty()) w.push_back(*s);
        return w;
    }
    // Voxels of the automatic brain mask found again on the corrected image (prepare_image), which
    // replaced the one N4 was fitted in; 0 when it was not.
    std::size_t brain_mask_after_n4 = 0;
    // The floor N4 fitted the image above when it held negative values where N4 fits (an offset, a
    // z-scored image), added back after; 0 when none.
    float bias_offset = 0.0f;
    // The image read as grey brighter than white (a T2, a PD) before N4: in the fit region where that
    // is an automatic brain mask (brain_contrast), in its head for a ROI from a file (auto_brain_mask's
    // reading; false where no head is found): SegmentRequest::model_region_grey_brighter. N4 fitted
    // in such a brain takes part of its grey-white contrast for a field (a PD of low contrast then
    // read as a T1), and a ROI from a file was not read at all (a PD in its own brain mask: GM Dice
    // 0.81; docs/BENCHMARKS.md, session 67).
    bool grey_brighter = false;
    // The region N4 and the tissue model are fitted in: the ROI, else fit_region, else none (N4
    // then takes Otsu's foreground).
    const Grid<std::uint8_t>* fit(const Grid<std::uint8_t>* roi) const { return roi ? roi : fit_region ? &*fit_region : nullptr; }
    // "roi", "auto brain mask" or "otsu": where N4 was fitted (the report's bias_correction.mask).
    std::string fit_name(const Grid<std::uint8_t>* roi) const { return roi ? "roi" : fit_region ? "auto brain mask" : "otsu"; }
    // That region is a whole brain (ROI "auto", a ROI from a file that is the brain, or fit_region):
    // SegmentRequest::model_region_is_brain.
    bool fit_is_brain(const std::optional<Roi>& roi) const {
        return roi ? roi->brain_mask.has_value() || roi->file_is_brain : fit_region.has_value();
    }
};
// N4 (BiasCorrectionOptions' defaults) on `image` per `mode`, fitted inside the ROI, else the
// automatic brain mask, else Otsu's foreground. `interrupt`: Ctrl-C (the report then says
// interrupted and the image is unchanged). Throws std::invalid_argument (kRequired) as correct_bias.
// An automatic brain mask (`roi` "auto", or the fit region without a ROI) is found again on the
// corrected image once N4 ran, inside the head the first was found in (Roi::head, released here),
// and replaces the first (kept when none is found there, or when it reads the head otherwise: a T1
// where the first read grey brighter, or a stripped brain where the first found a skull): a strong
// field drags the first mask's tissue window off (BrainWeb × a ±40 % field: brain mask Dice 0.904,
// found again 0.943; docs/BENCHMARKS.md, session 56).
// `lookup`: load_roi's, so a default that kept no ROI is not looked for again.
// `no_data`: a scan's no-data voxels (Scan::no_data), set below the corrected image again after N4.
PreparedImage prepare_image(Grid<float>& image, std::optional<Roi>& roi, BiasCorrection mode,
                            const std::atomic<bool>* interrupt = nullptr, BrainLookup* lookup = nullptr,
                            const Grid<std::uint8_t>* no_data = nullptr);
// What fit_seeds_to_roi said and did.
struct SeedFit {
    std::vector<std::string> warnings;
    bool default_dropped = false;  // the ROI chosen by default was given up: the run is `--roi none`'s
};
// The seeds (and the initial mask, `init`, may be null) against the ROI prepare_image left (call it
// next). Seeds whose whole ball lies outside it (no voxel of it in the mask; a seed astride its edge
// is clipped, as ever) are removed, one warning each ("the seed at voxel (i, j, k) lies outside <the
// ROI>: it is left out", and with a ROI chosen by default "; pass <none_hint> to segment outside the
// brain"). When every seed does: a UsageError for a ROI asked for. A ROI chosen by default is
// dropped instead (its mask becomes prepared.fit_region, so the run is <none_hint>'s bit for bit)
// with a warning as soon as more than half of the seeds lie outside it: the seeds ask for something
// else than a T1 brain (the eyes, the scalp), or the image is no T1 and the mask is wrong (a T2
// synthesised from BrainWeb: half the brain, 5 of the 8 seeds outside, GM Dice 0.034 in it, 0.846
// without it). So is it when over kLeakShare of `init` lies outside it.
SeedFit fit_seeds_to_roi(std::optional<Roi>& roi, PreparedImage& prepared, std::vector<SeedBall>& seeds, const Grid<std::uint8_t>* init,
                         std::string_view none_hint);
// The report's "bias_correction" object (bias_correction_report and where it was fitted), or, when
// the default correction was skipped, its warning appended to the report's "warnings"; so is
// PreparedImage::no_brain.
void add_bias_report(nlohmann::json& report, const PreparedImage& prepared, const Grid<std::uint8_t>* roi);
// Without a ROI on a head, `brain` is the automatic brain mask prepare_image found
// (`prepared.fit(nullptr)`: null with a ROI or when none was found): a warning when more than kLeakShare of the
// segmented voxels lie outside it (the front leaked into scalp, muscle or eyes), naming `roi_hint`
// ("--roi auto", "roi='auto'") as the cure; empty otherwise.
inline constexpr double kLeakShare = 0.05;
std::string leak_warning(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>* brain, std::string_view roi_hint);
// leak_warning for an editing session (the viewer, Python's Session): its mask against the brain mask
// its tissue model was fitted in (SessionOptions::model_region); empty with a ROI or without that mask.
std::string session_leak_warning(const Session& session, std::string_view roi_hint);

// True when every voxel is exactly 0 or 1 (a mask stored as a float image).
bool is_binary_mask(const Grid<float>& image);
// Non-zero -> 1, on the image's lattice.
Grid<std::uint8_t> to_mask(const Grid<float>& image);

// A φ image (< 0 inside) or a 0/1 mask (stored as any pixel type) as a 2-layer sparse field on
// `reference`'s lattice; UsageError when the sizes differ or it holds no surface.
SparseField load_level_set(const std::string& path, const Lattice& reference);
// The same loaded into `session` (Session::load_mask or load_phi: a new history).
void load_level_set(Session& session, const std::string& path);

struct SegmentRun {
    SegmentOutcome outcome;
    bool interrupted = false;  // Ctrl-C (nothing must be written)
};
// segment_image() with Ctrl-C handling and a progress line on a terminal.
// With a non-empty `log_path`, one JSON line per iteration (iteration, zero_layer, band, changed,
// flips, inside, dt, ms) is written there (atomically, after the run).
SegmentRun segment_with_progress(const Grid<float>& image, const SegmentRequest& request, bool quiet,
                                 const std::string& log_path = {});
// The same, the image handed over (segment_image's: left empty once the speed is built).
SegmentRun segment_with_progress(Grid<float>&& image, const SegmentRequest& request, bool quiet, const std::string& log_path = {});

// The tissue model (classes with names, means, spreads, weights; partial-volume weights) and the
// seeds' class when the window came from it.
nlohmann::json tissue_model_report(const TissueModel& model, const ModelWindow* window);

// Parameters, window (raw, with its source), tissue model, warnings, iterations, timing and
// volume of a segmentation.
nlohmann::json segmentation_report(const SegmentOutcome& outcome, const Lattice& lattice);
// The report's "bias_correction" object: ms (whole correction) and n4_ms, field_min/field_max (the
// multiplicative field's range inside the fit mask), mask ("roi" or "otsu") and mask_voxels,
// shrink_factors, shrunk_dims, control_points, level_iterations, final_convergence.
nlohmann::json bias_correction_report(const BiasCorrectionReport& report);
// Prints the report's lines (with a bias-correction line when it holds "bias_correction").
void print_segmentation_summary(const nlohmann::json& report);

// `liveset eval` metrics of a mask against a truth mask: dice, jaccard, volume_difference,
// hausdorff95_mm (+ hausdorff_mm, mean_surface_mm), components, euler, genus, cavities, holes and
// the truth's topology.
nlohmann::json evaluation_report(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth);
void print_evaluation(const nlohmann::json& report, const std::string& indent = "  ");

// One repair target's verdict: {"target": [i,j,k], "hole_voxels", "closed", "finder_voxels_near":
// {before, after}, "local_genus": {before, after}} (hole_voxels omitted when 0).
nlohmann::json verdict_json(Vec3i target, std::size_t hole_voxels, const HoleVerdict& verdict);

// What `liveset segment`'s options put into a request: the seeds (voxel and mm, parsed and checked
// inside the image) and the speed, window and loop settings. Shared by the CLI and the Python module,
// so both segment alike; `Options` is the command's (or the binding's) argument struct.
template <class Options>
void fill_segment_request(SegmentRequest& req, const Options& a, const Lattice& lattice) {
    for (const std::string& s : a.seeds) {
        req.seeds.push_back(parse_seed_voxel(s, a.seed_radius));
        check_seed_inside(req.seeds.back(), lattice, s);
    }
    for (const std::string& s : a.seeds_mm) {
        req.seeds.push_back(parse_seed_mm(s, lattice, a.seed_radius));
        check_seed_inside(req.seeds.back(), lattice, s + " (mm)");
    }
    req.n = a.n;
    req.alpha = a.alpha;
    req.smooth_mm = a.smooth_mm;
    req.loop.max_iterations = a.iterations;
    // segment_step() (converged stretches of front sleep, docs/ARCHITECTURE.md) with the thin-front
    // rule as asked; `liveset segment` then sets --step's (step_options), Python has no --step.
    req.loop.step = segment_step();
    req.loop.step.thin_fronts = a.thin_fronts;
    req.mu = a.mu;
    req.epsilon = a.epsilon;
    req.mu_raw = a.mu_raw;
    req.epsilon_raw = a.epsilon_raw;
    req.window.estimate = a.window_from == "seeds" ? WindowSource::kSeeds : WindowSource::kModel;
    req.window.model.classes = a.classes;
    req.coarse_start = parse_coarse_start(a.coarse_start);
}

}  // namespace liveset::cli
