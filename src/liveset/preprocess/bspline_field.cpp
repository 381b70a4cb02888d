// Cubic B-spline control lattice -> values on a grid, rounding as ITK's BSplineControlPointImageFilter.
#include "liveset/preprocess/bspline_field.hpp"

#include <itkBSplineKernelFunction.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <vector>

namespace liveset {

namespace {

constexpr int kOrder = 3;

// One axis: for each output index, the first of the four control points it reads and their weights.
struct AxisWeights {
    std::vector<int> first;
    std::vector<std::array<float, 4>> weight;
};

// ITK 5's BSplineControlPointImageFilter::DynamicThreadedGenerateData and CollapsePhiLattice, one
// axis, with their types: RealType is float, the kernel is BSplineKernelFunction<3> (double).
AxisWeights axis_weights(int size, int control_points, double spacing) {
    using Real = float;
    const auto kernel = itk::BSplineKernelFunction<kOrder>::New();
    const auto spans = static_cast<unsigned>(control_points - kOrder);
    const Real r = static_cast<Real>(static_cast<Real>(spans) / (static_cast<Real>(size - 1) * spacing));
    const Real epsilon = static_cast<Real>(r * spacing * static_cast<Real>(1e-3));
    AxisWeights w{std::vector<int>(static_cast<std::size_t>(size)), std::vector<std::array<float, 4>>(static_cast<std::size_t>(size))};
    for (int i = 0; i < size; ++i) {
        Real u = static_cast<Real>(spans) * static_cast<Real>(i) / static_cast<Real>(size - 1);
        if (std::abs(u - static_cast<Real>(spans)) <= epsilon) u = static_cast<Real>(spans) - epsilon;
        if (u < Real{0} && std::abs(u) <= epsilon) u = Real{0};
        const auto first = static_cast<unsigned>(u);
        w.first[static_cast<std::size_t>(i)] = static_cast<int>(first);
        for (int k = 0; k <= kOrder; ++k) {
            const long index = static_cast<long>(first) + k;
            const Real v = static_cast<Real>(u - index + 0.5 * static_cast<Real>(kOrder - 1));
            w.weight[static_cast<std::size_t>(i)][static_cast<std::size_t>(k)] = static_cast<Real>(kernel->Evaluate(v));
        }
    }
    return w;
}

// Σ_k values[k·stride] · weight[k] in ITK's order: from 0, one product added at a time.
inline float collapse(const float* values, std::size_t stride, const std::array<float, 4>& weight) {
    float sum = 0.0f;
    for (std::size_t k = 0; k < 4; ++k) sum += values[k * stride] * weight[k];
    return sum;
}

}  // namespace

Grid<float> evaluate_cubic_bspline(std::span<const float> control, Vec3i control_dims, Vec3i size, Vec3d spacing,
                                   const Lattice& out_lattice) {
    const Vec3i count = out_lattice.dims();
    for (int a = 0; a < 3; ++a) {
        if (control_dims[a] < kOrder + 1 || control_dims[a] > 100000)
            throw std::invalid_argument("B-spline control lattice needs 4 to 100000 points per axis, got " + std::to_string(control_dims[a]));
        if (size[a] < 2 || size[a] > 100000)
            throw std::invalid_argument("B-spline evaluation grid needs 2 to 100000 points per axis, got " + std::to_string(size[a]));
        if (!(spacing[a] > 0.0) || !std::isfinite(spacing[a])) throw std::invalid_argument("B-spline evaluation grid spacing must be positive");
        if (count[a] < 1 || count[a] > size[a])
            throw std::invalid_argument("B-spline evaluation count " + std::to_string(count[a]) + " is outside [1, " + std::to_string(size[a]) + "]");
    }
    const auto cx = static_cast<std::size_t>(control_dims.x), cy = static_cast<std::size_t>(control_dims.y);
    if (control.size() != cx * cy * static_cast<std::size_t>(control_dims.z))
        throw std::invalid_argument("B-spline control lattice holds " + std::to_string(control.size()) + " values, not " +
                                    std::to_string(cx * cy * static_cast<std::size_t>(control_dims.z)));
    const AxisWeights wx = axis_weights(size.x, control_dims.x, spacing.x);
    const AxisWeights wy = axis_weights(size.y, control_dims.y, spacing.y);
    const AxisWeights wz = axis_weights(size.z, control_dims.z, spacing.z);
    Grid<float> out(out_lattice);
    tbb::parallel_for(tbb::blocked_range<int>(0, count.z), [&](const tbb::blocked_range<int>& range) {
        std::vector<float> plane(cx * cy), line(cx);
        for (int z = range.begin(); z != range.end(); ++z) {
            const auto zi = static_cast<std::size_t>(z);
            const float* base = control.data() + static_cast<std::size_t>(wz.first[zi]) * cx * cy;
            for (std::size_t p = 0; p < cx * cy; ++p) plane[p] = collapse(base + p, cx * cy, wz.weight[zi]);
            for (int y = 0; y < count.y; ++y) {
                const auto yi = static_cast<std::size_t>(y);
                const float* rows = plane.data() + static_cast<std::size_t>(wy.first[yi]) * cx;
                for (std::size_t x = 0; x < cx; ++x) line[x] = collapse(rows + x, cx, wy.weight[yi]);
                float* dst = &out(Vec3i{0, y, z});
                for (int x = 0; x < count.x; ++x) {
                    const auto xi = static_cast<std::size_t>(x);
                    dst[x] = collapse(line.data() + wx.first[xi], 1, wx.weight[xi]);
                }
            }
        }
    });
    return out;
}

}  // namespace liveset
