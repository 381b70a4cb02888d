// Synthetic cortex MR phantom: geometry (folded WM surface, GM shell, CSF, skull ellipsoid),
// partial-volume image, blur, bias field, counter-based Rician noise, seeds and weak spots.
// Every voxel is a pure function of the options and its index, so parallel loops are bit-identical
// for any thread count.
#include "liveset/phantom/phantom.hpp"
#include "liveset/phantom/topology_growth.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace liveset {

namespace {

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
std::uint64_t mix64(std::uint64_t z) {
    z += kGolden;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

double unit_open_closed(std::uint64_t h) { return static_cast<double>((h >> 11) + 1) * 0x1.0p-53; }  // (0, 1]
double unit_closed_open(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }        // [0, 1)

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
void box_muller(double u1, double u2, double& n1, double& n2) {
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
double waves_at(const std::vector<Wave>& waves, Vec3d q, Vec3d* grad) {
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

double ramp(double s, double h) { return std::clamp(0.5 - s / h, 0.0, 1.0); }  // fraction inside (s < 0)

Vec3d divide(Vec3d a, Vec3d b) { return {a.x / b.x, a.y / b.y, a.z / b.z}; }

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
void blur(std::vector<float>& values, Vec3i dims, double sigma) {
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

template <class T>
void check_range(const char* name, T value, T lo, T hi) {
    if (value >= lo && value <= hi) return;  // NaN fails both
    std::ostringstream msg;
    msg << "phantom: " << name << " must be in [" << lo << ", " << hi << "], got " << value;
    throw std::invalid_argument(msg.str());
}

}  // namespace

void validate(const PhantomOptions& o) {
    check_range("size", o.size, 32, 512);
    if (!(o.spacing_mm > 0.0)) throw std::invalid_argument("phantom: spacing_mm must be positive and finite");
    check_range("spacing_mm", o.spacing_mm, 0.0, 10.0);
    check_range("noise", o.noise, 0.0, 0.5);
    check_range("bias", o.bias, 0.0, 1.0);
    check_range("fold_depth", o.fold_depth, 0.0, 1.5);
    if (!(o.gm_thickness_min_mm > 0.0)) throw std::invalid_argument("phantom: gm_thickness_min_mm must be positive and finite");
    check_range("gm_thickness_min_mm", o.gm_thickness_min_mm, 0.0, 10.0);
    check_range("gm_thickness_max_mm", o.gm_thickness_max_mm, o.gm_thickness_min_mm, 10.0);
    check_range("csf_thickness_mm", o.csf_thickness_mm, 0.0, 10.0);
    check_range("blur", o.blur, 0.0, 2.0);
    const Model m(o);
    if (!(m.r0 - m.amplitude >= 0.25 * m.crest))
        throw std::invalid_argument("phantom: field of view too small for the GM and CSF thickness");
}

IntensityWindow gm_window(const Phantom& p) {
    return {p.gm_intensity - 0.5f * (p.gm_intensity - p.csf_intensity),
            p.gm_intensity + 0.5f * (p.wm_intensity - p.gm_intensity)};
}

Phantom make_phantom(const PhantomOptions& options) {
    validate(options);
    const Model model(options);
    const int n = options.size;
    const double h = options.spacing_mm;
    const double o = -0.5 * (n - 1) * h;
    const Lattice lattice({n, n, n}, {h, h, h}, {o, o, o});
    const std::size_t sy = static_cast<std::size_t>(n), sz = sy * sy;

    const auto position = [&](Vec3i c) { return Vec3d{o + c.x * h, o + c.y * h, o + c.z * h}; };
    const auto radius = [&](Vec3d p) { return norm(divide(p, kAspect)); };  // |x / a|
    constexpr double kMinAspect = 0.80;  // one mm moves |x / a| by at most 1 / kMinAspect
    constexpr std::uint32_t kNone = 0xFFFFFFFFu;

    // 1. The side of the WM surface F = 0 each voxel centre lies on (F is only evaluated where
    //    the sign is not known from the radius).
    const double f_lo = model.r0 - model.amplitude, f_hi = model.r0 + model.amplitude;
    std::vector<std::uint8_t> inside(lattice.size(), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& zr) {
        for (int z = zr.begin(); z != zr.end(); ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const Vec3d p = position({x, y, z});
                    const double r = radius(p);
                    inside[x + sy * y + sz * z] = r <= f_lo || (r < f_hi && model.wm_function(p, nullptr) < 0.0);
                }
    });

    // 2. Seeds of the distance transform: voxels with a 6-neighbour on the other side, each with
    //    its own foot point on the surface.
    const Vec3i face[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    const std::vector<PointIndex> seeds = collect_slices<PointIndex>(n, [&](int z, std::vector<PointIndex>& out) {
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const double r = radius(position({x, y, z}));
                if (r < f_lo - 2.0 * h / kMinAspect || r > f_hi + 2.0 * h / kMinAspect) continue;
                const PointIndex i = lattice.index({x, y, z});
                for (const Vec3i& e : face) {
                    const Vec3i q{x + e.x, y + e.y, z + e.z};
                    if (lattice.contains(q) && inside[lattice.index(q)] != inside[i]) {
                        out.push_back(i);
                        break;
                    }
                }
            }
    });
    std::vector<Vec3d> feet(seeds.size());
    std::vector<double> feet_thickness(seeds.size());  // GM thickness at each foot point
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, seeds.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t s = r.begin(); s != r.end(); ++s) {
            feet[s] = model.foot(position(lattice.coord(seeds[s])));
            feet_thickness[s] = model.thickness_at(feet[s]);
        }
    });

    // 3. Jump flooding over the voxels outside the WM within `reach` of the surface: each pass
    //    gives every voxel the nearest foot point among those of its neighbours at offsets in
    //    {-k, 0, k}^3, with balanced-ternary steps k = ..., 9, 3, 1 and a final extra pass of 1.
    //    Each pass reads only the previous one and ties go to the lower seed number, so the result
    //    is thread-independent. (WM voxels that are not seeds lie over half a voxel deep: they need
    //    only their sign.)
    const double reach = model.t_max + model.csf + 2.0 * h;
    const std::vector<PointIndex> band = collect_slices<PointIndex>(n, [&](int z, std::vector<PointIndex>& out) {
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const PointIndex i = lattice.index({x, y, z});
                if (inside[i]) continue;
                const double r = radius(position({x, y, z}));
                if (r >= f_lo && r <= f_hi + (reach + h) / kMinAspect) out.push_back(i);
            }
    });
    std::vector<std::uint32_t> owner(lattice.size(), kNone);
    for (std::size_t s = 0; s < seeds.size(); ++s) owner[seeds[s]] = static_cast<std::uint32_t>(s);
    std::vector<std::uint32_t> next = owner;
    const auto dist2 = [&](Vec3d p, std::uint32_t s) {
        const Vec3d d = p - feet[s];
        return dot(d, d);
    };
    int step = 1;
    while ((3 * step - 1) / 2 < static_cast<int>(std::ceil(reach / h))) step *= 3;
    std::vector<int> steps;
    for (int k = step; k >= 1; k /= 3) steps.push_back(k);
    steps.push_back(1);
    for (const int k : steps) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, band.size()), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t b = r.begin(); b != r.end(); ++b) {
                const PointIndex i = band[b];
                const Vec3i c = lattice.coord(i);
                const Vec3d p = position(c);
                std::uint32_t best = owner[i], last = best;
                double best_d = best == kNone ? 0.0 : dist2(p, best);
                const bool interior = c.x >= k && c.y >= k && c.z >= k && c.x < n - k && c.y < n - k && c.z < n - k;
                for (int dz = -k; dz <= k; dz += k)
                    for (int dy = -k; dy <= k; dy += k)
                        for (int dx = -k; dx <= k; dx += k) {
                            if (!interior && !lattice.contains(Vec3i{c.x + dx, c.y + dy, c.z + dz})) continue;
                            const std::uint32_t s = owner[i + static_cast<std::ptrdiff_t>(dx) +
                                                          static_cast<std::ptrdiff_t>(dy) * static_cast<std::ptrdiff_t>(sy) +
                                                          static_cast<std::ptrdiff_t>(dz) * static_cast<std::ptrdiff_t>(sz)];
                            if (s == kNone || s == last) continue;  // neighbours often share an owner
                            last = s;
                            const double d = dist2(p, s);
                            if (best == kNone || d < best_d || (d == best_d && s < best)) {
                                best = s;
                                best_d = d;
                            }
                        }
                next[i] = best;
            }
        });
        owner.swap(next);
    }

    // Signed distance d to the WM surface and GM thickness t at a voxel (d = ±"far" beyond the band).
    const auto wm_distance = [&](PointIndex i, Vec3d p, double& t) {
        t = model.t_max;
        if (owner[i] == kNone) return inside[i] ? -1e9 : 1e9;
        t = feet_thickness[owner[i]];
        return (inside[i] ? -1.0 : 1.0) * std::sqrt(dist2(p, owner[i]));
    };

    // 4. Radial closure of the pial body {d < t}: where two GM banks meet across a narrow sulcus
    //    they would enclose CSF pockets and form bridges (cavities and handles of the GM truth, so
    //    `holes` would count the anatomy instead of the segmentation's perforations). A voxel
    //    outside the body whose outward ray from the centre meets the body again lies under such a
    //    bridge: it becomes GM. The WM is star-shaped (its radius is a function of direction), so
    //    the closed body is too, and the GM truth is one closed shell around the WM (euler 4).
    std::vector<std::uint8_t> body(lattice.size(), 0), filled(lattice.size(), 0);
    tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& zr) {
        for (int z = zr.begin(); z != zr.end(); ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const PointIndex i = lattice.index({x, y, z});
                    double t;
                    body[i] = inside[i] || wm_distance(i, position({x, y, z}), t) < t;
                }
    });
    const double body_top = f_hi + (model.t_max + 2.0 * h) / kMinAspect;  // no body voxel lies beyond
    // Passes until nothing changes; each reads the closed body of the previous pass only (Jacobi,
    // thread-independent), so pockets under freshly filled voxels are caught by the next pass.
    std::vector<std::uint8_t> closed = body;
    for (int pass = 0; pass < 16; ++pass) {
        std::vector<std::uint8_t> hits(lattice.size(), 0);
        tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& zr) {
            for (int z = zr.begin(); z != zr.end(); ++z)
                for (int y = 0; y < n; ++y)
                    for (int x = 0; x < n; ++x) {
                        const PointIndex i = lattice.index({x, y, z});
                        const Vec3d p = position({x, y, z});
                        if (closed[i] || radius(p) > body_top) continue;
                        const Vec3d u = p / norm(p);
                        for (double s = 0.5 * h;; s += 0.5 * h) {
                            const Vec3d q = p + u * s;
                            if (radius(q) > body_top) break;
                            const Vec3i c{static_cast<int>(std::floor((q.x - o) / h)), static_cast<int>(std::floor((q.y - o) / h)),
                                          static_cast<int>(std::floor((q.z - o) / h))};
                            if (!lattice.contains(c) || !lattice.contains(c + Vec3i{1, 1, 1})) break;
                            bool hit = false;
                            for (int k = 0; k < 8 && !hit; ++k) hit = closed[lattice.index(c + Vec3i{k & 1, (k >> 1) & 1, k >> 2})];
                            if (hit) {
                                hits[i] = 1;
                                break;
                            }
                        }
                    }
        });
        std::size_t added = 0;
        for (std::size_t i = 0; i < lattice.size(); ++i)
            if (hits[i]) {
                closed[i] = filled[i] = 1;
                ++added;
            }
        if (added == 0) break;
    }

    // Pockets the rays missed (enclosed by filled voxels): everything outside the closed body not
    // 6-connected to the lattice border joins it as GM (breadth-first flood from the border).
    {
        std::vector<std::uint8_t> open(lattice.size(), 0);
        std::vector<PointIndex> queue;
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    if (x != 0 && y != 0 && z != 0 && x != n - 1 && y != n - 1 && z != n - 1) continue;
                    const PointIndex i = lattice.index({x, y, z});
                    if (!closed[i]) {
                        open[i] = 1;
                        queue.push_back(i);
                    }
                }
        for (std::size_t head = 0; head < queue.size(); ++head) {
            const Vec3i c = lattice.coord(queue[head]);
            for (const Vec3i& e : face) {
                const Vec3i q = c + e;
                if (!lattice.contains(q)) continue;
                const PointIndex j = lattice.index(q);
                if (open[j] || closed[j]) continue;
                open[j] = 1;
                queue.push_back(j);
            }
        }
        for (std::size_t i = 0; i < lattice.size(); ++i)
            if (!open[i] && !closed[i]) closed[i] = filled[i] = 1;
    }

    // Voxel sampling of thin blades and of banks that meet can still leave handles: grow the pial
    // body from the centre voxel within the closed body, then the WM from the centre within its
    // voxels whose 26 neighbours all lie in the grown body, adding only simple points (closest to
    // the centre first). Both are then digital balls and the WM never touches the CSF, so the GM
    // between them is one shell. The few voxels refused take the label (and a crisp intensity) of
    // the tissue outside: WM -> GM, GM -> CSF.
    const auto centre_distance = [&](Vec3i c) { return radius(position(c)); };
    const PointIndex centre = lattice.index({n / 2, n / 2, n / 2});
    std::vector<std::uint8_t> pial_body(lattice.size(), 0), wm(lattice.size(), 0), wm_allowed(lattice.size(), 0);
    pial_body[centre] = 1;
    grow_preserving_topology(lattice, pial_body, closed, centre_distance);
    tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& zr) {
        for (int z = zr.begin(); z != zr.end(); ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const PointIndex i = lattice.index({x, y, z});
                    wm_allowed[i] = inside[i] && !any_in_cube(lattice, {x, y, z}, [&](PointIndex j) { return !pial_body[j]; }, true);
                }
    });
    wm[centre] = 1;
    grow_preserving_topology(lattice, wm, wm_allowed, centre_distance, 6);

    // 5. Labels and the noise-free partial-volume image from the signed distance d to the WM
    //    surface, the local GM thickness t and the skull ellipsoid (filled voxels: pure GM).
    Phantom ph;
    ph.wm_intensity = kWmValue;
    ph.gm_intensity = kGmValue;
    ph.csf_intensity = kCsfValue;
    ph.background_intensity = kBgValue;
    ph.labels = Grid<std::uint8_t>(lattice, kBackground);
    ph.bias_field = Grid<float>(lattice, 1.0f);
    std::vector<float> clean(lattice.size(), kBgValue);
    Grid<float> depth(lattice, -1.0f);  // min(d, t - d) in voxels inside GM, -1 elsewhere
    tbb::parallel_for(tbb::blocked_range<int>(0, n), [&](const tbb::blocked_range<int>& zr) {
        for (int z = zr.begin(); z != zr.end(); ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const PointIndex i = lattice.index({x, y, z});
                    const Vec3d p = position({x, y, z});
                    ph.bias_field[i] = static_cast<float>(model.bias_at(p));
                    double t;
                    double d = wm_distance(i, p, t);
                    double pial = filled[i] ? -h : d - t;
                    if (inside[i] && !wm[i]) d = h, pial = -h;  // refused WM: pure GM
                    if (!pial_body[i] && pial < 0) pial = h;      // refused GM: pure CSF
                    // Next to a filled or refused voxel the pial surface d = t is no longer the
                    // GM/CSF border: crisp there, so no voxel keeps a CSF fraction inside the GM.
                    const bool changed_nearby = any_in_cube(lattice, {x, y, z}, [&](PointIndex j) {
                        return filled[j] || (closed[j] && !pial_body[j]);
                    }, false);
                    if (changed_nearby) pial = pial_body[i] ? -h : std::max(pial, h);
                    const double outside = std::min(pial - model.csf, model.skull(p));
                    const double f_wm = ramp(d, h), f_in_pial = ramp(pial, h), f_in_csf = ramp(outside, h);
                    clean[i] = static_cast<float>(kWmValue * f_wm + kGmValue * (f_in_pial - f_wm) +
                                                  kCsfValue * (f_in_csf - f_in_pial) + kBgValue * (1.0 - f_in_csf));
                    std::uint8_t label = kBackground;
                    if (wm[i]) {
                        label = kWhiteMatter;
                    } else if (pial_body[i]) {
                        label = kGreyMatter;
                        depth[i] = filled[i] ? 0.0f : static_cast<float>(std::min(d, -pial) / h);
                    } else if (outside < 0) {
                        label = kCsf;
                    }
                    ph.labels[i] = label;
                }
    });
    blur(clean, lattice.dims(), options.blur);

    // Bias and noise: each voxel's normals come from a hash of (seed, voxel index).
    ph.image = Grid<float>(lattice, 0.0f);
    ph.truth = Grid<std::uint8_t>(lattice, 0);
    const double sigma = options.noise * kWmValue;
    const std::uint64_t key = mix64(options.seed ^ 0x5EEDF00Dull);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lattice.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const auto pi = static_cast<PointIndex>(i);
            const double signal = static_cast<double>(ph.bias_field[pi]) * clean[i];
            double n1, n2;
            box_muller(unit_open_closed(mix64(key + 2 * i)), unit_closed_open(mix64(key + 2 * i + 1)), n1, n2);
            const double re = signal + sigma * n1;
            const double im = sigma * n2;
            ph.image[pi] = static_cast<float>(options.rician ? std::sqrt(re * re + im * im) : re);
            ph.truth[pi] = ph.labels[pi] == kGreyMatter ? 1 : 0;
        }
    });

    // Weak spots: for each local bias bump, the GM voxel where that bump is strongest, preferring
    // voxels at least a voxel from the other tissues (pure GM, no partial volume).
    for (int k = 1; k < Model::kBumps; ++k) {
        double best = -1.0;
        Vec3i best_p{-1, -1, -1};
        for (std::size_t i = 0; i < lattice.size(); ++i) {
            const float dep = depth[static_cast<PointIndex>(i)];
            if (dep < 0) continue;
            const Vec3i c = lattice.coord(static_cast<PointIndex>(i));
            const double g = model.bump(k, position(c)) + (dep >= 1.0f ? 1.0 : 0.0);
            if (g > best) {
                best = g;
                best_p = c;
            }
        }
        if (best_p.x >= 0) ph.weak_spots.push_back(best_p);
    }

    // Seeds: in a cone around each of five directions away from the bias peaks, the best GM voxel
    // with the image inside the window, preferring in turn low bias (b <= 1 + bias / 4), all 26
    // neighbours GM, all 6 neighbours GM, and depth.
    const IntensityWindow window = gm_window(ph);
    const Vec3d directions[5] = {{0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    double best[5] = {-1, -1, -1, -1, -1};
    Vec3i best_p[5];
    const auto gm_neighbours = [&](Vec3i c, bool all26) {
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    if (!all26 && std::abs(dx) + std::abs(dy) + std::abs(dz) != 1) continue;
                    if (ph.labels({c.x + dx, c.y + dy, c.z + dz}) != kGreyMatter) return false;
                }
        return true;
    };
    for (int z = 1; z < n - 1; ++z)
        for (int y = 1; y < n - 1; ++y)
            for (int x = 1; x < n - 1; ++x) {
                const Vec3i c{x, y, z};
                const PointIndex i = lattice.index(c);
                const double dep = depth[i];
                if (dep < 0 || !window.contains(ph.image[i])) continue;
                const Vec3d p = position(c);
                const Vec3d u = p / norm(p);
                int dir = -1;
                for (int k = 0; k < 5 && dir < 0; ++k)
                    if (dot(u, directions[k]) >= 0.75) dir = k;
                if (dir < 0) continue;
                const bool low_bias = ph.bias_field[i] <= 1.0 + 0.25 * options.bias + 1e-6;
                const double score = dep + (low_bias ? 400.0 : 0.0) +
                                     (gm_neighbours(c, true) ? 200.0 : (gm_neighbours(c, false) ? 100.0 : 0.0));
                if (score > best[dir]) {
                    best[dir] = score;
                    best_p[dir] = c;
                }
            }
    for (int k = 0; k < 5; ++k)
        if (best[k] >= 0) ph.seeds.push_back(best_p[k]);
    if (ph.seeds.size() < 3) throw std::runtime_error("phantom: could not place three seeds in the grey matter");
    return ph;
}

}  // namespace liveset
