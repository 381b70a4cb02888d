// Fast whole-volume marching cubes for a φ with no band (e.g. read from a file): one vectorised
// sign pass packs is_inside() into bits, crossing cells are found 64 at a time per x-row from the
// bits, and z-slabs of cell layers are polygonised in parallel (oneTBB) and stitched so that the
// result is IDENTICAL (same V, same T, same order) to marching_cubes_naive whatever the thread count.
#pragma once

#include <cstdint>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/mesh/mesh.hpp"
#include "liveset/mesh/sign_bits.hpp"

namespace liveset {

struct SlabMarchingCubesOptions {
    // Cell layers per z-slab (the unit of parallel work). Any value >= 1 gives the same mesh.
    int slab_layers = 16;
    void validate() const;  // throws std::invalid_argument on slab_layers < 1
};

// Equal to marching_cubes_naive(phi) (vertices bit-identical, same indices), computed with the
// sign bits and z-slabs in parallel. O(volume / 64) word operations plus O(surface) polygonising.
Mesh marching_cubes_slabs(const Grid<float>& phi, const SlabMarchingCubesOptions& options = {});

// The sign pass (parallel over z, vectorised where SSE2 is available).
SignBits sign_bits(const Grid<float>& phi);

}  // namespace liveset
