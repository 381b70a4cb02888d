// Helpers shared by the level-set tests: bitwise state comparison, brute-force change sets and
// random zero-layer edits (fixed seeds).
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <random>
#include <span>
#include <vector>

#include "liveset/levelset/invariants.hpp"
#include "liveset/levelset/sparse_field.hpp"

namespace liveset::testing {

inline bool same_state(const SparseField& a, const SparseField& b) {
    const auto pa = a.phi().values(), pb = b.phi().values();
    const auto sa = a.status().values(), sb = b.status().values();
    for (std::size_t i = 0; i < pa.size(); ++i)
        if (std::bit_cast<std::uint32_t>(pa[i]) != std::bit_cast<std::uint32_t>(pb[i]) || sa[i] != sb[i]) return false;
    return true;
}

// Every point whose φ (bitwise) or status differs between two states, sorted.
inline std::vector<PointIndex> brute_force_changes(const SparseField& before, const SparseField& after) {
    std::vector<PointIndex> out;
    const auto pa = before.phi().values(), pb = after.phi().values();
    const auto sa = before.status().values(), sb = after.status().values();
    for (std::size_t i = 0; i < pa.size(); ++i)
        if (std::bit_cast<std::uint32_t>(pa[i]) != std::bit_cast<std::uint32_t>(pb[i]) || sa[i] != sb[i])
            out.push_back(static_cast<PointIndex>(i));
    return out;
}

inline std::vector<PointIndex> sorted(std::vector<PointIndex> v) {
    std::sort(v.begin(), v.end());
    return v;
}

// Every point whose sign of φ (φ < 0) differs between two states, sorted.
inline std::vector<PointIndex> brute_force_sign_changes(const SparseField& before, const SparseField& after) {
    std::vector<PointIndex> out;
    const auto pa = before.phi().values(), pb = after.phi().values();
    for (std::size_t i = 0; i < pa.size(); ++i)
        if ((pa[i] < 0.0f) != (pb[i] < 0.0f)) out.push_back(static_cast<PointIndex>(i));
    return out;
}

// An update's report of its sign changes is present and exact (what a mesher relies on).
inline ::testing::AssertionResult reports_sign_changes(const ChangedPoints& x, const SparseField& before, const SparseField& after) {
    if (!x.sign_changes) return ::testing::AssertionFailure() << "no sign changes reported";
    if (sorted(*x.sign_changes) != brute_force_sign_changes(before, after))
        return ::testing::AssertionFailure() << x.sign_changes->size() << " sign changes reported, "
                                             << brute_force_sign_changes(before, after).size() << " by brute force";
    return ::testing::AssertionSuccess();
}

// A random local edit: a Gaussian bump (raise or lower) of the given radius around a random
// zero-layer point, or a handful of scattered single-point edits.
inline std::vector<ZeroLayerEdit> random_edit(const SparseField& f, std::mt19937& rng, double radius = 3.0) {
    std::vector<ZeroLayerEdit> edits;
    const auto zero = f.zero_layer();
    if (zero.empty()) return edits;
    std::uniform_int_distribution<std::size_t> pick(0, zero.size() - 1);
    std::uniform_real_distribution<float> amp(-0.5f, 0.5f);
    if (rng() % 4 == 0) {
        const int n = 1 + static_cast<int>(rng() % 6);
        for (int k = 0; k < n; ++k) edits.push_back({zero[pick(rng)], amp(rng)});
        return edits;
    }
    const Vec3i c = f.lattice().coord(zero[pick(rng)]);
    const float a = amp(rng);
    const int r = static_cast<int>(std::ceil(radius));
    for (int z = c.z - r; z <= c.z + r; ++z)
        for (int y = c.y - r; y <= c.y + r; ++y)
            for (int x = c.x - r; x <= c.x + r; ++x) {
                const Vec3i p{x, y, z};
                if (!f.lattice().contains(p)) continue;
                const PointIndex i = f.lattice().index(p);
                if (f.status()[i] != 0) continue;
                const double d2 = dot((p - c).cast<double>(), (p - c).cast<double>());
                if (d2 > radius * radius) continue;
                edits.push_back({i, a * static_cast<float>(std::exp(-d2 / (radius * radius)))});
            }
    return edits;
}

// A threshold-like speed on a synthetic "image": the front expands (F = -0.45) inside a blob with a
// wavy surface and contracts (F = +0.45) outside it, plus a small curvature term - the regime of a
// segmentation (growth, then a front that stalls, flickers and oscillates at the window's edge).
// Points with x < still_below_x have F = 0: there the front stops dead, so only part of it moves.
class BlobSpeed final : public Speed {
public:
    BlobSpeed(Vec3d centre, double radius, float curvature = 0.05f, int still_below_x = -1)
        : c_(centre), r_(radius), w_(curvature), still_(still_below_x) {}
    SpeedSample at(const Grid<float>& phi, Vec3i p) const override {
        if (p.x < still_) return {};
        const Vec3d d = p.cast<double>() - c_;
        const double wave = 1.5 * std::sin(0.9 * d.x) * std::cos(0.7 * d.y) + std::sin(1.3 * d.z + 0.4 * d.x);
        const float prop = norm(d) < r_ + wave ? -0.45f : 0.45f;
        return {prop, w_ * mean_curvature(phi, p)};
    }
    float curvature_weight() const override { return w_; }

private:
    Vec3d c_;
    double r_;
    float w_;
    int still_;
};

// Every point's state in `before` at the points of X (what an undo records).
inline std::vector<PointState> states_at(const SparseField& before, std::span<const PointIndex> x) {
    std::vector<PointState> out;
    for (PointIndex i : x) out.push_back({i, before.phi()[i], before.status()[i]});
    return out;
}

// The layer lists of `a` and `b` hold the same points in the same order.
inline void expect_same_list_order(const SparseField& a, const SparseField& b) {
    for (int k = -a.layers(); k <= a.layers(); ++k) {
        const auto la = a.layer(k), lb = b.layer(k);
        EXPECT_TRUE(std::equal(la.begin(), la.end(), lb.begin(), lb.end())) << "layer list order " << k;
    }
}

inline void expect_valid(const SparseField& f, const char* where) {
    const InvariantReport r = check_invariants(f);
    EXPECT_TRUE(r.ok()) << where << ": " << r.summary();
}

}  // namespace liveset::testing
