// Shared image-command pieces: scans, masks, ROIs, N4 and the fit region, seeds, level sets (reports: image_reports.cpp).
#include "image_commands.hpp"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <vector>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/intensity.hpp"

namespace liveset::cli {

Scan scan_of(Grid<float> image, ImageHeader header) {
    Scan s{std::move(image), std::move(header), std::nullopt, 0};
    s.no_data = lower_no_data(s.image);  // refuses infinite voxels, and an image all NaN
    if (s.no_data)
        for (const std::uint8_t v : s.no_data->values()) s.no_data_voxels += v;
    return s;
}

Scan read_scan(const std::string& path) {
    ImageHeader header;
    Grid<float> image = read_image(path, kDefaultImageMemoryLimit, &header, NanVoxels::keep);
    try {
        return scan_of(std::move(image), std::move(header));
    } catch (const std::invalid_argument& e) {
        throw ImageIoError(fmt::format("cannot read \"{}\": {}", path, e.what()));
    }
}

std::string Scan::note(const std::string& path) const {
    if (no_data_voxels == 0) return {};
    return fmt::format("{} voxel(s) of \"{}\" ({:.1f}%) are NaN, a masked image's \"no data\": read as lying below every other value "
                       "(outside the brain)",
                       no_data_voxels, path, 100.0 * static_cast<double>(no_data_voxels) / static_cast<double>(image.size()));
}

void Scan::print_note(const std::string& path) const {
    if (no_data_voxels) fmt::print(stderr, "liveset: note: {}\n", note(path));
}

Grid<float> Scan::restored(const Grid<float>& values) const {
    Grid<float> out = values;
    if (no_data)
        for (PointIndex i = 0; i < out.size(); ++i)
            if ((*no_data)[i]) out[i] = std::numeric_limits<float>::quiet_NaN();
    return out;
}

Grid<std::uint8_t> load_mask_like(const std::string& path, const Lattice& reference, const std::string& option) {
    // Read as real values: a MINC byte mask whose real range is 0..1 holds 1/255 inside, a resampled
    // mask fractions; non-zero is inside, whatever the type (README, "ROI").
    const Grid<float> raw = read_image(path);
    try {
        require_same_geometry(raw.lattice(), reference, option, "mask", "image");
    } catch (const std::invalid_argument& e) {
        throw UsageError(fmt::format("{} {} does not overlay the image: {}", option, path, e.what()));
    }
    Grid<std::uint8_t> m(raw.lattice(), 0);
    for (PointIndex i = 0; i < raw.size(); ++i) {
        if (!std::isfinite(raw[i])) throw UsageError(fmt::format("{} {} is not a mask: it holds NaN or infinite values", option, path));
        m[i] = raw[i] != 0.0f;
    }
    return m;
}

BrainMaskOptions brain_mask_options(const ImageHeader& header) {
    BrainMaskOptions o;
    o.superior_from_header = header.orientation_known;
    return o;
}

std::optional<Roi> load_roi(const std::string& arg, const Grid<float>& image, const std::string& option, BrainLookup* lookup) {
    if (arg == "none") return std::nullopt;
    if (!arg.empty() && arg != "auto") return Roi{load_mask_like(arg, image.lattice(), option), arg, std::nullopt, nullptr};
    const BrainMaskOptions options = lookup ? lookup->options : BrainMaskOptions{};
    BrainMaskReport report;
    auto head = std::make_shared<BrainMaskHead>();
    const auto learnt = [&](std::optional<Grid<std::uint8_t>> mask, std::shared_ptr<BrainMaskHead> where) {
        if (lookup == nullptr) return;
        lookup->done = true;
        if (mask) lookup->report = report;
        lookup->mask = std::move(mask);
        lookup->head = std::move(where);
    };
    try {
        Grid<std::uint8_t> mask = auto_brain_mask(image, options, &report, head.get());
        // By default only a full head: a skull-stripped brain (or a phantom) has no scalp to leak into,
        // unless its outside was left mid-range (a z-scored brain's 0): the front would flow into it.
        if (arg.empty() && report.skull_stripped && std::isnan(report.mid_range_fill)) {
            learnt(std::move(mask), std::move(head));
            return std::nullopt;
        }
        return Roi{std::move(mask), "auto", report, std::move(head), arg.empty()};
    } catch (const std::invalid_argument& e) {
        if (arg.empty()) {  // not a head: the default is no ROI
            learnt(std::nullopt, nullptr);
            if (lookup && dynamic_cast<const NoBrainFound*>(&e)) {  // a head, though: said, not silent
                constexpr std::string_view prefix = "brain mask: ";
                std::string_view why = e.what();
                if (why.starts_with(prefix)) why.remove_prefix(prefix.size());
                lookup->no_brain = fmt::format("the default ROI: a head was found but no brain in it ({}); the whole image is "
                                               "segmented: where it holds scalp, muscle or eyes, give {} a brain mask to keep the front out of them",
                                               why, option);
            }
            return std::nullopt;
        }
        throw UsageError(fmt::format("{} auto: {}", option, e.what()));
    }
}

std::optional<Grid<std::uint8_t>> try_auto_brain_mask(const Grid<float>& image, BrainMaskHead* head, const BrainMaskOptions& options,
                                                      BrainMaskReport* report) {
    try {
        return auto_brain_mask(image, options, report, head);
    } catch (const std::invalid_argument&) {
        return std::nullopt;
    }
}

namespace {

// The share of the voxels N4 would fit (the region, else Otsu's foreground, as correct_bias) that
// are negative.
double negative_share(const Grid<float>& image, const Grid<std::uint8_t>* region) {
    const std::optional<Grid<std::uint8_t>> otsu = region ? std::nullopt : std::optional(otsu_foreground(image));
    const Grid<std::uint8_t>& fit = region ? *region : *otsu;
    std::size_t negative = 0, total = 0;
    for (std::size_t i = 0; i < image.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if (fit[p] == 0) continue;
        ++total;
        negative += image[p] < 0.0f;
    }
    return total > 0 ? static_cast<double>(negative) / static_cast<double>(total) : 0.0;
}

}  // namespace

namespace {

// The image's floor: its 0.1 % quantile (a z-scored head's air, a stripped brain's background),
// robust to the few values ringing below it after a resampling.
float image_floor(const Grid<float>& image) {
    std::vector<float> v(image.values().begin(), image.values().end());
    const auto k = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 1000);
    std::nth_element(v.begin(), k, v.end());
    return *k;
}

// N4 per `mode` on `image`, fitted in `fit` (null: Otsu's foreground), as prepare_image.
void correct_for(Grid<float>& image, const Grid<std::uint8_t>* fit, BiasCorrection mode, const std::atomic<bool>* interrupt,
                 PreparedImage& out) {
    const auto skip = [&](const std::string& why) {
        out.bias_skipped = "bias correction skipped: " + why + "; the uncorrected image is used";
    };
    BiasCorrectionReport report;
    try {
        // N4 models a multiplicative field on magnitude data, whose zero is the air's. Negative values
        // where it would fit (an offset, a z-scored image) put that zero elsewhere: N4 then fits the
        // image above its floor (the air's value), and the floor is added back. Where the floor is
        // not below zero (negatives in the tissue only), the default skips N4 as before.
        const double negative = negative_share(image, fit);
        const float offset = negative > 0.01 ? std::min(image_floor(image), 0.0f) : 0.0f;
        if (negative > 0.01 && offset == 0.0f && mode == BiasCorrection::kDefault)  // no floor below zero to fit above
            return skip(fmt::format("{:.1f} % of the voxels it would fit are negative, but the image's floor is not (negative tissue, "
                                    "not an offset), outside N4's multiplicative model",
                                    100.0 * negative));
        if (offset == 0.0f) {
            image = correct_bias(image, fit, {}, &report, interrupt);
        } else {
            Grid<float> shifted = image;
            for (float& v : shifted.values()) v -= offset;
            shifted = correct_bias(shifted, fit, {}, &report, interrupt);
            if (!report.interrupted) {
                for (float& v : shifted.values()) v += offset;
                image = std::move(shifted);
            }
            out.bias_offset = offset;
        }
    } catch (const std::invalid_argument& e) {  // the input N4 cannot take
        if (mode == BiasCorrection::kRequired) throw;
        return skip(e.what());
    } catch (const std::runtime_error& e) {  // N4 itself failed
        if (mode == BiasCorrection::kRequired) throw;
        return skip(e.what());
    }
    out.bias = std::move(report);
}

}  // namespace

namespace {

// The automatic brain mask (ROI "auto", or the fit region without a ROI) found again on the corrected
// image, in the head it was first found in (`head`; null: the head is found again too). A field N4
// takes out changes neither a head's contrast nor its skull: a second look that loses the first's
// grey-brighter reading (T2, PD) or its FLAIR reading, or takes for a stripped brain a head whose
// skull the first found, was misled (N4 fitted in a PD's brain flattens its grey-white contrast, grey matter lying outside
// white: the second look then read a T1 and took the whole head for a stripped brain;
// docs/BENCHMARKS.md, session 66), and the first stays. (A first look misled by a field, read as a
// T1, may be corrected; one read as a FLAIR stays.)
void find_brain_again(const Grid<float>& image, std::optional<Roi>& roi, BrainMaskHead* head, const BrainMaskOptions& options,
                      const BrainMaskReport* first, PreparedImage& out) {
    Grid<std::uint8_t>* automatic = roi ? (roi->brain_mask ? &roi->mask : nullptr) : out.fit_region ? &*out.fit_region : nullptr;
    if (automatic == nullptr) return;
    BrainMaskReport report;
    BrainMaskHead anew;
    Grid<std::uint8_t> again;
    try {
        again = auto_brain_mask(image, options, &report, head ? head : &anew);
    } catch (const std::invalid_argument&) {
        return;  // none found there: the first stays
    }
    if (first && ((first->contrast == TissueContrast::kGreyBrighter && report.contrast != first->contrast) ||
                  (first->flair && !report.flair) || (report.skull_stripped && !first->skull_stripped)))
        return;
    *automatic = std::move(again);
    if (roi) roi->brain_mask = report;
    out.brain_mask_after_n4 = report.mask_voxels;
}

// A ROI from a file this close to the automatic brain mask (Dice) is a whole brain
// (Roi::file_is_brain): another tool's brain mask agrees with ours to 0.9-0.99 on the
// BrainWeb variants; a hemisphere's mask reaches 0.67 at most, a box about the brain (twice its
// volume) 0.67 too.
constexpr double kSameBrainDice = 0.8;

}  // namespace

SheetFit fit_for_roi(const Grid<float>& image, const Grid<std::uint8_t>* roi, const BrainMaskOptions& options) {
    SheetFit f;
    f.brain = options;
    if (!roi) return f;
    if (!(roi->dims() == image.dims())) throw std::invalid_argument("the ROI and the image differ in size");
    BrainMaskReport head;
    const std::optional<Grid<std::uint8_t>> brain = try_auto_brain_mask(image, nullptr, options, &head);
    f.known_grey_brighter = brain && head.contrast == TissueContrast::kGreyBrighter;
    f.region_is_brain = brain && compare_overlap(*brain, *roi).dice >= kSameBrainDice;
    return f;
}

namespace {

// PreparedImage::grey_brighter on the image as given: the automatic brain mask's region read
// (brain_contrast), or for a ROI from a file the head's reading (auto_brain_mask's): such a ROI may
// be any shape, and a box astride a T1's cortex and scalp reads grey brighter. The ROI from a file
// is compared with the mask found there (Roi::file_is_brain).
bool read_grey_brighter(const Grid<float>& image, std::optional<Roi>& roi, const PreparedImage& out, const BrainMaskOptions& options) {
    if (roi && !roi->brain_mask) {
        const SheetFit f = fit_for_roi(image, &roi->mask, options);
        roi->file_is_brain = f.region_is_brain;
        return f.known_grey_brighter;
    }
    const Grid<std::uint8_t>* fit = out.fit(roi ? &roi->mask : nullptr);
    return fit && brain_contrast(image, *fit) == TissueContrast::kGreyBrighter;
}

}  // namespace

PreparedImage prepare_image(Grid<float>& image, std::optional<Roi>& roi, BiasCorrection mode, const std::atomic<bool>* interrupt,
                            BrainLookup* lookup, const Grid<std::uint8_t>* no_data) {
    PreparedImage out;
    if (lookup && !roi) out.no_brain = lookup->no_brain;
    const BrainMaskOptions options = lookup ? lookup->options : BrainMaskOptions{};
    BrainMaskHead own_head;  // the fit region's head, without a ROI
    BrainMaskHead* fit_head = &own_head;
    BrainMaskReport fit_report;
    const BrainMaskReport* first = roi && roi->brain_mask ? &*roi->brain_mask : nullptr;  // how the mask was first found
    if (!roi && lookup && lookup->done) {  // the default looked already
        out.fit_region = std::move(lookup->mask);
        if (lookup->report) first = &*lookup->report;
        if (lookup->head) fit_head = lookup->head.get();
    } else if (!roi) {
        out.fit_region = try_auto_brain_mask(image, fit_head, options, &fit_report);
        if (out.fit_region) first = &fit_report;
    }
    out.grey_brighter = read_grey_brighter(image, roi, out, options);  // as the scan has it, before N4
    if (mode != BiasCorrection::kOff) {
        correct_for(image, out.fit(roi ? &roi->mask : nullptr), mode, interrupt, out);
        // N4 divides the lowered no-data voxels by its field too: below the corrected image again.
        if (out.bias && !out.bias->interrupted && no_data) lower_voxels(image, *no_data);
        if (out.bias && !out.bias->interrupted) find_brain_again(image, roi, roi ? roi->head.get() : fit_head, options, first, out);
    }
    if (roi) roi->head.reset();  // only needed here
    return out;
}

namespace {

// The default ROI given up for the whole image (its mask becomes the fit region, where N4 was
// fitted, as without a ROI), with the warning saying why.
void drop_default_roi(std::optional<Roi>& roi, PreparedImage& prepared, SeedFit& out, std::string why, std::string_view none_hint) {
    out.warnings.push_back(fmt::format("{}: the whole image is segmented, as with {}", why, none_hint));
    out.default_dropped = true;
    prepared.fit_region = std::move(roi->mask);
    roi.reset();
}

}  // namespace

SeedFit fit_seeds_to_roi(std::optional<Roi>& roi, PreparedImage& prepared, std::vector<SeedBall>& seeds, const Grid<std::uint8_t>* init,
                         std::string_view none_hint) {
    SeedFit out;
    if (!roi) return out;
    if (init != nullptr && roi->by_default) {  // a region to start from, mostly outside the brain: not the brain's
        std::size_t inside = 0, outside = 0;
        for (std::size_t i = 0; i < init->size(); ++i) {
            const auto p = static_cast<PointIndex>(i);
            if ((*init)[p] == 0) continue;
            (roi->mask[p] != 0 ? inside : outside) += 1;
        }
        const double share = inside + outside > 0 ? static_cast<double>(outside) / static_cast<double>(inside + outside) : 0.0;
        if (share > kLeakShare) {
            drop_default_roi(roi, prepared, out,
                             fmt::format("{:.0f} % of the initial mask lies outside the automatic brain mask (a T1 brain's)", 100.0 * share),
                             none_hint);
            return out;
        }
    }
    if (seeds.empty()) return out;
    const std::string what = roi->by_default ? "the automatic brain mask (the default ROI of a head)"
                             : roi->brain_mask ? "the automatic brain mask (--roi auto)"
                                               : "the ROI " + roi->source;
    const std::string hint = roi->by_default ? fmt::format("; pass {} to segment outside the brain", none_hint) : std::string();
    std::vector<Vec3i> outside;
    std::vector<SeedBall> kept;
    for (const SeedBall& s : seeds) {
        if (ball_touches(roi->mask, s)) {
            kept.push_back(s);
            continue;
        }
        outside.push_back({static_cast<int>(std::lround(s.center.x)), static_cast<int>(std::lround(s.center.y)),
                           static_cast<int>(std::lround(s.center.z))});
    }
    if (kept.empty() && !roi->by_default)
        throw UsageError(fmt::format("every seed lies outside {}, the first at voxel ({}, {}, {})", what, outside[0].x, outside[0].y, outside[0].z));
    if (roi->by_default && 2 * outside.size() > seeds.size()) {  // the default's guess does not fit these seeds
        const std::string which = kept.empty() ? std::string("every seed lies") : fmt::format("{} of the {} seeds lie", outside.size(), seeds.size());
        drop_default_roi(roi, prepared, out,
                         fmt::format("{} outside the automatic brain mask (a T1 brain's), the first at voxel ({}, {}, {})", which,
                                     outside[0].x, outside[0].y, outside[0].z),
                         none_hint);
        return out;
    }
    for (const Vec3i& c : outside)
        out.warnings.push_back(fmt::format("the seed at voxel ({}, {}, {}) lies outside {}: it is left out{}", c.x, c.y, c.z, what, hint));
    seeds = std::move(kept);
    return out;
}

bool is_binary_mask(const Grid<float>& image) {
    for (float v : image.values())
        if (v != 0.0f && v != 1.0f) return false;
    return true;
}

Grid<std::uint8_t> to_mask(const Grid<float>& image) {
    Grid<std::uint8_t> m(image.lattice());
    for (std::size_t i = 0; i < image.size(); ++i) m[static_cast<PointIndex>(i)] = image[static_cast<PointIndex>(i)] != 0.0f;
    return m;
}

namespace {

// segment_with_progress for an image given (kept) or handed over (freed once the speed is built).
template <class Image>
SegmentRun run_with_progress(Image&& image, const SegmentRequest& request, bool quiet, const std::string& log_path) {
    InterruptGuard interrupt;
    ProgressLine progress(quiet);
    const int limit = request.loop.max_iterations;
    std::string log;
    const SegmentationHook hook = [&](const SegmentationProgress& p, const ChangedPoints&) {
        if (!log_path.empty())
            log += fmt::format("{{\"iteration\":{},\"zero_layer\":{},\"band\":{},\"awake\":{},\"changed\":{},\"flips\":{},\"inside\":{},\"dt\":{:.6g},\"ms\":{:.3f}{}}}\n",
                               p.iteration, p.zero_layer, p.band, p.awake, p.changed, p.flips, p.inside, p.dt, p.ms,
                               p.level == 1 ? ",\"level\":\"coarse\"" : "");
        progress.update(fmt::format("segmenting{}: iteration {}/{}  zero layer {}  band {}  changed {}  flips {}", p.level == 1 ? " (coarse start)" : "",
                                    p.iteration, limit, p.zero_layer, p.band, p.changed, p.flips));
        return true;
    };
    SegmentRun run{segment_image(std::forward<Image>(image), request, hook, &interrupt.flag()), false};
    progress.finish();
    if (!quiet)
        for (const std::string& w : run.outcome.warnings) fmt::print(stderr, "liveset: warning: {}\n", w);
    run.interrupted = run.outcome.result.reason == StopReason::kInterrupted;
    if (!log_path.empty() && !run.interrupted) write_atomically(log_path, log);
    return run;
}

}  // namespace

SegmentRun segment_with_progress(const Grid<float>& image, const SegmentRequest& request, bool quiet, const std::string& log_path) {
    return run_with_progress(image, request, quiet, log_path);
}

SegmentRun segment_with_progress(Grid<float>&& image, const SegmentRequest& request, bool quiet, const std::string& log_path) {
    return run_with_progress(std::move(image), request, quiet, log_path);
}

namespace {

// A φ or mask read for `reference`'s lattice: the grid, and whether it is a 0/1 mask.
Grid<float> read_level_set_image(const std::string& path, const Lattice& reference, bool& mask) {
    Grid<float> g = read_image(path);
    if (!(g.dims() == reference.dims()))
        throw UsageError(fmt::format("{} ({}x{}x{}) does not match the image's size", path, g.dims().x, g.dims().y, g.dims().z));
    mask = is_binary_mask(g);
    std::size_t inside = 0;
    for (float v : g.values()) inside += mask ? v == 1.0f : v < 0.0f;
    if (inside == 0) throw UsageError(fmt::format("{} holds no surface (nothing inside, or no voxel changes sign)", path));
    return g;
}

}  // namespace

SparseField load_level_set(const std::string& path, const Lattice& reference) {
    bool mask = false;
    const Grid<float> g = read_level_set_image(path, reference, mask);
    SparseField field(reference, 2);
    if (mask) {
        field.init_from_mask(to_mask(g));
    } else {
        field.init_from_sdf([&](Vec3d p) {
            const Vec3i q{static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)), static_cast<int>(std::lround(p.z))};
            return static_cast<double>(g(q));
        });
    }
    if (field.zero_layer().empty()) throw UsageError(fmt::format("{} holds no surface (nothing inside, or no voxel changes sign)", path));
    return field;
}

void load_level_set(Session& session, const std::string& path) {
    bool mask = false;
    const Grid<float> g = read_level_set_image(path, session.lattice(), mask);
    if (mask) session.load_mask(to_mask(g));
    else session.load_phi(g);
    if (!session.has_surface()) throw UsageError(fmt::format("{} holds no surface (nothing inside, or no voxel changes sign)", path));
}

nlohmann::json verdict_json(Vec3i c, std::size_t hole_voxels, const HoleVerdict& h) {
    nlohmann::json j{{"target", {c.x, c.y, c.z}}, {"closed", h.closed}, {"finder_voxels_near", {{"before", h.before}, {"after", h.after}}},
                     {"local_genus", {{"before", h.genus_before}, {"after", h.genus_after}}}};
    if (hole_voxels) j["hole_voxels"] = hole_voxels;
    return j;
}

}  // namespace liveset::cli
