// Simple-point test (26/6) and topology-preserving region growing; see topology_growth.hpp.
#include "liveset/phantom/topology_growth.hpp"

#include "liveset/grid/digital_topology.hpp"

#include <queue>
#include <utility>

namespace liveset {

bool is_simple_addition(const Lattice& lattice, const std::vector<std::uint8_t>& region, Vec3i p, int connectivity) {
    const auto inside = [&](Vec3i q) { return lattice.contains(q) && region[lattice.index(q)] != 0; };
    return topological_numbers(inside, p, connectivity).simple();
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
