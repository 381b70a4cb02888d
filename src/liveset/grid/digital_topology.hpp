// Local digital topology of a binary voxel set read with 26-connected foreground and 6-connected
// background (the reading of liveset::mask_topology): the topological numbers of a voxel, which
// say whether flipping it changes the set's topology and how. Used to give the phantom a clean
// truth and to keep swarm edits from opening tunnels or bridging surfaces. Header only.
#pragma once

#include <cstdlib>

#include "liveset/grid/vec3.hpp"

namespace liveset {

// Topological numbers of voxel p (Bertrand & Malandain), its own state ignored:
//   foreground = 26-connected components of the foreground among its 26 neighbours;
//   background = 6-connected components (within the 18-neighbourhood) of the background among its
//                18 neighbours that contain a face neighbour of p.
// p is simple — flipping it changes no component, cavity or tunnel — iff both are 1. Adding p
// with foreground >= 2 joins pieces (a bridge/handle or a merge); with background >= 2 it closes a
// tunnel or seals a cavity. Removing p with background >= 2 opens a tunnel (or a cavity to the
// outside); with foreground >= 2 it cuts a handle or splits a piece.
struct TopologicalNumbers {
    int foreground = 0;
    int background = 0;
    bool simple() const { return foreground == 1 && background == 1; }
};

namespace detail {

inline int cube_cell(int dx, int dy, int dz) { return (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1); }

// Components of the marked cells of the 3x3x3 cube (centre excluded) with 26- or 6-adjacency;
// with `touch_centre`, only those containing a face neighbour of the centre count.
inline int cube_components(const bool marked[27], bool use26, bool touch_centre) {
    int label[27] = {};
    int count = 0, counted = 0;
    for (int start = 0; start < 27; ++start) {
        if (start == 13 || !marked[start] || label[start]) continue;
        int stack[27], top = 0;
        stack[top++] = start;
        label[start] = ++count;
        bool touches = false;
        while (top) {
            const int c = stack[--top];
            const int cx = c % 3 - 1, cy = (c / 3) % 3 - 1, cz = c / 9 - 1;
            if (std::abs(cx) + std::abs(cy) + std::abs(cz) == 1) touches = true;
            for (int dz = -1; dz <= 1; ++dz)
                for (int dy = -1; dy <= 1; ++dy)
                    for (int dx = -1; dx <= 1; ++dx) {
                        const int m = std::abs(dx) + std::abs(dy) + std::abs(dz);
                        if (m == 0 || (!use26 && m != 1)) continue;
                        const int nx = cx + dx, ny = cy + dy, nz = cz + dz;
                        if (nx < -1 || nx > 1 || ny < -1 || ny > 1 || nz < -1 || nz > 1) continue;
                        const int q = cube_cell(nx, ny, nz);
                        if (q == 13 || !marked[q] || label[q]) continue;
                        label[q] = count;
                        stack[top++] = q;
                    }
        }
        if (!touch_centre || touches) ++counted;
    }
    return counted;
}

}  // namespace detail

// `inside(Vec3i q)` -> bool tells whether neighbour q is foreground (the caller decides what lies
// outside the lattice, normally background). connectivity 26 gives the (26, 6) numbers above;
// connectivity 6 the dual (6, 26) reading (foreground 6-connected within the 18-neighbourhood,
// background 26-connected).
template <class Inside>
TopologicalNumbers topological_numbers(Inside&& inside, Vec3i p, int connectivity = 26) {
    const bool fg26 = connectivity == 26;
    bool fg[27] = {}, bg[27] = {};
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int c = detail::cube_cell(dx, dy, dz);
                if (c == 13) continue;
                const bool in = inside(Vec3i{p.x + dx, p.y + dy, p.z + dz});
                const bool in18 = std::abs(dx) + std::abs(dy) + std::abs(dz) <= 2;
                fg[c] = in && (fg26 || in18);
                bg[c] = !in && (!fg26 || in18);
            }
    if (fg26) return {detail::cube_components(fg, true, false), detail::cube_components(bg, false, true)};
    return {detail::cube_components(fg, false, true), detail::cube_components(bg, true, false)};
}

}  // namespace liveset
