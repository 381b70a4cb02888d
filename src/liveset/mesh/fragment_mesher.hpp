// Incremental marching cubes over a lattice of mesh fragments (Feltell & Bai §2.1): each fragment
// owns the V/T arrays of a block of cells; an update takes the changed φ points X, finds the
// affected fragments U (deduplicated with the flag lattice B), re-polygonises only those (in
// parallel with oneTBB) and returns U so a renderer re-uploads exactly those buffers.
//
// Border policy (better than the paper's): fragment f owns exactly the cells
// [origin, origin + S) ∩ lattice cells, so every cell - and so every triangle - belongs to exactly
// one fragment and no triangle is built twice. Only the vertices on the faces shared by two
// fragments are computed in both (each fragment's V/T must be a self-contained GPU buffer); they are
// bit-identical because make_edge_vertex() is a pure function of φ.
//
// Surface-proportional rebuilds: the mesher keeps one sign bit per lattice point (SignBits, rows of
// 64-bit words) and each fragment a bitmap of its cell rows (y, z) that hold a crossing cell
// (corner signs differ). A cell starts or stops crossing only if one of its corners flips sign, so
// a rebuild visits the rows (old crossing rows) ∪ (rows of cells with a corner whose sign flipped)
// and, in each, finds the crossing cells 64 at a time from the sign bits - under a moving front, X
// holds the whole band but only a thin sheet of it flips sign. It never scans the fragment's cells,
// so a single whole-lattice fragment (the paper's x100 case) costs O(surface) cell work plus one
// bit per cell row. The only O(volume) pass is full_rebuild(φ) without a zero layer.
//
// Vertex-only refresh: a fragment's triangles depend only on the signs of its cells' corners. An
// affected fragment none of whose cells has a corner whose sign flipped keeps its T and vertex ids;
// only its vertices are recomputed, from the lattice edge kept per vertex (no row pass, no cases,
// no G), and update() lists it in U like any other (its V changed, its T did not). Under a moving
// front most fragments see values move every step but a sign flip only now and then.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/grid/index_decoder.hpp"
#include "liveset/mesh/cell_polygoniser.hpp"
#include "liveset/mesh/mesh.hpp"
#include "liveset/mesh/sign_bits.hpp"

namespace liveset {

using FragmentId = std::uint32_t;  // linear index in the fragment lattice (x fastest)

// One fragment's buffers as seen by a renderer.
struct FragmentView {
    FragmentId id = 0;
    Vec3i cell_origin{};  // first owned cell
    Vec3i cell_extent{};  // number of owned cells per axis (smaller at the lattice's far border)
    std::span<const Vertex> vertices;       // V, index space
    std::span<const std::uint32_t> indices;  // T, 3 per triangle, local to V
    // Changes whenever T is rebuilt (unique across meshers; 0 never): two views with the same stamp
    // have the same T and vertex count, so a renderer re-uploads only V (a vertex-only refresh).
    std::uint64_t topology = 0;
    MeshView mesh() const { return {vertices, indices}; }
};

struct FragmentUpdateStats {
    std::size_t fragments_rebuilt = 0;
    std::size_t cells_visited = 0;       // cells polygonised (a scan: every cell of the fragments)
    std::size_t rows_visited = 0;        // candidate cell rows examined (0 for a scan)
    std::size_t vertices_computed = 0;   // edge vertices computed (border vertices count per fragment)
    std::size_t vertices_only = 0;       // of fragments_rebuilt: refreshed with T unchanged (no sign flip)
};

// Thread safety: update()/full_rebuild() parallelise internally and must not run concurrently
// with each other or with readers of fragment() spans (which they invalidate for the fragments in U).
class FragmentMesher {
public:
    // fragment_size S: cells per fragment edge (>= 1; the paper's smallest workable size is 3).
    // A size >= the largest cell dimension gives a single fragment (naive whole-lattice meshing).
    // Throws std::invalid_argument on S < 1 or an empty lattice.
    FragmentMesher(const Lattice& lattice, int fragment_size);
    ~FragmentMesher();
    FragmentMesher(FragmentMesher&&) noexcept;
    FragmentMesher& operator=(FragmentMesher&&) noexcept;

    const Lattice& lattice() const { return lattice_; }
    int fragment_size() const { return size_; }
    Vec3i fragment_dims() const { return fdims_; }  // fragments per axis
    std::size_t fragment_count() const { return fragments_.size(); }
    FragmentId fragment_id(Vec3i fragment_coord) const;
    Vec3i fragment_coord(FragmentId id) const;
    FragmentId fragment_of_cell(Vec3i cell) const;
    FragmentView fragment(FragmentId id) const;

    // Rebuilds every fragment by scanning all cells (O(volume)); returns nothing since all changed.
    void full_rebuild(const Grid<float>& phi);
    // Rebuilds every fragment visiting only cells with a corner in `zero_layer` (see
    // marching_cubes_band for the completeness condition).
    void full_rebuild(const Grid<float>& phi, std::span<const PointIndex> zero_layer);

    // Incremental update after the φ values at `changed` (X) were modified; every modified point must
    // be listed (duplicates allowed). Before the first full_rebuild() it performs one (scan) and
    // returns every fragment. Re-polygonises the affected fragments U and returns their ids,
    // sorted ascending. A fragment is affected when one of its cells has a corner in X (signs and
    // vertex positions) or a corner that is a 6-neighbour of a point of X (vertex normals read φ
    // through the central-difference stencil). φ must have this mesher's lattice dimensions.
    // `sign_changes`, when given, must hold every point of X whose sign of φ (is_inside) may differ
    // from the φ this mesher last meshed (update or full_rebuild) - the level set's
    // ChangedPoints::sign_changes, or for several updates their union. A listed point whose sign
    // did not change is harmless (each is checked). The pass over X then reads no φ values: only
    // these points' signs are checked. Without it every point of X is checked.
    std::vector<FragmentId> update(const Grid<float>& phi, std::span<const PointIndex> changed,
                                   std::optional<std::span<const PointIndex>> sign_changes = std::nullopt);

    // The fragments update() would rebuild for `changed`, without rebuilding (sorted).
    std::vector<FragmentId> affected_fragments(std::span<const PointIndex> changed) const;

    std::size_t triangle_count() const;
    std::size_t vertex_count() const;  // sum over fragments (border vertices counted per fragment)
    Mesh merged() const;               // all fragments concatenated (border vertices duplicated)
    const FragmentUpdateStats& last_stats() const { return stats_; }

private:
    struct Fragment {
        Vec3i origin{}, extent{};
        Mesh mesh;  // V and T
        // Bitmaps over the owned cell rows, bit (y - origin.y) + extent.y * (z - origin.z):
        std::vector<std::uint64_t> rows;     // rows holding a crossing cell, as last meshed
        std::vector<std::uint64_t> pending;  // rows with a cell corner whose sign flipped since then
        // The lattice edge of every vertex, for a vertex-only refresh; valid after a row pass (a
        // scan does not record them, so the fragment's next rebuild is a row pass).
        std::vector<CellPolygoniser::EdgeRef> edges;
        bool edges_valid = false;
        std::uint64_t topology = 0;  // FragmentView::topology
    };
    struct Scratch;

    void check_phi(const Grid<float>& phi) const;
    // Fragment-coordinate ranges of the cells around a point coordinate v on one axis: narrow =
    // cells with a corner at v ([v-1, v]), wide = with a corner at v-1, v or v+1 ([v-2, v+1]).
    struct AxisRange {
        int narrow_lo, narrow_hi, wide_lo, wide_hi;
    };

    template <class Visit>
    void for_each_affected(Vec3i p, Visit&& visit) const;
    void sync_signs(const Grid<float>& phi);
    // Marks the fragments of the cells with corner p reshaped and queues those cell rows in their
    // fragments' pending bitmaps (p's sign flipped).
    void mark_flipped(Vec3i p);
    void flag(FragmentId f, std::vector<FragmentId>& flagged);  // set B[f]; record f if this call set it
    [[gnu::noinline]] void claim(FragmentId f, std::vector<FragmentId>& flagged);  // flag()'s slow path: B[f] was clear
    void build_span_tables();
    std::vector<FragmentId> flag_and_flip(const Grid<float>& phi, std::span<const PointIndex> changed,
                                          std::optional<std::span<const PointIndex>> sign_changes);
    // The X pass's per-thread working set: the corner sets per block base (all zero between
    // calls) and the bases that hold one, in order of appearance.
    struct Blocks {
        std::vector<std::uint8_t> corners;
        std::vector<FragmentId> bases;
    };
    // The X pass over xs[b, e): flag the affected fragments and, with kSigns, synchronise the sign
    // bits (sizes >= 3; every loop value is a local, so the loop keeps them in registers).
    template <bool kSigns>
    void flag_points(const PointIndex* xs, std::size_t b, std::size_t e, const float* values, Blocks& blocks,
                     std::vector<FragmentId>& flagged);
    // Sets the sign bit of point x (row, px) to φ's sign; queues its cells when it flipped.
    void sync_sign(const float* values, PointIndex x, std::uint32_t row, std::uint32_t px);
    void rebuild(const Grid<float>& phi, std::span<const FragmentId> ids, bool scan);

    Lattice lattice_;
    int size_ = 0;
    Vec3i cells_{};  // cells per axis
    Vec3i fdims_{};
    std::vector<Fragment> fragments_;
    std::vector<std::uint8_t> flags_;  // B
    std::vector<std::uint8_t> reshaped_;  // per fragment: a corner of one of its cells flipped sign since it was meshed
    IndexDecoder decode_;
    std::array<std::vector<AxisRange>, 3> ranges_;  // per axis, indexed by point coordinate
    // The X pass's tables (fragment sizes >= 3, where a wide range holds at most two fragment
    // coordinates per axis): a changed point's affected fragments are a subset of the 2x2x2 block
    // of fragments from its wide ranges' first ones, corner c = i + 2j + 4k of that block at
    // fragment id base + corner_offset_[c]. for_each_affected's union of three boxes (wide on one
    // axis, narrow on the others) is (Xw & Yn & Zn) | (Xn & Yw & Zn) | (Xn & Yn & Zw) as 8-bit
    // corner sets, split into a part per x and a part per point row, so a point costs one
    // division (its row) and two table reads. Each entry packs base | a << 32 | b << 40:
    //   x_spans_[x]:   base = the wide range's first fragment x; a = Xw, b = Xn
    //   row_spans_[r]: base = the first fragment y and z times their id strides; a = Yn & Zn,
    //                  b = (Yw & Zn) | (Yn & Zw)
    // so (x & row) >> 32 holds the two halves of the corner set. Empty for sizes 1 and 2.
    std::vector<std::uint64_t> x_spans_;    // per point x
    std::vector<std::uint64_t> row_spans_;  // per point row y + dims.y * z
    std::array<std::uint32_t, 8> corner_offset_{};
    FastDivider row_of_;              // point index -> row (index / dims.x)
    std::array<std::vector<int>, 3> cell_fragment_, cell_offset_;  // per axis: cell c -> c / S, c % S
    SignBits signs_;              // is_inside() per lattice point, as last meshed
    bool initialised_ = false;    // signs_ and the row bitmaps are valid
    FragmentUpdateStats stats_;
    std::unique_ptr<Scratch> scratch_;  // per-thread polygonisers
};

// The whole volume meshed fragment by fragment (`liveset mesh --fragment S`): a FragmentMesher of
// `fragment_size` fully rebuilt on `phi`, its fragments merged (border vertices duplicated);
// `fragments` receives their number.
Mesh mesh_in_fragments(const Grid<float>& phi, int fragment_size, std::size_t* fragments = nullptr);

}  // namespace liveset
