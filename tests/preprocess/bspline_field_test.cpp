// evaluate_cubic_bspline against ITK's BSplineControlPointImageFilter, the code it replaces in N4's
// full-resolution field: the same bits on random control lattices, anisotropic spacings, grids whose
// sizes do not divide into the spans, a cropped output, and 1 or 2 threads; and its errors.
#include <gtest/gtest.h>
#include <itkBSplineControlPointImageFilter.h>
#include <itkImage.h>
#include <tbb/global_control.h>

#include <cstring>
#include <random>
#include <stdexcept>
#include <vector>

#include "liveset/preprocess/bspline_field.hpp"

using namespace liveset;

namespace {

using Point = itk::Vector<float, 1>;
using ControlImage = itk::Image<Point, 3>;

struct Case {
    Vec3i control;  // control points per axis
    Vec3i size;     // evaluation grid
    Vec3d spacing;
    Vec3i count;    // evaluated voxels (the first of each axis)
};

// ITK's values on the whole grid of `size`, the first `count` voxels of each axis.
std::vector<float> itk_values(const std::vector<float>& control, const Case& c) {
    auto lattice = ControlImage::New();
    ControlImage::SizeType lsize;
    for (int a = 0; a < 3; ++a) lsize[a] = static_cast<itk::SizeValueType>(c.control[a]);
    lattice->SetRegions(lsize);
    lattice->Allocate();
    for (std::size_t i = 0; i < control.size(); ++i) lattice->GetBufferPointer()[i][0] = control[i];
    auto filter = itk::BSplineControlPointImageFilter<ControlImage, ControlImage>::New();
    filter->SetInput(lattice);
    filter->SetSplineOrder(3);
    ControlImage::SizeType size;
    ControlImage::SpacingType spacing;
    for (int a = 0; a < 3; ++a) {
        size[a] = static_cast<itk::SizeValueType>(c.size[a]);
        spacing[a] = c.spacing[a];
    }
    filter->SetSize(size);
    filter->SetSpacing(spacing);
    filter->Update();
    std::vector<float> out;
    const Point* all = filter->GetOutput()->GetBufferPointer();
    for (int z = 0; z < c.count.z; ++z)
        for (int y = 0; y < c.count.y; ++y)
            for (int x = 0; x < c.count.x; ++x)
                out.push_back(all[(static_cast<std::size_t>(z) * c.size.y + static_cast<std::size_t>(y)) * c.size.x + static_cast<std::size_t>(x)][0]);
    return out;
}

}  // namespace

TEST(BsplineField, MatchesItksControlPointFilterBitForBit) {
    const std::vector<Case> cases = {
        {{4, 4, 4}, {31, 37, 31}, {6.0, 6.0, 6.0}, {31, 37, 31}},     // N4's first level on BrainWeb's shrunk grid
        {{7, 8, 7}, {187, 223, 187}, {1.0, 1.0, 1.0}, {181, 217, 181}},  // its third level at full resolution, cropped
        {{5, 9, 6}, {40, 53, 17}, {0.9375, 0.9375, 1.5}, {40, 50, 11}},  // anisotropic, a cropped output
        {{4, 4, 4}, {2, 3, 2}, {2.0, 1.0, 3.0}, {2, 3, 2}},            // the smallest grids
    };
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> value(-0.4f, 0.4f);
    for (const Case& c : cases) {
        std::vector<float> control(static_cast<std::size_t>(c.control.x) * c.control.y * c.control.z);
        for (float& v : control) v = value(rng);
        const std::vector<float> expected = itk_values(control, c);
        for (int threads : {1, 2}) {
            const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads));
            const Grid<float> got = evaluate_cubic_bspline(control, c.control, c.size, c.spacing, Lattice(c.count, {9.0, 9.0, 9.0}));
            ASSERT_EQ(got.dims(), c.count);
            ASSERT_EQ(got.size(), expected.size());
            for (std::size_t i = 0; i < expected.size(); ++i)
                ASSERT_EQ(std::memcmp(&got.values()[i], &expected[i], sizeof(float)), 0)
                    << "voxel " << i << " of grid " << c.size.x << "x" << c.size.y << "x" << c.size.z << ": " << got.values()[i]
                    << " vs ITK " << expected[i] << " (" << threads << " threads)";
        }
    }
}

TEST(BsplineField, ConstantAndLinearControlPointsAreReproduced) {
    // A cubic B-spline reproduces constants and linear functions of the parameter exactly (up to
    // rounding): control points c_k = a + b·(k - 1) give a + b·U along that axis.
    const Vec3i control{6, 4, 4};
    const Vec3i size{41, 9, 5};
    std::vector<float> points(static_cast<std::size_t>(control.x) * control.y * control.z);
    for (int z = 0; z < control.z; ++z)
        for (int y = 0; y < control.y; ++y)
            for (int x = 0; x < control.x; ++x)
                points[(static_cast<std::size_t>(z) * control.y + static_cast<std::size_t>(y)) * control.x + static_cast<std::size_t>(x)] =
                    0.25f + 0.1f * static_cast<float>(x - 1);
    const Grid<float> got = evaluate_cubic_bspline(points, control, size, {1.0, 1.0, 1.0}, Lattice(size));
    for (int x = 0; x < size.x; ++x) {
        const double u = 3.0 * x / (size.x - 1);  // 3 spans
        EXPECT_NEAR(got(Vec3i{x, 4, 2}), 0.25 + 0.1 * u, 1e-5) << x;
    }
}

TEST(BsplineField, BadSizesThrowOneLine) {
    const std::vector<float> points(64, 0.0f);
    EXPECT_THROW(evaluate_cubic_bspline(points, {3, 4, 4}, {10, 10, 10}, {1.0, 1.0, 1.0}, Lattice({10, 10, 10})), std::invalid_argument);
    EXPECT_THROW(evaluate_cubic_bspline(points, {4, 4, 4}, {1, 10, 10}, {1.0, 1.0, 1.0}, Lattice({1, 10, 10})), std::invalid_argument);
    EXPECT_THROW(evaluate_cubic_bspline(points, {4, 4, 4}, {10, 10, 10}, {1.0, 1.0, 1.0}, Lattice({11, 10, 10})), std::invalid_argument);
    EXPECT_THROW(evaluate_cubic_bspline(points, {4, 4, 4}, {10, 10, 10}, {0.0, 1.0, 1.0}, Lattice({10, 10, 10})), std::invalid_argument);
    EXPECT_THROW(evaluate_cubic_bspline(std::vector<float>(63, 0.0f), {4, 4, 4}, {10, 10, 10}, {1.0, 1.0, 1.0}, Lattice({10, 10, 10})),
                 std::invalid_argument);
}
