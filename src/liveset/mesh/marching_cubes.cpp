// Whole-lattice marching cubes (naive and band-driven) and the cell-set helpers they share with
// the fragment mesher.
#include "liveset/mesh/marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace liveset {

namespace {

Vec3i cell_dims(const Lattice& l) {
    const Vec3i d = l.dims();
    return {std::max(d.x - 1, 0), std::max(d.y - 1, 0), std::max(d.z - 1, 0)};
}

}  // namespace

void sort_unique(std::vector<std::uint32_t>& keys) {
    if (keys.size() < 256) {
        std::sort(keys.begin(), keys.end());
    } else {
        std::vector<std::uint32_t> tmp(keys.size());
        for (int shift = 0; shift < 32; shift += 8) {
            std::array<std::size_t, 257> count{};
            for (std::uint32_t k : keys) ++count[((k >> shift) & 0xFFu) + 1];
            if (count[1] == keys.size() && shift > 0) continue;  // this byte is 0 everywhere
            for (int i = 0; i < 256; ++i) count[i + 1] += count[i];
            for (std::uint32_t k : keys) tmp[count[(k >> shift) & 0xFFu]++] = k;
            keys.swap(tmp);
        }
    }
    keys.erase(std::unique(keys.begin(), keys.end()), keys.end());
}

std::vector<CellKey> cells_around_points(const Lattice& lattice, std::span<const PointIndex> points) {
    const Vec3i nc = cell_dims(lattice);
    std::vector<CellKey> cells;
    if (nc.x == 0 || nc.y == 0 || nc.z == 0) return cells;
    cells.reserve(points.size() * 8);
    for (PointIndex i : points) {
        if (i >= lattice.size()) throw std::out_of_range("zero-layer point index outside the lattice");
        const Vec3i p = lattice.coord(i);
        const int x0 = std::max(p.x - 1, 0), x1 = std::min(p.x, nc.x - 1);
        const int y0 = std::max(p.y - 1, 0), y1 = std::min(p.y, nc.y - 1);
        const int z0 = std::max(p.z - 1, 0), z1 = std::min(p.z, nc.z - 1);
        for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y)
                for (int x = x0; x <= x1; ++x) cells.push_back(lattice.index({x, y, z}));
    }
    sort_unique(cells);
    return cells;
}

Mesh marching_cubes_naive(const Grid<float>& phi) {
    Mesh out;
    CellPolygoniser poly;
    poly.polygonise_box(phi, {0, 0, 0}, cell_dims(phi.lattice()), out);
    return out;
}

Mesh marching_cubes_band(const Grid<float>& phi, std::span<const PointIndex> zero_layer) {
    Mesh out;
    const std::vector<CellKey> cells = cells_around_points(phi.lattice(), zero_layer);
    CellPolygoniser poly;
    poly.polygonise_cells(phi, {0, 0, 0}, cell_dims(phi.lattice()), cells, out);
    return out;
}

std::vector<PointIndex> zero_crossing_points(const Grid<float>& phi) {
    const Lattice& l = phi.lattice();
    const Vec3i d = l.dims();
    std::vector<PointIndex> pts;
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) {
                const Vec3i p{x, y, z};
                const bool in = is_inside(phi(p));
                bool crossing = false;
                for (int a = 0; a < 3 && !crossing; ++a)
                    for (int s = -1; s <= 1 && !crossing; s += 2) {
                        Vec3i q = p;
                        q[a] += s;
                        if (l.contains(q) && is_inside(phi(q)) != in) crossing = true;
                    }
                if (crossing) pts.push_back(l.index(p));
            }
    return pts;
}

}  // namespace liveset
