// Threshold speed (paper Eq. 2-3), tabulated per voxel.
#include "liveset/segment/threshold_speed.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "liveset/segment/smoothing.hpp"

namespace liveset {

void validate(const ThresholdParams& p) {
    auto fail = [](const std::string& m) { throw std::invalid_argument(m); };
    if (!std::isfinite(p.mu) || p.mu < 0.0 || p.mu > 1.0) fail("mu must be a normalised intensity in [0, 1]");
    if (!std::isfinite(p.epsilon) || p.epsilon <= 0.0) fail("epsilon must be positive");
    if (!std::isfinite(p.n) || p.n <= 0.0 || p.n > 100.0) fail("n must be in (0, 100]");
    if (!std::isfinite(p.alpha) || p.alpha < 0.0 || p.alpha >= 1.0) fail("alpha must be in [0, 1)");
    check_smooth_mm(p.smooth_mm);
}

double threshold_term(double intensity, const ThresholdParams& p) {
    const double d = std::abs(p.mu - intensity);
    // 2 dⁿ / (εⁿ + dⁿ) − 1 written as (dⁿ − εⁿ) / (dⁿ + εⁿ) = (r − 1) / (r + 1), r = (d/ε)ⁿ, which
    // stays finite for any n (r may overflow to +inf: the limit is 1).
    const double r = std::pow(d / p.epsilon, p.n);
    if (!std::isfinite(r)) return 1.0;
    return (r - 1.0) / (r + 1.0);
}

ThresholdSpeed::ThresholdSpeed(const Grid<float>& unit_image, const ThresholdParams& params, const Grid<std::uint8_t>* roi,
                               const Grid<float>* blurred)
    : params_(params), propagation_(unit_image.lattice()), roi_(roi) {
    validate(params);
    const auto check_dims = [&](const char* what, Vec3i dims) {
        if (dims == unit_image.dims()) return;
        std::ostringstream os;
        os << what << " " << dims << " does not match the image " << unit_image.dims();
        throw std::invalid_argument(os.str());
    };
    if (roi) check_dims("region-of-interest mask", roi->dims());
    if (blurred) check_dims("blurred image", blurred->dims());
    std::optional<Grid<float>> own;  // the blur, when the caller keeps none
    const Grid<float>* source = &unit_image;
    if (params.smooth_mm > 0.0) source = blurred ? blurred : &own.emplace(gaussian_smooth(unit_image, params.smooth_mm));
    const std::span<const float> img = source->values();
    tabulate([&](std::size_t i) {
        const float v = img[i];
        if (!std::isfinite(v)) throw std::invalid_argument("normalised image has non-finite voxels");
        return threshold_term(v, params);
    });
}

ThresholdSpeed::ThresholdSpeed(TermTag, const Grid<float>& term, const ThresholdParams& params, const Grid<std::uint8_t>* roi)
    : params_(params), propagation_(term.lattice()), roi_(roi) {
    validate(params);
    if (roi && !(roi->dims() == term.dims())) throw std::invalid_argument("region-of-interest mask does not match the threshold terms");
    tabulate([&](std::size_t i) {
        const float d = term[static_cast<PointIndex>(i)];
        if (!(d >= -1.0f && d <= 1.0f)) throw std::invalid_argument("threshold terms must lie in [-1, 1]");
        return static_cast<double>(d);
    });
}

ThresholdSpeed ThresholdSpeed::from_terms(const Grid<float>& term, const ThresholdParams& params, const Grid<std::uint8_t>* roi) {
    return ThresholdSpeed(TermTag{}, term, params, roi);
}

template <class D>
void ThresholdSpeed::tabulate(const D& term_at) {
    const double w = 0.5 * (1.0 - params_.alpha);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, propagation_.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const auto pi = static_cast<PointIndex>(i);
            propagation_[pi] = roi_ && (*roi_)[pi] == 0 ? 0.5f : static_cast<float>(w * term_at(i));
        }
    });
    // The sign table, a byte (four voxels) per index, so that no two tasks write one byte.
    const std::span<const float> f = propagation_.values();
    signs_.resize((f.size() + 3) / 4);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, signs_.size(), 1 << 14), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t b = r.begin(); b != r.end(); ++b) {
            unsigned byte = 0;
            for (std::size_t k = 0; k < 4 && 4 * b + k < f.size(); ++k) {
                const float v = f[4 * b + k];
                byte |= (v > 0.0f ? 1u : v < 0.0f ? 2u : 0u) << (2 * k);
            }
            signs_[b] = static_cast<std::uint8_t>(byte);
        }
    });
}

void ThresholdSpeed::propagation_signs(const Grid<float>&, std::span<const PointIndex> points, std::span<std::int8_t> out) const {
    // The points are scattered (the thin-front rule's): each table byte fetched 16 points ahead.
    constexpr std::size_t kAhead = 16;
    const std::uint8_t* const table = signs_.data();
    for (std::size_t k = 0; k < points.size(); ++k) {
        if (k + kAhead < points.size()) __builtin_prefetch(table + points[k + kAhead] / 4, 0);
        const PointIndex i = points[k];
        out[k] = kSignOfCode[(table[i / 4] >> (2 * (i % 4))) & 3u];
    }
}

SpeedSample ThresholdSpeed::at(const Grid<float>& phi, Vec3i p) const {
    const PointIndex i = phi.lattice().index(p);
    if (roi_ && (*roi_)[i] == 0) return {propagation_[i], 0.0f};
    return {propagation_[i], curvature_weight() * mean_curvature(phi, p)};
}

// rate_of(at(phi, p), phi, p) at each point, the curvature, the central and the upwind |∇φ| batched.
void ThresholdSpeed::rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const {
    if (out.size() != points.size()) throw std::invalid_argument("Speed::rates: output size differs from the points'");
    const float weight = curvature_weight();
    std::array<CurvatureAndGradient, 256> batch;
    std::array<float, 256> propagation, upwind;
    std::array<bool, 256> curved;
    for (std::size_t b = 0; b < points.size(); b += batch.size()) {
        const std::size_t m = std::min(batch.size(), points.size() - b);
        // The per-voxel tables first, in a loop of independent loads: their cache misses (a
        // brain's tables are tens of MB) overlap instead of waiting one by one in the loop below.
        for (std::size_t k = 0; k < m; ++k) {
            propagation[k] = propagation_[points[b + k]];
            curved[k] = roi_ == nullptr || (*roi_)[points[b + k]] != 0;
        }
        // The curvature, the central and the upwind |∇φ| from one set of loads per point.
        curvature_gradient_and_upwind(phi, points.subspan(b, m), std::span(propagation).first(m), std::span(batch).first(m),
                                      std::span(upwind).first(m));
        for (std::size_t k = 0; k < m; ++k) {
            double r = 0.0;
            if (propagation[k] != 0.0f) r += static_cast<double>(propagation[k]) * upwind[k];
            const float curvature = curved[k] ? weight * batch[k].kappa : 0.0f;
            if (curvature != 0.0f) r += static_cast<double>(curvature) * batch[k].gradient_norm;
            out[b + k] = r;
        }
    }
}

}  // namespace liveset
