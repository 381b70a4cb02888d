// segment_image(): normalise, estimate the window, initialise, evolve.
#include "liveset/segment/pipeline.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace liveset {

void estimate_window(const SeedStatistics& stats, double epsilon_sigmas, double min_epsilon, ThresholdParams& params) {
    params.mu = stats.median;
    params.epsilon = std::max(min_epsilon, epsilon_sigmas * stats.mad_sigma);
}

SegmentOutcome segment_image(const Grid<float>& image, const SegmentRequest& req, const SegmentationHook& hook,
                             const std::atomic<bool>* interrupt) {
    if (req.seeds.empty() && !req.initial_mask) throw std::invalid_argument("give at least one seed or an initial mask");
    if (req.initial_mask && !(req.initial_mask->dims() == image.dims())) {
        std::ostringstream os;
        os << "initial mask " << req.initial_mask->dims() << " does not match the image " << image.dims();
        throw std::invalid_argument(os.str());
    }
    if (!std::isfinite(req.epsilon_sigmas) || req.epsilon_sigmas <= 0 || !std::isfinite(req.min_epsilon) ||
        req.min_epsilon <= 0)
        throw std::invalid_argument("the epsilon estimate needs positive sigmas and floor");
    validate(req.loop);
    if ((req.mu && req.mu_raw) || (req.epsilon && req.epsilon_raw))
        throw std::invalid_argument("give the window in normalised or raw units, not both");

    SegmentOutcome out;
    out.scale = robust_scale(image, req.roi, req.scale);
    const Grid<float> unit = normalise(image, out.scale);

    std::optional<double> mu = req.mu, epsilon = req.epsilon;
    if (req.mu_raw) mu = (*req.mu_raw - out.scale.low) / (out.scale.high - out.scale.low);
    if (req.epsilon_raw) epsilon = out.scale.unit_length(*req.epsilon_raw);

    ThresholdParams p;
    p.n = req.n;
    p.alpha = req.alpha;
    if (!mu || !epsilon) {
        if (req.seeds.empty())
            throw std::invalid_argument("mu and epsilon must be given when starting from a mask (no seeds to estimate them)");
        out.seed_stats = seed_statistics(unit, req.seeds, req.roi);
        estimate_window(*out.seed_stats, req.epsilon_sigmas, req.min_epsilon, p);
    }
    if (mu) p.mu = *mu;
    if (epsilon) p.epsilon = *epsilon;
    validate(p);
    out.params = p;

    const ThresholdSpeed speed(unit, p, req.roi);
    out.field = std::make_unique<SparseField>(image.lattice(), req.layers);
    if (req.initial_mask) {
        std::size_t inside = 0;
        for (std::size_t i = 0; i < req.initial_mask->size(); ++i) inside += (*req.initial_mask)[static_cast<PointIndex>(i)] != 0;
        if (inside == 0) throw std::invalid_argument("the initial mask is empty");
        out.field->init_from_mask(*req.initial_mask);
    } else {
        init_from_seeds(*out.field, req.seeds);
    }
    out.result = run_segmentation(*out.field, speed, req.loop, hook, interrupt);
    out.mask = inside_mask(out.field->phi(), req.roi);
    return out;
}

}  // namespace liveset
