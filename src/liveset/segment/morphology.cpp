// Binary morphology in mm: exact balls by their chords or eval's distance transform, components as runs (see morphology.hpp).
#include "liveset/segment/morphology.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "liveset/eval/surface_distance.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/grid/uninit_allocator.hpp"

namespace liveset {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void check_radius(double r) {
    if (!std::isfinite(r) || r < 0) throw std::invalid_argument("morphology radius must be finite and >= 0 mm");
}

Grid<std::uint8_t> complement(const Grid<std::uint8_t>& mask) {
    Grid<std::uint8_t> out(mask.lattice());
    for (std::size_t i = 0; i < mask.size(); ++i) out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] == 0;
    return out;
}

// The ball of radius r on the lattice's axes: sq[a][k] = (k·s_a)² for k = 0..k[a], the largest k
// whose (k·s_a)² is within `limit` = r²(1 + 1e-9) (distances equal to r up to rounding count as r: a
// 4 mm ball at 1 mm spacing holds (0, 0, 4)), and no more than the lattice holds.
struct Ball {
    double limit = 0;
    Vec3i k{0, 0, 0};
    std::array<std::vector<double>, 3> sq;
};

Ball ball(const Lattice& lat, double r) {
    Ball b;
    b.limit = r * r * (1 + 1e-9);
    for (int a = 0; a < 3; ++a) {
        std::vector<double>& sq = b.sq[static_cast<std::size_t>(a)];
        sq.push_back(0.0);
        for (int k = 1; k < lat.dims()[a]; ++k) {
            const double d = k * lat.spacing()[a];  // as (a.x - b.x) · s.x: the same rounding as a brute force
            if (d * d > b.limit) break;
            sq.push_back(d * d);
        }
        b.k[a] = static_cast<int>(sq.size()) - 1;
    }
    return b;
}

// Index box [lo, hi) on every axis.
struct Box {
    Vec3i lo{0, 0, 0}, hi{0, 0, 0};
    bool empty() const { return hi.x <= lo.x || hi.y <= lo.y || hi.z <= lo.z; }
    int size(int axis) const { return hi[axis] - lo[axis]; }
};

// The bounding box of the nonzero voxels (empty when there is none).
Box bounding_box(const Grid<std::uint8_t>& mask) {
    const Vec3i d = mask.dims();
    Box b{d, {0, 0, 0}};
    const std::uint8_t* v = mask.values().data();
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y) {
            const std::uint8_t* row = v + (static_cast<std::size_t>(z) * static_cast<std::size_t>(d.y) + static_cast<std::size_t>(y)) * static_cast<std::size_t>(d.x);
            int first = 0, last = d.x - 1;
            while (first < d.x && row[first] == 0) ++first;
            if (first == d.x) continue;
            while (row[last] == 0) --last;
            b.lo = {std::min(b.lo.x, first), std::min(b.lo.y, y), std::min(b.lo.z, z)};
            b.hi = {std::max(b.hi.x, last + 1), std::max(b.hi.y, y + 1), std::max(b.hi.z, z + 1)};
        }
    return b;
}

Box grown(const Box& b, Vec3i k, Vec3i dims) {
    return {{std::max(b.lo.x - k.x, 0), std::max(b.lo.y - k.y, 0), std::max(b.lo.z - k.z, 0)},
            {std::min(b.hi.x + k.x, dims.x), std::min(b.hi.y + k.y, dims.y), std::min(b.hi.z + k.z, dims.z)}};
}

// dst[i] = min(dst[i], src[i] + c): one line of the separable minimum.
void min_shifted(double* dst, const double* src, double c, int n) {
    for (int i = 0; i < n; ++i) {
        const double v = src[i] + c;
        dst[i] = v < dst[i] ? v : dst[i];
    }
}

// g[x - lo] = (k·sx)² for the nearest feature k voxels away along the row (features: the voxels of
// row[ext_lo..ext_hi) that are nonzero when feature_nonzero, else zero), +infinity beyond the ball;
// `k` is scratch for hi - lo voxel distances.
void row_distances(const std::uint8_t* row, bool feature_nonzero, int ext_lo, int ext_hi, int lo, int hi, const Ball& b, int* k,
                   double* g) {
    const int cap = b.k.x + 1;  // "none within the ball"
    const std::uint8_t want = feature_nonzero ? 1 : 0;
    const auto feature = [&](int x) { return static_cast<std::uint8_t>(row[x] != 0) == want; };
    int dist = cap;
    for (int x = ext_lo; x < lo; ++x) dist = feature(x) ? 0 : std::min(dist + 1, cap);
    for (int x = lo; x < hi; ++x) k[x - lo] = dist = feature(x) ? 0 : std::min(dist + 1, cap);
    dist = cap;
    for (int x = ext_hi - 1; x >= hi; --x) dist = feature(x) ? 0 : std::min(dist + 1, cap);
    for (int x = hi - 1; x >= lo; --x) {
        dist = feature(x) ? 0 : std::min(dist + 1, cap);
        const int nearest = std::min(dist, k[x - lo]);
        g[x - lo] = nearest < cap ? b.sq[0][static_cast<std::size_t>(nearest)] : kInf;
    }
}

// 1 inside `out_box` where a feature (a voxel of `mask` that is nonzero when feature_nonzero, else
// zero) lies within the ball, 0 elsewhere: exactly the brute force ((dx² + dy²) + dz² ≤ limit), by
// the separable minimum over the ball's chords. Per z slice of the box grown by the ball: the
// nearest feature along each row, then the minimum of (dx² + dy²) over the ball's y chord; per
// output voxel, the minimum of that plus dz² over its z chord. The slices run in one chunk of z per
// thread, each with a ring of the 2·K_z + 1 slices its output needs (recomputing K_z on either side); every voxel
// is computed on its own, so the result does not depend on the thread count or the chunks.
Grid<std::uint8_t> near_features(const Grid<std::uint8_t>& mask, bool feature_nonzero, const Box& out_box, const Ball& b) {
    const Lattice& lat = mask.lattice();
    Grid<std::uint8_t> out(lat);
    if (out_box.empty()) return out;
    const Box ext = grown(out_box, b.k, lat.dims());
    const int nx = out_box.size(0), ny = out_box.size(1), nz = out_box.size(2);
    const std::size_t plane = static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
    const auto row_of = [&](int y, int z) { return mask.values().data() + (static_cast<std::size_t>(z) * lat.stride_z() + static_cast<std::size_t>(y) * lat.stride_y()); };
    const int tasks = std::max(1, tbb::this_task_arena::max_concurrency());  // results do not depend on it
    const int chunk = std::max(2 * b.k.z + 1, (nz + tasks - 1) / tasks);
    const int ring = 2 * b.k.z + 1;
    tbb::parallel_for(tbb::blocked_range<int>(0, (nz + chunk - 1) / chunk, 1), [&](const tbb::blocked_range<int>& chunks) {
        UninitVector<double> g(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ext.size(1)));
        UninitVector<int> k(static_cast<std::size_t>(nx));
        UninitVector<double> slices(plane * static_cast<std::size_t>(ring)), m(plane);
        const auto slice = [&](int z) { return slices.data() + static_cast<std::size_t>((z - ext.lo.z) % ring) * plane; };
        const auto g_row = [&](int y) { return g.data() + static_cast<std::size_t>(y - ext.lo.y) * static_cast<std::size_t>(nx); };
        const auto in_plane = [&](int z) {  // slice(z) = min over the y chord of (dx² + dy²)
            for (int y = ext.lo.y; y < ext.hi.y; ++y)
                row_distances(row_of(y, z), feature_nonzero, ext.lo.x, ext.hi.x, out_box.lo.x, out_box.hi.x, b, k.data(), g_row(y));
            for (int y = out_box.lo.y; y < out_box.hi.y; ++y) {
                double* dst = slice(z) + static_cast<std::size_t>(y - out_box.lo.y) * static_cast<std::size_t>(nx);
                std::copy(g_row(y), g_row(y) + nx, dst);
                for (int j = 1; j <= b.k.y; ++j) {
                    if (y - j >= ext.lo.y) min_shifted(dst, g_row(y - j), b.sq[1][static_cast<std::size_t>(j)], nx);
                    if (y + j < ext.hi.y) min_shifted(dst, g_row(y + j), b.sq[1][static_cast<std::size_t>(j)], nx);
                }
            }
        };
        for (int c = chunks.begin(); c < chunks.end(); ++c) {
            const int z0 = out_box.lo.z + c * chunk, z1 = std::min(z0 + chunk, out_box.hi.z);
            int done = std::max(z0 - b.k.z, ext.lo.z);  // the next slice to compute
            for (int z = z0; z < z1; ++z) {
                for (; done <= std::min(z + b.k.z, ext.hi.z - 1); ++done) in_plane(done);
                std::copy(slice(z), slice(z) + plane, m.begin());
                for (int l = 1; l <= b.k.z; ++l) {
                    if (z - l >= ext.lo.z) min_shifted(m.data(), slice(z - l), b.sq[2][static_cast<std::size_t>(l)], static_cast<int>(plane));
                    if (z + l < ext.hi.z) min_shifted(m.data(), slice(z + l), b.sq[2][static_cast<std::size_t>(l)], static_cast<int>(plane));
                }
                for (int y = 0; y < ny; ++y) {
                    std::uint8_t* o = out.values().data() + static_cast<std::size_t>(z) * lat.stride_z() +
                                      static_cast<std::size_t>(y + out_box.lo.y) * lat.stride_y() + static_cast<std::size_t>(out_box.lo.x);
                    const double* mr = m.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(nx);
                    for (int x = 0; x < nx; ++x) o[x] = mr[x] <= b.limit;
                }
            }
        }
    });
    return out;
}

// A ball wider than this many voxels along y and z together is applied through the distance
// transform, whose cost does not grow with the radius; a smaller one by its chords (near_features),
// 2-4x faster at the brain mask's 2-6 mm (docs/BENCHMARKS.md, session 58).
constexpr int kMaxChordVoxels = 40;

// 1 where the squared distance (mm²) to the features is within the ball's limit, by the exact
// distance transform (the same predicate as near_features).
Grid<std::uint8_t> within_by_transform(const Grid<std::uint8_t>& features, const Ball& b) {
    const double r2 = b.limit;
    const Grid<double> d2 = squared_distance_transform_mm(features, r2);
    Grid<std::uint8_t> out(features.lattice());
    for (std::size_t i = 0; i < out.size(); ++i) {
        const double v = d2[static_cast<PointIndex>(i)];
        out[static_cast<PointIndex>(i)] = v <= r2;
    }
    return out;
}

Grid<std::uint8_t> binarised(const Grid<std::uint8_t>& mask) {
    Grid<std::uint8_t> out(mask.lattice());
    for (std::size_t i = 0; i < mask.size(); ++i) out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] != 0;
    return out;
}

}  // namespace

Grid<std::uint8_t> erode_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    check_radius(radius_mm);
    if (radius_mm == 0) return binarised(mask);
    // Only the mask's own box can stay; the outside voxels that can erode it lie within a ball of it.
    const Ball b = ball(mask.lattice(), radius_mm);
    Grid<std::uint8_t> out = b.k.y + b.k.z > kMaxChordVoxels ? within_by_transform(complement(mask), b)
                                                             : near_features(mask, false, bounding_box(mask), b);
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] != 0 && out[static_cast<PointIndex>(i)] == 0;
    return out;
}

Grid<std::uint8_t> dilate_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    check_radius(radius_mm);
    if (radius_mm == 0) return binarised(mask);
    const Ball b = ball(mask.lattice(), radius_mm);
    if (b.k.y + b.k.z > kMaxChordVoxels) return within_by_transform(mask, b);
    return near_features(mask, true, grown(bounding_box(mask), b.k, mask.dims()), b);
}

Grid<std::uint8_t> close_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    Grid<std::uint8_t> out = erode_mm(dilate_mm(mask, radius_mm), radius_mm);
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] |= mask[static_cast<PointIndex>(i)] != 0;
    return out;
}

namespace {

// Per label (index 0 unused): its voxel count.
std::vector<std::size_t> component_sizes(const RunComponents& c) {
    std::vector<std::size_t> sizes(c.count + 1, 0);
    for (std::size_t k = 0; k < c.runs.size(); ++k) sizes[c.label[k]] += static_cast<std::size_t>(c.runs[k].x1 - c.runs[k].x0);
    return sizes;
}

}  // namespace

Grid<std::uint8_t> largest_component(const Grid<std::uint8_t>& mask) {
    const RunComponents c = component_runs(mask, 6);
    Grid<std::uint8_t> out(mask.lattice());
    if (c.count == 0) return out;
    const std::vector<std::size_t> sizes = component_sizes(c);
    std::uint32_t best = 1;
    for (std::uint32_t l = 2; l <= c.count; ++l)
        if (sizes[l] > sizes[best]) best = l;  // labels follow scan order: strict > keeps the first on ties
    write_runs(c, static_cast<std::size_t>(out.dims().x), [&](std::uint32_t l) { return l == best; }, out.values());
    return out;
}

Grid<std::uint8_t> large_components(const Grid<std::uint8_t>& mask, double fraction) {
    if (!(fraction > 0 && fraction <= 1)) throw std::invalid_argument("large_components: fraction must lie in (0, 1]");
    const RunComponents c = component_runs(mask, 6);
    Grid<std::uint8_t> out(mask.lattice());
    if (c.count == 0) return out;
    const std::vector<std::size_t> sizes = component_sizes(c);
    const double largest = static_cast<double>(*std::max_element(sizes.begin(), sizes.end()));
    write_runs(c, static_cast<std::size_t>(out.dims().x), [&](std::uint32_t l) { return static_cast<double>(sizes[l]) >= fraction * largest; },
               out.values());
    return out;
}

Grid<std::uint8_t> fill_holes(const Grid<std::uint8_t>& mask) {
    const RunComponents outside = component_runs(mask, 6, false);
    const std::vector<std::uint8_t> open = border_components(outside, mask.dims());  // reach the border
    Grid<std::uint8_t> out = binarised(mask);
    write_runs(outside, static_cast<std::size_t>(out.dims().x), [&](std::uint32_t l) { return open[l] == 0; }, out.values());  // outside: 0 or filled
    return out;
}

Grid<float> depth_mm(const Grid<std::uint8_t>& mask) {
    const Grid<double> d2 = squared_distance_transform_mm(complement(mask));
    Grid<float> out(mask.lattice());
    for (std::size_t i = 0; i < out.size(); ++i) out[static_cast<PointIndex>(i)] = static_cast<float>(std::sqrt(d2[static_cast<PointIndex>(i)]));
    return out;
}

}  // namespace liveset
