// Polygonisation of marching-cubes cells with the vertex-index lattice G (Feltell & Bai §2.2):
// the sign test, the edge-vertex computation and a reusable polygoniser that walks a box of cells
// (all of them, or only a sorted list) and appends vertices/triangles to a Mesh, computing each
// lattice-edge vertex once and reusing it through G.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <climits>
#include <cstdint>
#include <span>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/grid/index_decoder.hpp"
#include "liveset/mesh/mesh.hpp"
#include "liveset/mesh/sign_bits.hpp"

namespace liveset {

// THE sign test used by every mesh routine: a point is inside iff φ < 0 (φ = 0 counts as outside).
constexpr bool is_inside(float phi) { return phi < 0.0f; }

// Edge vertices are kept at least this far (in voxels) from the lattice points, so vertices of
// distinct lattice edges never coincide even where φ is exactly 0 at a lattice point (otherwise a
// zero corner collapses several vertices into one and leaves degenerate triangles). The position
// error it introduces is at most kEdgeVertexMargin voxels.
inline constexpr float kEdgeVertexMargin = 1e-3f;

// Vertex on the lattice edge from point p one step along +axis; the endpoints must differ in sign.
// Position: linear interpolation of φ to 0 along the edge (clamped by kEdgeVertexMargin).
// Normal: central-difference ∇φ of both endpoints interpolated with the same weight, normalised;
// where that vanishes, the edge direction from the inside endpoint to the outside one.
// A pure function of (φ, p, axis): every fragment computes bit-identical border vertices.
Vertex make_edge_vertex(const Grid<float>& phi, Vec3i p, int axis);

// make_edge_vertex() for an edge whose two endpoints have all 6 neighbours inside the lattice, from
// φ's values v, the linear index i of the start point p and the strides: the same arithmetic in the
// same order, so bit-identical results (make_edge_vertex uses it for such edges).
inline Vertex edge_vertex_interior(const float* v, std::size_t i, Vec3i p, int axis, std::size_t sy, std::size_t sz) {
    const std::size_t step = axis == 0 ? 1 : axis == 1 ? sy : sz;
    const std::size_t j = i + step;
    const float a = v[i], b = v[j];
    float t = a / (a - b);
    if (!std::isfinite(t)) t = 0.5f;
    t = std::clamp(t, kEdgeVertexMargin, 1.0f - kEdgeVertexMargin);
    const float ga[3] = {(v[i + 1] - v[i - 1]) / 2.0f, (v[i + sy] - v[i - sy]) / 2.0f, (v[i + sz] - v[i - sz]) / 2.0f};
    const float gb[3] = {(v[j + 1] - v[j - 1]) / 2.0f, (v[j + sy] - v[j - sy]) / 2.0f, (v[j + sz] - v[j - sz]) / 2.0f};
    const float s = 1.0f - t;
    const float n[3] = {s * ga[0] + t * gb[0], s * ga[1] + t * gb[1], s * ga[2] + t * gb[2]};
    const float len = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    // Every field is a scalar assigned once (no store through a run-time axis index), so the caller
    // receives the vertex in registers rather than through a stack copy it must reload.
    float nx = 0.0f, ny = 0.0f, nz = 0.0f;
    if (std::isfinite(len) && len > 1e-20f) {
        const float inv = 1.0f / len;
        nx = n[0] * inv;
        ny = n[1] * inv;
        nz = n[2] * inv;
    } else {
        const float d = is_inside(a) ? 1.0f : -1.0f;
        nx = axis == 0 ? d : 0.0f;
        ny = axis == 1 ? d : 0.0f;
        nz = axis == 2 ? d : 0.0f;
    }
    const float px = static_cast<float>(p.x), py = static_cast<float>(p.y), pz = static_cast<float>(p.z);
    return Vertex{{axis == 0 ? px + t : px, axis == 1 ? py + t : py, axis == 2 ? pz + t : pz}, {nx, ny, nz}};
}

// Marching-cubes case index of the cell with minimum corner c (bit k set when corner k is inside).
int cell_case(const Grid<float>& phi, Vec3i c);

// Linear key of a cell: the lattice index of its minimum corner. Ascending keys visit cells in
// z-major order, which is the order the polygoniser needs.
using CellKey = PointIndex;

// Polygonises cells of one half-open box [lo, hi) of cell coordinates (a cell c has corners
// c .. c+1; valid cells satisfy 0 <= c < dims-1). G is held for two z-slices of lattice points only
// (a ring indexed by z parity), so memory is O(box footprint in x*y) whatever the box depth; a
// slice is reset in O(1) by a generation stamp, never by clearing the array.
// Not thread-safe; use one per thread. Output is a deterministic function of (φ, box, cells).
class CellPolygoniser {
public:
    // The lattice edge a vertex lies on: from point p one step along +axis.
    struct EdgeRef {
        Vec3i p;
        int axis;
    };

    // Visits every cell of the box in z, y, x order.
    void polygonise_box(const Grid<float>& phi, Vec3i lo, Vec3i hi, Mesh& out,
                        std::vector<CellKey>* crossing_cells = nullptr);
    // Visits only the listed cells, which must be strictly ascending and inside the box. Gives the
    // same output as polygonise_box() when the list holds every cell of the box with a crossing.
    void polygonise_cells(const Grid<float>& phi, Vec3i lo, Vec3i hi, std::span<const CellKey> cells,
                          Mesh& out, std::vector<CellKey>* crossing_cells = nullptr);

    // Visits the cell rows of the box listed in the bitmap rows_a | rows_b (bit (y - lo.y) +
    // (hi.y - lo.y) * (z - lo.z) for cell row (y, z); both spans hold ceil(rows / 64) words) and,
    // in each, the cells whose corners differ in sign, read 64 at a time from `signs` (which must
    // be φ's sign bits). Sets in `crossing_rows` (same layout, cleared by the caller) the rows that
    // hold a crossing cell. Gives the same output as polygonise_box() when the listed rows include
    // every row of the box with a crossing.
    // With `vertex_edges`, it is set to the edge of every vertex appended, in order (the input of
    // refresh_vertices()).
    void polygonise_rows(const Grid<float>& phi, const SignBits& signs, Vec3i lo, Vec3i hi,
                         std::span<const std::uint64_t> rows_a, std::span<const std::uint64_t> rows_b, Mesh& out,
                         std::span<std::uint64_t> crossing_rows, std::vector<EdgeRef>* vertex_edges = nullptr);

    // Recomputes out[k] as the vertex on edges[k] (sizes must match): the same function and bits as
    // a polygonisation, for a mesh whose cells' signs did not change - its triangles are the same,
    // only the vertices moved with φ.
    void refresh_vertices(const Grid<float>& phi, std::span<const EdgeRef> edges, std::span<Vertex> out);

    // Lattice-edge vertices computed by the last call (each exactly once).
    std::size_t vertices_computed() const { return computed_; }
    // Crossing cells polygonised by the last call.
    std::size_t cells_polygonised() const { return cells_; }
    // Cell rows examined by the last polygonise_rows() call.
    std::size_t rows_visited() const { return rows_; }

private:
    void prepare(const Grid<float>& phi, Vec3i lo, Vec3i hi);
    void bind(const Grid<float>& phi);  // dims_, values_ and strides for edge_vertex()
    void enter_layer(int z);
    void renew_slot(int slot);
    void emit_cell(const Grid<float>& phi, Vec3i c, int cs, Mesh& out);
    // polygonise_rows()' raw cursors into index_scratch_ and deferred_, and the next vertex id.
    struct Emit {
        CellPolygoniser* owner;
        std::uint32_t* index;
        EdgeRef* edge;
        std::uint32_t next_id;
        // Makes room for `cells` more cells (growing the scratch arrays, which may move them).
        void reserve(std::size_t cells);
    };
    // emit_cell() for polygonise_rows(), which visits every crossing cell of the box: a cell creates
    // exactly the vertices of the edges it is the first visited cell of (kOwnedEdges) and reads the
    // others from gid_, with no generation test.
    void emit_cell_owned(Vec3i c, int cs, Emit& em);
    void finish_vertices(const Grid<float>& phi, std::span<const EdgeRef> edges, Mesh& out);  // appends their vertices
    // The vertex on the edge from p along +axis: edge_vertex_interior() on the cached values away
    // from the lattice's border, make_edge_vertex() next to it.
    Vertex edge_vertex(const Grid<float>& phi, Vec3i p, int axis) const;
    // Both endpoints of the edge have all 6 neighbours in the lattice (edge_vertex_interior applies).
    bool interior(EdgeRef e) const;

    // G: 2 slices * px * py * 3 entries, each (generation << 32 | vertex id). An entry is set only
    // when its generation equals its slot's current one, so a slice is cleared in O(1) by giving
    // its slot a new generation.
    std::vector<std::uint64_t> g_;
    std::array<std::uint64_t, 2> generation_{};  // current generation per slot, in the high half
    std::vector<std::uint32_t> gid_;  // polygonise_rows()' G, same layout: vertex ids only
    // polygonise_rows()' scratch (sized to the most it ever needed, filled from the front): the
    // vertices' edges, ids assigned, not yet computed; and the triangles' vertex ids.
    std::vector<EdgeRef> deferred_;
    std::vector<std::uint32_t> index_scratch_;
    std::uint32_t next_generation_ = 1;
    IndexDecoder decoder_;  // for the lattice of dims decoder_dims_
    Vec3i decoder_dims_{};
    Vec3i lo_{};
    Vec3i dims_{};                   // φ's lattice, its values and strides (set by prepare())
    const float* values_ = nullptr;
    std::size_t sy_ = 0, sz_ = 0;
    int px_ = 0, py_ = 0;
    std::size_t slice_ = 0;  // entries per slice
    // G entry of edge e of a cell, relative to the cell's row offset, for a cell in an even (0) or
    // odd (1) z layer: the edge's slice slot, row, x and axis folded into one offset per box.
    std::array<std::array<std::size_t, 12>, 2> edge_offset_{};
    int layer_ = INT_MIN;    // cell layer z currently being polygonised
    std::size_t computed_ = 0;
    std::size_t cells_ = 0;
    std::size_t rows_ = 0;
};

}  // namespace liveset
