// Where a segmented shell is perforated or has spurious cavities: the places to point a repair at. A perforation is a
// 6-connected region of missed truth (truth and not mask) that touches, through voxels outside the
// mask, both the tissue the shell should enclose (`inner`, e.g. white matter under grey matter) and
// the tissue outside it (neither truth nor inner, e.g. CSF) — a tunnel of the mask's outside
// through the shell. Used by the demo and tests to place swarm targets "at the holes" as a user
// would, from the ground truth.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

struct Perforation {
    std::size_t voxels = 0;  // missed truth voxels in the region
    Vec3d centroid;          // index space
    Vec3i nearest;           // the region's voxel nearest the centroid (lies in the region)
};

// Largest first (ties by centroid). All grids must share dimensions (std::invalid_argument).
std::vector<Perforation> find_perforations(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth,
                                           const Grid<std::uint8_t>& inner);

// Spurious cavities: 6-connected components of the mask's outside that are enclosed (touch
// neither the image border nor any `inner` voxel), e.g. a one-voxel bubble a noisy voxel left in
// the tissue. They are holes as `holes_between` counts them (each adds one to the mask's b2) but no
// perforation. The shell's legitimate cavity (its `inner` core) is never reported. Largest first
// (ties by centroid); `nearest` is the cavity voxel nearest its centroid. Same dimensions required.
std::vector<Perforation> find_cavities(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& inner);

// Tunnels of the mask that missed truth closes without being a perforation (e.g. a one-voxel
// pinhole through the shell, or a crack between two fronts): 6-connected regions of missed truth
// (truth and not mask) whose filling raises the mask's Euler characteristic (counted in the
// region's box). Largest first (ties by centroid). Same dimensions required.
std::vector<Perforation> find_missed_tunnels(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth);

// Handles of the mask made of `inner` tissue it took in (e.g. white matter in a grey-matter
// segmentation, bridging a fold): 26-connected regions of mask and inner whose removal raises the
// mask's Euler characteristic (counted in the region's box) and leaves its pieces and cavities as
// they are (mask_topology with and without the region), so removing it cuts a handle. `voxels` is
// the region's size. Largest first (ties by centroid). Same dimensions required.
std::vector<Perforation> find_inner_handles(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& inner);

}  // namespace liveset
