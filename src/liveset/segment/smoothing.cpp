// gaussian_smooth(): a separable, sampled Gaussian in millimetres, one axis after another.
#include "liveset/segment/smoothing.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace liveset {

namespace {

// The sampled, normalised kernel w[0..2r] for σ voxels, r = ⌊4σ + ½⌋.
std::vector<float> kernel(double sigma) {
    const int r = static_cast<int>(4.0 * sigma + 0.5);
    std::vector<double> w(static_cast<std::size_t>(2 * r + 1));
    double sum = 0.0;
    for (int k = -r; k <= r; ++k) sum += w[static_cast<std::size_t>(k + r)] = std::exp(-0.5 * k * k / (sigma * sigma));
    std::vector<float> out(w.size());
    for (std::size_t i = 0; i < w.size(); ++i) out[i] = static_cast<float>(w[i] / sum);
    return out;
}

// One axis: out(p) = Σ_k w[k] in(p + (k − r)·e_axis), the index clamped onto the lattice. Rows of
// x are the unit of work; along y and z the sum runs over whole rows at once (contiguous loads).
void convolve_axis(const Grid<float>& in, Grid<float>& out, int axis, const std::vector<float>& w) {
    const Vec3i d = in.dims();
    const int r = static_cast<int>(w.size() / 2);
    const std::size_t nx = static_cast<std::size_t>(d.x);
    const std::span<const float> src = in.values();
    const std::span<float> dst = out.values();
    const std::size_t rows_total = static_cast<std::size_t>(d.y) * static_cast<std::size_t>(d.z);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows_total, 16), [&](const tbb::blocked_range<std::size_t>& rows) {
        std::vector<float> pad(axis == 0 ? nx + 2 * static_cast<std::size_t>(r) : 0);
        for (std::size_t row = rows.begin(); row != rows.end(); ++row) {
            const int y = static_cast<int>(row % static_cast<std::size_t>(d.y)), z = static_cast<int>(row / static_cast<std::size_t>(d.y));
            float* o = dst.data() + nx * row;
            if (axis == 0) {
                const float* s = src.data() + nx * static_cast<std::size_t>(row);
                for (std::size_t i = 0; i < pad.size(); ++i)
                    pad[i] = s[std::clamp<std::ptrdiff_t>(static_cast<std::ptrdiff_t>(i) - r, 0, static_cast<std::ptrdiff_t>(nx) - 1)];
                for (std::size_t x = 0; x < nx; ++x) {
                    float v = 0.0f;
                    for (std::size_t k = 0; k < w.size(); ++k) v += w[k] * pad[x + k];
                    o[x] = v;
                }
                continue;
            }
            std::fill(o, o + nx, 0.0f);
            for (int k = -r; k <= r; ++k) {
                const int yy = axis == 1 ? std::clamp(y + k, 0, d.y - 1) : y;
                const int zz = axis == 2 ? std::clamp(z + k, 0, d.z - 1) : z;
                const float* s = src.data() + nx * (static_cast<std::size_t>(yy) + static_cast<std::size_t>(d.y) * static_cast<std::size_t>(zz));
                const float wk = w[static_cast<std::size_t>(k + r)];
                for (std::size_t x = 0; x < nx; ++x) o[x] += wk * s[x];
            }
        }
    });
}

}  // namespace

double presmoothing_mm(Vec3f spacing) {
    const double h_min = std::min({spacing.x, spacing.y, spacing.z});  // float -> double: exact
    return std::min(kSmoothVoxels * h_min, kMaxSmoothMm);
}

void check_smooth_mm(double sigma_mm) {
    if (std::isfinite(sigma_mm) && sigma_mm >= 0.0 && sigma_mm <= kMaxSmoothMm) return;
    std::ostringstream os;
    os << "the smoothing sigma must be in [0, " << kMaxSmoothMm << "] mm, not " << sigma_mm;
    throw std::invalid_argument(os.str());
}

Grid<float> gaussian_smooth(const Grid<float>& image, double sigma_mm) {
    check_smooth_mm(sigma_mm);
    Grid<float> out = image;
    if (sigma_mm == 0.0) return out;
    Grid<float> tmp(image.lattice());
    // The voxel sides as float, as the curvature and the automatic α take them.
    const Vec3f h = image.lattice().spacing_float();
    for (int axis = 0; axis < 3; ++axis) {
        // Rounded to 1e-4 voxel: float sizes one unit in the last place apart (a NIfTI's 1.2 mm and a
        // MINC's 1.1999999552 round to neighbouring floats) still give the same kernel.
        const double sigma = std::round(sigma_mm / static_cast<double>(axis == 0 ? h.x : axis == 1 ? h.y : h.z) * 1e4) / 1e4;
        if (sigma < kNegligibleSigma) continue;
        if (sigma > kMaxSmoothVoxels) {
            std::ostringstream os;
            os << "the smoothing sigma " << sigma_mm << " mm is " << sigma << " voxels along " << "xyz"[axis] << ": at most "
               << kMaxSmoothVoxels << " voxels";
            throw std::invalid_argument(os.str());
        }
        convolve_axis(out, tmp, axis, kernel(sigma));
        std::swap(out, tmp);
    }
    return out;
}

}  // namespace liveset
