// segment_image(): normalise, estimate the window, initialise, evolve.
#include "liveset/segment/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <sstream>
#include <stdexcept>

#include "liveset/grid/large_page_allocator.hpp"
#include "liveset/segment/smoothing.hpp"
#include "liveset/segment/voxel_loops.hpp"

namespace liveset {

namespace {

// µ and ε for the request: the user's where given, the rest estimated (window.hpp). Fills the
// outcome's window source, model, statistics and warnings.
void choose_window(const Grid<float>& image, const SegmentRequest& req, SegmentOutcome& out, ThresholdParams& p) {
    std::optional<double> mu = req.mu, epsilon = req.epsilon;
    if (req.mu_raw) mu = (*req.mu_raw - out.scale.low) / (out.scale.high - out.scale.low);
    if (req.epsilon_raw) epsilon = out.scale.unit_length(*req.epsilon_raw);
    if (!req.seeds.empty()) {  // the model: for the window, or to check the user's window
        bool automatic = false;  // no region given: the automatic brain mask, when the image is a head
        const Grid<std::uint8_t> region = model_region(image, req.model_region, req.roi, req.window.model.classes, &automatic, req.brain_mask);
        out.model = fit_window_model(image, region, req.window.model, out.warnings, automatic || req.model_region_is_brain,
                                     req.model_region_grey_brighter);
    }
    if (!mu || !epsilon) {
        if (req.seeds.empty())
            throw std::invalid_argument("mu and epsilon must be given when starting from a mask (no seeds to estimate them)");
        const WindowEstimate w = estimate_window(image, out.scale, req.seeds, req.roi, out.model ? &*out.model : nullptr, req.window);
        out.window_source = w.source;
        out.seed_stats = w.seed_stats;
        out.model_window = w.model_window;
        out.warnings.insert(out.warnings.end(), w.warnings.begin(), w.warnings.end());
        p.mu = w.mu;
        p.epsilon = w.epsilon;
    }
    if (mu) p.mu = *mu;
    if (epsilon) p.epsilon = *epsilon;
    if (mu && epsilon && out.model && out.model->usable()) {
        const auto more = window_warnings(*out.model, out.scale.to_raw(p.mu - p.epsilon), out.scale.to_raw(p.mu + p.epsilon));
        out.warnings.insert(out.warnings.end(), more.begin(), more.end());
    }
}

// A front that converged far short of its tissue is warned about: the mask is then the seeds'
// neighbourhood, not the tissue, and would otherwise pass silently (docs/BENCHMARKS.md, session 49:
// a noisy 2 mm scan's grey matter, 1.7 %). Both must hold: the result is under kStalledShare of
// the pure voxels the tissue model gives the seeds' class (the class that set the window) in its
// region, and under the volume of the seeds' balls grown by kStalledReach voxels - so a small
// structure segmented on purpose (a nucleus, a lesion: many times its seed balls) is not warned
// about although its class fills the brain.
constexpr double kStalledShare = 0.05;
constexpr double kStalledReach = 4.0;  // voxels

void warn_if_stalled(const std::vector<SeedBall>& seeds, SegmentOutcome& out) {
    if (seeds.empty() || !out.model || !out.model_window || out.result.reason != StopReason::kConverged) return;
    const int k = out.model_window->seed_class;
    if (k < 0 || static_cast<std::size_t>(k) >= out.model->classes.size()) return;
    const double expected = out.model->classes[static_cast<std::size_t>(k)].weight * static_cast<double>(out.model->voxels);
    double reach = 0.0;  // the seeds' balls grown by kStalledReach, overlaps counted twice
    for (const SeedBall& b : seeds) reach += 4.0 / 3.0 * std::numbers::pi * std::pow(b.radius + kStalledReach, 3.0);
    const std::uint8_t* const mask = out.mask.values().data();
    const std::size_t inside = voxel_loops::count_if(out.mask.size(), [&](std::size_t i) { return mask[i] != 0; });
    const auto n = static_cast<double>(inside);
    if (expected <= 0.0 || n >= kStalledShare * expected || n >= reach) return;
    std::ostringstream os;
    os.setf(std::ios::fixed);
    os.precision(1);
    os << "the segmentation holds " << inside << " voxels, " << 100.0 * n / expected << " % of the "
       << static_cast<std::size_t>(std::lround(expected)) << " the tissue model puts in the seeds' class ("
       << tissue_class_name(*out.model, k)
       << ") in its region, the front hardly past its seeds: if the whole tissue was meant, it stopped early (noise or "
          "thin tissue cut it off; more seeds, a lower alpha or a wider window may help)";
    out.warnings.push_back(os.str());
}

// The speed's table from the normalised image, blurred where p.smooth_mm asks, each image freed
// once the next is made and the table made after the blur: besides the caller's image, three
// grids of the scan's size at most (during the blur: the normalised image, the blur and its pass
// buffer; then the blur and the table), where the speed blurring its own copy held four (a 0.5 mm
// brain's are 226 MB each).
ThresholdSpeed tabulated_speed(const Grid<float>& image, const IntensityScale& scale, const ThresholdParams& p,
                               const Grid<std::uint8_t>* roi) {
    Grid<float> source = normalise(image, scale);
    if (p.smooth_mm > 0.0) source = gaussian_smooth(source, p.smooth_mm);
    return ThresholdSpeed(source, p, roi, p.smooth_mm > 0.0 ? &source : nullptr);
}

// The request checked, the window, α and the speed's table from the image (filling `out`'s scale,
// window, model, α and parameters).
ThresholdSpeed speed_for(const Grid<float>& image, const SegmentRequest& req, SegmentOutcome& out) {
    if (req.seeds.empty() && !req.initial_mask) throw std::invalid_argument("give at least one seed or an initial mask");
    if (req.initial_mask && !(req.initial_mask->dims() == image.dims())) {
        std::ostringstream os;
        os << "initial mask " << req.initial_mask->dims() << " does not match the image " << image.dims();
        throw std::invalid_argument(os.str());
    }
    req.window.validate();
    validate(req.loop);
    if ((req.mu && req.mu_raw) || (req.epsilon && req.epsilon_raw))
        throw std::invalid_argument("give the window in normalised or raw units, not both");
    if (req.smooth_mm && !req.alpha)
        throw std::invalid_argument("give the smoothing together with alpha: the automatic choice sets both");

    out.scale = robust_scale(image, req.roi, req.scale);
    ThresholdParams p;
    p.n = req.n;
    choose_window(image, req, out, p);
    if (!req.mu && !req.mu_raw) p.mu = std::clamp(p.mu, 0.0, 1.0);  // an estimate beyond the scale's range
    if (req.alpha) {
        out.alpha.alpha = *req.alpha;
        out.alpha.smooth_mm = req.smooth_mm.value_or(0.0);
    } else {
        // The seeds' class when the whole window is theirs; with µ or ε given, the class nearest µ
        // (as the Session, whose window is either the seeds' or set).
        const bool window_given = req.mu || req.mu_raw || req.epsilon || req.epsilon_raw;
        const int window_class = out.model_window && !window_given ? out.model_window->seed_class : -1;
        out.alpha = automatic_alpha(out.model ? &*out.model : nullptr, out.scale.to_raw(p.mu), image.lattice().spacing_float(),
                                    window_class);
    }
    p.alpha = out.alpha.alpha;
    p.smooth_mm = out.alpha.smooth_mm;
    validate(p);
    out.params = p;
    out.step = req.loop.step;
    return tabulated_speed(image, out.scale, p, req.roi);
}

// The front from the request's start (its initial mask, or its seeds with or without the coarse
// start) evolved under `speed` on `lattice`, and the mask.
void evolve(const Lattice& lattice, const ThresholdSpeed& speed, const SegmentRequest& req, const SegmentationHook& hook,
            const std::atomic<bool>* interrupt, SegmentOutcome& out) {
    out.field = std::make_unique<SparseField>(lattice, req.layers);
    // The blocks kept for the preprocessing's grids (large_page_allocator.hpp: the blur's, the
    // normalised image's) serve no request of the evolution: given back before the band is built
    // (a 0.5 mm brain's: 226 MB). Process-wide: a viewer's or Python's other thread then makes its
    // next grids on fresh pages (time only).
    detail::release_recycled();
    if (req.initial_mask) {
        const std::uint8_t* const init = req.initial_mask->values().data();
        const std::size_t inside = voxel_loops::count_if(req.initial_mask->size(), [&](std::size_t i) { return init[i] != 0; });
        if (inside == 0) throw std::invalid_argument("the initial mask is empty");
        out.field->init_from_mask(*req.initial_mask);
    } else if (coarse_start_applies(req.coarse_start, lattice)) {
        out.coarse.emplace();
        const std::optional<Grid<std::uint8_t>> start =
            run_coarse_start(speed, lattice, req.roi, req.seeds, req.loop, req.layers, hook, interrupt, *out.coarse);
        // So are the coarse grids' blocks (a 0.5 mm brain's: 140 MB).
        detail::release_recycled();
        init_fine_start(*out.field, start, req.seeds);
        if (out.coarse->result.reason == StopReason::kInterrupted) {
            out.result.reason = StopReason::kInterrupted;
            out.mask = inside_mask(out.field->phi(), req.roi);
            return;
        }
    } else {
        init_from_seeds(*out.field, req.seeds);
    }
    out.result = run_segmentation(*out.field, speed, req.loop, hook, interrupt);
    out.mask = inside_mask(out.field->phi(), req.roi);
    warn_if_stalled(req.seeds, out);
}

}  // namespace

SegmentOutcome segment_image(const Grid<float>& image, const SegmentRequest& req, const SegmentationHook& hook,
                             const std::atomic<bool>* interrupt) {
    SegmentOutcome out;
    const ThresholdSpeed speed = speed_for(image, req, out);
    evolve(image.lattice(), speed, req, hook, interrupt, out);
    return out;
}

SegmentOutcome segment_image(Grid<float>&& image, const SegmentRequest& req, const SegmentationHook& hook,
                             const std::atomic<bool>* interrupt) {
    SegmentOutcome out;
    const ThresholdSpeed speed = speed_for(image, req, out);
    const Lattice lattice = image.lattice();
    image = Grid<float>();  // the evolution never reads it: one grid of the scan's size less while the front moves
    evolve(lattice, speed, req, hook, interrupt, out);
    return out;
}

}  // namespace liveset
