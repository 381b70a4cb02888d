// Binary morphology in mm: exact balls by their chords (as bytes, or separably) or eval's distance transform, components as runs (see morphology.hpp).
#include "liveset/segment/morphology.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <span>
#include <stdexcept>
#include <vector>

#include "liveset/eval/surface_distance.hpp"
#include "liveset/eval/topology.hpp"
#include "liveset/grid/uninit_allocator.hpp"
#include "liveset/segment/voxel_loops.hpp"

namespace liveset {

namespace morphology_detail {

void min_over_chord_16(std::uint8_t* acc, const std::uint8_t* d, std::uint8_t w, std::size_t n) {
#if defined(__SSE2__)
    const __m128i wv = _mm_set1_epi8(static_cast<char>(w));
    for (std::size_t x = 0; x < n; x += 16) {
        const __m128i over = _mm_subs_epu8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(d + x)), wv);
        __m128i* a = reinterpret_cast<__m128i*>(acc + x);
        _mm_storeu_si128(a, _mm_min_epu8(_mm_loadu_si128(a), over));
    }
#else
    for (std::size_t x = 0; x < n; ++x) {
        const std::uint8_t over = d[x] > w ? static_cast<std::uint8_t>(d[x] - w) : std::uint8_t{0};
        acc[x] = over < acc[x] ? over : acc[x];
    }
#endif
}

#if defined(__x86_64__) || defined(__i386__)
[[gnu::target("avx2")]] void min_over_chord_32(std::uint8_t* acc, const std::uint8_t* d, std::uint8_t w, std::size_t n) {
    const __m256i wv = _mm256_set1_epi8(static_cast<char>(w));
    for (std::size_t x = 0; x < n; x += 32) {
        const __m256i over = _mm256_subs_epu8(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(d + x)), wv);
        __m256i* a = reinterpret_cast<__m256i*>(acc + x);
        _mm256_storeu_si256(a, _mm256_min_epu8(_mm256_loadu_si256(a), over));
    }
}
#else
void min_over_chord_32(std::uint8_t* acc, const std::uint8_t* d, std::uint8_t w, std::size_t n) { min_over_chord_16(acc, d, w, n); }
#endif

bool has_avx2() noexcept {
#if defined(__x86_64__) || defined(__i386__)
    static const bool yes = [] {
        __builtin_cpu_init();  // needed where this runs before the processor check's own constructor
        return __builtin_cpu_supports("avx2") != 0;
    }();
    return yes;
#else
    return false;
#endif
}

MinOverChord min_over_chord() noexcept { return has_avx2() ? &min_over_chord_32 : &min_over_chord_16; }

}  // namespace morphology_detail

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

void check_radius(double r) {
    if (!std::isfinite(r) || r < 0) throw std::invalid_argument("morphology radius must be finite and >= 0 mm");
}

Grid<std::uint8_t> complement(const Grid<std::uint8_t>& mask) {
    Grid<std::uint8_t> out(mask.lattice());
    voxel_loops::for_each(mask.size(), [&](std::size_t i) { out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] == 0; });
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
    const std::uint8_t* v = mask.values().data();
    const Box none{d, {0, 0, 0}};
    return voxel_loops::reduce(
        static_cast<std::size_t>(d.z), 1, none,
        [&](std::size_t zb, std::size_t ze, Box b) {
            for (auto z = static_cast<int>(zb); z < static_cast<int>(ze); ++z)
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
        },
        [](const Box& a, const Box& b) {
            return Box{{std::min(a.lo.x, b.lo.x), std::min(a.lo.y, b.lo.y), std::min(a.lo.z, b.lo.z)},
                       {std::max(a.hi.x, b.hi.x), std::max(a.hi.y, b.hi.y), std::max(a.hi.z, b.hi.z)}};
        });
}

Box grown(const Box& b, Vec3i k, Vec3i dims) {
    return {{std::max(b.lo.x - k.x, 0), std::max(b.lo.y - k.y, 0), std::max(b.lo.z - k.z, 0)},
            {std::min(b.hi.x + k.x, dims.x), std::min(b.hi.y + k.y, dims.y), std::min(b.hi.z + k.z, dims.z)}};
}

// The ball's chords across x: for each (dy, dz) whose chord is not empty, the largest x offset w
// with (dx² + dy²) + dz² within the ball's limit, summed in the order the brute force sums them
// (rounding is monotone, so a feature k voxels away along the chord's row is within the ball exactly
// when k <= w).
struct Chord {
    int dy, dz;
    std::uint8_t w;
};

std::vector<Chord> chords(const Ball& b) {
    std::vector<Chord> out;
    for (int dz = -b.k.z; dz <= b.k.z; ++dz)
        for (int dy = -b.k.y; dy <= b.k.y; ++dy) {
            const double yz = b.sq[1][static_cast<std::size_t>(std::abs(dy))], z2 = b.sq[2][static_cast<std::size_t>(std::abs(dz))];
            int w = -1;
            while (w < b.k.x && (b.sq[0][static_cast<std::size_t>(w + 1)] + yz) + z2 <= b.limit) ++w;
            if (w >= 0) out.push_back({dy, dz, static_cast<std::uint8_t>(w)});
        }
    return out;
}

// A byte distance meaning "no feature within the ball along the row": the byte chords take balls
// reaching fewer voxels than this along x.
constexpr int kFar = 255;

// d[x - lo] = voxels to the nearest feature along the row (features: the voxels of
// row[ext_lo..ext_hi) that are nonzero when feature_nonzero, else zero), kFar when none is within
// `cap` (<= kFar); returns the row's smallest distance.
std::uint8_t row_distances(const std::uint8_t* row, bool feature_nonzero, int ext_lo, int ext_hi, int lo, int hi, int cap,
                           std::uint8_t* d) {
    const std::uint8_t want = feature_nonzero ? 1 : 0;
    const auto feature = [&](int x) { return static_cast<std::uint8_t>(row[x] != 0) == want; };
    int dist = cap;
    for (int x = ext_lo; x < lo; ++x) dist = feature(x) ? 0 : std::min(dist + 1, cap);
    for (int x = lo; x < hi; ++x) d[x - lo] = static_cast<std::uint8_t>(dist = feature(x) ? 0 : std::min(dist + 1, cap));
    dist = cap;
    for (int x = ext_hi - 1; x >= hi; --x) dist = feature(x) ? 0 : std::min(dist + 1, cap);
    std::uint8_t smallest = kFar;
    for (int x = hi - 1; x >= lo; --x) {
        dist = feature(x) ? 0 : std::min(dist + 1, cap);
        const int nearest = std::min<int>(dist, d[x - lo]);
        d[x - lo] = static_cast<std::uint8_t>(nearest < cap ? nearest : kFar);
        smallest = std::min(smallest, d[x - lo]);
    }
    return smallest;
}

using morphology_detail::kRowBytes;
using morphology_detail::min_over_chord;
using morphology_detail::MinOverChord;

// 1 inside `out_box` where a feature (a voxel of `mask` that is nonzero when feature_nonzero, else
// zero) lies within the ball, 0 elsewhere: exactly the brute force ((dx² + dy²) + dz² ≤ limit), by
// the ball's chords across x. Per z slice of the box grown by the ball, the distance along each row
// to its nearest feature (a byte); per output row, a feature lies within the ball when, for some
// chord (dy, dz), the row (y + dy, z + dz) has one within the chord's half width w — sixteen or
// more voxels at a time, a saturating subtraction and a minimum per chord, no floating point.
// The slices run in one chunk of z per thread, each with a ring of the 2·K_z + 1 slices its output
// needs (recomputing K_z on either side); every voxel is computed on its own, so the result does
// not depend on the thread count or the chunks. Needs the ball's x reach below kFar; its cost grows
// with the number of chords (~π·K_y·K_z), the separable form's (below) with K_y + K_z.
Grid<std::uint8_t> near_features_bytes(const Grid<std::uint8_t>& mask, bool feature_nonzero, const Box& out_box, const Ball& b,
                                       const std::vector<Chord>& chord) {
    const Lattice& lat = mask.lattice();
    Grid<std::uint8_t> out(lat);
    if (out_box.empty()) return out;
    const Box ext = grown(out_box, b.k, lat.dims());
    const int nx = out_box.size(0), nz = out_box.size(2), ey = ext.size(1);
    const std::size_t sx = (static_cast<std::size_t>(nx) + kRowBytes - 1) / kRowBytes * kRowBytes;  // a row's bytes, padded with kFar
    const std::size_t plane = sx * static_cast<std::size_t>(ey);
    const auto row_of = [&](int y, int z) { return mask.values().data() + (static_cast<std::size_t>(z) * lat.stride_z() + static_cast<std::size_t>(y) * lat.stride_y()); };
    const MinOverChord min_over = min_over_chord();
    const int cap = b.k.x + 1;  // "none within the ball"
    const int tasks = std::max(1, tbb::this_task_arena::max_concurrency());  // results do not depend on it
    const int chunk = std::max(2 * b.k.z + 1, (nz + tasks - 1) / tasks);
    const int ring = 2 * b.k.z + 1;
    tbb::parallel_for(tbb::blocked_range<int>(0, (nz + chunk - 1) / chunk, 1), [&](const tbb::blocked_range<int>& chunks) {
        std::vector<std::uint8_t> slices(plane * static_cast<std::size_t>(ring), std::uint8_t{kFar}), acc(sx);
        UninitVector<std::uint8_t> nearest(static_cast<std::size_t>(ey) * static_cast<std::size_t>(ring));  // per row: its smallest distance
        const auto slot = [&](int z) { return static_cast<std::size_t>((z - ext.lo.z) % ring); };
        const auto d_row = [&](int y, int z) {
            return slices.data() + slot(z) * plane + static_cast<std::size_t>(y - ext.lo.y) * sx;
        };
        const auto row_nearest = [&](int y, int z) { return nearest[slot(z) * static_cast<std::size_t>(ey) + static_cast<std::size_t>(y - ext.lo.y)]; };
        const auto in_plane = [&](int z) {
            for (int y = ext.lo.y; y < ext.hi.y; ++y)
                nearest[slot(z) * static_cast<std::size_t>(ey) + static_cast<std::size_t>(y - ext.lo.y)] =
                    row_distances(row_of(y, z), feature_nonzero, ext.lo.x, ext.hi.x, out_box.lo.x, out_box.hi.x, cap, d_row(y, z));
        };
        for (int c = chunks.begin(); c < chunks.end(); ++c) {
            const int z0 = out_box.lo.z + c * chunk, z1 = std::min(z0 + chunk, out_box.hi.z);
            int done = std::max(z0 - b.k.z, ext.lo.z);  // the next slice to compute
            for (int z = z0; z < z1; ++z) {
                for (; done <= std::min(z + b.k.z, ext.hi.z - 1); ++done) in_plane(done);
                for (int y = out_box.lo.y; y < out_box.hi.y; ++y) {
                    std::fill(acc.begin(), acc.end(), std::uint8_t{kFar});
                    bool any = false;
                    for (const Chord& ch : chord) {
                        const int yy = y + ch.dy, zz = z + ch.dz;
                        if (yy < ext.lo.y || yy >= ext.hi.y || zz < ext.lo.z || zz >= ext.hi.z || row_nearest(yy, zz) > ch.w) continue;
                        any = true;
                        min_over(acc.data(), d_row(yy, zz), ch.w, sx);
                    }
                    if (!any) continue;  // the output is zero already
                    std::uint8_t* o = out.values().data() + static_cast<std::size_t>(z) * lat.stride_z() +
                                      static_cast<std::size_t>(y) * lat.stride_y() + static_cast<std::size_t>(out_box.lo.x);
                    for (int x = 0; x < nx; ++x) o[x] = acc[x] == 0;
                }
            }
        }
    });
    return out;
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
void row_squared_distances(const std::uint8_t* row, bool feature_nonzero, int ext_lo, int ext_hi, int lo, int hi, const Ball& b, int* k,
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
Grid<std::uint8_t> near_features_separable(const Grid<std::uint8_t>& mask, bool feature_nonzero, const Box& out_box, const Ball& b) {
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
                row_squared_distances(row_of(y, z), feature_nonzero, ext.lo.x, ext.hi.x, out_box.lo.x, out_box.hi.x, b, k.data(), g_row(y));
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

// The byte chords up to this many chords (a ball of 8 mm at 1 mm holds 197), where they cost no
// more than the separable form: on BrainWeb's brain mask, one thread, dilation and erosion
// together at 2 / 4 / 6 / 8 / 10 / 12 mm, 37 / 50 / 73 / 111 / 156 / 202 ms against 51 / 70 / 89 /
// 110 / 133 / 160 ms (docs/BENCHMARKS.md, session 74).
constexpr std::size_t kMaxByteChords = 200;

// near_features by the byte chords or the separable form, whichever costs less for this ball (the
// same voxels).
Grid<std::uint8_t> near_features(const Grid<std::uint8_t>& mask, bool feature_nonzero, const Box& out_box, const Ball& b) {
    if (b.k.x < kFar) {
        const std::vector<Chord> chord = chords(b);
        if (chord.size() <= kMaxByteChords) return near_features_bytes(mask, feature_nonzero, out_box, b, chord);
    }
    return near_features_separable(mask, feature_nonzero, out_box, b);
}

// A ball wider than this many voxels along y and z together is applied through the distance
// transform, whose cost does not grow with the radius; a smaller one by its chords (near_features),
// 2-4x faster at the brain mask's 2-6 mm (docs/BENCHMARKS.md, session 58; the transform 180-234 ms
// at 2-16 mm in the table above).
constexpr int kMaxChordVoxels = 40;
bool by_chords(const Ball& b) { return b.k.y + b.k.z <= kMaxChordVoxels; }

// 1 where the squared distance (mm²) to the features is within the ball's limit, by the exact
// distance transform (the same predicate as the chords).
Grid<std::uint8_t> within_by_transform(const Grid<std::uint8_t>& features, const Ball& b) {
    const double r2 = b.limit;
    const Grid<double> d2 = squared_distance_transform_mm(features, r2);
    Grid<std::uint8_t> out(features.lattice());
    voxel_loops::for_each(out.size(), [&](std::size_t i) { out[static_cast<PointIndex>(i)] = d2[static_cast<PointIndex>(i)] <= r2; });
    return out;
}

Grid<std::uint8_t> binarised(const Grid<std::uint8_t>& mask) {
    Grid<std::uint8_t> out(mask.lattice());
    voxel_loops::for_each(mask.size(), [&](std::size_t i) { out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] != 0; });
    return out;
}

}  // namespace

Grid<std::uint8_t> erode_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    check_radius(radius_mm);
    if (radius_mm == 0) return binarised(mask);
    // Only the mask's own box can stay; the outside voxels that can erode it lie within a ball of it.
    const Ball b = ball(mask.lattice(), radius_mm);
    Grid<std::uint8_t> out = by_chords(b) ? near_features(mask, false, bounding_box(mask), b)
                                          : within_by_transform(complement(mask), b);
    voxel_loops::for_each(out.size(), [&](std::size_t i) {
        out[static_cast<PointIndex>(i)] = mask[static_cast<PointIndex>(i)] != 0 && out[static_cast<PointIndex>(i)] == 0;
    });
    return out;
}

Grid<std::uint8_t> dilate_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    check_radius(radius_mm);
    if (radius_mm == 0) return binarised(mask);
    const Ball b = ball(mask.lattice(), radius_mm);
    if (!by_chords(b)) return within_by_transform(mask, b);
    return near_features(mask, true, grown(bounding_box(mask), b.k, mask.dims()), b);
}

Grid<std::uint8_t> close_mm(const Grid<std::uint8_t>& mask, double radius_mm) {
    Grid<std::uint8_t> out = erode_mm(dilate_mm(mask, radius_mm), radius_mm);
    voxel_loops::for_each(out.size(), [&](std::size_t i) { out[static_cast<PointIndex>(i)] |= mask[static_cast<PointIndex>(i)] != 0; });
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

// In single precision, in place (docs/BENCHMARKS.md, session 75): at integer spacings the same bits
// as the double transform's root (the squared distances are the same integers, and a float's root
// of one is the double root rounded, sqrt's double rounding being innocuous); at others the values
// may differ from that by a float's rounding.
Grid<float> depth_mm(const Grid<std::uint8_t>& mask) {
    Grid<float> out = squared_distance_to_outside_mm(mask);
    const std::span<float> v = out.values();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, v.size(), 1 << 16), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) v[i] = std::sqrt(v[i]);
    });
    return out;
}

}  // namespace liveset
