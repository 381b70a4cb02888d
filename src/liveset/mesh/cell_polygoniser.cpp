// Cell polygonisation with the vertex-index lattice G: edge vertices, case indices and the
// two-slice G ring used by every marching-cubes driver (whole lattice, band, fragments).
#include "liveset/mesh/cell_polygoniser.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "liveset/grid/sampling.hpp"
#include "liveset/mesh/mc_tables.hpp"

namespace liveset {

namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

}  // namespace

Vertex make_edge_vertex(const Grid<float>& phi, Vec3i p, int axis) {
    Vec3i q = p;
    q[axis] += 1;
    const double a = phi(p);
    const double b = phi(q);
    double t = a / (a - b);
    if (!std::isfinite(t)) t = 0.5;
    const double m = kEdgeVertexMargin;
    t = std::clamp(t, m, 1.0 - m);

    const Vec3f ga = central_gradient(phi, p);
    const Vec3f gb = central_gradient(phi, q);
    double n[3];
    for (int k = 0; k < 3; ++k) n[k] = (1.0 - t) * ga[k] + t * gb[k];
    const double len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    Vertex v{};
    if (std::isfinite(len) && len > 1e-20) {
        for (int k = 0; k < 3; ++k) v.normal[k] = static_cast<float>(n[k] / len);
    } else {
        // Degenerate gradient: point along the edge from its inside end to its outside end.
        v.normal[axis] = is_inside(static_cast<float>(a)) ? 1.0f : -1.0f;
    }
    for (int k = 0; k < 3; ++k) v.position[k] = static_cast<float>(p[k]);
    v.position[axis] = static_cast<float>(p[axis] + t);
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
    lo_ = lo;
    px_ = hi.x - lo.x + 1;
    py_ = hi.y - lo.y + 1;
    const std::size_t need = std::size_t{2} * static_cast<std::size_t>(px_) * static_cast<std::size_t>(py_) * 3;
    if (dirty_) {
        std::fill(g_.begin(), g_.end(), kNone);
        written_[0].clear();
        written_[1].clear();
    }
    // Entries are all kNone between calls, so growing keeps that invariant whatever the layout.
    if (g_.size() < need) g_.resize(need, kNone);
    layer_ = INT_MIN;
    computed_ = 0;
    dirty_ = true;
}

void CellPolygoniser::clear_slot(int slot) {
    for (std::uint32_t i : written_[slot]) g_[i] = kNone;
    written_[slot].clear();
}

void CellPolygoniser::enter_layer(int z) {
    if (z == layer_) return;
    if (layer_ != INT_MIN && z < layer_) throw std::invalid_argument("cells must be visited in ascending order");
    if (layer_ != INT_MIN && z == layer_ + 1) {
        clear_slot(layer_ & 1);  // slice layer_ is done; its slot now holds slice z + 1
    } else {
        clear_slot(0);
        clear_slot(1);
    }
    layer_ = z;
}

std::uint32_t CellPolygoniser::edge_vertex(const Grid<float>& phi, Vec3i p, int axis, Mesh& out) {
    const int slot = p.z & 1;
    const std::size_t gi =
        ((static_cast<std::size_t>(slot) * static_cast<std::size_t>(py_) + static_cast<std::size_t>(p.y - lo_.y)) *
             static_cast<std::size_t>(px_) +
         static_cast<std::size_t>(p.x - lo_.x)) *
            3 +
        static_cast<std::size_t>(axis);
    std::uint32_t& slot_ref = g_[gi];
    if (slot_ref != kNone) return slot_ref;
    if (out.vertices.size() >= kNone) throw std::length_error("mesh has too many vertices for 32-bit indices");
    const auto id = static_cast<std::uint32_t>(out.vertices.size());
    out.vertices.push_back(make_edge_vertex(phi, p, axis));
    slot_ref = id;
    written_[slot].push_back(static_cast<std::uint32_t>(gi));
    ++computed_;
    return id;
}

void CellPolygoniser::emit_cell(const Grid<float>& phi, Vec3i c, int cs, Mesh& out) {
    const auto& tables = mc::kTables;
    const unsigned mask = tables.edges[cs];
    std::uint32_t v[mc::kEdges];
    for (int e = 0; e < mc::kEdges; ++e) {
        if (!((mask >> e) & 1u)) continue;
        const mc::EdgeInfo info = mc::edge_info(e);
        const Vec3i p{c.x + mc::corner_offset(info.start_corner, 0), c.y + mc::corner_offset(info.start_corner, 1),
                      c.z + mc::corner_offset(info.start_corner, 2)};
        v[e] = edge_vertex(phi, p, info.axis, out);
    }
    const auto& tri = tables.triangles[cs];
    for (int j = 0; tri[j] != mc::kEnd; ++j) out.indices.push_back(v[tri[j]]);
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
                if (crossing_cells) crossing_cells->push_back(l.index(c));
            }
        }
    }
    clear_slot(0);
    clear_slot(1);
    dirty_ = false;
}

void CellPolygoniser::polygonise_cells(const Grid<float>& phi, Vec3i lo, Vec3i hi, std::span<const CellKey> cells,
                                       Mesh& out, std::vector<CellKey>* crossing_cells) {
    prepare(phi, lo, hi);
    const Lattice& l = phi.lattice();
    bool first = true;
    CellKey prev = 0;
    for (CellKey key : cells) {
        if (!first && key <= prev) throw std::invalid_argument("cell list must be strictly ascending");
        first = false;
        prev = key;
        if (key >= l.size()) throw std::out_of_range("cell key outside the lattice");
        const Vec3i c = l.coord(key);
        if (c.x < lo.x || c.y < lo.y || c.z < lo.z || c.x >= hi.x || c.y >= hi.y || c.z >= hi.z)
            throw std::out_of_range("listed cell outside the polygonised box");
        const int cs = cell_case(phi, c);
        if (cs == 0 || cs == 255) continue;
        enter_layer(c.z);
        emit_cell(phi, c, cs, out);
        if (crossing_cells) crossing_cells->push_back(key);
    }
    clear_slot(0);
    clear_slot(1);
    dirty_ = false;
}

}  // namespace liveset
