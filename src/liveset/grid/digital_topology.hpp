// Local digital topology of a binary voxel set read with 26-connected foreground and 6-connected
// background (the reading of liveset::mask_topology): the topological numbers of a voxel, which
// say whether flipping it changes the set's topology and how. Used to give the phantom a clean
// truth and to keep swarm edits from opening tunnels or bridging surfaces. Header only.
#pragma once

#include <algorithm>
#include <cstdlib>
#include <span>
#include <tuple>
#include <vector>

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

// The 13 lines through a voxel, one direction of each ± pair: 3 along faces, 6 along edges, 4
// along corners (the digital lines a one-voxel gap can lie across).
inline constexpr int kLineDirections[13][3] = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1},  {1, 1, 0},  {1, -1, 0},
                                               {1, 0, 1},  {1, 0, -1}, {0, 1, 1},  {0, 1, -1}, {1, 1, 1},
                                               {1, 1, -1}, {1, -1, 1}, {1, -1, -1}};

// The part of χ = V − E + F − C that starts at corner point (x, y, z), the point shared by voxels
// (x..x+1, y..y+1, z..z+1): its vertex, the three edges, three faces and the cube that start there
// towards +x, +y, +z, each counted when some inside voxel's closed cube holds it.
template <class In>
long euler_corner_26(const In& in, int x, int y, int z) {
    bool a[2][2][2];
    bool any = false;
    for (int k = 0; k < 8; ++k) {
        a[k >> 2][(k >> 1) & 1][k & 1] = in(x + (k & 1), y + ((k >> 1) & 1), z + (k >> 2));
        any = any || a[k >> 2][(k >> 1) & 1][k & 1];
    }
    const long e = long{a[0][0][1] || a[0][1][1] || a[1][0][1] || a[1][1][1]} +  // along x
                   long{a[0][1][0] || a[0][1][1] || a[1][1][0] || a[1][1][1]} +  // along y
                   long{a[1][0][0] || a[1][0][1] || a[1][1][0] || a[1][1][1]};   // along z
    const long f = long{a[0][1][1] || a[1][1][1]} + long{a[1][0][1] || a[1][1][1]} + long{a[1][1][0] || a[1][1][1]};
    return long{any} - e + f - long{a[1][1][1]};
}

// Euler characteristic χ = V − E + F − C of the union of the closed unit cubes of the foreground
// voxels inside the box [lo, hi] (26-connected foreground: χ = components − tunnels + cavities).
// Flipping voxels at least one voxel inside the box changes the whole set's χ exactly as it
// changes this one's: χ is a sum of cell counts, and only the cells of the flipped cubes change.
template <class Inside>
long euler_characteristic_26(Inside&& inside, Vec3i lo, Vec3i hi) {
    const auto in = [&](int x, int y, int z) {
        return x >= lo.x && y >= lo.y && z >= lo.z && x <= hi.x && y <= hi.y && z <= hi.z && inside(Vec3i{x, y, z});
    };
    long chi = 0;
    for (int z = lo.z - 1; z <= hi.z; ++z)
        for (int y = lo.y - 1; y <= hi.y; ++y)
            for (int x = lo.x - 1; x <= hi.x; ++x) chi += euler_corner_26(in, x, y, z);
    return chi;
}

// The corner points whose 2×2×2 window holds one of `voxels` (each voxel's own and the seven
// towards −x, −y, −z), sorted and without repeats: flipping those voxels changes χ only there.
inline std::vector<Vec3i> euler_corners_of(std::span<const Vec3i> voxels) {
    std::vector<Vec3i> corners;
    corners.reserve(voxels.size() * 8);
    for (const Vec3i v : voxels)
        for (int k = 0; k < 8; ++k) corners.push_back(v - Vec3i{k & 1, (k >> 1) & 1, k >> 2});
    const auto key = [](Vec3i c) { return std::tuple(c.z, c.y, c.x); };
    std::sort(corners.begin(), corners.end(), [&](Vec3i a, Vec3i b) { return key(a) < key(b); });
    corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
    return corners;
}

// Σ of euler_corner_26 over `corners`, with `inside` (Vec3i → bool) read as is (no box): taken
// before and after some voxels flip, over euler_corners_of(them), the difference is the change of
// χ of the whole set — that of euler_characteristic_26 over any box one voxel around them.
template <class Inside>
long euler_at_corners_26(const Inside& inside, std::span<const Vec3i> corners) {
    const auto in = [&](int x, int y, int z) { return inside(Vec3i{x, y, z}); };
    long chi = 0;
    for (const Vec3i c : corners) chi += euler_corner_26(in, c.x, c.y, c.z);
    return chi;
}

}  // namespace liveset
