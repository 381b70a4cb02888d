// SparseField initialisation (sparse_field.hpp): the field from a signed distance or a mask, the
// band built by the shared sweep (relayer.cpp).
#include "liveset/levelset/sparse_field.hpp"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>
#include <string>

#include "liveset/levelset/band_detail.hpp"

namespace liveset {

using detail::for_each_neighbor6;
using detail::kNoSlot;
using detail::point_text;

void SparseField::evaluate_sdf(const std::function<double(Vec3d)>& sdf, Vec3i lo, Vec3i hi) {
    // Evaluated into a grid of the box and checked before anything of the field changes, so a
    // throw (a value that is not finite, or one from `sdf` itself) leaves the field as it was.
    const Vec3i n{hi.x - lo.x + 1, hi.y - lo.y + 1, hi.z - lo.z + 1};
    Grid<float> values{Lattice(n)};
    const float far = static_cast<float>(layers_ + 1);
    // Evaluate the distance in the box (clamped to the far value); zero layer = |φ| ≤ 0.5.
    tbb::parallel_for(0, n.z, [&](int z) {
        for (int y = 0; y < n.y; ++y)
            for (int x = 0; x < n.x; ++x) {
                const double v = sdf(Vec3d{static_cast<double>(lo.x + x), static_cast<double>(lo.y + y), static_cast<double>(lo.z + z)});
                values[values.lattice().index({x, y, z})] =
                    std::isfinite(v) ? static_cast<float>(std::clamp(v, -static_cast<double>(far), static_cast<double>(far)))
                                     : std::numeric_limits<float>::quiet_NaN();
            }
    });
    for (std::size_t i = 0; i < values.size(); ++i)
        if (!std::isfinite(values[static_cast<PointIndex>(i)]))
            throw std::invalid_argument("signed distance is not finite at " +
                                        point_text(lattice(), lattice().index(lo + values.lattice().coord(static_cast<PointIndex>(i)))));
    clear_lists();
    // Copied, not moved: φ keeps its storage (the viewer's crash handler reads it in place).
    // Outside the box the function is at least the far value, which the clamp makes exactly far.
    if (!(n == lattice().dims())) phi_.fill(far);
    for (int z = 0; z < n.z; ++z)
        for (int y = 0; y < n.y; ++y) {
            const auto row = values.values().subspan(values.lattice().index({0, y, z}), static_cast<std::size_t>(n.x));
            std::copy(row.begin(), row.end(), phi_.values().begin() + lattice().index(lo + Vec3i{0, y, z}));
        }
}

void SparseField::init_from_sdf(const std::function<double(Vec3d)>& sdf) {
    init_from_sdf(sdf, {0, 0, 0}, lattice().dims() - Vec3i{1, 1, 1});
}

void SparseField::clear_lists() {
    activity_.reset();  // a new front: everything awake again
    for (auto& l : lists_) l.clear();
    slot_.fill(kNoSlot);
    slots_stale_ = false;
}

void SparseField::init_from_sdf(const std::function<double(Vec3d)>& sdf, Vec3i lo, Vec3i hi) {
    const Vec3i d = lattice().dims();
    for (int a = 0; a < 3; ++a) {
        lo[a] = std::clamp(lo[a], 0, d[a] - 1);
        hi[a] = std::clamp(hi[a], lo[a], d[a] - 1);
    }
    evaluate_sdf(sdf, lo, hi);
    band_from_phi(lo, hi);
}

namespace {

// f(i) for every point of the box's z-planes [z0, z1), row by row, in index order.
template <class F>
void for_planes(const Lattice& lattice, Vec3i lo, Vec3i hi, int z0, int z1, const F& f) {
    for (int z = z0; z < z1; ++z)
        for (int y = lo.y; y <= hi.y; ++y) {
            const PointIndex row = lattice.index({0, y, z});
            for (int x = lo.x; x <= hi.x; ++x) f(row + static_cast<PointIndex>(x));
        }
}

// The points of the box [lo, hi] for which `pick(i)` holds, in index order: the box's z-planes in
// parallel, each into its own list, joined in plane order (the same list on any thread count).
// `pick` may write point i's own entries, nothing else.
template <class F>
UninitVector<PointIndex> pick_in_box(const Lattice& lattice, Vec3i lo, Vec3i hi, const F& pick) {
    const int planes = hi.z - lo.z + 1;
    std::vector<std::vector<PointIndex>> found(static_cast<std::size_t>(planes));
    tbb::parallel_for(0, planes, [&](int k) {
        std::vector<PointIndex>& out = found[static_cast<std::size_t>(k)];
        for_planes(lattice, lo, hi, lo.z + k, lo.z + k + 1, [&](PointIndex i) {
            if (pick(i)) out.push_back(i);
        });
    });
    std::size_t n = 0;
    for (const auto& v : found) n += v.size();
    UninitVector<PointIndex> all;
    all.reserve(n);
    for (const auto& v : found) all.insert(all.end(), v.begin(), v.end());
    return all;
}

}  // namespace

void SparseField::band_from_phi(Vec3i lo, Vec3i hi, bool steep_possible) {
    const Vec3i d = lattice().dims();
    // The box grown by one point: outside it every point and all its neighbours hold the far
    // value, so neither pass below can find anything there.
    Vec3i glo = lo, ghi = hi;
    for (int a = 0; a < 3; ++a) {
        glo[a] = std::max(lo[a] - 1, 0);
        ghi[a] = std::min(hi[a] + 1, d[a] - 1);
    }
    // A sign change between two far points (a function steeper than a distance) would leave the
    // front without zero-layer points: pull both sides onto the zero layer (found first, then
    // pulled: every point is judged on the values as evaluated).
    // A whole-lattice pass with six reads a point: skipped where no such pair can exist.
    if (steep_possible) {
        const UninitVector<PointIndex> steep = pick_in_box(lattice(), glo, ghi, [&](PointIndex i) {
            const float v = phi_[i];
            if (std::abs(v) <= 0.5f) return false;
            bool opposite = false;
            for_each_neighbor6(lattice(), decoder_, i, [&](PointIndex q) {
                if (std::abs(phi_[q]) > 0.5f && ((phi_[q] < 0) != (v < 0))) opposite = true;
            });
            return opposite;
        });
        for (PointIndex i : steep) phi_[i] = phi_[i] < 0 ? -0.5f : 0.5f;
    }

    const float far = static_cast<float>(layers_ + 1);
    if (!(glo == Vec3i{0, 0, 0} && ghi == d - Vec3i{1, 1, 1})) status_.fill(far_outside());
    // Each point's own status and φ set in parallel; the zero layer listed in index order.
    PointList zero = pick_in_box(lattice(), glo, ghi, [&](PointIndex i) {
        if (std::abs(phi_[i]) <= 0.5f) {
            status_[i] = 0;
            return true;
        }
        status_[i] = phi_[i] < 0 ? far_inside() : far_outside();
        phi_[i] = phi_[i] < 0 ? -far : far;
        return false;
    });
    // Every other point is far: the sweep reaches the new layers from the zero layer, keeping
    // each level's points, which become the outer lists as a whole-band repair rebuilds its lists
    // (relist: the zero list in index order, slots written when next needed); the lists are empty
    // here (clear_lists), so no point is moved between them one by one.
    std::vector<RegionPoint> region;
    region.reserve(zero.size() * (2 * static_cast<std::size_t>(layers_) + 1));
    for (PointIndex i : zero) mark_pending(i, region);
    sweep_whole_band(region, zero, /*keep_levels=*/true);
    finish(region, /*rebuilding_lists=*/true);
    relist(zero);
    // The sweep's level buffers are not kept: an initialisation reaches the whole band at once,
    // which no incremental step does on a large front (those repair locally, or sweep a front of
    // at most StepOptions::dense_front_max points); a 0.5 mm brain's are 120 MB. A kFullBand step
    // grows them again on its first sweep.
    sweep_from_.v = PointList{};
    sweep_next_.v = PointList{};
}

void SparseField::init_from_mask(const Grid<std::uint8_t>& mask) {
    if (!(mask.dims() == lattice().dims()))
        throw std::invalid_argument("mask dimensions " + mask.lattice().describe() +
                                    " differ from the level-set lattice " + lattice().describe());
    // Boundary voxels of either side become the zero layer (±0.5: the front lies half-way), the
    // others far: init_from_sdf's values, written straight into φ (nothing here can fail halfway).
    clear_lists();
    const Lattice& lat = lattice();
    const float far = static_cast<float>(layers_ + 1);
    const Vec3i d = lat.dims();
    tbb::parallel_for(0, d.z, [&](int z) {
        for_planes(lat, {0, 0, 0}, d - Vec3i{1, 1, 1}, z, z + 1, [&](PointIndex i) {
            const bool inside = mask[i] != 0;
            bool boundary = false;
            for_each_neighbor6(lat, decoder_, i, [&](PointIndex q) { boundary = boundary || ((mask[q] != 0) != inside); });
            phi_[i] = boundary ? (inside ? -0.5f : 0.5f) : (inside ? -far : far);
        });
    });
    band_from_phi({0, 0, 0}, d - Vec3i{1, 1, 1}, /*steep=*/false);  // a sign change's both sides are ±0.5 here
}

}  // namespace liveset
