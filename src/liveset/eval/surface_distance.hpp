// Boundary-to-boundary distances between a segmentation mask and a ground-truth mask: Hausdorff
// distance, robust 95% Hausdorff distance and average symmetric surface distance, in millimetres,
// built on an exact separable Euclidean distance transform with anisotropic voxel spacing.
#pragma once

#include <cstdint>
#include <limits>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

// Boundary (surface) voxels of a mask: foreground (nonzero) voxels that have a 6-neighbour
// background voxel or lie on the image border. Linear indices in scan order.
std::vector<PointIndex> boundary_voxels(const Grid<std::uint8_t>& mask);

// Exact squared Euclidean distance, in mm², from every voxel centre to the nearest nonzero voxel
// centre of `features`, using the lattice spacing (Felzenszwalb–Huttenlocher lower envelope of
// parabolas, one separable pass per axis, O(volume)). +infinity everywhere when there is no feature.
// Direction cosines are ignored: distances in an orthonormal frame do not depend on them.
// Lines run in parallel (oneTBB); every line is computed independently, so the result does not
// depend on the thread count. With `max_mm2`, a value above it is only known to be above it
// (+infinity or a larger distance): morphology by a ball of radius r needs no more than r², and
// the passes then skip the sites beyond it.
Grid<double> squared_distance_transform_mm(const Grid<std::uint8_t>& features,
                                           double max_mm2 = std::numeric_limits<double>::infinity());
// The same transform stored in single precision, to the voxels where `mask` is 0 (its complement
// as the features, without building it): half the memory, which a brain mask's depth reads in
// (depth_mm). Each pass computes in double, as the transform above, and rounds its values once to
// float; so at integer spacings every value is the double transform's (squared distances are
// integers, exact in a float below 2^24 mm², distances under 4 m), and at others each pass's
// rounding moves a value by at most a float's half ulp.
Grid<float> squared_distance_to_outside_mm(const Grid<std::uint8_t>& mask);

struct SurfaceDistance {
    // max over both directions of the largest boundary-voxel distance to the other boundary.
    double hausdorff_mm = 0;
    // "95% Hausdorff": max of the two directed 95th percentiles (mask→truth, truth→mask), each the
    // 95th percentile with linear interpolation between order statistics (numpy's default: value at
    // rank 0.95·(n-1) of the sorted distances). This is the definition of plastimatch and of the
    // DeepMind surface-distance package; MedPy's hd95 instead pools both directions, which can be
    // smaller.
    double hausdorff95_mm = 0;
    // Average symmetric surface distance (Heimann et al. 2009): the sum of all directed
    // boundary-voxel distances of both sets divided by the total number of boundary voxels.
    double mean_mm = 0;
};

// Distances between voxel centres of the boundary voxels of `mask` and of `truth` (see
// boundary_voxels). Identical masks give all zeros. When either mask is empty (no boundary), every
// field is NaN. Throws std::invalid_argument when the masks do not share a lattice
// (require_same_geometry in overlap.hpp). O(volume).
SurfaceDistance surface_distance(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth);

}  // namespace liveset
