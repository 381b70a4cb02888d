// Synthetic cortex MR phantom: geometry (folded WM surface, GM shell, CSF, skull ellipsoid),
// partial-volume image, blur, bias field, counter-based Rician noise, seeds and weak spots.
// Every voxel is a pure function of the options and its index, so parallel loops are bit-identical
// for any thread count. The construction runs in numbered steps (PhantomBuilder); the model they
// sample is in phantom_model.hpp.
#include "liveset/phantom/phantom.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "liveset/phantom/phantom_model.hpp"
#include "liveset/phantom/topology_growth.hpp"

namespace liveset {

using namespace phantom_detail;

namespace {

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

namespace {

constexpr double kMinAspect = 0.80;  // one mm moves |x / a| by at most 1 / kMinAspect
constexpr std::uint32_t kNone = 0xFFFFFFFFu;
constexpr Vec3i kFace[6] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};

// The phantom's construction, one method per numbered step; each step reads what the earlier ones
// left in the members.
class PhantomBuilder {
public:
    explicit PhantomBuilder(const PhantomOptions& options)
        : options_(options),
          model_(options),
          n_(options.size),
          h_(options.spacing_mm),
          o_(-0.5 * (n_ - 1) * h_),
          lattice_({n_, n_, n_}, {h_, h_, h_}, {o_, o_, o_}),
          sy_(static_cast<std::size_t>(n_)),
          sz_(sy_ * sy_),
          f_lo_(model_.r0 - model_.amplitude),
          f_hi_(model_.r0 + model_.amplitude) {}

    Phantom build() {
        classify_wm();
        find_surface_feet();
        jump_flood();
        close_pial_body();
        fill_pockets();
        grow_without_handles();
        tissue_image();
        bias_and_noise();
        find_weak_spots();
        place_seeds();
        return std::move(ph_);
    }

private:
    Vec3d position(Vec3i c) const { return {o_ + c.x * h_, o_ + c.y * h_, o_ + c.z * h_}; }
    static double radius(Vec3d p) { return norm(divide(p, kAspect)); }  // |x / a|
    double dist2(Vec3d p, std::uint32_t s) const {
        const Vec3d d = p - feet_[s];
        return dot(d, d);
    }
    // Signed distance d to the WM surface and GM thickness t at a voxel (d = ±"far" beyond the band).
    double wm_distance(PointIndex i, Vec3d p, double& t) const {
        t = model_.t_max;
        if (owner_[i] == kNone) return inside_[i] ? -1e9 : 1e9;
        t = feet_thickness_[owner_[i]];
        return (inside_[i] ? -1.0 : 1.0) * std::sqrt(dist2(p, owner_[i]));
    }
    // body(z) for every slice z, in parallel.
    template <class Body>
    void for_slices(Body body) const {
        tbb::parallel_for(tbb::blocked_range<int>(0, n_), [&](const tbb::blocked_range<int>& zr) {
            for (int z = zr.begin(); z != zr.end(); ++z)
                for (int y = 0; y < n_; ++y)
                    for (int x = 0; x < n_; ++x) body(Vec3i{x, y, z});
        });
    }

    void classify_wm();
    void find_surface_feet();
    void jump_flood();
    void close_pial_body();
    void fill_pockets();
    void grow_without_handles();
    void tissue_image();
    void bias_and_noise();
    void find_weak_spots();
    void place_seeds();

    const PhantomOptions& options_;
    const Model model_;
    const int n_;
    const double h_, o_;
    const Lattice lattice_;
    const std::size_t sy_, sz_;
    const double f_lo_, f_hi_;  // F's sign is known below f_lo (inside) and above f_hi (outside)
    std::vector<std::uint8_t> inside_;           // 1: the voxel centre lies inside the WM surface
    std::vector<PointIndex> seeds_;              // voxels with a 6-neighbour on the other side
    std::vector<Vec3d> feet_;                    // each seed's foot point on the surface
    std::vector<double> feet_thickness_;         // the GM thickness there
    std::vector<std::uint32_t> owner_;           // nearest foot point of each band voxel (kNone: far)
    std::vector<std::uint8_t> closed_, filled_;  // the radially closed pial body, what closing added
    std::vector<std::uint8_t> pial_body_, wm_;   // the handle-free pial body and WM
    std::vector<float> clean_;                   // the noise-free, bias-free partial-volume image
    Grid<float> depth_;                          // min(d, t - d) in voxels inside GM, -1 elsewhere
    Phantom ph_;
};

// 1. The side of the WM surface F = 0 each voxel centre lies on (F is only evaluated where the sign
//    is not known from the radius).
void PhantomBuilder::classify_wm() {
    inside_.assign(lattice_.size(), 0);
    for_slices([&](Vec3i c) {
        const Vec3d p = position(c);
        const double r = radius(p);
        inside_[lattice_.index(c)] = r <= f_lo_ || (r < f_hi_ && model_.wm_function(p, nullptr) < 0.0);
    });
}

// 2. Seeds of the distance transform: voxels with a 6-neighbour on the other side, each with its
//    own foot point on the surface.
void PhantomBuilder::find_surface_feet() {
    seeds_ = collect_slices<PointIndex>(n_, [&](int z, std::vector<PointIndex>& out) {
        for (int y = 0; y < n_; ++y)
            for (int x = 0; x < n_; ++x) {
                const double r = radius(position({x, y, z}));
                if (r < f_lo_ - 2.0 * h_ / kMinAspect || r > f_hi_ + 2.0 * h_ / kMinAspect) continue;
                const PointIndex i = lattice_.index({x, y, z});
                for (const Vec3i& e : kFace) {
                    const Vec3i q{x + e.x, y + e.y, z + e.z};
                    if (lattice_.contains(q) && inside_[lattice_.index(q)] != inside_[i]) {
                        out.push_back(i);
                        break;
                    }
                }
            }
    });
    feet_.resize(seeds_.size());
    feet_thickness_.resize(seeds_.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, seeds_.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t s = r.begin(); s != r.end(); ++s) {
            feet_[s] = model_.foot(position(lattice_.coord(seeds_[s])));
            feet_thickness_[s] = model_.thickness_at(feet_[s]);
        }
    });
}

// 3. Jump flooding over the voxels outside the WM within `reach` of the surface: each pass gives
//    every voxel the nearest foot point among those of its neighbours at offsets in {-k, 0, k}^3,
//    with balanced-ternary steps k = ..., 9, 3, 1 and a final extra pass of 1. Each pass reads only
//    the previous one and ties go to the lower seed number, so the result is thread-independent.
//    (WM voxels that are not seeds lie over half a voxel deep: they need only their sign.)
void PhantomBuilder::jump_flood() {
    const double reach = model_.t_max + model_.csf + 2.0 * h_;
    const std::vector<PointIndex> band = collect_slices<PointIndex>(n_, [&](int z, std::vector<PointIndex>& out) {
        for (int y = 0; y < n_; ++y)
            for (int x = 0; x < n_; ++x) {
                const PointIndex i = lattice_.index({x, y, z});
                if (inside_[i]) continue;
                const double r = radius(position({x, y, z}));
                if (r >= f_lo_ && r <= f_hi_ + (reach + h_) / kMinAspect) out.push_back(i);
            }
    });
    owner_.assign(lattice_.size(), kNone);
    for (std::size_t s = 0; s < seeds_.size(); ++s) owner_[seeds_[s]] = static_cast<std::uint32_t>(s);
    std::vector<std::uint32_t> next = owner_;
    int step = 1;
    while ((3 * step - 1) / 2 < static_cast<int>(std::ceil(reach / h_))) step *= 3;
    std::vector<int> steps;
    for (int k = step; k >= 1; k /= 3) steps.push_back(k);
    steps.push_back(1);
    for (const int k : steps) {
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, band.size()), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t b = r.begin(); b != r.end(); ++b) {
                const PointIndex i = band[b];
                const Vec3i c = lattice_.coord(i);
                const Vec3d p = position(c);
                std::uint32_t best = owner_[i], last = best;
                double best_d = best == kNone ? 0.0 : dist2(p, best);
                const bool interior = c.x >= k && c.y >= k && c.z >= k && c.x < n_ - k && c.y < n_ - k && c.z < n_ - k;
                for (int dz = -k; dz <= k; dz += k)
                    for (int dy = -k; dy <= k; dy += k)
                        for (int dx = -k; dx <= k; dx += k) {
                            if (!interior && !lattice_.contains(Vec3i{c.x + dx, c.y + dy, c.z + dz})) continue;
                            const std::uint32_t s = owner_[i + static_cast<std::ptrdiff_t>(dx) +
                                                           static_cast<std::ptrdiff_t>(dy) * static_cast<std::ptrdiff_t>(sy_) +
                                                           static_cast<std::ptrdiff_t>(dz) * static_cast<std::ptrdiff_t>(sz_)];
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
        owner_.swap(next);
    }
}

// 4. Radial closure of the pial body {d < t}: where two GM banks meet across a narrow sulcus they
//    would enclose CSF pockets and form bridges (cavities and handles of the GM truth, so `holes`
//    would count the anatomy instead of the segmentation's perforations). A voxel outside the body
//    whose outward ray from the centre meets the body again lies under such a bridge: it becomes
//    GM. The WM is star-shaped (its radius is a function of direction), so the closed body is too,
//    and the GM truth is one closed shell around the WM (euler 4).
void PhantomBuilder::close_pial_body() {
    closed_.assign(lattice_.size(), 0);
    filled_.assign(lattice_.size(), 0);
    for_slices([&](Vec3i c) {
        const PointIndex i = lattice_.index(c);
        double t;
        closed_[i] = inside_[i] || wm_distance(i, position(c), t) < t;
    });
    const double body_top = f_hi_ + (model_.t_max + 2.0 * h_) / kMinAspect;  // no body voxel lies beyond
    // Passes until nothing changes; each reads the closed body of the previous pass only (Jacobi,
    // thread-independent), so pockets under freshly filled voxels are caught by the next pass.
    for (int pass = 0; pass < 16; ++pass) {
        std::vector<std::uint8_t> hits(lattice_.size(), 0);
        for_slices([&](Vec3i v) {
            const PointIndex i = lattice_.index(v);
            const Vec3d p = position(v);
            if (closed_[i] || radius(p) > body_top) return;
            const Vec3d u = p / norm(p);
            for (double s = 0.5 * h_;; s += 0.5 * h_) {
                const Vec3d q = p + u * s;
                if (radius(q) > body_top) break;
                const Vec3i c{static_cast<int>(std::floor((q.x - o_) / h_)), static_cast<int>(std::floor((q.y - o_) / h_)),
                              static_cast<int>(std::floor((q.z - o_) / h_))};
                if (!lattice_.contains(c) || !lattice_.contains(c + Vec3i{1, 1, 1})) break;
                bool hit = false;
                for (int k = 0; k < 8 && !hit; ++k) hit = closed_[lattice_.index(c + Vec3i{k & 1, (k >> 1) & 1, k >> 2})];
                if (hit) {
                    hits[i] = 1;
                    break;
                }
            }
        });
        std::size_t added = 0;
        for (std::size_t i = 0; i < lattice_.size(); ++i)
            if (hits[i]) {
                closed_[i] = filled_[i] = 1;
                ++added;
            }
        if (added == 0) break;
    }
}

// Pockets the rays missed (enclosed by filled voxels): everything outside the closed body not
// 6-connected to the lattice border joins it as GM (breadth-first flood from the border).
void PhantomBuilder::fill_pockets() {
    const int n = n_;
    std::vector<std::uint8_t> open(lattice_.size(), 0);
    std::vector<PointIndex> queue;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                if (x != 0 && y != 0 && z != 0 && x != n - 1 && y != n - 1 && z != n - 1) continue;
                const PointIndex i = lattice_.index({x, y, z});
                if (!closed_[i]) {
                    open[i] = 1;
                    queue.push_back(i);
                }
            }
    for (std::size_t head = 0; head < queue.size(); ++head) {
        const Vec3i c = lattice_.coord(queue[head]);
        for (const Vec3i& e : kFace) {
            const Vec3i q = c + e;
            if (!lattice_.contains(q)) continue;
            const PointIndex j = lattice_.index(q);
            if (open[j] || closed_[j]) continue;
            open[j] = 1;
            queue.push_back(j);
        }
    }
    for (std::size_t i = 0; i < lattice_.size(); ++i)
        if (!open[i] && !closed_[i]) closed_[i] = filled_[i] = 1;
}

// Voxel sampling of thin blades and of banks that meet can still leave handles: grow the pial body
// from the centre voxel within the closed body, then the WM from the centre within its voxels whose
// 26 neighbours all lie in the grown body, adding only simple points (closest to the centre first).
// Both are then digital balls and the WM never touches the CSF, so the GM between them is one shell.
// The few voxels refused take the label (and a crisp intensity) of the tissue outside: WM -> GM,
// GM -> CSF.
void PhantomBuilder::grow_without_handles() {
    const auto centre_distance = [&](Vec3i c) { return radius(position(c)); };
    const PointIndex centre = lattice_.index({n_ / 2, n_ / 2, n_ / 2});
    pial_body_.assign(lattice_.size(), 0);
    wm_.assign(lattice_.size(), 0);
    std::vector<std::uint8_t> wm_allowed(lattice_.size(), 0);
    pial_body_[centre] = 1;
    grow_preserving_topology(lattice_, pial_body_, closed_, centre_distance);
    for_slices([&](Vec3i c) {
        const PointIndex i = lattice_.index(c);
        wm_allowed[i] = inside_[i] && !any_in_cube(lattice_, c, [&](PointIndex j) { return !pial_body_[j]; }, true);
    });
    wm_[centre] = 1;
    grow_preserving_topology(lattice_, wm_, wm_allowed, centre_distance, 6);
}

// 5. Labels and the noise-free partial-volume image from the signed distance d to the WM surface,
//    the local GM thickness t and the skull ellipsoid (filled voxels: pure GM).
void PhantomBuilder::tissue_image() {
    ph_.wm_intensity = kWmValue;
    ph_.gm_intensity = kGmValue;
    ph_.csf_intensity = kCsfValue;
    ph_.background_intensity = kBgValue;
    ph_.labels = Grid<std::uint8_t>(lattice_, kBackground);
    ph_.bias_field = Grid<float>(lattice_, 1.0f);
    clean_.assign(lattice_.size(), kBgValue);
    depth_ = Grid<float>(lattice_, -1.0f);
    const double h = h_;
    for_slices([&](Vec3i c) {
        const PointIndex i = lattice_.index(c);
        const Vec3d p = position(c);
        ph_.bias_field[i] = static_cast<float>(model_.bias_at(p));
        double t;
        double d = wm_distance(i, p, t);
        double pial = filled_[i] ? -h : d - t;
        if (inside_[i] && !wm_[i]) d = h, pial = -h;  // refused WM: pure GM
        if (!pial_body_[i] && pial < 0) pial = h;      // refused GM: pure CSF
        // Next to a filled or refused voxel the pial surface d = t is no longer the GM/CSF border:
        // crisp there, so no voxel keeps a CSF fraction inside the GM.
        const bool changed_nearby =
            any_in_cube(lattice_, c, [&](PointIndex j) { return filled_[j] || (closed_[j] && !pial_body_[j]); }, false);
        if (changed_nearby) pial = pial_body_[i] ? -h : std::max(pial, h);
        const double outside = std::min(pial - model_.csf, model_.skull(p));
        const double f_wm = ramp(d, h), f_in_pial = ramp(pial, h), f_in_csf = ramp(outside, h);
        clean_[i] = static_cast<float>(kWmValue * f_wm + kGmValue * (f_in_pial - f_wm) + kCsfValue * (f_in_csf - f_in_pial) +
                                       kBgValue * (1.0 - f_in_csf));
        std::uint8_t label = kBackground;
        if (wm_[i]) {
            label = kWhiteMatter;
        } else if (pial_body_[i]) {
            label = kGreyMatter;
            depth_[i] = filled_[i] ? 0.0f : static_cast<float>(std::min(d, -pial) / h);
        } else if (outside < 0) {
            label = kCsf;
        }
        ph_.labels[i] = label;
    });
    blur(clean_, lattice_.dims(), options_.blur);
}

// 6. Bias and noise: each voxel's normals come from a hash of (seed, voxel index).
void PhantomBuilder::bias_and_noise() {
    ph_.image = Grid<float>(lattice_, 0.0f);
    ph_.truth = Grid<std::uint8_t>(lattice_, 0);
    const double sigma = options_.noise * kWmValue;
    const std::uint64_t key = mix64(options_.seed ^ 0x5EEDF00Dull);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lattice_.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const auto pi = static_cast<PointIndex>(i);
            const double signal = static_cast<double>(ph_.bias_field[pi]) * clean_[i];
            double n1, n2;
            box_muller(unit_open_closed(mix64(key + 2 * i)), unit_closed_open(mix64(key + 2 * i + 1)), n1, n2);
            const double re = signal + sigma * n1;
            const double im = sigma * n2;
            ph_.image[pi] = static_cast<float>(options_.rician ? std::sqrt(re * re + im * im) : re);
            ph_.truth[pi] = ph_.labels[pi] == kGreyMatter ? 1 : 0;
        }
    });
}

// 7. Weak spots: for each local bias bump, the GM voxel where that bump is strongest, preferring
//    voxels at least a voxel from the other tissues (pure GM, no partial volume).
void PhantomBuilder::find_weak_spots() {
    for (int k = 1; k < Model::kBumps; ++k) {
        double best = -1.0;
        Vec3i best_p{-1, -1, -1};
        for (std::size_t i = 0; i < lattice_.size(); ++i) {
            const float dep = depth_[static_cast<PointIndex>(i)];
            if (dep < 0) continue;
            const Vec3i c = lattice_.coord(static_cast<PointIndex>(i));
            const double g = model_.bump(k, position(c)) + (dep >= 1.0f ? 1.0 : 0.0);
            if (g > best) {
                best = g;
                best_p = c;
            }
        }
        if (best_p.x >= 0) ph_.weak_spots.push_back(best_p);
    }
}

// 8. Seeds: in a cone around each of five directions away from the bias peaks, the best GM voxel
//    with the image inside the window, preferring in turn low bias (b <= 1 + bias / 4), all 26
//    neighbours GM, all 6 neighbours GM, and depth.
void PhantomBuilder::place_seeds() {
    const IntensityWindow window = gm_window(ph_);
    const Vec3d directions[5] = {{0, 0, -1}, {1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}};
    double best[5] = {-1, -1, -1, -1, -1};
    Vec3i best_p[5];
    const auto gm_neighbours = [&](Vec3i c, bool all26) {
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    if (!all26 && std::abs(dx) + std::abs(dy) + std::abs(dz) != 1) continue;
                    if (ph_.labels({c.x + dx, c.y + dy, c.z + dz}) != kGreyMatter) return false;
                }
        return true;
    };
    for (int z = 1; z < n_ - 1; ++z)
        for (int y = 1; y < n_ - 1; ++y)
            for (int x = 1; x < n_ - 1; ++x) {
                const Vec3i c{x, y, z};
                const PointIndex i = lattice_.index(c);
                const double dep = depth_[i];
                if (dep < 0 || !window.contains(ph_.image[i])) continue;
                const Vec3d p = position(c);
                const Vec3d u = p / norm(p);
                int dir = -1;
                for (int k = 0; k < 5 && dir < 0; ++k)
                    if (dot(u, directions[k]) >= 0.75) dir = k;
                if (dir < 0) continue;
                const bool low_bias = ph_.bias_field[i] <= 1.0 + 0.25 * options_.bias + 1e-6;
                const double score = dep + (low_bias ? 400.0 : 0.0) +
                                     (gm_neighbours(c, true) ? 200.0 : (gm_neighbours(c, false) ? 100.0 : 0.0));
                if (score > best[dir]) {
                    best[dir] = score;
                    best_p[dir] = c;
                }
            }
    for (int k = 0; k < 5; ++k)
        if (best[k] >= 0) ph_.seeds.push_back(best_p[k]);
    if (ph_.seeds.size() < 3) throw std::runtime_error("phantom: could not place three seeds in the grey matter");
}

}  // namespace

Phantom make_phantom(const PhantomOptions& options) {
    validate(options);
    return PhantomBuilder(options).build();
}

}  // namespace liveset
