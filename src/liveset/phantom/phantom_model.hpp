// Internal to the phantom (phantom.cpp): the anatomy and bias model derived from the options, the
// counter-based random numbers, and the small lattice helpers the construction steps share.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "liveset/phantom/phantom.hpp"

namespace liveset::phantom_detail {

// Nominal tissue intensities (T1-weighted, scanner-like units).
constexpr float kWmValue = 800.0f;
constexpr float kGmValue = 530.0f;
constexpr float kCsfValue = 220.0f;
constexpr float kBgValue = 0.0f;

constexpr Vec3d kAspect{0.84, 1.0, 0.80};  // brain semi-axes relative to the y (AP) axis
constexpr double kSkullFraction = 0.88;      // skull ellipsoid's largest semi-axis / half FOV
constexpr double kFoldAmplitude = 0.13;      // fold amplitude / pial crest radius
constexpr double kFoldWavelength = 0.24;     // fold wavelength / pial crest radius
constexpr int kFoldWaves = 24;
constexpr double kFoldLevel = 0.4;           // gyri where n > kFoldLevel
constexpr double kFoldSharpness = 0.5;       // width of the n -> fold profile transition
constexpr int kThicknessWaves = 6;
constexpr double kThicknessWavelength = 1.5;  // / pial crest radius
constexpr double kMinGmVoxels = 2.5;
constexpr double kMinCsfVoxels = 2.0;
constexpr double kBroadBumpWeight = 0.1;
constexpr double kBroadBumpSigma = 0.6;   // / half FOV
constexpr double kFirstBumpSigma = 0.11;
constexpr double kSecondBumpSigma = 0.10;
constexpr double kSecondBumpWeight = 1.0;

constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ull;

// splitmix64 output function of state z + golden: a bijective 64-bit mixer, used both to seed
// xoshiro and as the counter-based hash of (seed, voxel index) for the noise.
inline std::uint64_t mix64(std::uint64_t z) {
    z += kGolden;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

inline double unit_open_closed(std::uint64_t h) { return static_cast<double>((h >> 11) + 1) * 0x1.0p-53; }  // (0, 1]
inline double unit_closed_open(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }        // [0, 1)

// xoshiro256** seeded through splitmix64: the anatomy's random parameters.
class Xoshiro256 {
public:
    explicit Xoshiro256(std::uint64_t seed) {
        for (auto& s : s_) {  // the splitmix64 stream from `seed`
            s = mix64(seed);
            seed += kGolden;
        }
    }
    std::uint64_t next() {
        const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
        const std::uint64_t t = s_[1] << 17;
        s_[2] ^= s_[0];
        s_[3] ^= s_[1];
        s_[1] ^= s_[2];
        s_[0] ^= s_[3];
        s_[2] ^= t;
        s_[3] = rotl(s_[3], 45);
        return result;
    }
    double uniform() { return unit_closed_open(next()); }
    Vec3d direction() {  // uniform on the unit sphere
        const double z = 2.0 * uniform() - 1.0;
        const double phi = 2.0 * std::numbers::pi * uniform();
        const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
        return {s * std::cos(phi), s * std::sin(phi), z};
    }

private:
    static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
    std::uint64_t s_[4]{};
};

// Box–Muller: two independent standard normals from two uniforms.
inline void box_muller(double u1, double u2, double& n1, double& n2) {
    const double r = std::sqrt(-2.0 * std::log(u1));
    const double a = 2.0 * std::numbers::pi * u2;
    n1 = r * std::cos(a);
    n2 = r * std::sin(a);
}

struct Wave {
    Vec3d k;  // wave vector (rad/mm)
    double phase;
    double coeff;
};

// Sum of plane waves at q and its gradient.
inline double waves_at(const std::vector<Wave>& waves, Vec3d q, Vec3d* grad) {
    double v = 0.0;
    Vec3d g{0, 0, 0};
    for (const Wave& w : waves) {
        const double arg = dot(w.k, q) + w.phase;
        v += w.coeff * std::cos(arg);
        if (grad) g -= w.k * (w.coeff * std::sin(arg));
    }
    if (grad) *grad = g;
    return v;
}

inline double ramp(double s, double h) { return std::clamp(0.5 - s / h, 0.0, 1.0); }  // fraction inside (s < 0)

inline Vec3d divide(Vec3d a, Vec3d b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }

// The geometry and bias model derived from the options (see the header for the formulas).
struct Model {
    double h = 1.0;            // spacing (mm)
    double half_fov = 0.0;     // L
    double csf = 0.0;          // c
    double t_min = 0.0, t_max = 0.0;
    double crest = 0.0;        // R: pial crest radius (in |x / a| units)
    double amplitude = 0.0;    // A
    double r0 = 0.0;           // R0
    double fold_wavelength = 0.0;
    double bias = 0.0;
    std::vector<Wave> folds, thickness;
    // Bias bumps: [0] a broad superior gradient, [1] and [2] the local peaks (weak spots).
    static constexpr int kBumps = 3;
    Vec3d bump_centre[kBumps];
    Vec3d bump_axis[kBumps];                  // unit vector from the origin to the centre
    double bump_sigma[kBumps] = {0, 0, 0};         // across the axis
    double bump_radial_sigma[kBumps] = {0, 0, 0};  // along the axis
    double bump_weight[kBumps] = {kBroadBumpWeight, 1.0, kSecondBumpWeight};

    explicit Model(const PhantomOptions& o) {
        h = o.spacing_mm;
        half_fov = 0.5 * o.size * h;
        csf = std::max(o.csf_thickness_mm, kMinCsfVoxels * h);
        t_min = std::max(o.gm_thickness_min_mm, kMinGmVoxels * h);
        t_max = std::max(o.gm_thickness_max_mm, t_min);
        crest = kSkullFraction * half_fov - csf;
        amplitude = kFoldAmplitude * crest * o.fold_depth;
        r0 = crest - t_max - amplitude;
        bias = o.bias;

        Xoshiro256 rng(o.anatomy_seed);
        // Gyrus + sulcus period: a WM core, two GM banks and a thin CSF slit, at least.
        fold_wavelength = std::max(kFoldWavelength * crest, t_min + t_max + 4.5 * h);
        const double k_fold = 2.0 * std::numbers::pi / fold_wavelength;
        for (int j = 0; j < kFoldWaves; ++j) {
            const Vec3d dir = rng.direction();
            const double k = k_fold * (0.85 + 0.3 * rng.uniform());
            folds.push_back({dir * k, 2.0 * std::numbers::pi * rng.uniform(), std::sqrt(2.0 / kFoldWaves)});
        }
        const double k_thick = 2.0 * std::numbers::pi / (kThicknessWavelength * crest);
        for (int j = 0; j < kThicknessWaves; ++j) {
            const Vec3d dir = rng.direction();
            thickness.push_back({dir * k_thick, 2.0 * std::numbers::pi * rng.uniform(),
                                 std::sqrt(2.0 / kThicknessWaves)});
        }
        // Bias bumps: a broad one on the superior pole of the skull, and two local peaks at the
        // pial crest level, superior-posterior and left-anterior-superior.
        const Vec3d u1 = Vec3d{0.0, 0.3, 1.0} / norm(Vec3d{0.0, 0.3, 1.0});
        const Vec3d u2 = Vec3d{0.7, -0.4, 0.7} / norm(Vec3d{0.7, -0.4, 0.7});
        // The local peaks sit half a GM thickness below the crest; they are narrow across the
        // surface (small holes) but long along the radius (3 t_max), so that they brighten the
        // whole thickness of the shell.
        bump_centre[0] = Vec3d{0.0, 0.0, kAspect.z * (crest + csf)};
        bump_centre[1] = hadamard(kAspect, u1) * (crest - 0.5 * t_max);
        bump_centre[2] = hadamard(kAspect, u2) * (crest - 0.5 * t_max);
        for (int k = 0; k < kBumps; ++k) bump_axis[k] = bump_centre[k] / norm(bump_centre[k]);
        bump_sigma[0] = bump_radial_sigma[0] = kBroadBumpSigma * half_fov;
        bump_sigma[1] = std::max(kFirstBumpSigma * half_fov, t_max);
        bump_sigma[2] = std::max(kSecondBumpSigma * half_fov, t_max);
        bump_radial_sigma[1] = bump_radial_sigma[2] = 3.0 * t_max;
    }

    // F = 0 is the WM surface (F < 0 inside); F is known to be negative below the radius
    // r0 - amplitude and positive above r0 + amplitude (in |x / a| units).
    double wm_function(Vec3d x, Vec3d* grad) const {
        const double r = norm(x);
        const Vec3d u = r > 1e-12 ? x / r : Vec3d{0, 0, 1};
        Vec3d gq;
        const double n = waves_at(folds, u * crest, &gq);
        const double th = std::tanh((n - kFoldLevel) / kFoldSharpness);
        const Vec3d y = divide(x, kAspect);
        const double rho = norm(y);
        if (grad) {
            const double dg_dn = amplitude / kFoldSharpness * (1.0 - th * th);
            // grad_x n(crest x / |x|) = crest / |x| (I - u u^T) grad_q n
            const Vec3d tangential = (gq - u * dot(u, gq)) * (r > 1e-12 ? crest / r : 0.0);
            const Vec3d grad_rho = rho > 1e-12 ? divide(y, kAspect) / rho : Vec3d{0, 0, 0};
            *grad = grad_rho - tangential * dg_dn;
        }
        return rho - r0 - amplitude * th;
    }

    // A point of the WM surface near x (x within a voxel or two of it): two Newton steps along
    // grad F (quadratic convergence: ample at a voxel's distance).
    Vec3d foot(Vec3d x) const {
        Vec3d p = x;
        for (int it = 0; it < 2; ++it) {
            Vec3d g;
            const double f = wm_function(p, &g);
            const double gg = dot(g, g);
            if (gg < 1e-12) break;
            Vec3d step = g * (f / gg);
            const double len = norm(step);
            if (len > 1.5 * h) step *= 1.5 * h / len;
            p -= step;
        }
        return p;
    }

    double thickness_at(Vec3d x) const {
        const double r = norm(x);
        const Vec3d u = r > 1e-12 ? x / r : Vec3d{0, 0, 1};
        const double m = std::tanh(1.2 * waves_at(thickness, u * crest, nullptr));
        return t_min + (t_max - t_min) * (0.5 + 0.5 * m);
    }

    // Signed distance (approximate, mm) to the skull ellipsoid with semi-axes (crest + c) * a.
    double skull(Vec3d x) const {
        const Vec3d axes = kAspect * (crest + csf);
        const Vec3d y = divide(x, axes);
        const double rho = norm(y);
        const Vec3d grad = divide(y, hadamard(axes, Vec3d{rho, rho, rho}));
        const double g = norm(grad);
        return g > 0 ? (rho - 1.0) / g : -(crest + csf);
    }

    double bump(int k, Vec3d x) const {
        const Vec3d d = x - bump_centre[k];
        const double along = dot(d, bump_axis[k]);
        const double across2 = std::max(0.0, dot(d, d) - along * along);
        const double e = -0.5 * (along * along / (bump_radial_sigma[k] * bump_radial_sigma[k]) +
                                 across2 / (bump_sigma[k] * bump_sigma[k]));
        return e > -60.0 ? std::exp(e) : 0.0;  // exp(-60) ~ 1e-26 vanishes next to 1 anyway
    }
    double bias_at(Vec3d x) const {
        double keep = 1.0;  // 1 - B = prod (1 - w_k G_k)
        for (int k = 0; k < kBumps; ++k) keep *= 1.0 - bump_weight[k] * bump(k, x);
        return 1.0 + bias * (1.0 - keep);
    }
};

// True when pred holds for a voxel of the 3x3x3 cube around c (c included); a voxel outside the
// lattice counts as `outside`.
template <class Pred>
bool any_in_cube(const Lattice& lattice, Vec3i c, Pred pred, bool outside) {
    for (int k = 0; k < 27; ++k) {
        const Vec3i q{c.x + k % 3 - 1, c.y + (k / 3) % 3 - 1, c.z + k / 9 - 1};
        if (!lattice.contains(q) ? outside : pred(lattice.index(q))) return true;
    }
    return false;
}

// Runs body(z) for every slice z in parallel and concatenates the per-slice outputs in z order,
// so the result does not depend on the thread count.
template <class T, class Body>
std::vector<T> collect_slices(int slices, Body body) {
    std::vector<std::vector<T>> parts(static_cast<std::size_t>(slices));
    tbb::parallel_for(tbb::blocked_range<int>(0, slices), [&](const tbb::blocked_range<int>& r) {
        for (int z = r.begin(); z != r.end(); ++z) body(z, parts[static_cast<std::size_t>(z)]);
    });
    std::vector<T> all;
    for (auto& part : parts) all.insert(all.end(), part.begin(), part.end());
    return all;
}

// Separable Gaussian blur (border replicated), in place through a scratch buffer.
inline void blur(std::vector<float>& values, Vec3i dims, double sigma) {
    if (sigma <= 0.0) return;
    const int radius = static_cast<int>(std::ceil(3.0 * sigma));
    std::vector<double> kernel(2 * radius + 1);
    double sum = 0.0;
    for (int i = -radius; i <= radius; ++i) sum += kernel[i + radius] = std::exp(-0.5 * i * i / (sigma * sigma));
    for (double& k : kernel) k /= sum;
    std::vector<float> scratch(values.size());
    const std::size_t sy = static_cast<std::size_t>(dims.x), sz = sy * static_cast<std::size_t>(dims.y);
    for (int axis = 0; axis < 3; ++axis) {
        const int n = dims[axis];
        const std::size_t stride = axis == 0 ? 1 : (axis == 1 ? sy : sz);
        tbb::parallel_for(tbb::blocked_range<int>(0, dims.z), [&](const tbb::blocked_range<int>& zr) {
            for (int z = zr.begin(); z != zr.end(); ++z)
                for (int y = 0; y < dims.y; ++y)
                    for (int x = 0; x < dims.x; ++x) {
                        const Vec3i p{x, y, z};
                        const std::size_t i = static_cast<std::size_t>(x) + sy * y + sz * z;
                        double acc = 0.0;
                        for (int k = -radius; k <= radius; ++k) {
                            const int c = std::clamp(p[axis] + k, 0, n - 1);
                            acc += kernel[k + radius] * values[i + (static_cast<std::ptrdiff_t>(c) - p[axis]) *
                                                                      static_cast<std::ptrdiff_t>(stride)];
                        }
                        scratch[i] = static_cast<float>(acc);
                    }
        });
        values.swap(scratch);
    }
}

}  // namespace liveset::phantom_detail
