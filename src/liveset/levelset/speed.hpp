// Speed terms for the level-set equation ∂φ/∂t = |∇φ| F (φ < 0 inside; F > 0 moves the front
// inwards). A speed is evaluated at zero-layer points (and, with the thin-front rule, at L±1 points
// beside them: StepOptions::thin_fronts), split into a propagation part
// (multiplied by the upwind |∇φ|) and a curvature part (multiplied by the central |∇φ|). Both |∇φ|
// are per finest voxel (each axis's differences times h_min/h: 1 on an isotropic grid), so a front
// moves alike in mm along every axis of an anisotropic one.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>

#include "liveset/grid/grid.hpp"

namespace liveset {

struct SpeedSample {
    float propagation = 0.0f;  // multiplies the Godunov upwind |∇φ|
    float curvature = 0.0f;    // multiplies the central-difference |∇φ| (parabolic term)
};

class Speed {
public:
    Speed() : serial_(next_serial()) {}
    Speed(const Speed&) : serial_(next_serial()) {}
    Speed& operator=(const Speed&) {
        serial_ = next_serial();
        return *this;
    }
    virtual ~Speed() = default;
    // Distinct for every speed object (a copy or an assignment gets a new one): a sparse field
    // that lets converged stretches sleep wakes everything when the speed is not the last one's.
    // A speed must therefore not change its behaviour after construction.
    std::uint64_t serial() const { return serial_; }
    // F at band point p (a zero-layer point, or an L±1 one for the thin-front rule). Must be
    // thread-safe (called concurrently) and deterministic.
    virtual SpeedSample at(const Grid<float>& phi, Vec3i p) const = 0;
    // The rate |∇φ|·F (what a step multiplies by dt) at each band point of `points` (lattice
    // indices) into `out`, of the same size: at()'s propagation part times the Godunov upwind |∇φ|
    // plus its curvature part times the central |∇φ|, in double (rate_of). A speed may override
    // it with a faster form of exactly these bits (a batched curvature). Thread-safe like at().
    virtual void rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const;
    // Upper bound of the coefficient w in the curvature part w·κ (κ per mm), for the parabolic
    // time-step bound dt ≤ h_min/(4w). Zero when the speed has no curvature part.
    virtual float curvature_weight() const = 0;
    // The sign of at()'s propagation part (-1, 0 or +1) at each lattice index of `points` into
    // `out`, of the same size: the thin-front rule's test of which way the propagation would move
    // the front there, before it asks for a rate. By default from at(); a speed that tabulates it
    // (ThresholdSpeed, in a table of 2 bits a voxel, which stays in cache where the rule asks tens
    // of thousands of scattered points a step, fetched ahead along the batch) or has none
    // (CurvatureSpeed) answers without the curvature. Thread-safe like at().
    virtual void propagation_signs(const Grid<float>& phi, std::span<const PointIndex> points, std::span<std::int8_t> out) const {
        for (std::size_t k = 0; k < points.size(); ++k) {
            const float f = at(phi, phi.lattice().coord(points[k])).propagation;
            out[k] = static_cast<std::int8_t>(static_cast<int>(f > 0.0f) - static_cast<int>(f < 0.0f));
        }
    }

private:
    static std::uint64_t next_serial();
    std::uint64_t serial_;
};

// Mean curvature κ = ∇·(∇φ/|∇φ|) (sum of principal curvatures, 2/r on a sphere) at lattice point p,
// in 1/mm: the derivatives are physical, by the lattice's voxel sizes h, so a sphere of radius r mm
// gives 2/r on any grid, anisotropic included. By the difference-of-normals method: normals at the
// six half-way points p ± ½e_a of the gradient from one-sided differences along a and averaged
// central differences across, each divided by its axis's h, then κ = Σ_a (n_a(p+½e_a) − n_a(p−½e_a))/h_a.
// On a 1 mm lattice every factor is 1.0f: the index-unit curvature, bit for bit.
float mean_curvature(const Grid<float>& phi, Vec3i p);

// mean_curvature() and the norm of central_gradient() per finest voxel at each of `points` into `out` (the same
// size), four interior stencils at a time: the same bits as the single calls.
struct CurvatureAndGradient {
    float kappa;
    float gradient_norm;
};
void mean_curvature_and_gradient(const Grid<float>& phi, std::span<const PointIndex> points, std::span<CurvatureAndGradient> out);
// The same, and at each point upwind_gradient_norm(phi, p, speed[k], h_min/h) (sampling.hpp) into `upwind`
// (all four spans of the same size): the same bits as the single calls, from the same loads.
void curvature_gradient_and_upwind(const Grid<float>& phi, std::span<const PointIndex> points, std::span<const float> speed,
                                   std::span<CurvatureAndGradient> out, std::span<float> upwind);

// Speed::rate's formula for a sample `s` taken at p.
double rate_of(SpeedSample s, const Grid<float>& phi, Vec3i p);

// F = weight · κ: mean curvature flow (the paper's Figure 3 experiment).
class CurvatureSpeed final : public Speed {
public:
    explicit CurvatureSpeed(float weight = 1.0f);
    SpeedSample at(const Grid<float>& phi, Vec3i p) const override {
        return {0.0f, weight_ * mean_curvature(phi, p)};
    }
    void rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const override;
    float curvature_weight() const override { return weight_; }
    void propagation_signs(const Grid<float>&, std::span<const PointIndex>, std::span<std::int8_t> out) const override {
        std::fill(out.begin(), out.end(), std::int8_t{0});
    }

private:
    float weight_;
};

}  // namespace liveset
