// The paper's threshold speed (Feltell & Bai Eq. 2-3) for MR tissue segmentation:
//   D(p) = 2 |µ − I(p)|ⁿ / (εⁿ + |µ − I(p)|ⁿ) − 1      ∈ [−1, 1), negative inside the window µ ± ε
//   F(p) = ½ ((1 − α) D(p) + α κ(p))
// with I normalised to [0, 1] (intensity.hpp), κ the difference-of-normals mean curvature, and the
// level set's convention ∂φ/∂t = |∇φ| F (φ < 0 inside): D < 0 expands the front, D > 0 contracts
// it, and the curvature term smooths it and keeps it from leaking through thin gaps.
//
// Region of interest (as ITK-SNAP's mask): at a point outside the ROI, F = +½ (pure contraction,
// no curvature), so the front cannot settle there; segmentations intersect the final mask with the
// ROI as well (the front may overshoot the ROI border by less than one voxel during a step).
#pragma once

#include <cstdint>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/levelset/speed.hpp"

namespace liveset {

struct ThresholdParams {
    double mu = 0.5;       // ideal intensity, normalised units
    double epsilon = 0.1;  // acceptable error (half window), normalised units, > 0
    double n = 4.0;        // steepness of D at the window edge, > 0
    double alpha = 0.1;    // curvature weight in [0, 1)
    // σ (mm) of the Gaussian the image is blurred with before D is tabulated (smoothing.hpp); 0: none.
    double smooth_mm = 0.0;
};

// Throws std::invalid_argument with a one-line message for non-finite values, ε ≤ 0, n ≤ 0,
// α outside [0, 1), µ outside [0, 1], a smoothing σ outside [0, kMaxSmoothMm].
void validate(const ThresholdParams& params);

// D(I) of Eq. 3 for one normalised intensity.
double threshold_term(double intensity, const ThresholdParams& params);

class ThresholdSpeed final : public Speed {
public:
    // `unit_image` (normalised to [0, 1]) and `roi` (optional, non-zero = allowed) must match
    // each other's dimensions, and `roi` must outlive the speed (the images are read only here).
    // D is tabulated per voxel at construction, of the image blurred by params.smooth_mm when it
    // is positive. A caller that keeps that blurred image (gaussian_smooth(unit_image,
    // params.smooth_mm), e.g. a session whose window changes) passes it as `blurred`, which is
    // then read instead of blurring again (ignored when smooth_mm is 0); `unit_image` then gives
    // only the lattice (segment_image passes the blur as both).
    ThresholdSpeed(const Grid<float>& unit_image, const ThresholdParams& params, const Grid<std::uint8_t>* roi = nullptr,
                   const Grid<float>* blurred = nullptr);
    // The speed of given threshold terms D ∈ [-1, 1] per voxel (in place of D(I) of an image; the
    // coarse start's block means), with `params`' α; µ, ε, n and the blur are not used.
    static ThresholdSpeed from_terms(const Grid<float>& term, const ThresholdParams& params, const Grid<std::uint8_t>* roi = nullptr);

    SpeedSample at(const Grid<float>& phi, Vec3i p) const override;
    void rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const override;
    float curvature_weight() const override { return static_cast<float>(0.5 * params_.alpha); }
    void propagation_signs(const Grid<float>& phi, std::span<const PointIndex> points, std::span<std::int8_t> out) const override;

    const ThresholdParams& params() const { return params_; }
    // ½(1 − α)·D at a lattice point (+½ outside the ROI).
    float propagation(Vec3i p) const { return propagation_(p); }
    const Lattice& lattice() const { return propagation_.lattice(); }

private:
    struct TermTag {};
    ThresholdSpeed(TermTag, const Grid<float>& term, const ThresholdParams& params, const Grid<std::uint8_t>* roi);
    // propagation_ = ½(1 − α)·term_at(i) inside the ROI (+½ outside), and its sign table.
    template <class D>
    void tabulate(const D& term_at);

    ThresholdParams params_;
    Grid<float> propagation_;             // ½(1 − α) D(p), or +½ outside the ROI
    // propagation_'s signs, 2 bits a voxel (four to a byte, the lowest first): 0 zero, 1 positive,
    // 2 negative.
    static constexpr std::int8_t kSignOfCode[4] = {0, 1, -1, 0};
    std::vector<std::uint8_t> signs_;
    const Grid<std::uint8_t>* roi_;       // curvature applies only inside (null: everywhere)
};

}  // namespace liveset
