// Binary morphology in millimetres on a lattice with (possibly anisotropic) spacing: erosion,
// dilation and closing by a Euclidean ball (exact: by the ball's chords within the mask's box, or
// through the distance transform for a ball over 40 voxels wide along y and z together), the largest
// connected component and hole filling — the building blocks of the automatic brain mask.
#pragma once

#include <cstdint>

#include "liveset/grid/grid.hpp"

namespace liveset {

// Masks are Grid<std::uint8_t>, nonzero = inside; results hold 0/1.
// The lattice border is not background: a mask touching the border is not eroded from it (an image
// cut through the neck keeps the cut face), and nothing is dilated in from outside the lattice.
// Distances are between voxel centres in mm (lattice spacing; direction cosines do not matter).
// radius_mm must be finite and >= 0 (std::invalid_argument otherwise); radius 0 returns the mask.

// Voxels whose distance to the nearest outside voxel is greater than radius_mm (a mask with no
// outside voxel is returned whole).
Grid<std::uint8_t> erode_mm(const Grid<std::uint8_t>& mask, double radius_mm);
// Voxels within radius_mm of an inside voxel.
Grid<std::uint8_t> dilate_mm(const Grid<std::uint8_t>& mask, double radius_mm);
// mask ∪ erode(dilate(mask, r), r): fills gaps and concavities narrower than the ball.
Grid<std::uint8_t> close_mm(const Grid<std::uint8_t>& mask, double radius_mm);

// The largest 6-connected component (ties: the one whose first voxel comes first in scan order);
// an empty mask stays empty.
Grid<std::uint8_t> largest_component(const Grid<std::uint8_t>& mask);
// Every 6-connected component with at least `fraction` (in (0, 1]) of the largest one's voxels.
Grid<std::uint8_t> large_components(const Grid<std::uint8_t>& mask, double fraction);
// The mask plus every outside region (6-connected) that does not touch the lattice border.
Grid<std::uint8_t> fill_holes(const Grid<std::uint8_t>& mask);

// Distance in mm from every voxel to the nearest voxel outside the mask (0 outside; +infinity when
// the mask has no outside voxel).
Grid<float> depth_mm(const Grid<std::uint8_t>& mask);
// (The Gaussian blur in millimetres is gaussian_smooth(), smoothing.hpp.)

}  // namespace liveset
