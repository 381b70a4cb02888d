// Slab-parallel whole-volume marching cubes: sign bits, per-row crossing-cell words, one
// polygoniser per z-slab with the vertex-index lattice G, and a stitch that gives the naive order.
#include "liveset/mesh/slab_marching_cubes.hpp"

#include <algorithm>
#include <array>
#include <bit>
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

inline int bit(const std::uint64_t* row, int x) { return static_cast<int>((row[x >> 6] >> (x & 63)) & 1u); }

// The G offset (start corner dx, dy, dz; axis) of every cube edge.
struct EdgeStart {
    int dx, dy, dz, axis;
};
constexpr std::array<EdgeStart, mc::kEdges> kEdgeStarts = [] {
    std::array<EdgeStart, mc::kEdges> t{};
    for (int e = 0; e < mc::kEdges; ++e) {
        const mc::EdgeInfo info = mc::edge_info(e);
        t[static_cast<std::size_t>(e)] = {mc::corner_offset(info.start_corner, 0), mc::corner_offset(info.start_corner, 1),
                                          mc::corner_offset(info.start_corner, 2), info.axis};
    }
    return t;
}();

// Index of an x- or y-edge within a z-plane of points: (y * dims.x + x) * 2 + axis.
constexpr std::uint32_t kExternal = 0x8000'0000u;  // T entry naming a vertex of the slab below

// One slab's output. Vertex ids in mesh.indices are local (creation order), except entries with
// kExternal set: x/y-edge vertices of the slab's bottom plane, created by the slab below and named
// by their plane edge index. `top` maps the plane edge index of the top plane to a local id.
struct SlabOut {
    Mesh mesh;
    std::unique_ptr<std::uint32_t[]> top;
};

// Polygonises cell layers [z0, z1) into a SlabOut; reusable (one per thread).
class SlabWorker {
public:
    void run(const Grid<float>& phi, const SignBits& s, int z0, int z1, SlabOut& out);

private:
    void renew(int slot) { generation_[slot] = std::uint64_t{next_generation_++} << 32; }

    std::vector<std::uint64_t> g_;  // 2 slots * plane * 3: (generation << 32) | local id
    std::array<std::uint64_t, 2> generation_{};
    std::uint64_t next_generation_ = 1;
};

void SlabWorker::run(const Grid<float>& phi, const SignBits& s, int z0, int z1, SlabOut& out) {
    const Vec3i d = s.dims;
    const std::size_t plane = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y);
    if (g_.size() < 2 * plane * 3 || next_generation_ > 0xFFFF'FF00u) {
        g_.assign(2 * plane * 3, 0);  // generation 0 is never current
        next_generation_ = 1;
    }
    const bool has_below = z0 > 0, has_above = z1 < d.z - 1;
    if (has_above) out.top.reset(new std::uint32_t[plane * 2]);
    const auto& tables = mc::kTables;
    const int ncx = d.x - 1;
    const std::size_t wpr = s.words_per_row;
    Mesh& m = out.mesh;
    std::uint32_t own = 0;
    for (int z = z0; z < z1; ++z) {
        if (z == z0) {
            renew(0);
            renew(1);
        } else {
            renew((z + 1) & 1);  // plane z - 1 is done; its slot now holds plane z + 1
        }
        const int slot0 = z & 1;
        const bool bottom_external = has_below && z == z0, top_record = has_above && z == z1 - 1;
        for (int y = 0; y + 1 < d.y; ++y) {
            const std::uint64_t* r00 = s.row(y, z);
            const std::uint64_t* r10 = s.row(y + 1, z);
            const std::uint64_t* r01 = s.row(y, z + 1);
            const std::uint64_t* r11 = s.row(y + 1, z + 1);
            for (std::size_t k = 0; k < wpr; ++k) {
                const std::uint64_t o = r00[k] | r10[k] | r01[k] | r11[k];
                const std::uint64_t a = r00[k] & r10[k] & r01[k] & r11[k];
                const std::uint64_t o1 = k + 1 < wpr ? (r00[k + 1] | r10[k + 1] | r01[k + 1] | r11[k + 1]) : 0;
                const std::uint64_t a1 = k + 1 < wpr ? (r00[k + 1] & r10[k + 1] & r01[k + 1] & r11[k + 1]) : 0;
                std::uint64_t cross = (o | (o >> 1) | (o1 << 63)) & ~(a & ((a >> 1) | (a1 << 63)));
                const int valid = ncx - static_cast<int>(64 * k);  // cells x < ncx only
                if (valid < 64) cross &= valid <= 0 ? 0 : (std::uint64_t{1} << valid) - 1;
                for (; cross != 0; cross &= cross - 1) {
                    const int x = static_cast<int>(64 * k) + std::countr_zero(cross);
                    const int cs = bit(r00, x) | bit(r00, x + 1) << 1 | bit(r10, x) << 2 | bit(r10, x + 1) << 3 |
                                   bit(r01, x) << 4 | bit(r01, x + 1) << 5 | bit(r11, x) << 6 | bit(r11, x + 1) << 7;
                    std::uint32_t v[mc::kEdges];
                    for (unsigned mask = tables.edges[static_cast<std::size_t>(cs)]; mask != 0; mask &= mask - 1) {
                        const int e = std::countr_zero(mask);
                        const EdgeStart& es = kEdgeStarts[static_cast<std::size_t>(e)];
                        const std::size_t pidx = static_cast<std::size_t>(y + es.dy) * static_cast<std::size_t>(d.x) +
                                                 static_cast<std::size_t>(x + es.dx);
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
                        if (own >= kExternal) throw std::length_error("mesh has too many vertices for 32-bit indices");
                        m.vertices.push_back(make_edge_vertex(phi, {x + es.dx, y + es.dy, z + es.dz}, es.axis));
                        entry = generation_[slot] | own;
                        if (top_record && es.dz == 1 && es.axis < 2) out.top[pidx * 2 + static_cast<std::size_t>(es.axis)] = own;
                        v[e] = own++;
                    }
                    const auto& tri = tables.triangles[static_cast<std::size_t>(cs)];
                    const int n = 3 * tables.triangle_count[static_cast<std::size_t>(cs)];
                    for (int j = 0; j < n; ++j) m.indices.push_back(v[tri[static_cast<std::size_t>(j)]]);
                }
            }
        }
    }
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
    std::vector<SlabOut> slabs(static_cast<std::size_t>(nslabs));
    tbb::enumerable_thread_specific<SlabWorker> workers;
    tbb::parallel_for(tbb::blocked_range<int>(0, nslabs, 1), [&](const tbb::blocked_range<int>& r) {
        SlabWorker& w = workers.local();
        for (int i = r.begin(); i != r.end(); ++i) {
            const int z0 = i * options.slab_layers;
            w.run(phi, s, z0, std::min(z0 + options.slab_layers, layers), slabs[static_cast<std::size_t>(i)]);
        }
    });
    // Stitch: slab i's own vertices follow those of slabs < i (the naive creation order).
    std::vector<std::size_t> voff(slabs.size() + 1, 0), ioff(slabs.size() + 1, 0);
    for (std::size_t i = 0; i < slabs.size(); ++i) {
        voff[i + 1] = voff[i] + slabs[i].mesh.vertices.size();
        ioff[i + 1] = ioff[i] + slabs[i].mesh.indices.size();
    }
    if (voff.back() >= 0xFFFF'FFFFu) throw std::length_error("mesh has too many vertices for 32-bit indices");
    result.vertices.resize(voff.back());
    result.indices.resize(ioff.back());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, slabs.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            const Mesh& m = slabs[i].mesh;
            std::copy(m.vertices.begin(), m.vertices.end(), result.vertices.begin() + static_cast<std::ptrdiff_t>(voff[i]));
            const auto base = static_cast<std::uint32_t>(voff[i]);
            const auto below = i > 0 ? static_cast<std::uint32_t>(voff[i - 1]) : 0u;
            const std::uint32_t* top = i > 0 ? slabs[i - 1].top.get() : nullptr;
            std::uint32_t* dst = result.indices.data() + ioff[i];
            for (std::size_t j = 0; j < m.indices.size(); ++j) {
                const std::uint32_t id = m.indices[j];
                dst[j] = (id & kExternal) != 0 ? below + top[id & ~kExternal] : base + id;
            }
        }
    });
    return result;
}

}  // namespace liveset
