// Topology-preserving region growing on the voxel lattice (26-connected foreground, 6-connected
// background — the reading of liveset::mask_topology): a voxel joins the region only when it is a
// simple point, so the region keeps the topology of its start set (a ball stays a ball: one
// component, no cavity, no tunnel). The phantom uses it to give its ground truth a clean topology:
// where voxel sampling of thin folds would create spurious handles or pockets, the few voxels that
// would change the topology are left out. Standard library only.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "liveset/grid/lattice.hpp"

namespace liveset {

// True when adding voxel p (currently background) to the foreground `region` (0/1 per point,
// outside the lattice = background) changes no topology. connectivity 26 (the (26, 6) reading):
// its 26-neighbours in the region form one 26-connected set, and the background voxels of its
// 18-neighbourhood that are 6-adjacent to it lie in one 6-connected set within that
// neighbourhood; connectivity 6: the dual (6, 26) reading.
bool is_simple_addition(const Lattice& lattice, const std::vector<std::uint8_t>& region, Vec3i p, int connectivity = 26);

// Grows `region` (in place; it must be non-empty) into the voxels with allowed[i] != 0, visiting
// candidates in increasing `priority` (ties by point index) and adding each that is simple at that
// moment (in the `connectivity` reading, 26 or 6); a voxel refused is retried whenever a neighbour
// joins. Deterministic, sequential.
void grow_preserving_topology(const Lattice& lattice, std::vector<std::uint8_t>& region,
                              const std::vector<std::uint8_t>& allowed, const std::function<double(Vec3i)>& priority,
                              int connectivity = 26);

}  // namespace liveset
