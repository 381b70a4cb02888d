// Threshold window from the tissue model or the seeds' statistics.
#include "liveset/segment/window.hpp"

#include "liveset/segment/brain_mask.hpp"
#include "liveset/segment/smoothing.hpp"
#include "liveset/segment/voxel_loops.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace liveset {

const char* to_string(WindowSource source) {
    switch (source) {
        case WindowSource::kUser: return "user";
        case WindowSource::kModel: return "model";
        case WindowSource::kSeeds: return "seeds";
    }
    return "?";
}

void WindowOptions::validate() const {
    if (estimate == WindowSource::kUser) throw std::invalid_argument("the window estimate must be 'model' or 'seeds'");
    model.validate();
    if (!std::isfinite(epsilon_sigmas) || epsilon_sigmas <= 0 || !std::isfinite(min_epsilon) || min_epsilon <= 0)
        throw std::invalid_argument("the epsilon estimate needs positive sigmas and floor");
}

Grid<std::uint8_t> model_region(const Grid<float>& image, const Grid<std::uint8_t>* region, const Grid<std::uint8_t>* roi,
                                int classes, bool* whole_brain, const BrainMaskOptions& brain) {
    if (whole_brain) *whole_brain = false;
    for (const Grid<std::uint8_t>* m : {region, roi})
        if (m && !(m->dims() == image.dims())) {
            std::ostringstream os;
            os << "mask " << m->dims() << " does not match the image " << image.dims();
            throw std::invalid_argument(os.str());
        }
    if (region) return *region;
    if (roi) return *roi;
    validate(brain);  // bad options are an error, not "no head"
    try {  // a head (or a skull-stripped brain, or the phantom): the automatic brain mask
        Grid<std::uint8_t> found = auto_brain_mask(image, brain);
        if (whole_brain) *whole_brain = true;
        return found;
    } catch (const std::invalid_argument&) {  // not a head: the foreground
    }
    // Background and the tissue classes: the lowest threshold separates the background.
    const std::vector<double> t = otsu_thresholds(image.values(), std::min(classes + 1, 6));
    Grid<std::uint8_t> fg(image.lattice(), 0);
    voxel_loops::for_each(image.size(), [&](std::size_t i) { fg[static_cast<PointIndex>(i)] = image[static_cast<PointIndex>(i)] > t[0]; });
    return fg;
}

namespace {

// What both shading warnings (below and in fit_window_model) advise.
constexpr const char* kShadingHint = "if the scan is shaded: check that it was bias-corrected (the default; not with --no-bias-correct)";

// In a three-class (CSF, GM, WM) model, GM or WM holding under 3 % of the region: no whole-brain
// region measured is like that, but a bias field can split a tissue into a thin bright class and the
// rest (BrainWeb under a +-20 % ramp along z: WM 1.1 %, Dice 0.86; 0.936 after N4). Every BrainWeb
// variant and whole-brain ROI measured keeps each of them at 14 % or more (docs/BENCHMARKS.md,
// session 47). CSF is left out (a tight brain mask leaves next to no CSF: the darkest class, the
// brightest in a T2 or PD), and so are other class counts (a fourth class may be a small lesion population).
void thin_class_warnings(const TissueModel& m, std::vector<std::string>& warnings) {
    constexpr double kThinClass = 0.03;
    if (m.classes.size() != 3) return;
    const std::size_t csf = m.contrast == TissueContrast::kGreyBrighter ? 2 : 0;
    for (std::size_t k = 0; k < m.classes.size(); ++k) {
        const TissueClass& c = m.classes[k];
        if (k == csf || c.weight >= kThinClass) continue;
        std::ostringstream os;
        os.precision(4);  // the mean as window_warnings prints means; the share rounded down, so never "3.0 %"
        os << "tissue model: its " << tissue_class_name(m, static_cast<int>(k)) << " class (mean " << c.mean << ") holds only ";
        os.precision(1);
        os << std::fixed << std::floor(1000.0 * c.weight) / 10.0
           << " % of the region: a bias field may have split a tissue (" << kShadingHint << ")";
        warnings.push_back(os.str());
    }
}

// Noise that hides a tissue (docs/ARCHITECTURE.md; docs/BENCHMARKS.md, session 57): at BrainWeb +
// Rician σ 18 grey and white matter lie under two spreads apart, so the classes asked for
// "overlap" and a class fewer merges them (GM+WM as one, the seeds' window spanning both: GM Dice
// 0.685). The threshold term reads such a scan blurred (alpha.hpp: σ = kSmoothVoxels finest voxel
// sides), where they stand apart. Only in a whole brain, where the classes are known to be there:
// in a region holding fewer tissues (a grey + white matter ROI fitted for three classes) the
// blurred fit can split one tissue in two. A blur narrows each tissue's spread and hardly moves its
// mean (partial volume at thin cortex a little), so the blurred fit is taken only when it is sound
// and finds the same classes: each mean within the plain fit's spread of that class, each spread
// no wider than there.
std::optional<TissueModel> fit_through_noise(const Grid<float>& image, const Grid<std::uint8_t>& region,
                                             const TissueModelOptions& options, const TissueModel& plain) {
    if (plain.classes.size() != static_cast<std::size_t>(options.classes)) return std::nullopt;
    for (const TissueClass& c : plain.classes)  // an overlap, not a class without voxels
        if (!(c.weight >= 0.01) || !std::isfinite(c.mean) || !std::isfinite(c.sigma)) return std::nullopt;
    const double sigma_mm = presmoothing_mm(image.lattice().spacing_float());
    TissueModel blurred;
    try {
        blurred = fit_tissue_model(gaussian_smooth(image, sigma_mm), &region, options);
    } catch (const std::invalid_argument&) {
        return std::nullopt;
    }
    if (!blurred.usable() || blurred.classes.size() != plain.classes.size()) return std::nullopt;
    for (std::size_t k = 0; k < plain.classes.size(); ++k) {
        const TissueClass &b = blurred.classes[k], &p = plain.classes[k];
        if (!(std::abs(b.mean - p.mean) <= p.sigma) || !(b.sigma <= p.sigma)) return std::nullopt;
    }
    blurred.smooth_mm = sigma_mm;
    return blurred;
}

// The region's voxels above `floor` (a grey-brighter brain's, brain_contrast); nullopt for no finite
// floor or where they are under half of the region's voxels with a value (not such a brain).
std::optional<Grid<std::uint8_t>> above_floor(const Grid<float>& image, const Grid<std::uint8_t>& region, double floor) {
    if (!std::isfinite(floor)) return std::nullopt;
    Grid<std::uint8_t> tissue = region;
    std::size_t in = 0, kept = 0;
    for (PointIndex i = 0; i < tissue.size(); ++i) {
        in += tissue[i] != 0 && std::isfinite(image[i]);
        tissue[i] = tissue[i] != 0 && image[i] > floor;
        kept += tissue[i];
    }
    if (2 * kept < in) return std::nullopt;
    return tissue;
}

}  // namespace

std::optional<TissueModel> fit_window_model(const Grid<float>& image, const Grid<std::uint8_t>& region,
                                            const TissueModelOptions& options, std::vector<std::string>& warnings,
                                            bool whole_brain, bool known_grey_brighter) {
    try {
        // The contrast names the classes: a whole brain's read off it (the automatic brain mask, or a
        // brain mask from another tool that agrees with it: session 69), another region's (a ROI of
        // any shape) known from the head (`known_grey_brighter`; a PD in its brain mask given as a
        // file was fitted as a T1: GM Dice 0.81; docs/BENCHMARKS.md, session 67) - such a ROI is not
        // read itself: a box astride a T1's cortex and scalp reads grey brighter.
        // Where grey matter is brighter than white (a T2, a PD) white matter is the darkest tissue,
        // and the region's voxels below it (skull, dura, a rim of air) are a fourth population three
        // classes cannot hold: the fit spent a class on them and took grey matter and CSF as one (a
        // PD: GM Dice 0.81; session 66). They are left out of the fit, unless that leaves under half
        // the region (not such a brain) or the fit without them is unsound where the whole region's
        // is sound (a T2: its thin pure CSF then fails the partial-volume fit; with the skull and
        // muscle it held, it did not).
        double floor = -std::numeric_limits<double>::infinity();
        std::optional<TissueContrast> contrast;
        if (whole_brain || known_grey_brighter) contrast = brain_contrast(image, region, &floor, known_grey_brighter);
        const std::optional<Grid<std::uint8_t>> tissue = above_floor(image, region, floor);
        const Grid<std::uint8_t>* fit = tissue ? &*tissue : &region;
        TissueModel m = fit_tissue_model(image, fit, options);
        const auto sound = [](const TissueModel& t) { return t.usable() && t.note.empty(); };
        if (fit != &region && !sound(m)) {
            try {
                if (TissueModel whole = fit_tissue_model(image, &region, options); sound(whole)) {
                    m = std::move(whole);
                    fit = &region;
                }
            } catch (const std::invalid_argument&) {  // the whole region cannot be fitted (NaN in it): the fit above the floor stays
            }
        }
        if (!m.usable() && whole_brain)
            if (std::optional<TissueModel> b = fit_through_noise(image, *fit, options, m)) {
                std::ostringstream os;
                os.precision(3);
                os << "tissue model: on the image " << m.degenerate << "; blurred by " << b->smooth_mm
                   << " mm, as the threshold term reads a noisy scan, the " << options.classes
                   << " classes fit, each mean within its spread on the image: noise hid a tissue, and the blurred fit is used";
                warnings.push_back(os.str());
                m = std::move(*b);
            }
        // Fewer tissues in the region than classes asked for (a tight mask with next to no CSF: a
        // class under 1 %, or one tissue split in two): one class fewer, down to two.
        for (TissueModelOptions fewer = options; !m.usable() && fewer.classes > 2;) {
            const std::string why = m.degenerate;
            --fewer.classes;
            TissueModel next = fit_tissue_model(image, fit, fewer);
            if (next.usable())
                warnings.push_back("tissue model: " + std::to_string(options.classes) + " classes do not fit (" + why + "); " +
                                   std::to_string(fewer.classes) + " used");
            m = std::move(next);
        }
        if (!m.usable()) warnings.push_back("tissue model not usable (" + m.degenerate + ")");
        m.contrast = contrast;  // which way the classes are named
        if (fit != &region) m.floor = floor;  // fitted above it
        // (On BrainWeb only its shaded variants fail the partial-volume fit: say so. Fitted through
        // noise that hid a tissue, the noise is the likelier cause.)
        if (!m.note.empty())
            warnings.push_back("tissue model: " + m.note +
                               (m.smooth_mm > 0 ? std::string(" (heavy noise can do this)")
                                                : " (a bias field can do this; " + std::string(kShadingHint) + ")"));
        if (m.usable() && !m.converged)
            warnings.push_back("tissue model: EM stopped at its limit of " + std::to_string(options.max_iterations) +
                               " iterations before converging (the class means still drift slowly)");
        if (m.usable()) thin_class_warnings(m, warnings);
        return m;
    } catch (const std::invalid_argument& e) {
        warnings.push_back(std::string("no tissue model (") + e.what() + ")");
        return std::nullopt;
    }
}

std::vector<std::string> window_warnings(const TissueModel& model, double lower, double upper) {
    std::vector<int> inside;
    for (std::size_t c = 0; c < model.classes.size(); ++c)
        if (model.classes[c].mean >= lower && model.classes[c].mean <= upper) inside.push_back(static_cast<int>(c));
    if (inside.size() < 2) return {};
    std::ostringstream os;
    os.precision(4);
    os << "the window " << lower << " .. " << upper << " spans " << inside.size() << " tissue classes (";
    for (std::size_t i = 0; i < inside.size(); ++i)
        os << (i ? ", " : "") << tissue_class_name(model, inside[i]) << " " << model.classes[static_cast<std::size_t>(inside[i])].mean;
    os << "): the front will grow through both";
    return {os.str()};
}

WindowEstimate estimate_window(const Grid<float>& image, const IntensityScale& scale, std::span<const SeedBall> seeds,
                               const Grid<std::uint8_t>* roi, const TissueModel* model, const WindowOptions& options) {
    options.validate();
    // The seeds vote on the image the model was fitted on (blurred when noise hid a tissue).
    std::optional<Grid<float>> smooth;
    if (model && model->usable() && model->smooth_mm > 0) smooth = gaussian_smooth(image, model->smooth_mm);
    const std::vector<float> raw = seed_values(smooth ? *smooth : image, seeds, roi);
    WindowEstimate w;
    if (options.estimate == WindowSource::kModel && model && model->usable()) {
        w.model_window = liveset::model_window(*model, raw);
        w.source = WindowSource::kModel;
        w.mu = (w.model_window->mu() - scale.low) / (scale.high - scale.low);
        w.epsilon = scale.unit_length(w.model_window->epsilon());
        w.warnings = w.model_window->warnings;
        return w;
    }
    if (options.estimate == WindowSource::kModel)
        w.warnings.push_back("the window comes from the seeds' statistics (µ = median, ε = 5 robust σ): check it");
    std::vector<float> unit(raw.size());
    std::transform(raw.begin(), raw.end(), unit.begin(), [&](float x) { return static_cast<float>(scale.to_unit(x)); });
    w.seed_stats = seed_statistics_of(unit);
    w.source = WindowSource::kSeeds;
    w.mu = w.seed_stats->median;
    w.epsilon = std::max(options.min_epsilon, options.epsilon_sigmas * w.seed_stats->mad_sigma);
    if (model && model->usable()) {
        const auto more = window_warnings(*model, scale.to_raw(w.mu - w.epsilon), scale.to_raw(w.mu + w.epsilon));
        w.warnings.insert(w.warnings.end(), more.begin(), more.end());
    }
    return w;
}

std::optional<ModelWindow> sheet_window(const Grid<float>& image, const Grid<std::uint8_t>& mask,
                                        const Grid<std::uint8_t>* roi, const TissueModelOptions& options,
                                        std::vector<std::string>& warnings, TissueModel* model, const SheetFit& fit) {
    if (!(mask.dims() == image.dims()) || (roi && !(roi->dims() == image.dims())) || (fit.region && !(fit.region->dims() == image.dims())))
        throw std::invalid_argument("sheet window: image, mask, ROI and model region differ in size");
    const auto inside = [&](PointIndex i) { return mask[i] && (!roi || (*roi)[i]); };
    bool any = false;
    for (PointIndex i = 0; i < mask.size() && !any; ++i) any = inside(i);
    if (!any) {
        warnings.push_back("the segmentation is empty: no sheet to find holes in");
        return std::nullopt;
    }
    bool whole_brain = false;
    const Grid<std::uint8_t> region = model_region(image, fit.region, roi, options.classes, &whole_brain, fit.brain);
    const std::optional<TissueModel> m = fit_window_model(image, region, options, warnings,
                                                          whole_brain || fit.region_is_brain, fit.known_grey_brighter);
    if (!m || !m->usable()) return std::nullopt;
    if (model) *model = *m;
    // The voxels vote on the image the model was fitted on (blurred when noise hid a tissue).
    std::optional<Grid<float>> smooth;
    if (m->smooth_mm > 0) smooth = gaussian_smooth(image, m->smooth_mm);
    const Grid<float>& fitted = smooth ? *smooth : image;
    std::vector<float> values;
    for (PointIndex i = 0; i < mask.size(); ++i)
        if (inside(i)) values.push_back(fitted[i]);
    return model_window(*m, values);
}

}  // namespace liveset
