// Binary morphology in millimetres on a lattice with (possibly anisotropic) spacing: erosion,
// dilation and closing by a Euclidean ball (exact: by the ball's chords within the mask's box, as
// byte distances for a ball of up to 200 chords, else separably, or through the distance transform
// for a ball over 40 voxels wide along y and z together), the largest
// connected component and hole filling — the building blocks of the automatic brain mask.
#pragma once

#include <cstddef>
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

namespace morphology_detail {
// The chords' inner loop (morphology.cpp): acc[x] = min(acc[x], max(d[x] - w, 0)) for x < n, a
// multiple of kRowBytes; 0 where a feature lies within w voxels along the row. 16 bytes at a time
// (SSE2), or 32 (AVX2: only where has_avx2(), else the 16-byte loop); the same bytes either way.
// min_over_chord() is the one the processor runs (checked once).
inline constexpr std::size_t kRowBytes = 32;
using MinOverChord = void (*)(std::uint8_t*, const std::uint8_t*, std::uint8_t, std::size_t);
void min_over_chord_16(std::uint8_t* acc, const std::uint8_t* d, std::uint8_t w, std::size_t n);
void min_over_chord_32(std::uint8_t* acc, const std::uint8_t* d, std::uint8_t w, std::size_t n);
bool has_avx2() noexcept;
MinOverChord min_over_chord() noexcept;
}  // namespace morphology_detail

}  // namespace liveset
