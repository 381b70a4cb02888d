// Volume-overlap scores between a segmentation mask and a ground-truth mask (Dice, Jaccard, signed
// volume difference, voxel counts and physical volumes), plus the lattice-compatibility check the
// other evaluation measures share.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "liveset/grid/grid.hpp"

namespace liveset {

// Two lattices count as the same geometry when dims match exactly and spacing, origin and direction
// cosines agree within this absolute tolerance (mm for spacing/origin).
inline constexpr double kEvalGeometryTolerance = 1e-4;

// Throws std::invalid_argument with a one-line message naming `caller` and the two lattices (as
// `mask_name` and `truth_name`: "mask ... differ from truth ..." unless told) when their dims differ,
// or when their spacing/origin/direction differ by more than kEvalGeometryTolerance.
void require_same_geometry(const Lattice& mask, const Lattice& truth, std::string_view caller,
                           std::string_view mask_name = "mask", std::string_view truth_name = "truth");

struct OverlapMetrics {
    double dice = 0;               // 2|M∩T| / (|M|+|T|); 1.0 when both masks are empty
    double jaccard = 0;            // |M∩T| / |M∪T|;     1.0 when both masks are empty
    double volume_difference = 0;  // (V_mask - V_truth) / V_truth, signed; 0 when both are empty,
                                   // +infinity when only the truth is empty
    std::size_t mask_voxels = 0;
    std::size_t truth_voxels = 0;
    std::size_t intersection_voxels = 0;
    double mask_volume_mm3 = 0;   // mask_voxels * spacing.x * spacing.y * spacing.z
    double truth_volume_mm3 = 0;
};

// Nonzero voxels are foreground. Throws std::invalid_argument (see require_same_geometry) when the
// masks do not share a lattice. O(volume), deterministic.
OverlapMetrics compare_overlap(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth);

}  // namespace liveset
