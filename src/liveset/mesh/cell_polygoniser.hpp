// Polygonisation of marching-cubes cells with the vertex-index lattice G (Feltell & Bai §2.2):
// the sign test, the edge-vertex computation and a reusable polygoniser that walks a box of cells
// (all of them, or only a sorted list) and appends vertices/triangles to a Mesh, computing each
// lattice-edge vertex once and reusing it through G.
#pragma once

#include <array>
#include <climits>
#include <cstdint>
#include <span>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/mesh/mesh.hpp"

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

// Marching-cubes case index of the cell with minimum corner c (bit k set when corner k is inside).
int cell_case(const Grid<float>& phi, Vec3i c);

// Linear key of a cell: the lattice index of its minimum corner. Ascending keys visit cells in
// z-major order, which is the order the polygoniser needs.
using CellKey = PointIndex;

// Polygonises cells of one half-open box [lo, hi) of cell coordinates (a cell c has corners
// c .. c+1; valid cells satisfy 0 <= c < dims-1). G is held for two z-slices of lattice points only
// (a ring indexed by z parity), so memory is O(box footprint in x*y) whatever the box depth, and it
// is reset by undoing only the entries written (O(vertices)), never by clearing the whole array.
// Not thread-safe; use one per thread. Output is a deterministic function of (φ, box, cells).
class CellPolygoniser {
public:
    // Visits every cell of the box in z, y, x order.
    void polygonise_box(const Grid<float>& phi, Vec3i lo, Vec3i hi, Mesh& out,
                        std::vector<CellKey>* crossing_cells = nullptr);
    // Visits only the listed cells, which must be strictly ascending and inside the box. Gives the
    // same output as polygonise_box() when the list holds every cell of the box with a crossing.
    void polygonise_cells(const Grid<float>& phi, Vec3i lo, Vec3i hi, std::span<const CellKey> cells,
                          Mesh& out, std::vector<CellKey>* crossing_cells = nullptr);

    // Lattice-edge vertices computed by the last call (each exactly once).
    std::size_t vertices_computed() const { return computed_; }

private:
    void prepare(const Grid<float>& phi, Vec3i lo, Vec3i hi);
    void enter_layer(int z);
    void clear_slot(int slot);
    void emit_cell(const Grid<float>& phi, Vec3i c, int cs, Mesh& out);
    std::uint32_t edge_vertex(const Grid<float>& phi, Vec3i p, int axis, Mesh& out);

    std::vector<std::uint32_t> g_;                    // G: 2 slices * px * py * 3, kNone when unset
    std::array<std::vector<std::uint32_t>, 2> written_;  // G entries set, per slice slot
    Vec3i lo_{};
    int px_ = 0, py_ = 0;
    int layer_ = INT_MIN;  // cell layer z currently being polygonised
    std::size_t computed_ = 0;
    bool dirty_ = false;  // an exception left G partially written
};

}  // namespace liveset
