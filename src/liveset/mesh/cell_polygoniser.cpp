// Cell polygonisation with the vertex-index lattice G: edge vertices, case indices and the
// two-slice G ring used by every marching-cubes driver (whole lattice, band, fragments).
#include "liveset/mesh/cell_polygoniser.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "liveset/grid/sampling.hpp"
#include "liveset/mesh/mc_tables.hpp"

namespace liveset {

static_assert(mc::kEdges == 12, "CellPolygoniser::edge_offset_ holds 12 edges");

namespace {

// Edges whose vertex a cell creates when cells are visited in z, y, x order and every crossing cell
// of the box is visited: a crossing edge makes all 4 cells around it crossing, so its vertex is
// created by the first of them in that order that lies in the box - the cell at (start - 1) on
// each other axis b, or at start[b] when start[b] - 1 is outside the box. Indexed by bit b set when
// the cell is at the box's low end on axis b.
constexpr std::array<unsigned, 8> kOwnedEdges = [] {
    std::array<unsigned, 8> t{};
    for (unsigned low = 0; low < 8; ++low)
        for (int e = 0; e < mc::kEdges; ++e) {
            const mc::EdgeStart& es = mc::kEdgeStarts[static_cast<std::size_t>(e)];
            const int d[3] = {es.dx, es.dy, es.dz};
            bool owned = true;
            for (int b = 0; b < 3; ++b)
                if (b != es.axis && d[b] == 0 && (low & (1u << b)) == 0) owned = false;
            if (owned) t[low] |= 1u << e;
        }
    return t;
}();

#if defined(__SSE2__)
// edge_vertex_interior() for four edges at once, lane by lane: the same IEEE operations in the same
// order (SSE's add, sub, mul, div and sqrt round exactly like the scalar ones, and the build turns
// off FMA contraction), so the same bits; the three dependent divisions and the square root of a
// vertex overlap with those of three others.
void edge_vertices_interior4(const float* v, const CellPolygoniser::EdgeRef* e, std::ptrdiff_t sy, std::ptrdiff_t sz, Vertex* out) {
    const float* pi[4];
    const float* pj[4];
    for (int l = 0; l < 4; ++l) {
        const Vec3i p = e[l].p;
        pi[l] = v + (p.x + p.y * sy + p.z * sz);
        pj[l] = pi[l] + (e[l].axis == 0 ? 1 : e[l].axis == 1 ? sy : sz);
    }
    const auto at = [](const float* const (&p)[4], std::ptrdiff_t o) { return _mm_setr_ps(p[0][o], p[1][o], p[2][o], p[3][o]); };
    const __m128 half = _mm_set1_ps(0.5f), one = _mm_set1_ps(1.0f), inf = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const __m128 abs_mask = _mm_castsi128_ps(_mm_set1_epi32(0x7FFF'FFFF));
    const __m128 a = at(pi, 0), b = at(pj, 0);
    __m128 t = _mm_div_ps(a, _mm_sub_ps(a, b));
    const __m128 finite = _mm_cmplt_ps(_mm_and_ps(t, abs_mask), inf);  // false for NaN and ±inf
    t = _mm_or_ps(_mm_and_ps(finite, t), _mm_andnot_ps(finite, half));
    t = _mm_min_ps(_mm_max_ps(t, _mm_set1_ps(kEdgeVertexMargin)), _mm_set1_ps(1.0f - kEdgeVertexMargin));  // std::clamp of a finite t
    const auto grad = [&](const float* const (&p)[4], std::ptrdiff_t s) { return _mm_mul_ps(_mm_sub_ps(at(p, s), at(p, -s)), half); };
    const __m128 s = _mm_sub_ps(one, t);
    const __m128 n0 = _mm_add_ps(_mm_mul_ps(s, grad(pi, 1)), _mm_mul_ps(t, grad(pj, 1)));
    const __m128 n1 = _mm_add_ps(_mm_mul_ps(s, grad(pi, sy)), _mm_mul_ps(t, grad(pj, sy)));
    const __m128 n2 = _mm_add_ps(_mm_mul_ps(s, grad(pi, sz)), _mm_mul_ps(t, grad(pj, sz)));
    const __m128 len = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(n0, n0), _mm_mul_ps(n1, n1)), _mm_mul_ps(n2, n2)));
    const __m128 good = _mm_and_ps(_mm_cmplt_ps(len, inf), _mm_cmpgt_ps(len, _mm_set1_ps(1e-20f)));
    const __m128 inv = _mm_div_ps(one, len);
    // Per axis k: the lanes whose edge runs along k, and the degenerate normal (inside end to outside end).
    const __m128i axis = _mm_setr_epi32(e[0].axis, e[1].axis, e[2].axis, e[3].axis);
    const __m128 inside = _mm_cmplt_ps(a, _mm_setzero_ps());  // is_inside(a): false for -0 and NaN
    const __m128 d = _mm_or_ps(_mm_and_ps(inside, one), _mm_andnot_ps(inside, _mm_set1_ps(-1.0f)));
    const auto along = [&](int k) { return _mm_castsi128_ps(_mm_cmpeq_epi32(axis, _mm_set1_epi32(k))); };
    const auto normal = [&](__m128 n, int k) { return _mm_or_ps(_mm_and_ps(good, _mm_mul_ps(n, inv)), _mm_andnot_ps(good, _mm_and_ps(along(k), d))); };
    const auto position = [&](int k) {
        const __m128 c = _mm_cvtepi32_ps(_mm_setr_epi32(e[0].p[k], e[1].p[k], e[2].p[k], e[3].p[k]));
        return _mm_add_ps(c, _mm_and_ps(along(k), t));  // + 0 off the edge's axis: the coordinate itself
    };
    __m128 r0 = position(0), r1 = position(1), r2 = position(2), r3 = normal(n0, 0);
    _MM_TRANSPOSE4_PS(r0, r1, r2, r3);  // rows: (x, y, z, nx) of each vertex
    const __m128 ny = normal(n1, 1), nz = normal(n2, 2);
    const __m128 lo = _mm_unpacklo_ps(ny, nz), hi = _mm_unpackhi_ps(ny, nz);  // (ny, nz) of vertices 0, 1 | 2, 3
    _mm_storeu_ps(&out[0].position[0], r0);
    _mm_storel_pi(reinterpret_cast<__m64*>(&out[0].normal[1]), lo);
    _mm_storeu_ps(&out[1].position[0], r1);
    _mm_storeh_pi(reinterpret_cast<__m64*>(&out[1].normal[1]), lo);
    _mm_storeu_ps(&out[2].position[0], r2);
    _mm_storel_pi(reinterpret_cast<__m64*>(&out[2].normal[1]), hi);
    _mm_storeu_ps(&out[3].position[0], r3);
    _mm_storeh_pi(reinterpret_cast<__m64*>(&out[3].normal[1]), hi);
}
#endif

}  // namespace

Vertex make_edge_vertex(const Grid<float>& phi, Vec3i p, int axis) {
    const Lattice& l = phi.lattice();
    const std::size_t step = axis == 0 ? 1 : axis == 1 ? l.stride_y() : l.stride_z();
    const std::size_t i = l.index(p);
    const Vec3i d = l.dims();
    if (p.x >= 1 && p.y >= 1 && p.z >= 1 && p.x + (axis == 0) <= d.x - 2 && p.y + (axis == 1) <= d.y - 2 && p.z + (axis == 2) <= d.z - 2)
        return edge_vertex_interior(phi.values().data(), i, p, axis, l.stride_y(), l.stride_z());
    const float a = phi[static_cast<PointIndex>(i)];
    const float b = phi[static_cast<PointIndex>(i + step)];
    float t = a / (a - b);
    if (!std::isfinite(t)) t = 0.5f;
    t = std::clamp(t, kEdgeVertexMargin, 1.0f - kEdgeVertexMargin);

    Vec3i q = p;
    q[axis] += 1;
    const Vec3f ga = central_gradient(phi, p);
    const Vec3f gb = central_gradient(phi, q);
    const float s = 1.0f - t;
    const float n[3] = {s * ga.x + t * gb.x, s * ga.y + t * gb.y, s * ga.z + t * gb.z};
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    Vertex v{};
    if (std::isfinite(len) && len > 1e-20f) {
        const float inv = 1.0f / len;
        for (int k = 0; k < 3; ++k) v.normal[k] = n[k] * inv;
    } else {
        // Degenerate gradient: point along the edge from its inside end to its outside end.
        v.normal[axis] = is_inside(a) ? 1.0f : -1.0f;
    }
    for (int k = 0; k < 3; ++k) v.position[k] = static_cast<float>(p[k]);
    v.position[axis] = static_cast<float>(p[axis]) + t;
    return v;
}

int cell_case(const Grid<float>& phi, Vec3i c) {
    const Lattice& l = phi.lattice();
    const std::size_t sy = l.stride_y(), sz = l.stride_z();
    const std::size_t base = l.index(c);
    const std::size_t off[8] = {0, 1, sy, sy + 1, sz, sz + 1, sz + sy, sz + sy + 1};
    const std::span<const float> v = phi.values();
    int cs = 0;
    for (int k = 0; k < 8; ++k)
        if (is_inside(v[base + off[k]])) cs |= 1 << k;
    return cs;
}

void CellPolygoniser::prepare(const Grid<float>& phi, Vec3i lo, Vec3i hi) {
    const Vec3i d = phi.dims();
    for (int a = 0; a < 3; ++a) {
        if (lo[a] < 0 || lo[a] > hi[a] || hi[a] > std::max(d[a] - 1, 0)) {
            std::ostringstream os;
            os << "cell box " << lo << ".." << hi << " outside the lattice " << d;
            throw std::out_of_range(os.str());
        }
    }
    if (!(decoder_dims_ == d)) {
        decoder_ = IndexDecoder(phi.lattice());
        decoder_dims_ = d;
    }
    lo_ = lo;
    bind(phi);
    px_ = hi.x - lo.x + 1;
    py_ = hi.y - lo.y + 1;
    slice_ = static_cast<std::size_t>(px_) * static_cast<std::size_t>(py_) * 3;
    const std::size_t row_step = static_cast<std::size_t>(px_) * 3;
    for (int parity = 0; parity < 2; ++parity)
        for (std::size_t e = 0; e < mc::kEdgeStarts.size(); ++e) {
            const mc::EdgeStart& es = mc::kEdgeStarts[e];
            edge_offset_[static_cast<std::size_t>(parity)][e] =
                static_cast<std::size_t>(parity ^ es.dz) * slice_ + static_cast<std::size_t>(es.dy) * row_step +
                static_cast<std::size_t>(es.dx) * 3 + static_cast<std::size_t>(es.axis);
        }
    const std::size_t need = 2 * slice_;
    if (g_.size() < need) g_.resize(need, 0);  // generation 0 is never current: new entries are unset
    renew_slot(0);
    renew_slot(1);
    layer_ = INT_MIN;
    computed_ = 0;
    cells_ = 0;
    rows_ = 0;
}

void CellPolygoniser::bind(const Grid<float>& phi) {
    dims_ = phi.dims();
    values_ = phi.values().data();
    sy_ = phi.lattice().stride_y();
    sz_ = phi.lattice().stride_z();
}

void CellPolygoniser::renew_slot(int slot) {
    if (next_generation_ == 0xFFFF'FFFFu) {  // wrapped: forget every entry once every 2^32 slices
        std::fill(g_.begin(), g_.end(), 0);
        next_generation_ = 1;
    }
    generation_[slot] = std::uint64_t{next_generation_++} << 32;
}

void CellPolygoniser::enter_layer(int z) {
    if (z == layer_) return;
    if (layer_ != INT_MIN && z < layer_) throw std::invalid_argument("cells must be visited in ascending order");
    if (layer_ != INT_MIN && z == layer_ + 1) {
        renew_slot(layer_ & 1);  // slice layer_ is done; its slot now holds slice z + 1
    } else {
        renew_slot(0);
        renew_slot(1);
    }
    layer_ = z;
}

[[gnu::always_inline]] inline bool CellPolygoniser::interior(EdgeRef e) const {
    const Vec3i p = e.p;
    return p.x >= 1 && p.y >= 1 && p.z >= 1 && p.x + (e.axis == 0) <= dims_.x - 2 && p.y + (e.axis == 1) <= dims_.y - 2 &&
           p.z + (e.axis == 2) <= dims_.z - 2;
}

// Inlined into both emitters (no Vertex round trip through memory on the interior path).
[[gnu::always_inline]] inline Vertex CellPolygoniser::edge_vertex(const Grid<float>& phi, Vec3i p, int ax) const {
    if (interior({p, ax})) {
        const std::size_t i = static_cast<std::size_t>(p.x) + static_cast<std::size_t>(p.y) * sy_ + static_cast<std::size_t>(p.z) * sz_;
        return edge_vertex_interior(values_, i, p, ax, sy_, sz_);
    }
    return make_edge_vertex(phi, p, ax);
}

namespace {

// The triangles of case `cs`, their corners the cell's edge vertex ids `v`, appended to out.indices.
[[gnu::always_inline]] inline void append_triangles(int cs, const std::uint32_t* v, Mesh& out) {
    const auto& tri = mc::kTables.triangles[static_cast<std::size_t>(cs)];
    const int n = 3 * mc::kTables.triangle_count[static_cast<std::size_t>(cs)];
    const std::size_t base = out.indices.size();
    out.indices.resize(base + static_cast<std::size_t>(n));
    std::uint32_t* dst = out.indices.data() + base;
    for (int j = 0; j < n; ++j) dst[j] = v[tri[static_cast<std::size_t>(j)]];
}

}  // namespace

void CellPolygoniser::emit_cell(const Grid<float>& phi, Vec3i c, int cs, Mesh& out) {
    const auto& tables = mc::kTables;
    // G offset of the cell's minimum corner; edge e adds edge_offset_[z parity][e] (its corner's
    // dx*3 + dy*px*3 and the slot of its z slice).
    const std::size_t row = (static_cast<std::size_t>(c.y - lo_.y) * static_cast<std::size_t>(px_) +
                             static_cast<std::size_t>(c.x - lo_.x)) * 3;
    const int slot0 = c.z & 1;
    const std::size_t* offset = edge_offset_[static_cast<std::size_t>(slot0)].data();
    std::uint32_t v[mc::kEdges];
    for (unsigned mask = tables.edges[static_cast<std::size_t>(cs)]; mask != 0; mask &= mask - 1) {
        const int e = std::countr_zero(mask);
        const mc::EdgeStart& es = mc::kEdgeStarts[static_cast<std::size_t>(e)];
        const int slot = slot0 ^ es.dz;
        std::uint64_t& entry = g_[row + offset[e]];
        if ((entry & 0xFFFF'FFFF'0000'0000ull) == generation_[slot]) {
            v[e] = static_cast<std::uint32_t>(entry);
            continue;
        }
        if (out.vertices.size() >= 0xFFFF'FFFFu) throw std::length_error("mesh has too many vertices for 32-bit indices");
        const auto id = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(edge_vertex(phi, {c.x + es.dx, c.y + es.dy, c.z + es.dz}, es.axis));
        entry = generation_[slot] | id;
        v[e] = id;
        ++computed_;
    }
    append_triangles(cs, v, out);
}

// Inlined into the row pass: a call passed the cell through the stack and stalled reloading it.
[[gnu::always_inline]] inline void CellPolygoniser::emit_cell_owned(Vec3i c, int cs, Emit& em) {
    const auto& tables = mc::kTables;
    const std::size_t row = (static_cast<std::size_t>(c.y - lo_.y) * static_cast<std::size_t>(px_) +
                             static_cast<std::size_t>(c.x - lo_.x)) * 3;
    const std::size_t* offset = edge_offset_[static_cast<std::size_t>(c.z & 1)].data();
    std::uint32_t* g = gid_.data() + row;
    const unsigned edges = tables.edges[static_cast<std::size_t>(cs)];
    const unsigned owned = kOwnedEdges[static_cast<std::size_t>((c.x == lo_.x) | (c.y == lo_.y) << 1 | (c.z == lo_.z) << 2)];
    std::uint32_t v[mc::kEdges];
    for (unsigned mask = edges & ~owned; mask != 0; mask &= mask - 1) {  // created by an earlier cell
        const int e = std::countr_zero(mask);
        v[e] = g[offset[e]];
    }
    for (unsigned mask = edges & owned; mask != 0; mask &= mask - 1) {
        const int e = std::countr_zero(mask);
        const mc::EdgeStart& es = mc::kEdgeStarts[static_cast<std::size_t>(e)];
        *em.edge++ = {{c.x + es.dx, c.y + es.dy, c.z + es.dz}, es.axis};  // computed by finish_vertices()
        g[offset[e]] = em.next_id;
        v[e] = em.next_id++;
    }
    const auto& tri = tables.triangles[static_cast<std::size_t>(cs)];
    const int n = 3 * tables.triangle_count[static_cast<std::size_t>(cs)];
    std::uint32_t* __restrict index = em.index;  // no overlap with the tables: a plain loop, no run-time alias checks
#pragma GCC unroll 1
    for (int k = 0; k < n; ++k) index[k] = v[tri[static_cast<std::size_t>(k)]];
    em.index = index + n;
}

void CellPolygoniser::finish_vertices(const Grid<float>& phi, std::span<const EdgeRef> edges, Mesh& out) {
    // One simple loop over independent vertices: the φ loads of consecutive vertices overlap.
    const std::size_t first = out.vertices.size();
    out.vertices.resize(first + edges.size());
    refresh_vertices(phi, edges, std::span<Vertex>(out.vertices).subspan(first));
}

void CellPolygoniser::Emit::reserve(std::size_t cells) {
    // Room for the most a cell appends (5 triangles; 12 edges for a box's first cell), in the
    // scratch arrays, which only grow: filled through raw cursors, copied out once at the end.
    auto& p = *owner;
    const std::size_t n_index = static_cast<std::size_t>(index - p.index_scratch_.data());
    const std::size_t n_edge = static_cast<std::size_t>(edge - p.deferred_.data());
    if (next_id + mc::kEdges * cells >= 0xFFFF'FFFFu) throw std::length_error("mesh has too many vertices for 32-bit indices");
    constexpr std::size_t kMaxIndices = 3 * mc::kMaxTriangles;
    if (p.index_scratch_.size() < n_index + kMaxIndices * cells)
        p.index_scratch_.resize(std::max(2 * p.index_scratch_.size(), n_index + kMaxIndices * cells));
    if (p.deferred_.size() < n_edge + mc::kEdges * cells) p.deferred_.resize(std::max(2 * p.deferred_.size(), n_edge + mc::kEdges * cells));
    index = p.index_scratch_.data() + n_index;
    edge = p.deferred_.data() + n_edge;
}

void CellPolygoniser::refresh_vertices(const Grid<float>& phi, std::span<const EdgeRef> edges, std::span<Vertex> out) {
    if (edges.size() != out.size()) throw std::invalid_argument("refresh_vertices: one edge per vertex is needed");
    bind(phi);
    Vertex* dst = out.data();
    const EdgeRef* e = edges.data();
    std::size_t k = 0;
#if defined(__SSE2__)
    for (; k + 4 <= edges.size(); k += 4) {
        if (interior(e[k]) && interior(e[k + 1]) && interior(e[k + 2]) && interior(e[k + 3])) {
            edge_vertices_interior4(values_, e + k, static_cast<std::ptrdiff_t>(sy_), static_cast<std::ptrdiff_t>(sz_), dst + k);
        } else {
            for (std::size_t l = k; l < k + 4; ++l) dst[l] = edge_vertex(phi, e[l].p, e[l].axis);
        }
    }
#endif
    for (; k < edges.size(); ++k) dst[k] = edge_vertex(phi, e[k].p, e[k].axis);
}

void CellPolygoniser::polygonise_box(const Grid<float>& phi, Vec3i lo, Vec3i hi, Mesh& out,
                                     std::vector<CellKey>* crossing_cells) {
    prepare(phi, lo, hi);
    const Lattice& l = phi.lattice();
    for (int z = lo.z; z < hi.z; ++z) {
        for (int y = lo.y; y < hi.y; ++y) {
            for (int x = lo.x; x < hi.x; ++x) {
                const Vec3i c{x, y, z};
                const int cs = cell_case(phi, c);
                if (cs == 0 || cs == 255) continue;
                enter_layer(z);
                emit_cell(phi, c, cs, out);
                ++cells_;
                if (crossing_cells) crossing_cells->push_back(l.index(c));
            }
        }
    }
}

void CellPolygoniser::polygonise_cells(const Grid<float>& phi, Vec3i lo, Vec3i hi, std::span<const CellKey> cells,
                                       Mesh& out, std::vector<CellKey>* crossing_cells) {
    prepare(phi, lo, hi);
    const Lattice& l = phi.lattice();
    const std::size_t sy = l.stride_y(), sz = l.stride_z();
    const std::size_t off[8] = {0, 1, sy, sy + 1, sz, sz + 1, sz + sy, sz + sy + 1};
    const float* values = phi.values().data();
    bool first = true;
    CellKey prev = 0;
    for (CellKey key : cells) {
        if (!first && key <= prev) throw std::invalid_argument("cell list must be strictly ascending");
        first = false;
        prev = key;
        if (key >= l.size()) throw std::out_of_range("cell key outside the lattice");
        const Vec3i c = decoder_.coord(key);
        if (c.x < lo.x || c.y < lo.y || c.z < lo.z || c.x >= hi.x || c.y >= hi.y || c.z >= hi.z)
            throw std::out_of_range("listed cell outside the polygonised box");
        int cs = 0;
        for (int k = 0; k < 8; ++k) cs |= static_cast<int>(is_inside(values[key + off[k]])) << k;
        if (cs == 0 || cs == 255) continue;
        enter_layer(c.z);
        emit_cell(phi, c, cs, out);
        ++cells_;
        if (crossing_cells) crossing_cells->push_back(key);
    }
}

void CellPolygoniser::polygonise_rows(const Grid<float>& phi, const SignBits& signs, Vec3i lo, Vec3i hi,
                                      std::span<const std::uint64_t> rows_a, std::span<const std::uint64_t> rows_b, Mesh& out,
                                      std::span<std::uint64_t> crossing_rows, std::vector<EdgeRef>* vertex_edges) {
    prepare(phi, lo, hi);
    if (!(signs.dims == phi.dims())) throw std::invalid_argument("sign bits do not match the phi grid");
    const int ny = hi.y - lo.y;
    const std::size_t nrows = static_cast<std::size_t>(ny) * static_cast<std::size_t>(hi.z - lo.z);
    const std::size_t nwords = (nrows + 63) / 64;
    if (rows_a.size() < nwords || rows_b.size() < nwords || crossing_rows.size() < nwords)
        throw std::invalid_argument("row bitmaps are smaller than the box's cell rows");
    if (vertex_edges) vertex_edges->clear();
    if (ny <= 0 || hi.x <= lo.x) return;
    if (gid_.size() < 2 * slice_) gid_.resize(2 * slice_, 0);
    Emit em{this, index_scratch_.data(), deferred_.data(), static_cast<std::uint32_t>(out.vertices.size())};
    const FastDivider div_y(static_cast<std::uint32_t>(ny));
    const std::size_t wpr = signs.words_per_row;
    const auto k0 = static_cast<std::size_t>(lo.x) >> 6, k1 = static_cast<std::size_t>(hi.x - 1) >> 6;
    for (std::size_t w = 0; w < nwords; ++w) {
        for (std::uint64_t m = rows_a[w] | rows_b[w]; m != 0; m &= m - 1) {
            const auto r = static_cast<std::uint32_t>(64 * w + static_cast<std::size_t>(std::countr_zero(m)));
            if (r >= nrows) break;
            ++rows_;
            const std::uint32_t rz = div_y.divide(r);
            const int y = lo.y + static_cast<int>(r - rz * static_cast<std::uint32_t>(ny)), z = lo.z + static_cast<int>(rz);
            const CellRows cr(signs, y, z);
            bool any = false;
            for (std::size_t k = k0; k <= k1; ++k) {
                std::uint64_t cross = cr.crossing_unmasked(k, wpr);
                const int from = lo.x - static_cast<int>(64 * k), to = hi.x - static_cast<int>(64 * k);  // cells [from, to) of word k
                if (from > 0) cross &= ~std::uint64_t{0} << from;
                if (to < 64) cross &= (std::uint64_t{1} << to) - 1;
                if (cross == 0) continue;
                any = true;
                em.reserve(static_cast<std::size_t>(std::min(to, 64) - std::max(from, 0)));  // the word's cells in the box
                for (; cross != 0; cross &= cross - 1) {
                    const int x = static_cast<int>(64 * k) + std::countr_zero(cross);
                    emit_cell_owned({x, y, z}, cr.cell_case(x), em);
                    ++cells_;
                }
            }
            if (any) crossing_rows[r >> 6] |= std::uint64_t{1} << (r & 63);
        }
    }
    out.indices.insert(out.indices.end(), index_scratch_.data(), em.index);
    const std::span<const EdgeRef> edges(deferred_.data(), em.edge);
    computed_ = edges.size();
    finish_vertices(phi, edges, out);
    if (vertex_edges) vertex_edges->assign(edges.begin(), edges.end());
}

}  // namespace liveset
