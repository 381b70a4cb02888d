// Robust intensity normalisation and seed-neighbourhood statistics.
#include "liveset/segment/intensity.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>

#include "liveset/grid/large_page_allocator.hpp"
#include "liveset/segment/voxel_loops.hpp"

namespace liveset {

namespace {

void check_roi(const Grid<float>& image, const Grid<std::uint8_t>* roi) {
    if (roi && !(roi->dims() == image.dims())) {
        std::ostringstream os;
        os << "region-of-interest mask " << roi->dims() << " does not match the image " << image.dims();
        throw std::invalid_argument(os.str());
    }
}

// Value at fraction q in [0, 1] of `v` (linear interpolation between order statistics); reorders v.
template <class Alloc>
double quantile(std::vector<float, Alloc>& v, double q) {
    const double pos = q * static_cast<double>(v.size() - 1);
    const auto lo = static_cast<std::size_t>(std::floor(pos));
    const std::size_t hi = std::min(lo + 1, v.size() - 1);
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(lo), v.end());
    const double a = v[lo];
    if (hi == lo) return a;
    const double b = *std::min_element(v.begin() + static_cast<std::ptrdiff_t>(lo) + 1, v.end());
    return a + (pos - static_cast<double>(lo)) * (b - a);
}

}  // namespace

double IntensityScale::to_unit(double raw) const {
    return std::clamp((raw - low) / (high - low), 0.0, 1.0);
}

double IntensityScale::to_raw(double unit) const { return low + unit * (high - low); }

float value_below(float lo, float hi) { return hi > lo ? lo - 0.01f * (hi - lo) : lo - 1.0f; }

void lower_voxels(Grid<float>& image, const Grid<std::uint8_t>& where) {
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (PointIndex i = 0; i < image.size(); ++i)
        if (where[i] == 0) lo = std::min(lo, image[i]), hi = std::max(hi, image[i]);
    if (lo > hi) return;  // every voxel is to be lowered: no other to lie below
    const float below = value_below(lo, hi);
    for (PointIndex i = 0; i < image.size(); ++i)
        if (where[i] != 0) image[i] = below;
}

std::optional<Grid<std::uint8_t>> lower_no_data(Grid<float>& image) {
    std::optional<Grid<std::uint8_t>> nan;
    std::uint64_t count = 0, inf = 0;
    for (PointIndex i = 0; i < image.size(); ++i) {
        inf += std::isinf(image[i]);
        if (!std::isnan(image[i])) continue;
        if (!nan) nan.emplace(image.lattice(), 0);
        (*nan)[i] = 1;
        ++count;
    }
    if (inf) throw std::invalid_argument("the image has " + std::to_string(inf) + " infinite voxel(s)");
    if (count == image.size()) throw std::invalid_argument("every voxel of the image is NaN (no data)");
    if (nan) lower_voxels(image, *nan);
    return nan;
}

IntensityScale robust_scale(const Grid<float>& image, const Grid<std::uint8_t>* roi, const ScaleOptions& options) {
    check_roi(image, roi);
    const double lp = options.low_percentile, hp = options.high_percentile;
    if (!(lp >= 0.0 && hp <= 100.0 && lp < hp))
        throw std::invalid_argument("intensity percentiles must satisfy 0 <= low < high <= 100");
    LargeVector<float> v;  // huge pages: a copy of a brain's voxels
    v.reserve(image.size());
    const std::span<const float> values = image.values();
    for (std::size_t i = 0; i < values.size(); ++i) {
        if (roi && (*roi)[static_cast<PointIndex>(i)] == 0) continue;
        if (!std::isfinite(values[i])) throw std::invalid_argument("image has non-finite voxels");
        v.push_back(values[i]);
    }
    if (v.empty()) throw std::invalid_argument("region-of-interest mask selects no voxel");
    IntensityScale s;
    s.low = quantile(v, lp / 100.0);
    s.high = quantile(v, hp / 100.0);
    if (!(s.high > s.low)) {
        std::ostringstream os;
        os << "image intensities are flat between the " << lp << "th and " << hp << "th percentiles (" << s.low
           << "): nothing to segment";
        throw std::invalid_argument(os.str());
    }
    return s;
}

Grid<float> normalise(const Grid<float>& image, const IntensityScale& scale) {
    Grid<float> out(image.lattice());
    const std::span<const float> in = image.values();
    const std::span<float> o = out.values();
    voxel_loops::for_each(in.size(), [&](std::size_t i) { o[i] = static_cast<float>(scale.to_unit(in[i])); });
    return out;
}

bool ball_touches(const Grid<std::uint8_t>& mask, const SeedBall& s) {
    const Vec3i d = mask.dims();
    const double r = std::max(s.radius, 0.5);
    Vec3i lo, hi;
    for (int a = 0; a < 3; ++a) {
        lo[a] = std::max(0, static_cast<int>(std::floor(s.center[a] - r)));
        hi[a] = std::min(d[a] - 1, static_cast<int>(std::ceil(s.center[a] + r)));
    }
    for (int z = lo.z; z <= hi.z; ++z)
        for (int y = lo.y; y <= hi.y; ++y)
            for (int x = lo.x; x <= hi.x; ++x)
                if (mask({x, y, z}) != 0 && norm(Vec3d{double(x), double(y), double(z)} - s.center) <= r) return true;
    return false;
}

std::vector<float> seed_values(const Grid<float>& image, std::span<const SeedBall> seeds, const Grid<std::uint8_t>* roi) {
    check_roi(image, roi);
    const Lattice& l = image.lattice();
    std::vector<float> v;
    for (const SeedBall& s : seeds) {
        if (!l.contains(s.center)) {
            std::ostringstream os;
            os << "seed " << s.center << " lies outside the image " << l.dims();
            throw std::invalid_argument(os.str());
        }
        if (!std::isfinite(s.radius) || s.radius < 0) throw std::invalid_argument("seed radius must be finite and >= 0");
        const Vec3i d = l.dims();
        Vec3i lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = std::max(0, static_cast<int>(std::floor(s.center[a] - s.radius)));
            hi[a] = std::min(d[a] - 1, static_cast<int>(std::ceil(s.center[a] + s.radius)));
        }
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) {
                    const Vec3i p{x, y, z};
                    const Vec3d q{static_cast<double>(x), static_cast<double>(y), static_cast<double>(z)};
                    if (norm(q - s.center) > std::max(s.radius, 0.5)) continue;
                    if (roi && (*roi)(p) == 0) continue;
                    v.push_back(image(p));
                }
    }
    if (v.empty()) throw std::invalid_argument("the seeds cover no voxel (inside the region of interest)");
    return v;
}

SeedStatistics seed_statistics(const Grid<float>& image, std::span<const SeedBall> seeds, const Grid<std::uint8_t>* roi) {
    return seed_statistics_of(seed_values(image, seeds, roi));
}

SeedStatistics seed_statistics_of(std::vector<float> v) {
    if (v.empty()) throw std::invalid_argument("no seed voxel to take statistics of");
    SeedStatistics st;
    st.voxels = v.size();
    double sum = 0, sum2 = 0;
    for (float x : v) {
        sum += x;
        sum2 += static_cast<double>(x) * x;
    }
    st.mean = sum / static_cast<double>(v.size());
    st.stddev = std::sqrt(std::max(0.0, sum2 / static_cast<double>(v.size()) - st.mean * st.mean));
    st.median = quantile(v, 0.5);
    for (float& x : v) x = static_cast<float>(std::abs(x - st.median));
    st.mad_sigma = 1.4826 * quantile(v, 0.5);
    return st;
}

}  // namespace liveset
