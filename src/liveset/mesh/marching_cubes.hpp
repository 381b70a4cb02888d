// Whole-lattice marching cubes: the paper's naive baseline (every cell of the lattice) and a
// band-driven variant that visits only cells having a zero-layer point as a corner. Both visit
// crossing cells in the same ascending order, so they return identical meshes (same V, same T).
#pragma once

#include <span>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/mesh/cell_polygoniser.hpp"
#include "liveset/mesh/mesh.hpp"

namespace liveset {

// Naive marching cubes over every cell of the lattice: O(n³).
Mesh marching_cubes_naive(const Grid<float>& phi);

// Marching cubes over the cells having at least one of `zero_layer` as a corner: O(|zero layer|).
// Complete (identical to marching_cubes_naive) whenever every lattice edge whose endpoints differ in
// sign has at least one endpoint in `zero_layer` (true for a sparse-field zero layer, and for
// zero_crossing_points()). Duplicate points are allowed. Throws std::out_of_range on a bad index.
Mesh marching_cubes_band(const Grid<float>& phi, std::span<const PointIndex> zero_layer);

// Every lattice point having a 6-neighbour of the other sign (is_inside differs): a minimal
// "zero layer" for marching_cubes_band, in ascending order.
std::vector<PointIndex> zero_crossing_points(const Grid<float>& phi);

// Keys of the cells having a corner in `points` (sorted ascending, duplicates removed).
std::vector<CellKey> cells_around_points(const Lattice& lattice, std::span<const PointIndex> points);

// Sorts 32-bit keys ascending and removes duplicates (LSD radix sort: linear time).
void sort_unique(std::vector<std::uint32_t>& keys);

}  // namespace liveset
