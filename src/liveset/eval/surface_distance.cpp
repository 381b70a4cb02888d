// Boundary extraction, exact anisotropic Euclidean distance transform, and the Hausdorff / HD95 /
// mean surface distance measures built on them.
#include "liveset/eval/surface_distance.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "liveset/eval/overlap.hpp"

namespace liveset {

namespace {

// Scratch for one 1D transform of a line of n samples stored as T (double or float); the
// envelope's break points are doubles either way.
template <class T>
struct LineScratch {
    std::vector<T> d;
    std::vector<double> z;
    std::vector<int> v;
    void resize(int n) {
        const auto un = static_cast<std::size_t>(n);
        d.resize(un);
        v.resize(un);
        z.resize(un + 1);
    }
};

// 1D squared distance transform (Felzenszwalb & Huttenlocher 2012) on samples f at positions q·step:
// s.d[q] = min_p (step·(q-p))² + f[p]. Samples with f = +inf or above `cutoff` are not sites; with
// no site, d = +inf. Inside a run of zeros only the run's two ends are sites: an interior zero is
// never the nearest site of a point outside the run, and inside it d is 0 (as the full envelope gives).
// The arithmetic is in double whatever T: a float line is the double transform of the same values,
// each result rounded once to float.
template <class T>
void transform_line(const T* f, LineScratch<T>& s, int n, double step, double cutoff) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    T* d = s.d.data();
    int* v = s.v.data();
    double* z = s.z.data();
    int k = -1;
    for (int q = 0; q < n; ++q) {
        const double fq = f[q];
        if (fq == kInf || fq > cutoff) continue;
        if (fq == 0 && q > 0 && q + 1 < n && f[q - 1] == 0 && f[q + 1] == 0) continue;
        const double xq = q * step;
        if (k < 0) {
            k = 0;
            v[0] = q;
            z[0] = -kInf;
            z[1] = kInf;
            continue;
        }
        double sq = 0;
        while (true) {
            const int p = v[k];
            const double xp = p * step;
            sq = ((fq + xq * xq) - (static_cast<double>(f[p]) + xp * xp)) / (2.0 * (xq - xp));
            if (sq <= z[k]) {
                --k;  // z[0] = -inf, so k never drops below 0 here
                continue;
            }
            break;
        }
        ++k;
        v[k] = q;
        z[k] = sq;
        z[k + 1] = kInf;
    }
    if (k < 0) {
        std::fill(d, d + n, std::numeric_limits<T>::infinity());
        return;
    }
    int j = 0;
    for (int q = 0; q < n; ++q) {
        const double xq = q * step;
        while (z[j + 1] < xq) ++j;
        const double dx = xq - v[j] * step;
        d[q] = f[q] == 0 ? T(0) : static_cast<T>(dx * dx + static_cast<double>(f[v[j]]));
    }
}

// Runs the 1D transform in place along `axis` over every line of `grid`. Lines across x (y and z)
// are taken kBlock neighbours in x at a time, so each gather and scatter reads whole cache lines
// instead of one value per line: the same arithmetic per line.
template <class T>
void transform_axis(Grid<T>& grid, int axis, double cutoff) {
    constexpr int kBlock = 64;
    const Lattice& lat = grid.lattice();
    const Vec3i dims = lat.dims();
    const int n = dims[axis];
    const double step = lat.spacing()[axis];
    // A line of zeros is its own transform while zeros are sites (a cutoff not below 0).
    const bool skip_zero_lines = !(cutoff < 0.0);
    const std::size_t stride = axis == 0 ? 1 : (axis == 1 ? lat.stride_y() : lat.stride_z());
    // The other two axes, (a, b) with a fastest in memory; lines are enumerated over b in parallel.
    const int a_axis = axis == 0 ? 1 : 0;
    const int b_axis = axis == 2 ? 1 : 2;
    const std::size_t a_stride = a_axis == 0 ? 1 : lat.stride_y();
    const std::size_t b_stride = b_axis == 1 ? lat.stride_y() : lat.stride_z();
    const int width = axis == 0 ? 1 : kBlock;  // lines per gather; a_stride is 1 when axis != 0
    T* data = grid.values().data();
    tbb::parallel_for(tbb::blocked_range<int>(0, dims[b_axis]), [&](const tbb::blocked_range<int>& r) {
        LineScratch<T> s;
        s.resize(n);
        std::vector<T> block(static_cast<std::size_t>(n) * static_cast<std::size_t>(width));
        for (int b = r.begin(); b < r.end(); ++b) {
            for (int a0 = 0; a0 < dims[a_axis]; a0 += width) {
                const int w = std::min(width, dims[a_axis] - a0);
                T* first = data + static_cast<std::size_t>(a0) * a_stride + static_cast<std::size_t>(b) * b_stride;
                // A line of zeros (every point a feature, as outside a mask whose depth is taken)
                // is its own transform: such lines, and a gather of nothing else, are left as they are.
                std::array<unsigned char, kBlock> live{};
                for (int q = 0; q < n; ++q)
                    for (int l = 0; l < w; ++l) {
                        const T v = first[static_cast<std::size_t>(q) * stride + static_cast<std::size_t>(l)];
                        block[static_cast<std::size_t>(l * n + q)] = v;
                        live[static_cast<std::size_t>(l)] |= v != T(0) ? 1 : 0;
                    }
                if (skip_zero_lines && std::none_of(live.begin(), live.begin() + w, [](unsigned char c) { return c != 0; })) continue;
                for (int l = 0; l < w; ++l) {
                    if (skip_zero_lines && live[static_cast<std::size_t>(l)] == 0) continue;
                    T* line = block.data() + static_cast<std::size_t>(l * n);
                    transform_line(line, s, n, step, cutoff);
                    std::copy(s.d.begin(), s.d.begin() + n, line);
                }
                for (int q = 0; q < n; ++q)
                    for (int l = 0; l < w; ++l)
                        first[static_cast<std::size_t>(q) * stride + static_cast<std::size_t>(l)] = block[static_cast<std::size_t>(l * n + q)];
            }
        }
    });
}

// Percentile (fraction in [0,1]) with linear interpolation between order statistics (numpy "linear").
// Reorders `values`; requires a non-empty vector.
double percentile(std::vector<double>& values, double fraction) {
    const double rank = fraction * static_cast<double>(values.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(rank));
    std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(lo), values.end());
    const double v_lo = values[lo];
    if (lo + 1 >= values.size()) return v_lo;
    const double v_hi = *std::min_element(values.begin() + static_cast<std::ptrdiff_t>(lo) + 1, values.end());
    return v_lo + (rank - static_cast<double>(lo)) * (v_hi - v_lo);
}

// Distance (mm) from each voxel of `from` to the nearest voxel of `to` (both boundary voxel lists).
std::vector<double> directed_distances(const Lattice& lat, const std::vector<PointIndex>& from,
                                       const std::vector<PointIndex>& to) {
    Grid<std::uint8_t> features(lat, 0);
    for (PointIndex i : to) features[i] = 1;
    const Grid<double> dist2 = squared_distance_transform_mm(features);
    std::vector<double> out(from.size());
    for (std::size_t i = 0; i < from.size(); ++i) out[i] = std::sqrt(dist2[from[i]]);
    return out;
}

}  // namespace

std::vector<PointIndex> boundary_voxels(const Grid<std::uint8_t>& mask) {
    const Lattice& lat = mask.lattice();
    const Vec3i d = lat.dims();
    const std::size_t sy = lat.stride_y();
    const std::size_t sz = lat.stride_z();
    std::vector<PointIndex> out;
    for (int z = 0; z < d.z; ++z) {
        for (int y = 0; y < d.y; ++y) {
            for (int x = 0; x < d.x; ++x) {
                const PointIndex i = lat.index({x, y, z});
                if (mask[i] == 0) continue;
                const bool border = x == 0 || y == 0 || z == 0 || x == d.x - 1 || y == d.y - 1 || z == d.z - 1;
                if (border || mask[i - 1] == 0 || mask[i + 1] == 0 || mask[i - sy] == 0 || mask[i + sy] == 0 ||
                    mask[i - sz] == 0 || mask[i + sz] == 0) {
                    out.push_back(i);
                }
            }
        }
    }
    return out;
}

namespace {

// The transform along x of one row of binary features (a voxel is one where f is nonzero, or with
// kZeroIsFeature where it is 0): (x·s − p·s)² to the nearest feature p of the row (the left one on
// a tie), +infinity without one; in double (`left`: a row of scratch), each result rounded once to T.
template <class T, bool kZeroIsFeature>
void feature_row(const std::uint8_t* f, T* d, double* left, int n, double step) {
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const auto is_feature = [&](int x) { return kZeroIsFeature ? f[x] == 0 : f[x] != 0; };
    int last = -1;
    for (int x = 0; x < n; ++x) {
        if (is_feature(x)) last = x;
        left[x] = last < 0 ? kInf : x * step - last * step;
    }
    int next = -1;
    for (int x = n - 1; x >= 0; --x) {
        if (is_feature(x)) next = x;
        const double right = next < 0 ? kInf : next * step - x * step;
        const double nearest = right < left[x] ? right : left[x];
        d[x] = static_cast<T>(nearest * nearest);
    }
}

template <class T, bool kZeroIsFeature>
Grid<T> transform(const Grid<std::uint8_t>& features, double max_mm2) {
    Grid<T> dist(features.lattice());
    if (dist.size() == 0) return dist;
    const Vec3i d = features.dims();
    const double step = features.lattice().spacing().x;
    tbb::parallel_for(tbb::blocked_range<int>(0, d.z), [&](const tbb::blocked_range<int>& zs) {
        std::vector<double> left(static_cast<std::size_t>(d.x));
        for (int z = zs.begin(); z < zs.end(); ++z)
            for (int y = 0; y < d.y; ++y) {
                const std::size_t row = features.lattice().index({0, y, z});
                feature_row<T, kZeroIsFeature>(features.values().data() + row, dist.values().data() + row, left.data(), d.x, step);
            }
    });
    for (int axis = 1; axis < 3; ++axis) transform_axis(dist, axis, max_mm2);
    return dist;
}

}  // namespace

Grid<double> squared_distance_transform_mm(const Grid<std::uint8_t>& features, double max_mm2) {
    return transform<double, false>(features, max_mm2);
}

Grid<float> squared_distance_to_outside_mm(const Grid<std::uint8_t>& mask) {
    return transform<float, true>(mask, std::numeric_limits<double>::infinity());
}

SurfaceDistance surface_distance(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth) {
    require_same_geometry(mask.lattice(), truth.lattice(), "surface_distance");
    const std::vector<PointIndex> mask_boundary = boundary_voxels(mask);
    const std::vector<PointIndex> truth_boundary = boundary_voxels(truth);
    if (mask_boundary.empty() || truth_boundary.empty()) {
        const double nan = std::numeric_limits<double>::quiet_NaN();
        return {nan, nan, nan};
    }
    std::vector<double> m2t = directed_distances(mask.lattice(), mask_boundary, truth_boundary);
    std::vector<double> t2m = directed_distances(mask.lattice(), truth_boundary, mask_boundary);

    SurfaceDistance r;
    double sum = 0;
    for (double v : m2t) sum += v;
    for (double v : t2m) sum += v;
    r.mean_mm = sum / static_cast<double>(m2t.size() + t2m.size());
    r.hausdorff_mm = std::max(*std::max_element(m2t.begin(), m2t.end()), *std::max_element(t2m.begin(), t2m.end()));
    r.hausdorff95_mm = std::max(percentile(m2t, 0.95), percentile(t2m, 0.95));
    return r;
}

}  // namespace liveset
