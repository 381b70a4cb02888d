// Topology of a binary mask: connected components, enclosed cavities, Euler characteristic of the
// voxel solid and of its surface, and the number of tunnels/handles — the measures used to count the
// "holes" a segmentation has compared with its ground truth. Also a reusable connected-component
// labelling.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

// Connected-component labelling of the nonzero voxels. connectivity is 6 (face neighbours) or 26
// (face, edge and corner neighbours); anything else throws std::invalid_argument. Returns one label
// per voxel (linear index): 0 for background, 1..count for foreground, numbered in scan order
// (x fastest) of each component's first voxel, so the result is deterministic. `count` may be null.
using ComponentLabels = LargeVector<std::uint32_t>;

// The same components as runs: each row's (x fastest, row r = y + z·dims.y) maximal runs
// [x0, x1) of voxels whose nonzero-ness equals `foreground`, runs[row_begin[r] .. row_begin[r+1]),
// in scan order, with their component's label (1..count, numbered as label_components numbers
// them). For work per component (sizes, selection, fills) without a label per voxel.
struct VoxelRun {
    int x0, x1;
};
struct RunComponents {
    std::vector<VoxelRun> runs;
    std::vector<std::size_t> row_begin;
    std::vector<std::uint32_t> label;
    std::size_t count = 0;
};
RunComponents component_runs(const Grid<std::uint8_t>& mask, int connectivity, bool foreground = true);
// Per label (index 0 unused): 1 when one of its runs lies on the lattice's border.
std::vector<std::uint8_t> border_components(const RunComponents& components, Vec3i dims);
// Writes value(label) over every run of `components` into `out` (a lattice's values, x fastest, rows
// of `nx`); voxels outside the runs are left as they are.
template <class T, class Value>
void write_runs(const RunComponents& components, std::size_t nx, Value value, std::span<T> out) {
    for (std::size_t r = 0; r + 1 < components.row_begin.size(); ++r)
        for (std::size_t k = components.row_begin[r]; k < components.row_begin[r + 1]; ++k)
            std::fill(out.begin() + static_cast<std::ptrdiff_t>(r * nx + static_cast<std::size_t>(components.runs[k].x0)),
                      out.begin() + static_cast<std::ptrdiff_t>(r * nx + static_cast<std::size_t>(components.runs[k].x1)),
                      static_cast<T>(value(components.label[k])));
}
ComponentLabels label_components(const Grid<std::uint8_t>& mask, int connectivity,
                                            std::size_t* count);

// The mask's foreground is read as the union of its closed unit voxel cubes; everything outside the
// image counts as background. With that reading, 26-connectivity of the foreground and
// 6-connectivity of the background are exactly the connectivity of the solid and of its complement.
struct Topology {
    std::size_t components = 0;  // foreground components, 26-connected (Betti number b0)
    std::size_t cavities = 0;    // background components (6-connected) not touching the image border (b2)
    long euler_solid = 0;        // χ of the union of closed voxel cubes: V - E + F - C
    long euler = 0;              // χ of its boundary surface = 2·euler_solid
    long genus = 0;              // b1 = components + cavities - euler_solid: tunnels/handles
};

// O(volume). The Euler characteristic is counted from 2x2x2 voxel configurations with a lookup
// table (no per-voxel allocation); the component counts use label_components.
Topology mask_topology(const Grid<std::uint8_t>& mask);

// The paper's "holes" of a mask relative to its ground truth: (truth.euler - mask.euler) / 2.
// A closed thick spherical shell has euler 4; each perforation through it lowers euler by 2, so a
// shell with k perforations has k holes relative to the closed shell. Negative when the mask has
// fewer tunnels/more closed pieces than the truth.
long holes_between(const Topology& truth, const Topology& mask);

}  // namespace liveset
