// Simple-point test (26/6) and topology-preserving region growing; see topology_growth.hpp.
#include "liveset/phantom/topology_growth.hpp"

#include <cstdlib>
#include <queue>
#include <utility>

namespace liveset {

namespace {

constexpr int cube_index(int dx, int dy, int dz) { return (dx + 1) + 3 * (dy + 1) + 9 * (dz + 1); }

// Number of connected components of the marked cells of the 3x3x3 cube (centre excluded), with
// 26- or 6-adjacency between cells; with `touch_centre`, only components that contain a face
// neighbour of the centre are counted.
int count_components(const bool marked[27], bool use26, bool touch_centre) {
    int label[27] = {};
    int count = 0;
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
                        const int q = cube_index(nx, ny, nz);
                        if (q == 13 || !marked[q] || label[q]) continue;
                        label[q] = count;
                        stack[top++] = q;
                    }
        }
        if (touch_centre && !touches) --count;  // not adjacent to the centre: does not count
    }
    return count;
}

}  // namespace

bool is_simple_addition(const Lattice& lattice, const std::vector<std::uint8_t>& region, Vec3i p, int connectivity) {
    // (26, 6): foreground 26-connected, background 6-connected within the 18-neighbourhood; (6, 26)
    // is the dual reading with the roles swapped.
    const bool fg26 = connectivity == 26;
    bool fg[27] = {}, bg[27] = {};
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const int c = cube_index(dx, dy, dz);
                if (c == 13) continue;
                const Vec3i q{p.x + dx, p.y + dy, p.z + dz};
                const bool in = lattice.contains(q) && region[lattice.index(q)] != 0;
                const bool in18 = std::abs(dx) + std::abs(dy) + std::abs(dz) <= 2;
                fg[c] = in && (fg26 || in18);
                bg[c] = !in && (!fg26 || in18);
            }
    return fg26 ? count_components(fg, true, false) == 1 && count_components(bg, false, true) == 1
                : count_components(fg, false, true) == 1 && count_components(bg, true, false) == 1;
}

void grow_preserving_topology(const Lattice& lattice, std::vector<std::uint8_t>& region,
                              const std::vector<std::uint8_t>& allowed, const std::function<double(Vec3i)>& priority, int connectivity) {
    using Entry = std::pair<double, PointIndex>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
    std::vector<std::uint8_t> queued(region.size(), 0);
    const auto offer_neighbours = [&](Vec3i c) {
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const Vec3i q{c.x + dx, c.y + dy, c.z + dz};
                    if (!lattice.contains(q)) continue;
                    const PointIndex j = lattice.index(q);
                    if (region[j] || !allowed[j] || queued[j]) continue;
                    queued[j] = 1;
                    queue.push({priority(q), j});
                }
    };
    for (std::size_t i = 0; i < region.size(); ++i)
        if (region[i]) offer_neighbours(lattice.coord(static_cast<PointIndex>(i)));
    while (!queue.empty()) {
        const PointIndex i = queue.top().second;
        queue.pop();
        queued[i] = 0;
        if (region[i]) continue;
        const Vec3i c = lattice.coord(i);
        if (!is_simple_addition(lattice, region, c, connectivity)) continue;  // retried when a neighbour joins
        region[i] = 1;
        offer_neighbours(c);
    }
}

}  // namespace liveset
