// Connected-component labelling, cubical-complex Euler characteristic and Betti numbers of a mask.
#include "liveset/eval/topology.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <array>
#include <cstdlib>
#include <initializer_list>
#include <numeric>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace liveset {

namespace {

// Union-find over provisional labels; the root of a set is its smallest label.
struct LabelForest {
    std::vector<std::uint32_t> parent{0};  // label 0 is the background, never used
    std::uint32_t make() {
        const auto l = static_cast<std::uint32_t>(parent.size());
        parent.push_back(l);
        return l;
    }
    std::uint32_t find(std::uint32_t l) {
        while (parent[l] != l) {
            parent[l] = parent[parent[l]];
            l = parent[l];
        }
        return l;
    }
    std::uint32_t unite(std::uint32_t a, std::uint32_t b) {
        a = find(a);
        b = find(b);
        if (a == b) return a;
        if (b < a) std::swap(a, b);
        parent[b] = a;
        return a;
    }
};

// Unites every run of `row` with each run of `prev` it touches: overlapping x ranges, widened by
// `reach` voxels (0: a face neighbour row; 1: an edge or corner neighbour row under 26-connectivity).
void link_rows(std::span<const VoxelRun> row, std::size_t row_first, std::span<const VoxelRun> prev, std::size_t prev_first, int reach,
               LabelForest& forest) {
    std::size_t j = 0;
    for (std::size_t i = 0; i < row.size(); ++i) {
        const int lo = row[i].x0 - reach, hi = row[i].x1 + reach;
        while (j < prev.size() && prev[j].x1 <= lo) ++j;
        for (std::size_t k = j; k < prev.size() && prev[k].x0 < hi; ++k)
            forest.unite(static_cast<std::uint32_t>(row_first + i + 1), static_cast<std::uint32_t>(prev_first + k + 1));
    }
}


// Contribution to V - E + F - C of the cells "owned" by one lattice vertex: the vertex itself, the
// three edges, three faces and one cube that leave it in the +x/+y/+z directions. A cell belongs to
// the closed-cube union when any voxel incident to it is foreground. Configuration bit
// (dx + 2·dy + 4·dz) is voxel (i-1+dx, j-1+dy, k-1+dz) around vertex (i, j, k).
constexpr std::array<int, 256> make_euler_table() {
    std::array<int, 256> t{};
    for (int c = 0; c < 256; ++c) {
        auto any = [c](std::initializer_list<int> bits) {
            for (int b : bits)
                if (c & (1 << b)) return 1;
            return 0;
        };
        const int vertex = c != 0 ? 1 : 0;
        const int edges = any({1, 3, 5, 7}) + any({2, 3, 6, 7}) + any({4, 5, 6, 7});
        const int faces = any({3, 7}) + any({5, 7}) + any({6, 7});
        const int cube = any({7});
        t[static_cast<std::size_t>(c)] = vertex - edges + faces - cube;
    }
    return t;
}
constexpr std::array<int, 256> kEulerTable = make_euler_table();

// Spreads a 4-bit column (bit dy + 2·dz) to configuration bits dx + 2·dy + 4·dz.
constexpr unsigned spread_column(unsigned col, unsigned dx) {
    unsigned out = 0;
    for (unsigned b = 0; b < 4; ++b)
        if (col & (1u << b)) out |= 1u << (dx + 2 * b);
    return out;
}

long euler_characteristic(const Grid<std::uint8_t>& mask) {
    const Lattice& lat = mask.lattice();
    const Vec3i d = lat.dims();
    if (mask.size() == 0) return 0;
    const std::uint8_t* data = mask.values().data();
    // Vertices run over (d.x+1)·(d.y+1)·(d.z+1); slices of vertices along z are summed in parallel.
    // Integer sums are exact, so the result does not depend on how the range is split.
    return tbb::parallel_reduce(
        tbb::blocked_range<int>(0, d.z + 1), 0L,
        [&](const tbb::blocked_range<int>& r, long acc) {
            for (int k = r.begin(); k < r.end(); ++k) {
                for (int j = 0; j <= d.y; ++j) {
                    // The four voxel rows around this vertex row, or null outside the image.
                    std::array<const std::uint8_t*, 4> rows{};
                    for (int b = 0; b < 4; ++b) {
                        const int y = j - 1 + (b & 1);
                        const int z = k - 1 + (b >> 1);
                        rows[static_cast<std::size_t>(b)] =
                            (y >= 0 && y < d.y && z >= 0 && z < d.z) ? data + lat.index({0, y, z}) : nullptr;
                    }
                    unsigned previous = 0;  // column of voxels at x = i-1
                    for (int i = 0; i <= d.x; ++i) {
                        unsigned current = 0;
                        if (i < d.x)
                            for (unsigned b = 0; b < 4; ++b)
                                if (rows[b] && rows[b][i] != 0) current |= 1u << b;
                        const unsigned config = spread_column(previous, 0) | spread_column(current, 1);
                        acc += kEulerTable[config];
                        previous = current;
                    }
                }
            }
            return acc;
        },
        [](long a, long b) { return a + b; });
}

// Background 6-components that touch no image border face.
std::size_t count_cavities(const Grid<std::uint8_t>& mask) {
    const RunComponents c = component_runs(mask, 6, false);
    const std::vector<std::uint8_t> touches = border_components(c, mask.dims());
    return static_cast<std::size_t>(std::count(touches.begin() + 1, touches.end(), std::uint8_t{0}));
}

}  // namespace

RunComponents component_runs(const Grid<std::uint8_t>& mask, int connectivity, bool foreground) {
    if (connectivity != 6 && connectivity != 26) {
        throw std::invalid_argument("label_components: connectivity must be 6 or 26, got " +
                                    std::to_string(connectivity));
    }
    const Vec3i d = mask.dims();
    const std::uint8_t* in = mask.values().data();
    RunComponents c;
    c.row_begin.assign(static_cast<std::size_t>(d.y) * static_cast<std::size_t>(d.z) + 1, 0);
    // The runs of each plane on every thread (its rows' run counts in row_begin, then summed),
    // joined in plane order: the serial scan's runs.
    std::vector<std::vector<VoxelRun>> plane_runs(static_cast<std::size_t>(d.z));
    tbb::parallel_for(tbb::blocked_range<int>(0, d.z), [&](const tbb::blocked_range<int>& zs) {
        for (int z = zs.begin(); z < zs.end(); ++z) {
            std::vector<VoxelRun>& runs = plane_runs[static_cast<std::size_t>(z)];
            for (int y = 0; y < d.y; ++y) {
                const std::size_t r = static_cast<std::size_t>(z) * static_cast<std::size_t>(d.y) + static_cast<std::size_t>(y);
                const std::uint8_t* row = in + r * static_cast<std::size_t>(d.x);
                const std::size_t before = runs.size();
                for (int x = 0; x < d.x;) {
                    if ((row[x] != 0) != foreground) {
                        ++x;
                        continue;
                    }
                    const int x0 = x;
                    while (x < d.x && (row[x] != 0) == foreground) ++x;
                    runs.push_back({x0, x});
                }
                c.row_begin[r + 1] = runs.size() - before;
            }
        }
    });
    for (std::size_t r = 1; r < c.row_begin.size(); ++r) c.row_begin[r] += c.row_begin[r - 1];
    c.runs.reserve(c.row_begin.back());
    for (const std::vector<VoxelRun>& runs : plane_runs) c.runs.insert(c.runs.end(), runs.begin(), runs.end());
    LabelForest forest;  // run k is label k + 1
    std::vector<std::uint32_t> parent(c.runs.size() + 1);
    std::iota(parent.begin(), parent.end(), std::uint32_t{0});
    forest.parent = std::move(parent);
    const auto row_runs = [&](int y, int z) {
        const std::size_t r = static_cast<std::size_t>(z) * static_cast<std::size_t>(d.y) + static_cast<std::size_t>(y);
        return std::pair{std::span<const VoxelRun>(c.runs.data() + c.row_begin[r], c.runs.data() + c.row_begin[r + 1]), c.row_begin[r]};
    };
    const int diagonal = connectivity == 26 ? 1 : 0;
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y) {
            const auto here = row_runs(y, z);  // (runs, index of the first); no structured binding: captured below
            const std::span<const VoxelRun> row = here.first;
            const std::size_t first = here.second;
            if (row.empty()) continue;
            const auto link = [&](int py, int pz, int reach) {
                if (py < 0 || py >= d.y || pz < 0) return;
                const auto [prev, prev_first] = row_runs(py, pz);
                link_rows(row, first, prev, prev_first, reach, forest);
            };
            link(y - 1, z, diagonal);
            link(y, z - 1, diagonal);
            if (connectivity == 26) {
                link(y - 1, z - 1, 1);
                link(y + 1, z - 1, 1);
            }
        }
    std::vector<std::uint32_t> final_label(forest.parent.size(), 0);
    c.label.resize(c.runs.size());
    std::uint32_t next = 0;
    for (std::size_t k = 0; k < c.runs.size(); ++k) {  // runs are in scan order
        const std::uint32_t root = forest.find(static_cast<std::uint32_t>(k + 1));
        if (final_label[root] == 0) final_label[root] = ++next;
        c.label[k] = final_label[root];
    }
    c.count = next;
    return c;
}

std::vector<std::uint8_t> border_components(const RunComponents& c, Vec3i dims) {
    std::vector<std::uint8_t> touches(c.count + 1, 0);
    for (int z = 0; z < dims.z; ++z)
        for (int y = 0; y < dims.y; ++y) {
            const std::size_t r = static_cast<std::size_t>(z) * static_cast<std::size_t>(dims.y) + static_cast<std::size_t>(y);
            const bool face = z == 0 || y == 0 || z == dims.z - 1 || y == dims.y - 1;
            for (std::size_t k = c.row_begin[r]; k < c.row_begin[r + 1]; ++k)
                if (face || c.runs[k].x0 == 0 || c.runs[k].x1 == dims.x) touches[c.label[k]] = 1;
        }
    return touches;
}

ComponentLabels label_components(const Grid<std::uint8_t>& mask, int connectivity,
                                            std::size_t* count) {
    const RunComponents c = component_runs(mask, connectivity);
    ComponentLabels labels(mask.size(), 0);
    write_runs(c, static_cast<std::size_t>(mask.dims().x), [](std::uint32_t l) { return l; }, std::span<std::uint32_t>(labels));
    if (count) *count = c.count;
    return labels;
}

Topology mask_topology(const Grid<std::uint8_t>& mask) {
    Topology t;
    t.components = component_runs(mask, 26).count;
    t.cavities = count_cavities(mask);
    t.euler_solid = euler_characteristic(mask);
    t.euler = 2 * t.euler_solid;
    t.genus = static_cast<long>(t.components) + static_cast<long>(t.cavities) - t.euler_solid;
    return t;
}

long holes_between(const Topology& truth, const Topology& mask) { return (truth.euler - mask.euler) / 2; }

}  // namespace liveset
