// Agent swarm on the zero level set: Eq. 4 movement with a φ-scaled pull-back, Newton
// re-projection, and Gaussian-footprint surface edits driven by population intensity statistics.
//
// Movement (one step, every agent i computed from the previous positions only — Jacobi):
//   n   = ∇φ/|∇φ|, ∇φ = interpolated_gradient(φ, x) (central differences of the trilinear φ)
//   P   = attraction·unit(target − x) + random_walk·u_i + separation·Σ_j (1 − d_ij/R)·unit(x_i − x_j)
//         (u_i a uniform random unit vector from stream (seed, i, step); the sum over agents j with
//          0 < d_ij < R = separation_radius; coincident agents get a hashed direction)
//   T   = P − n(n·P), clamped to |T| ≤ max_step
//   B   = ε·φ(x)·n/|∇φ|, clamped to |B| ≤ max_step
//   x  ← x + T − B, clamped into the lattice box
// Why this is Eq. 4: ∇|φ| = sign(φ)∇φ, and for a signed distance |∇φ| = 1, so Eq. 4's
// P − ∇|φ|(∇|φ|·P) is exactly the tangential part T (the sign squares away), and its pull-back
// ε∇|φ| = ε·sign(φ)·n is a step of fixed length ε towards φ = 0. That fixed step overshoots
// whenever |φ| < ε, so agents chatter across the surface with amplitude ε. Scaling it by |φ|
// (ε·|φ|·sign(φ)·n = ε·φ·n, the gradient of ε·φ²/2) keeps the direction and makes it a damped
// projection: to first order φ ← (1 − ε)·φ per step, converging to the surface instead. Dividing
// by |∇φ| makes it exact for a non-unit gradient (the Newton step scaled by ε).
// Afterwards, an agent with |φ(x)| > 1 (off the zero layer, drifting towards the band's edge) is
// projected back by up to 8 Newton steps x ← x − φ·∇φ/|∇φ|² (stop at |φ| < 1e-3).
//
// Surface edits (one call = one frame):
//   population statistics: I(x_i) trilinear at every agent; the frame mean m and mean square s
//   update exponential moving averages μ ← (1−α)μ + α·m, S ← (1−α)S + α·s (first frame: μ = m,
//   S = s); σ = max(sqrt(max(S − μ², 0)), min_sigma).
//   each agent acts with probability p (stream (seed, i, frame)) — and, with edit_range > 0, only
//   within that distance of the target; it samples I_out = I(x + 1.5n),
//   I_in = I(x − 1.5n) and
//     expands  (Δ = −A) if |I_out − μ| ≤ k·σ   (the outside looks like the population: grow into it)
//     contracts(Δ = +A) else if |I_in − μ| > k'·σ (the inside does not look like it: retreat)
//   (decision kRandom, the paper's speed benchmark: an acting agent raises or lowers the surface
//   with equal probability instead, from the same stream)
//   (decision kSheet, hole repair in a sheet such as the cortex: no population statistics; an
//   acting agent expands (Δ = −A) only when both I(x + 0.75n) and I_out lie in the sheet's band
//   [sheet_lower, sheet_upper): the voxel it grows into looks like the sheet's tissue, neither the
//   enclosed tissue above the band (white matter) nor the outside below it (CSF) — or when the
//   voxel at x + 0.75n lies between the sheet's two sides (between_sheet_sides, within the brush
//   or sheet_reach, whichever is larger; sheet_between): a hole's tissue whose intensity bias, noise
//   or partial volume moved out of the band. It never
//   contracts: a repair closes holes, the segmentation's own faces stay where they are; and its
//   footprint skips the outside points whose own voxel lies outside the band unless it lies between
//   the sheet's sides and still holds at least sheet_between_share of the sheet's tissue by its
//   intensity (sheet_between_range; sheet_between_limited))
//   (decision kCut, cutting a handle the user points at: an acting agent lowers the surface,
//   Δ = +A, over the inside points of its footprint only; the repair loop's topology guard then
//   keeps only the flips that cut a handle, so no voxel leaves the segmentation but those)
//   Δ is spread over the zero-layer points p with |p − x| ≤ edit_radius, weighted by the
//   unit-peak Gaussian exp(−|p − x|²/(2σ_g²)), σ_g = edit_radius/2, so A is the change under the
//   agent whatever the zero-layer sampling density. Contributions to a point are summed in agent
//   order and clamped to ±0.5.
#include "liveset/swarm/swarm.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "liveset/grid/digital_topology.hpp"
#include "liveset/grid/radix_sort.hpp"
#include "liveset/grid/sampling.hpp"

namespace liveset {

namespace {

constexpr std::uint64_t kMoveTag = 0x6d6f7665ull;  // "move"
constexpr std::uint64_t kEditTag = 0x65646974ull;  // "edit"
constexpr std::uint64_t kPairTag = 0x70616972ull;  // "pair"

std::uint64_t splitmix64(std::uint64_t& state) {
    std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

std::uint64_t mix(std::uint64_t a, std::uint64_t b) {
    std::uint64_t s = a ^ (b * 0xd1342543de82ef95ull);
    return splitmix64(s);
}

// A small stream generator (splitmix64 sequence) keyed by (seed, agent, step, tag).
class Stream {
public:
    Stream(std::uint64_t seed, std::uint64_t agent, std::uint64_t step, std::uint64_t tag)
        : state_(mix(mix(mix(seed, tag), agent), step)) {}
    std::uint64_t next() { return splitmix64(state_); }
    double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
    Vec3d unit_vector() {
        const double z = 2.0 * uniform() - 1.0;
        const double a = 2.0 * std::numbers::pi * uniform();
        const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
        return {r * std::cos(a), r * std::sin(a), z};
    }

private:
    std::uint64_t state_;
};

Vec3d to_d(Vec3f v) { return v.cast<double>(); }

Vec3d clamp_to_box(Vec3d p, Vec3i dims) {
    return {std::clamp(p.x, 0.0, static_cast<double>(dims.x - 1)),
            std::clamp(p.y, 0.0, static_cast<double>(dims.y - 1)),
            std::clamp(p.z, 0.0, static_cast<double>(dims.z - 1))};
}

Vec3d clamp_length(Vec3d v, double max_len) {
    const double l = norm(v);
    return l > max_len && l > 0 ? v * (max_len / l) : v;
}

// Projection onto φ = 0 by safeguarded Newton steps x ← x − φ ∇φ/|∇φ|², each at most half a
// voxel long; a step that crosses the surface brackets it and bisection along that step finishes
// (plain Newton overshoots where ∇φ is small). Where ∇φ vanishes (the centre of a one-voxel bubble
// or pinch, a local extremum of φ) it first steps a tenth of a voxel along a fixed diagonal.
Vec3d project(const Grid<float>& phi, Vec3d x, int iterations) {
    constexpr double kTolerance = 1e-3;
    constexpr double kMaxStep = 0.5;  // voxels: a step cannot skip the surface
    bool nudged = false;
    for (int k = 0; k < iterations; ++k) {
        double f = trilinear(phi, x);
        if (std::abs(f) < kTolerance) break;
        Vec3d g = to_d(interpolated_gradient(phi, x));
        if (!(dot(g, g) > 1e-12) && !nudged) {
            nudged = true;
            x = clamp_to_box(x + Vec3d{1, 1, 1} * (0.1 / std::sqrt(3.0)), phi.dims());
            f = trilinear(phi, x);
            g = to_d(interpolated_gradient(phi, x));
        }
        const double g2 = dot(g, g);
        if (!(g2 > 1e-12)) break;
        const Vec3d y = clamp_to_box(x - clamp_length(g * (f / g2), kMaxStep), phi.dims());
        const double fy = trilinear(phi, y);
        if ((f < 0) == (fy < 0)) {
            x = y;
            continue;
        }
        Vec3d a = x, b = y;  // φ(a) and φ(b) have opposite signs
        for (int j = 0; j < 24; ++j) {
            const Vec3d m = (a + b) * 0.5;
            const double fm = trilinear(phi, m);
            if (std::abs(fm) < kTolerance) return m;
            ((fm < 0) == (f < 0) ? a : b) = m;
        }
        return (a + b) * 0.5;
    }
    return x;
}

}  // namespace

bool between_sheet_sides(const Grid<float>& phi, const Grid<float>& image_unit, Vec3i q, double reach, double lower, double upper) {
    const Lattice& lat = phi.lattice();
    if (!lat.contains(q) || phi(q) < 0.0f || !(reach > 0)) return false;
    // What a ray from q along v meets within reach, up to the sheet: kSheetHit when it meets the sheet,
    // kInner / kOuter when it passes enclosed tissue / the outside (or leaves the lattice) first.
    constexpr int kSheetHit = 1, kInner = 2, kOuter = 4;
    const auto ray = [&](Vec3i v) {
        const double step = norm(v.cast<double>());
        int met = 0;
        for (int k = 1; k * step <= reach; ++k) {
            const Vec3i p = q + v * k;
            if (!lat.contains(p)) return met | kOuter;
            if (phi(p) < 0.0f) return met | kSheetHit;
            const float x = image_unit(p);
            met |= x >= upper ? kInner : (x < lower ? kOuter : 0);
        }
        return met;
    };
    bool flanked = false, joins = false;
    for (const auto& d : kLineDirections) {
        const Vec3i v{d[0], d[1], d[2]};
        const int a = ray(v), b = ray(v * -1);
        flanked = flanked || ((a & kSheetHit) && (b & kSheetHit));
        joins = joins || ((a & kInner) && (b & kOuter)) || ((a & kOuter) && (b & kInner));
        if (flanked && joins) return true;
    }
    return false;
}

namespace {

bool finite_positive(double v) { return std::isfinite(v) && v > 0; }

void require(bool ok, const char* message) {
    if (!ok) throw std::invalid_argument(message);
}

}  // namespace

void validate(const SwarmOptions& o) {
    require(o.agents >= 1 && o.agents <= 1'000'000, "swarm: agents must be in [1, 1000000]");
    require(std::isfinite(o.pull_back) && o.pull_back >= 0 && o.pull_back < 1,
            "swarm: pull_back (epsilon) must be in [0, 1)");
    require(std::isfinite(o.attraction) && o.attraction >= 0, "swarm: attraction must be finite and >= 0");
    require(std::isfinite(o.random_walk) && o.random_walk >= 0, "swarm: random_walk must be finite and >= 0");
    require(std::isfinite(o.separation) && o.separation >= 0, "swarm: separation must be finite and >= 0");
    require(finite_positive(o.separation_radius), "swarm: separation_radius must be finite and > 0");
    require(finite_positive(o.max_step) && o.max_step <= 1.0, "swarm: max_step must be in (0, 1] voxels");
    require(std::isfinite(o.act_probability) && o.act_probability >= 0 && o.act_probability <= 1,
            "swarm: act_probability must be in [0, 1]");
    require(finite_positive(o.edit_radius) && o.edit_radius <= 16, "swarm: edit_radius must be in (0, 16] voxels");
    require(finite_positive(o.edit_amount) && o.edit_amount <= 0.5, "swarm: edit_amount must be in (0, 0.5]");
    require(std::isfinite(o.expand_sigmas) && o.expand_sigmas >= 0, "swarm: expand_sigmas must be finite and >= 0");
    require(std::isfinite(o.contract_sigmas) && o.contract_sigmas >= 0,
            "swarm: contract_sigmas must be finite and >= 0");
    require(finite_positive(o.min_sigma), "swarm: min_sigma must be finite and > 0");
    require(finite_positive(o.stats_smoothing) && o.stats_smoothing <= 1, "swarm: stats_smoothing must be in (0, 1]");
    require(std::isfinite(o.sample_depth) && o.sample_depth >= 0 && o.sample_depth <= 8, "swarm: sample_depth must be in [0, 8]");
    require(std::isfinite(o.edit_range) && o.edit_range >= 0, "swarm: edit_range must be finite and >= 0");
    require(std::isfinite(o.sheet_reach) && o.sheet_reach >= 0 && o.sheet_reach <= 32, "swarm: sheet_reach must be in [0, 32] voxels");
    require(o.decision != EditDecision::kSheet ||
                (std::isfinite(o.sheet_lower) && std::isfinite(o.sheet_upper) && o.sheet_lower < o.sheet_upper),
            "swarm: the sheet decision needs a finite band sheet_lower < sheet_upper");
    require(o.decision != EditDecision::kCut || o.edit_range > 0,
            "swarm: the cut decision needs an edit range (the brush around the handle to cut)");
    require(std::isfinite(o.sheet_between_share) && o.sheet_between_share >= 0 && o.sheet_between_share <= 0.5,
            "swarm: sheet_between_share must be in [0, 0.5]");
    require(std::isnan(o.sheet_mean) || (o.sheet_mean >= o.sheet_lower && o.sheet_mean <= o.sheet_upper),
            "swarm: sheet_mean must lie in the sheet's band [sheet_lower, sheet_upper]");
}

std::optional<EditDecision> edit_decision_named(std::string_view name) {
    if (name == "intensity") return EditDecision::kIntensity;
    if (name == "random") return EditDecision::kRandom;
    if (name == "sheet") return EditDecision::kSheet;
    if (name == "cut") return EditDecision::kCut;
    return std::nullopt;
}

std::pair<double, double> sheet_between_range(const SwarmOptions& o) {
    const double mean = std::isnan(o.sheet_mean) ? 0.5 * (o.sheet_lower + o.sheet_upper) : o.sheet_mean;
    const double widen = 1.0 - 2.0 * o.sheet_between_share;
    return {o.sheet_lower - widen * (mean - o.sheet_lower), o.sheet_upper + widen * (o.sheet_upper - mean)};
}

Swarm::Swarm(const SwarmOptions& options) : options_(options) { validate(options_); }

void Swarm::spawn(const SparseField& field, Vec3d near, double radius) {
    require(all_finite(near), "swarm: spawn position must be finite");
    require(finite_positive(radius), "swarm: spawn radius must be finite and > 0");
    const Lattice& lat = field.lattice();
    struct Candidate {
        double d2;
        PointIndex point;
    };
    std::vector<Candidate> candidates;
    for (PointIndex i : field.zero_layer()) {
        const Vec3d d = lat.coord(i).cast<double>() - near;
        const double d2 = dot(d, d);
        if (d2 <= radius * radius) candidates.push_back({d2, i});
    }
    require(!candidates.empty(), "swarm: no zero-layer point within the spawn radius");
    std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
        return a.d2 != b.d2 ? a.d2 < b.d2 : a.point < b.point;
    });
    agents_.assign(options_.agents, Agent{});
    for (std::size_t k = 0; k < agents_.size(); ++k) {
        const PointIndex p = candidates[k % candidates.size()].point;
        agents_[k].position = project(field.phi(), lat.coord(p).cast<double>(), 8);
    }
    move_steps_ = 0;
    edit_steps_ = 0;
    have_stats_ = false;
    mean_ = second_ = 0.0;
}

namespace {

// The repulsion of the agents within `radius` of one, Σ_j dir(i, j) (1 − l / radius) over j in
// increasing order. The positions are copied into three flat arrays and a pair is dropped on its
// squared distance first (no square root: most pairs are far) with a margin above radius², so
// every pair the test l < radius keeps still reaches it: the sum is bit for bit a plain loop's.
class Separation {
public:
    Separation(const std::vector<Agent>& agents, double radius) : radius_(radius), r2_(radius * radius * (1.0 + 1e-9)) {
        if (!(radius_ > 0)) return;
        for (int k = 0; k < 3; ++k) p_[k].reserve(agents.size());
        for (const Agent& a : agents)
            for (int k = 0; k < 3; ++k) p_[k].push_back(a.position[k]);
    }

    Vec3d push(std::size_t i, std::uint64_t seed) const {
        Vec3d rep{0, 0, 0};
        if (!(radius_ > 0)) return rep;
        const std::size_t n = p_[0].size();
        const Vec3d x{p_[0][i], p_[1][i], p_[2][i]};
        thread_local std::vector<double> d2;
        d2.resize(n);
        const double* px = p_[0].data();
        const double* py = p_[1].data();
        const double* pz = p_[2].data();
        for (std::size_t j = 0; j < n; ++j) {  // no branch: vectorised
            const double ex = x.x - px[j], ey = x.y - py[j], ez = x.z - pz[j];
            d2[j] = ex * ex + ey * ey + ez * ez;
        }
        for (std::size_t j = 0; j < n; ++j) {
            if (d2[j] > r2_ || j == i) continue;
            const Vec3d d = x - Vec3d{p_[0][j], p_[1][j], p_[2][j]};
            const double l = norm(d);
            if (l >= radius_) continue;
            Vec3d dir;
            if (l > 1e-9) {
                dir = d / l;
            } else {  // coincident agents: antisymmetric hashed direction
                const std::size_t a = std::min(i, j), b = std::max(i, j);
                dir = Stream(seed, a, b, kPairTag).unit_vector();
                if (i > j) dir = -dir;
            }
            rep += dir * (1.0 - l / radius_);
        }
        return rep;
    }

private:
    double radius_, r2_;
    std::vector<double> p_[3];
};

}  // namespace

StepReport Swarm::move(const SparseField& field) {
    const Grid<float>& phi = field.phi();
    const Vec3i dims = phi.dims();
    const std::size_t n_agents = agents_.size();
    const std::vector<Agent> previous = agents_;
    const double radius = options_.separation_radius;
    const std::uint64_t step = move_steps_++;

    std::vector<std::uint8_t> reprojected(n_agents, 0), on_surface(n_agents, 0);
    const Separation separation(previous, options_.separation > 0 ? radius : 0.0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_agents), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Vec3d x = previous[i].position;
            Stream rng(options_.seed, i, step, kMoveTag);

            Vec3d p{0, 0, 0};
            if (target_ && options_.attraction > 0) {
                const Vec3d d = *target_ - x;
                const double l = norm(d);
                if (l > 1e-9) p += d * (options_.attraction / l);
            }
            if (options_.random_walk > 0) p += rng.unit_vector() * options_.random_walk;
            if (options_.separation > 0) p += separation.push(i, options_.seed) * options_.separation;

            const Vec3d g = to_d(interpolated_gradient(phi, x));
            const double gl = norm(g);
            Vec3d next = x;
            if (gl > 1e-9) {
                const Vec3d n = g / gl;
                const Vec3d tangential = clamp_length(p - n * dot(n, p), options_.max_step);
                const double f = trilinear(phi, x);
                const Vec3d pull = clamp_length(n * (options_.pull_back * f / gl), options_.max_step);
                next = clamp_to_box(x + tangential - pull, dims);
            }
            // Off the zero layer: Newton re-projection.
            float at_next = trilinear(phi, next);
            if (std::abs(at_next) > 1.0) {
                next = project(phi, next, 8);
                reprojected[i] = 1;
                at_next = trilinear(phi, next);
            }
            on_surface[i] = std::abs(at_next) < 0.5 ? 1 : 0;
            agents_[i].position = next;
            agents_[i].velocity = next - x;
        }
    });

    StepReport report;
    for (std::size_t i = 0; i < n_agents; ++i) {
        report.on_surface += on_surface[i];
        report.reprojected += reprojected[i];
    }
    return report;
}

namespace {

// The agents' edits merged per point (summed in agent order, clamped to ±0.5), in point order.
std::vector<ZeroLayerEdit> merge_edits(const std::vector<std::vector<ZeroLayerEdit>>& per_agent) {
    std::vector<ZeroLayerEdit> all;
    std::size_t total = 0;
    for (const auto& v : per_agent) total += v.size();
    all.reserve(total);
    for (const auto& v : per_agent) all.insert(all.end(), v.begin(), v.end());
    std::vector<ZeroLayerEdit> scratch;
    stable_radix_sort(all, [](const ZeroLayerEdit& e) { return e.point; }, scratch);  // equal points: agent order
    std::vector<ZeroLayerEdit> merged;
    for (std::size_t k = 0; k < all.size();) {
        const PointIndex p = all[k].point;
        double total = 0.0;
        for (; k < all.size() && all[k].point == p; ++k) total += all[k].delta;
        merged.push_back({p, static_cast<float>(std::clamp(total, -0.5, 0.5))});
    }
    return merged;
}

}  // namespace

// The population's intensity mean and spread (summed in agent order: deterministic), smoothed
// over the steps; returns {µ, σ}.
std::pair<double, double> Swarm::population_statistics(const Grid<float>& phi, const Grid<float>& image_unit) {
    const std::size_t n_agents = agents_.size();
    double sum = 0.0, sum2 = 0.0;
    for (const Agent& a : agents_) {
        Vec3d where = a.position;
        if (options_.sample_depth > 0.0) {  // inside the segmented tissue, along -n
            const Vec3d g = to_d(interpolated_gradient(phi, a.position));
            const double gl = norm(g);
            if (gl > 1e-9) where = where - g * (options_.sample_depth / gl);
        }
        const double v = trilinear(image_unit, where);
        sum += v;
        sum2 += v * v;
    }
    const double m = sum / static_cast<double>(n_agents), s = sum2 / static_cast<double>(n_agents);
    if (!have_stats_) {
        mean_ = m;
        second_ = s;
        have_stats_ = true;
    } else {
        const double a = options_.stats_smoothing;
        mean_ = (1 - a) * mean_ + a * m;
        second_ = (1 - a) * second_ + a * s;
    }

    return {mean_, std::max(std::sqrt(std::max(second_ - mean_ * mean_, 0.0)), options_.min_sigma)};
}

std::vector<ZeroLayerEdit> Swarm::surface_edits(const SparseField& field, const Grid<float>& image_unit) {
    require(image_unit.dims() == field.lattice().dims(), "swarm: image and level set dimensions differ");
    const std::size_t n_agents = agents_.size();
    if (n_agents == 0) return {};
    const Grid<float>& phi = field.phi();
    const Lattice& lat = field.lattice();
    const std::uint64_t frame = edit_steps_++;

    // Plain variables, not a structured binding: the parallel loop below captures them (clang 14,
    // the fuzz preset's compiler, cannot capture structured bindings).
    const std::pair<double, double> stats = population_statistics(phi, image_unit);
    const double mu = stats.first, sigma = stats.second;

    const double support = options_.edit_radius;
    const double sg = support / 2.0;
    const double inv_two_var = 1.0 / (2.0 * sg * sg);
    const int reach = static_cast<int>(std::ceil(support));

    const bool sheet = options_.decision == EditDecision::kSheet;
    const bool cut = options_.decision == EditDecision::kCut;
    const double between_reach =
        options_.sheet_between && options_.edit_range > 0 ? std::max(options_.edit_range, options_.sheet_reach) : 0.0;
    const std::pair<double, double> between_range = sheet_between_range(options_);
    const double between_lo = between_range.first, between_hi = between_range.second;
    // `limited`: the voxel must also hold sheet_between_share of the sheet's tissue (the footprint's
    // test; an agent may decide to grow towards a gap at any intensity, but raises only such voxels).
    const auto between_voxel = [&](Vec3i q, bool limited) {
        if (!(between_reach > 0) || !lat.contains(q)) return false;
        const float v = image_unit(q);
        return (!limited || !options_.sheet_between_limited || (v >= between_lo && v < between_hi)) &&
               between_sheet_sides(phi, image_unit, q, between_reach, options_.sheet_lower, options_.sheet_upper);
    };
    const auto between = [&](Vec3d p) {
        return between_voxel({static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)), static_cast<int>(std::lround(p.z))},
                             false);
    };
    std::vector<std::vector<ZeroLayerEdit>> per_agent(n_agents);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n_agents), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            Stream rng(options_.seed, i, frame, kEditTag);
            if (!(rng.uniform() < options_.act_probability)) continue;
            const Vec3d x = agents_[i].position;
            if (options_.edit_range > 0.0 && target_ && norm(*target_ - x) > options_.edit_range) continue;
            const Vec3d g = to_d(interpolated_gradient(phi, x));
            const double gl = norm(g);
            if (!(gl > 1e-9)) continue;
            const Vec3d n = g / gl;
            const double outside = trilinear(image_unit, x + n * 1.5);
            const double inside = trilinear(image_unit, x - n * 1.5);
            double amount = 0.0;
            if (options_.decision == EditDecision::kRandom) {
                amount = rng.uniform() < 0.5 ? -options_.edit_amount : options_.edit_amount;
            } else if (options_.decision == EditDecision::kCut) {
                amount = options_.edit_amount;
            } else if (options_.decision == EditDecision::kSheet) {
                const double near = trilinear(image_unit, x + n * 0.75);
                const auto in_band = [&](double v) { return v >= options_.sheet_lower && v < options_.sheet_upper; };
                if ((in_band(near) && in_band(outside)) || between(x + n * 0.75)) amount = -options_.edit_amount;
            } else if (std::abs(outside - mu) <= options_.expand_sigmas * sigma)
                amount = -options_.edit_amount;
            else if (std::abs(inside - mu) > options_.contract_sigmas * sigma)
                amount = options_.edit_amount;
            if (amount == 0.0) continue;

            const Vec3i c{static_cast<int>(std::lround(x.x)), static_cast<int>(std::lround(x.y)),
                          static_cast<int>(std::lround(x.z))};
            auto& out = per_agent[i];
            for (int dz = -reach; dz <= reach; ++dz)
                for (int dy = -reach; dy <= reach; ++dy)
                    for (int dx = -reach; dx <= reach; ++dx) {
                        const Vec3i q = c + Vec3i{dx, dy, dz};
                        const Vec3d d = q.cast<double>() - x;
                        const double d2 = dot(d, d);
                        if (d2 > support * support || !lat.contains(q)) continue;  // the footprint first: no memory read
                        const PointIndex idx = lat.index(q);
                        if (field.status()[idx] != 0 || (cut && !(phi[idx] < 0.0f))) continue;
                        if (sheet && phi[idx] >= 0.0f && !(image_unit[idx] >= options_.sheet_lower && image_unit[idx] < options_.sheet_upper) &&
                            !between_voxel(q, true))
                            continue;  // kSheet: never raise the surface over a voxel that is neither the sheet's tissue nor between its sides
                        out.push_back({idx, static_cast<float>(amount * std::exp(-d2 * inv_two_var))});
                    }
        }
    });

    return merge_edits(per_agent);
}

std::optional<double> Swarm::intensity_mean() const {
    if (!have_stats_) return std::nullopt;
    return mean_;
}

std::optional<double> Swarm::intensity_sigma() const {
    if (!have_stats_) return std::nullopt;
    return std::max(std::sqrt(std::max(second_ - mean_ * mean_, 0.0)), options_.min_sigma);
}

}  // namespace liveset
