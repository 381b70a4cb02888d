// Slab-parallel whole-volume marching cubes: sign bits, per-row crossing-cell words, one
// polygoniser per z-slab with the vertex-index lattice G, and a stitch that gives the naive order.
#include "liveset/mesh/slab_marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <memory>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "liveset/mesh/cell_polygoniser.hpp"
#include "liveset/mesh/mc_tables.hpp"

namespace liveset {

void SlabMarchingCubesOptions::validate() const {
    if (slab_layers < 1) throw std::invalid_argument("slab_layers must be at least 1");
}

namespace {

// Bits of is_inside(v[0..n)), n <= 64.
inline std::uint64_t pack_signs(const float* v, int n) {
    std::uint64_t bits = 0;
    int x = 0;
#if defined(__SSE2__)
    const __m128 zero = _mm_setzero_ps();
    for (; x + 4 <= n; x += 4)  // _mm_cmplt_ps is false for NaN and -0, exactly like is_inside()
        bits |= static_cast<std::uint64_t>(_mm_movemask_ps(_mm_cmplt_ps(_mm_loadu_ps(v + x), zero))) << x;
#endif
    for (; x < n; ++x)
        if (is_inside(v[x])) bits |= std::uint64_t{1} << x;
    return bits;
}

// Crossing edges (bits differing between neighbours) along x in one point row of nx points.
inline std::size_t x_edge_count(const std::uint64_t* r, std::size_t wpr, int nx) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < wpr; ++k) {
        std::uint64_t e = r[k] ^ ((r[k] >> 1) | (k + 1 < wpr ? r[k + 1] << 63 : 0));
        const int valid = nx - 1 - static_cast<int>(64 * k);
        if (valid < 64) e &= valid <= 0 ? 0 : (std::uint64_t{1} << valid) - 1;
        n += static_cast<std::size_t>(std::popcount(e));
    }
    return n;
}

inline std::size_t diff_count(const std::uint64_t* a, const std::uint64_t* b, std::size_t wpr) {
    std::size_t n = 0;
    for (std::size_t k = 0; k < wpr; ++k) n += static_cast<std::size_t>(std::popcount(a[k] ^ b[k]));
    return n;
}

// Sizes of a slab's output: the vertices it creates (every crossing edge of its cell layers
// except the x/y edges of its bottom plane when a slab lies below) and its T entries.
struct SlabCount {
    std::size_t vertices = 0, indices = 0;
};

SlabCount count_slab(const SignBits& s, int z0, int z1) {
    const Vec3i d = s.dims;
    const std::size_t wpr = s.words_per_row;
    SlabCount c;
    for (int z = z0; z < z1; ++z) {
        for (int y = 0; y + 1 < d.y; ++y) {
            const CellRows rows(s, y, z);
            for (std::size_t k = 0; k < wpr; ++k)
                for (std::uint64_t cross = rows.crossing(k, wpr, d.x - 1); cross != 0; cross &= cross - 1)
                    c.indices += 3u * mc::kTables.triangle_count[static_cast<std::size_t>(
                                          rows.cell_case(static_cast<int>(64 * k) + std::countr_zero(cross)))];
        }
        for (int plane = (z == 0 ? 0 : z + 1); plane <= z + 1; ++plane)  // x/y edges of owned planes
            for (int y = 0; y < d.y; ++y) {
                c.vertices += x_edge_count(s.row(y, plane), wpr, d.x);
                if (y + 1 < d.y) c.vertices += diff_count(s.row(y, plane), s.row(y + 1, plane), wpr);
            }
        for (int y = 0; y < d.y; ++y) c.vertices += diff_count(s.row(y, z), s.row(y, z + 1), wpr);  // z edges
    }
    return c;
}

// Index of an x- or y-edge within a z-plane of points: (y * dims.x + x) * 2 + axis.
constexpr std::uint32_t kExternal = 0x8000'0000u;  // T entry naming a vertex of the slab below

// Where one slab writes: its vertices from `vertices` on with global ids from `first_id`, its T
// entries from `indices` on. T entries of the bottom plane's x/y edges (created by the slab
// below) are written as kExternal | plane edge index; `top` receives the global ids of the top
// plane's x/y edges (plane edge index -> id).
struct SlabTarget {
    Vertex* vertices;
    std::uint32_t* indices;
    std::uint32_t first_id;
    std::uint32_t* top;           // null for the last slab
    std::size_t first_layer_end;  // out: T entries written by the first cell layer
};

// Polygonises cell layers [z0, z1); reusable (one per thread).
class SlabWorker {
public:
    SlabCount run(const Grid<float>& phi, const SignBits& s, int z0, int z1, SlabTarget& out);

private:
    void renew(int slot) { generation_[slot] = std::uint64_t{next_generation_++} << 32; }

    std::vector<std::uint64_t> g_;  // 2 slots * plane * 3: (generation << 32) | global id
    std::array<std::uint64_t, 2> generation_{};
    std::uint64_t next_generation_ = 1;
};

SlabCount SlabWorker::run(const Grid<float>& phi, const SignBits& s, int z0, int z1, SlabTarget& out) {
    const Vec3i d = s.dims;
    const std::size_t plane = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y);
    if (g_.size() < 2 * plane * 3 || next_generation_ > 0xFFFF'FF00u) {
        g_.assign(2 * plane * 3, 0);  // generation 0 is never current
        next_generation_ = 1;
    }
    const auto& tables = mc::kTables;
    const std::size_t wpr = s.words_per_row;
    const float* values = phi.values().data();
    const std::size_t sy = static_cast<std::size_t>(d.x), sz = plane;
    SlabCount c;
    for (int z = z0; z < z1; ++z) {
        if (z == z0) {
            renew(0);
            renew(1);
        } else {
            renew((z + 1) & 1);  // plane z - 1 is done; its slot now holds plane z + 1
            if (z == z0 + 1) out.first_layer_end = c.indices;
        }
        const int slot0 = z & 1;
        const bool bottom_external = z0 > 0 && z == z0, top_record = out.top != nullptr && z == z1 - 1;
        for (int y = 0; y + 1 < d.y; ++y) {
            const CellRows rows(s, y, z);
            for (std::size_t k = 0; k < wpr; ++k) {
                for (std::uint64_t cross = rows.crossing(k, wpr, d.x - 1); cross != 0; cross &= cross - 1) {
                    const int x = static_cast<int>(64 * k) + std::countr_zero(cross);
                    const int cs = rows.cell_case(x);
                    std::uint32_t v[mc::kEdges];
                    for (unsigned mask = tables.edges[static_cast<std::size_t>(cs)]; mask != 0; mask &= mask - 1) {
                        const int e = std::countr_zero(mask);
                        const mc::EdgeStart& es = mc::kEdgeStarts[static_cast<std::size_t>(e)];
                        const Vec3i p{x + es.dx, y + es.dy, z + es.dz};
                        const std::size_t pidx = static_cast<std::size_t>(p.y) * sy + static_cast<std::size_t>(p.x);
                        if (bottom_external && es.dz == 0 && es.axis < 2) {
                            v[e] = kExternal | static_cast<std::uint32_t>(pidx * 2 + static_cast<std::size_t>(es.axis));
                            continue;
                        }
                        const int slot = slot0 ^ es.dz;
                        std::uint64_t& entry = g_[static_cast<std::size_t>(slot) * plane * 3 + pidx * 3 + static_cast<std::size_t>(es.axis)];
                        if ((entry & 0xFFFF'FFFF'0000'0000ull) == generation_[slot]) {
                            v[e] = static_cast<std::uint32_t>(entry);
                            continue;
                        }
                        Vec3i q = p;
                        q[es.axis] += 1;
                        const bool interior = p.x >= 1 && p.y >= 1 && p.z >= 1 && q.x <= d.x - 2 && q.y <= d.y - 2 && q.z <= d.z - 2;
                        out.vertices[c.vertices] = interior ? edge_vertex_interior(values, pidx + static_cast<std::size_t>(p.z) * sz, p, es.axis, sy, sz)
                                                            : make_edge_vertex(phi, p, es.axis);
                        const auto id = out.first_id + static_cast<std::uint32_t>(c.vertices++);
                        entry = generation_[slot] | id;
                        if (top_record && es.dz == 1 && es.axis < 2) out.top[pidx * 2 + static_cast<std::size_t>(es.axis)] = id;
                        v[e] = id;
                    }
                    const auto& tri = tables.triangles[static_cast<std::size_t>(cs)];
                    const int n = 3 * tables.triangle_count[static_cast<std::size_t>(cs)];
                    for (int j = 0; j < n; ++j) out.indices[c.indices++] = v[tri[static_cast<std::size_t>(j)]];
                }
            }
        }
    }
    if (z1 == z0 + 1) out.first_layer_end = c.indices;
    return c;
}

}  // namespace

SignBits sign_bits(const Grid<float>& phi) {
    SignBits s;
    s.dims = phi.dims();
    const Vec3i d = s.dims;
    s.words_per_row = (static_cast<std::size_t>(std::max(d.x, 0)) + 63) / 64;
    const std::size_t rows = static_cast<std::size_t>(std::max(d.y, 0)) * static_cast<std::size_t>(std::max(d.z, 0));
    s.words.resize(rows * s.words_per_row);
    const float* v = phi.values().data();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 64), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t row = r.begin(); row != r.end(); ++row) {
            const float* src = v + row * static_cast<std::size_t>(d.x);
            std::uint64_t* dst = s.words.data() + row * s.words_per_row;
            for (std::size_t w = 0; w < s.words_per_row; ++w)
                dst[w] = pack_signs(src + 64 * w, std::min(64, d.x - static_cast<int>(64 * w)));
        }
    });
    return s;
}

Mesh marching_cubes_slabs(const Grid<float>& phi, const SlabMarchingCubesOptions& options) {
    options.validate();
    const Vec3i d = phi.dims();
    Mesh result;
    if (d.x < 2 || d.y < 2 || d.z < 2) return result;
    const SignBits s = sign_bits(phi);
    const int layers = d.z - 1;
    const int nslabs = (layers + options.slab_layers - 1) / options.slab_layers;
    const auto slab_z = [&](int i) { return std::pair{i * options.slab_layers, std::min((i + 1) * options.slab_layers, layers)}; };
    // Pass 1 (parallel): output sizes per slab, so that pass 2 writes in place in the naive order.
    std::vector<SlabCount> counts(static_cast<std::size_t>(nslabs));
    tbb::parallel_for(tbb::blocked_range<int>(0, nslabs, 1), [&](const tbb::blocked_range<int>& r) {
        for (int i = r.begin(); i != r.end(); ++i) counts[static_cast<std::size_t>(i)] = count_slab(s, slab_z(i).first, slab_z(i).second);
    });
    std::vector<std::size_t> voff(counts.size() + 1, 0), ioff(counts.size() + 1, 0);
    for (std::size_t i = 0; i < counts.size(); ++i) {
        voff[i + 1] = voff[i] + counts[i].vertices;
        ioff[i + 1] = ioff[i] + counts[i].indices;
    }
    if (voff.back() >= kExternal) throw std::length_error("mesh has too many vertices for 32-bit indices");
    result.vertices.resize(voff.back());
    result.indices.resize(ioff.back());
    const std::size_t plane_edges = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y) * 2;
    std::vector<std::unique_ptr<std::uint32_t[]>> tops(counts.size());
    std::vector<SlabTarget> targets(counts.size());
    for (std::size_t i = 0; i < counts.size(); ++i) {
        if (i + 1 < counts.size()) tops[i].reset(new std::uint32_t[plane_edges]);
        targets[i] = {result.vertices.data() + voff[i], result.indices.data() + ioff[i], static_cast<std::uint32_t>(voff[i]),
                      tops[i].get(), 0};
    }
    // Pass 2 (parallel): polygonise every slab in place.
    tbb::enumerable_thread_specific<SlabWorker> workers;
    tbb::parallel_for(tbb::blocked_range<int>(0, nslabs, 1), [&](const tbb::blocked_range<int>& r) {
        SlabWorker& w = workers.local();
        for (int i = r.begin(); i != r.end(); ++i) {
            const auto k = static_cast<std::size_t>(i);
            const SlabCount c = w.run(phi, s, slab_z(i).first, slab_z(i).second, targets[k]);
            if (c.vertices != counts[k].vertices || c.indices != counts[k].indices)
                throw std::logic_error("marching_cubes_slabs: slab output differs from its count");
        }
    });
    // Pass 3 (parallel): the first layer of each slab names bottom-plane vertices of the slab below.
    tbb::parallel_for(tbb::blocked_range<std::size_t>(1, counts.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            std::uint32_t* t = targets[i].indices;
            const std::uint32_t* top = tops[i - 1].get();
            for (std::size_t j = 0; j < targets[i].first_layer_end; ++j)
                if ((t[j] & kExternal) != 0) t[j] = top[t[j] & ~kExternal];
        }
    });
    return result;
}

}  // namespace liveset
