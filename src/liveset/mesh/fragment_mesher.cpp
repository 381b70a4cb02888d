// FragmentMesher: fragment lattice bookkeeping, affected-fragment search with the flag lattice B,
// and parallel (oneTBB) surface-proportional re-polygonisation of the affected fragments.
#include "liveset/mesh/fragment_mesher.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <sstream>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/mesh/slab_marching_cubes.hpp"

namespace liveset {

struct FragmentMesher::Scratch {
    struct Local {
        CellPolygoniser poly;
        std::vector<CellKey> crossing;     // a scan's crossing cells
        std::vector<std::uint64_t> rows;   // the rebuilt fragment's new crossing rows
        std::vector<FragmentId> flagged;   // fragments this thread flagged in B during update()
        Blocks blocks;
    };
    tbb::enumerable_thread_specific<Local> locals;
};

FragmentMesher::FragmentMesher(const Lattice& lattice, int fragment_size)
    : lattice_(lattice), size_(fragment_size), scratch_(std::make_unique<Scratch>()) {
    if (fragment_size < 1) throw std::invalid_argument("fragment size must be at least 1 cell");
    const Vec3i d = lattice.dims();
    for (int a = 0; a < 3; ++a) {
        cells_[a] = std::max(d[a] - 1, 0);
        fdims_[a] = (cells_[a] + size_ - 1) / size_;
    }
    if (cells_.x == 0 || cells_.y == 0 || cells_.z == 0) fdims_ = {0, 0, 0};
    const std::size_t n = static_cast<std::size_t>(fdims_.x) * static_cast<std::size_t>(fdims_.y) *
                          static_cast<std::size_t>(fdims_.z);
    fragments_.resize(n);
    flags_.assign(n, 0);
    reshaped_.assign(n, 0);
    decode_ = IndexDecoder(lattice);
    signs_.dims = d;
    signs_.words_per_row = (static_cast<std::size_t>(std::max(d.x, 0)) + 63) / 64;
    signs_.words.assign(static_cast<std::size_t>(std::max(d.y, 0)) * static_cast<std::size_t>(std::max(d.z, 0)) * signs_.words_per_row, 0);
    if (n > 0) {
        for (int a = 0; a < 3; ++a) {
            auto& t = ranges_[a];
            t.resize(static_cast<std::size_t>(d[a]));
            const int last = cells_[a] - 1;
            for (int v = 0; v < d[a]; ++v) {
                AxisRange& r = t[static_cast<std::size_t>(v)];
                r.narrow_lo = std::max(v - 1, 0) / size_;
                r.narrow_hi = std::min(v, last) / size_;
                r.wide_lo = std::max(v - 2, 0) / size_;
                r.wide_hi = std::min(v + 1, last) / size_;
            }
            cell_fragment_[a].resize(static_cast<std::size_t>(cells_[a]));
            cell_offset_[a].resize(static_cast<std::size_t>(cells_[a]));
            for (int c = 0; c < cells_[a]; ++c) {
                cell_fragment_[a][static_cast<std::size_t>(c)] = c / size_;
                cell_offset_[a][static_cast<std::size_t>(c)] = c % size_;
            }
        }
    }
    if (n > 0) row_of_ = FastDivider(static_cast<std::uint32_t>(d.x));
    if (n > 0 && size_ >= 3) build_span_tables();
    for (FragmentId id = 0; id < n; ++id) {
        Fragment& f = fragments_[id];
        const Vec3i fc = fragment_coord(id);
        for (int a = 0; a < 3; ++a) {
            f.origin[a] = fc[a] * size_;
            f.extent[a] = std::min(size_, cells_[a] - f.origin[a]);
        }
        const std::size_t words = (static_cast<std::size_t>(f.extent.y) * static_cast<std::size_t>(f.extent.z) + 63) / 64;
        f.rows.assign(words, 0);
        f.pending.assign(words, 0);
    }
}

void FragmentMesher::build_span_tables() {
    // Per axis: 2-bit masks over the two fragment coordinates (first, first + 1) of a point's wide
    // range, for the wide and the narrow range; then as 8-bit corner sets of the 2x2x2 block.
    static constexpr std::uint8_t kX[4] = {0x00, 0x55, 0xAA, 0xFF}, kY[4] = {0x00, 0x33, 0xCC, 0xFF}, kZ[4] = {0x00, 0x0F, 0xF0, 0xFF};
    struct Masks {
        std::uint32_t first;
        unsigned wide, narrow;
    };
    const auto masks = [&](int a, int v) {
        const AxisRange& r = ranges_[static_cast<std::size_t>(a)][static_cast<std::size_t>(v)];
        const auto bits = [&](int lo, int hi) { return ((2u << (hi - r.wide_lo)) - 1) & ~((1u << (lo - r.wide_lo)) - 1); };
        return Masks{static_cast<std::uint32_t>(r.wide_lo), bits(r.wide_lo, r.wide_hi), bits(r.narrow_lo, r.narrow_hi)};
    };
    const Vec3i d = lattice_.dims();
    const auto fx = static_cast<std::uint32_t>(fdims_.x), fxy = fx * static_cast<std::uint32_t>(fdims_.y);
    x_spans_.resize(static_cast<std::size_t>(d.x));
    for (int x = 0; x < d.x; ++x) {
        const Masks m = masks(0, x);
        x_spans_[static_cast<std::size_t>(x)] = m.first | std::uint64_t{kX[m.wide]} << 32 | std::uint64_t{kX[m.narrow]} << 40;
    }
    row_spans_.resize(static_cast<std::size_t>(d.y) * static_cast<std::size_t>(d.z));
    for (int z = 0; z < d.z; ++z) {
        const Masks mz = masks(2, z);
        for (int y = 0; y < d.y; ++y) {
            const Masks my = masks(1, y);
            const std::uint64_t nn = kY[my.narrow] & kZ[mz.narrow];
            const std::uint64_t wn = (kY[my.wide] & kZ[mz.narrow]) | (kY[my.narrow] & kZ[mz.wide]);
            row_spans_[static_cast<std::size_t>(y) + static_cast<std::size_t>(d.y) * static_cast<std::size_t>(z)] =
                (my.first * fx + mz.first * fxy) | nn << 32 | wn << 40;
        }
    }
    for (unsigned c = 0; c < 8; ++c) corner_offset_[c] = (c & 1u) + ((c >> 1) & 1u) * fx + (c >> 2) * fxy;
}

FragmentMesher::~FragmentMesher() = default;
FragmentMesher::FragmentMesher(FragmentMesher&&) noexcept = default;
FragmentMesher& FragmentMesher::operator=(FragmentMesher&&) noexcept = default;

FragmentId FragmentMesher::fragment_id(Vec3i fc) const {
    return static_cast<FragmentId>(fc.x + fdims_.x * (fc.y + fdims_.y * fc.z));
}

Vec3i FragmentMesher::fragment_coord(FragmentId id) const {
    const int i = static_cast<int>(id);
    return {i % fdims_.x, (i / fdims_.x) % fdims_.y, i / (fdims_.x * fdims_.y)};
}

FragmentId FragmentMesher::fragment_of_cell(Vec3i cell) const {
    return fragment_id({cell.x / size_, cell.y / size_, cell.z / size_});
}

FragmentView FragmentMesher::fragment(FragmentId id) const {
    const Fragment& f = fragments_.at(id);
    return {id, f.origin, f.extent, f.mesh.vertices, f.mesh.indices, f.topology};
}

void FragmentMesher::check_phi(const Grid<float>& phi) const {
    if (!(phi.dims() == lattice_.dims())) {
        std::ostringstream os;
        os << "phi grid " << phi.dims() << " does not match the mesher's lattice " << lattice_.dims();
        throw std::invalid_argument(os.str());
    }
}

template <class Visit>
void FragmentMesher::for_each_affected(Vec3i p, Visit&& visit) const {
    // Cells with a corner at p or at a 6-neighbour of p (the central-difference stencil): per axis a,
    // the box "wide on a, narrow on the others"; their union is what a change at p can touch.
    const AxisRange& rx = ranges_[0][static_cast<std::size_t>(p.x)];
    const AxisRange& ry = ranges_[1][static_cast<std::size_t>(p.y)];
    const AxisRange& rz = ranges_[2][static_cast<std::size_t>(p.z)];
    if (rx.wide_lo == rx.wide_hi && ry.wide_lo == ry.wide_hi && rz.wide_lo == rz.wide_hi) {
        visit(static_cast<FragmentId>(rx.wide_lo + fdims_.x * (ry.wide_lo + fdims_.y * rz.wide_lo)));  // interior
        return;
    }
    const AxisRange* r[3] = {&rx, &ry, &rz};
    for (int a = 0; a < 3; ++a) {
        int lo[3], hi[3];
        for (int b = 0; b < 3; ++b) {
            lo[b] = a == b ? r[b]->wide_lo : r[b]->narrow_lo;
            hi[b] = a == b ? r[b]->wide_hi : r[b]->narrow_hi;
        }
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x)
                    visit(static_cast<FragmentId>(x + fdims_.x * (y + fdims_.y * z)));
    }
}

std::vector<FragmentId> FragmentMesher::affected_fragments(std::span<const PointIndex> changed) const {
    std::vector<FragmentId> ids;
    for (PointIndex x : changed) {
        if (x >= lattice_.size()) throw std::out_of_range("changed point index outside the lattice");
        if (!fragments_.empty()) for_each_affected(decode_.coord(x), [&](FragmentId f) { ids.push_back(f); });
    }
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    return ids;
}

void FragmentMesher::rebuild(const Grid<float>& phi, std::span<const FragmentId> ids, bool scan) {
    static std::atomic<std::uint64_t> next_topology{1};  // process-wide: stamps never repeat across meshers
    const std::uint64_t topology = next_topology.fetch_add(1, std::memory_order_relaxed);
    std::atomic<std::size_t> visited{0}, rows{0}, computed{0}, vertices_only{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ids.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
        Scratch::Local& local = scratch_->locals.local();
        std::size_t my_visited = 0, my_rows = 0, my_computed = 0, my_vertices_only = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            Fragment& f = fragments_[ids[i]];
            const bool reshaped = reshaped_[ids[i]] != 0;
            reshaped_[ids[i]] = 0;
            if (!scan && !reshaped && f.edges_valid) {  // the same cells cross: T stays, V moves with φ
                local.poly.refresh_vertices(phi, f.edges, f.mesh.vertices);
                my_computed += f.edges.size();
                ++my_vertices_only;
                continue;
            }
            const Vec3i hi = f.origin + f.extent;
            f.mesh.clear();
            f.edges_valid = false;
            f.topology = topology;
            local.rows.assign(f.rows.size(), 0);
            if (scan) {
                local.crossing.clear();
                local.poly.polygonise_box(phi, f.origin, hi, f.mesh, &local.crossing);
                my_visited += static_cast<std::size_t>(f.extent.x) * static_cast<std::size_t>(f.extent.y) *
                              static_cast<std::size_t>(f.extent.z);
                for (CellKey key : local.crossing) {
                    const Vec3i c = decode_.coord(key);
                    const auto bit = static_cast<std::size_t>((c.y - f.origin.y) + f.extent.y * (c.z - f.origin.z));
                    local.rows[bit >> 6] |= std::uint64_t{1} << (bit & 63);
                }
            } else {
                local.poly.polygonise_rows(phi, signs_, f.origin, hi, f.rows, f.pending, f.mesh, local.rows, &f.edges);
                f.edges_valid = true;
                my_visited += local.poly.cells_polygonised();
                my_rows += local.poly.rows_visited();
            }
            my_computed += local.poly.vertices_computed();
            f.rows.swap(local.rows);
            std::fill(f.pending.begin(), f.pending.end(), 0);
        }
        visited += my_visited;
        rows += my_rows;
        computed += my_computed;
        vertices_only += my_vertices_only;
    });
    stats_.fragments_rebuilt = ids.size();
    stats_.cells_visited = visited;
    stats_.rows_visited = rows;
    stats_.vertices_computed = computed;
    stats_.vertices_only = vertices_only;
}

void FragmentMesher::sync_signs(const Grid<float>& phi) {
    signs_ = sign_bits(phi);
    initialised_ = true;
}

void FragmentMesher::full_rebuild(const Grid<float>& phi) {
    check_phi(phi);
    sync_signs(phi);
    std::vector<FragmentId> all(fragments_.size());
    for (FragmentId i = 0; i < all.size(); ++i) all[i] = i;
    rebuild(phi, all, true);
}

void FragmentMesher::full_rebuild(const Grid<float>& phi, std::span<const PointIndex> zero_layer) {
    check_phi(phi);
    const std::vector<CellKey> cells = cells_around_points(lattice_, zero_layer);  // validates indices
    sync_signs(phi);
    std::fill(reshaped_.begin(), reshaped_.end(), 1);  // any sign may differ from the last mesh: no vertex-only refresh
    for (Fragment& f : fragments_) {
        std::fill(f.rows.begin(), f.rows.end(), 0);
        std::fill(f.pending.begin(), f.pending.end(), 0);
    }
    for (CellKey key : cells) {
        const Vec3i c = decode_.coord(key);
        Fragment& f = fragments_[fragment_of_cell(c)];
        const auto bit = static_cast<std::size_t>((c.y - f.origin.y) + f.extent.y * (c.z - f.origin.z));
        f.pending[bit >> 6] |= std::uint64_t{1} << (bit & 63);
    }
    std::vector<FragmentId> all(fragments_.size());
    for (FragmentId i = 0; i < all.size(); ++i) all[i] = i;
    rebuild(phi, all, false);
}

void FragmentMesher::mark_flipped(Vec3i p) {
    // Cells with corner p: x in [p.x - 1, p.x] (one or two fragments), the same for y and z.
    const int x0 = std::max(p.x - 1, 0), x1 = std::min(p.x, cells_.x - 1);
    const int y0 = std::max(p.y - 1, 0), y1 = std::min(p.y, cells_.y - 1);
    const int z0 = std::max(p.z - 1, 0), z1 = std::min(p.z, cells_.z - 1);
    const int fx0 = cell_fragment_[0][static_cast<std::size_t>(x0)], fx1 = cell_fragment_[0][static_cast<std::size_t>(x1)];
    for (int z = z0; z <= z1; ++z) {
        const int fz = cell_fragment_[2][static_cast<std::size_t>(z)], oz = cell_offset_[2][static_cast<std::size_t>(z)];
        for (int y = y0; y <= y1; ++y) {
            const int fy = cell_fragment_[1][static_cast<std::size_t>(y)], oy = cell_offset_[1][static_cast<std::size_t>(y)];
            for (int fx = fx0; fx <= fx1; ++fx) {
                const FragmentId id = fragment_id({fx, fy, fz});
                std::atomic_ref<std::uint8_t> reshaped(reshaped_[id]);
                if (reshaped.load(std::memory_order_relaxed) == 0) reshaped.store(1, std::memory_order_relaxed);
                Fragment& f = fragments_[id];
                const auto bit = static_cast<std::size_t>(oy + f.extent.y * oz);
                const std::uint64_t mask = std::uint64_t{1} << (bit & 63);
                if ((f.rows[bit >> 6] & mask) != 0) continue;  // a candidate anyway (rows are not written here)
                std::atomic_ref<std::uint64_t> word(f.pending[bit >> 6]);
                if ((word.load(std::memory_order_relaxed) & mask) == 0) word.fetch_or(mask, std::memory_order_relaxed);
            }
        }
    }
}

void FragmentMesher::claim(FragmentId f, std::vector<FragmentId>& flagged) {
    if (std::atomic_ref<std::uint8_t>(flags_[f]).exchange(1, std::memory_order_relaxed) == 0) flagged.push_back(f);
}

[[gnu::always_inline]] inline void FragmentMesher::flag(FragmentId f, std::vector<FragmentId>& flagged) {
    if (std::atomic_ref<std::uint8_t>(flags_[f]).load(std::memory_order_relaxed) == 0) claim(f, flagged);
}

[[gnu::always_inline]] inline void FragmentMesher::sync_sign(const float* values, PointIndex x, std::uint32_t row, std::uint32_t px) {
    const bool now = is_inside(values[x]);
    const std::uint64_t bit = std::uint64_t{1} << (px & 63);
    std::atomic_ref<std::uint64_t> word(signs_.words[signs_.word_of(row, px)]);
    if (((word.load(std::memory_order_relaxed) & bit) != 0) == now) return;
    const std::uint64_t old = now ? word.fetch_or(bit, std::memory_order_relaxed) : word.fetch_and(~bit, std::memory_order_relaxed);
    if (((old & bit) != 0) != now) mark_flipped(decode_.coord(x));  // exactly one thread sees the flip
}

template <bool kSigns>
void FragmentMesher::flag_points(const PointIndex* xs, std::size_t b, std::size_t e, const float* values, Blocks& blocks,
                                 std::vector<FragmentId>& flagged) {
    // First the points' corner sets OR-ed per block base into blocks.corners, with no compare
    // against the previous point's fragments (consecutive points of X often lie in different
    // fragments: a box's opposite faces alternate in index order, so "same as the last point"
    // mispredicts); then each distinct block's fragments are flagged once.
    blocks.bases.reserve(blocks.bases.size() + (e - b));  // the loop below then cannot throw
    const std::uint64_t* const xsp = x_spans_.data();
    const std::uint64_t* const rsp = row_spans_.data();
    std::uint8_t* const seen = blocks.corners.data();
    const FastDivider row_of = row_of_;
    const auto nx = static_cast<std::uint32_t>(signs_.dims.x);
    for (std::size_t k = b; k != e; ++k) {
        if (kSigns && k + 16 < e) __builtin_prefetch(values + xs[k + 16]);  // X is scattered over the lattice
        const PointIndex x = xs[k];
        const std::uint32_t row = row_of.divide(x);  // y + dims.y * z
        const std::uint32_t px = x - row * nx;
        const std::uint64_t sx = xsp[px], sr = rsp[row];
        const std::uint64_t halves = (sx & sr) >> 32;
        const auto base = static_cast<std::uint32_t>(sx + sr);
        const auto corners = static_cast<std::uint8_t>(halves | halves >> 8);  // never empty: the point's own fragment
        const std::uint8_t before = seen[base];
        seen[base] = before | corners;
        if (before == 0) blocks.bases.push_back(base);
        if constexpr (kSigns) sync_sign(values, x, row, px);
    }
    for (const FragmentId base : blocks.bases) {
        for (unsigned corners = seen[base]; corners != 0; corners &= corners - 1)
            flag(base + corner_offset_[static_cast<std::size_t>(std::countr_zero(corners))], flagged);
        seen[base] = 0;
    }
    blocks.bases.clear();
}

std::vector<FragmentId> FragmentMesher::flag_and_flip(const Grid<float>& phi, std::span<const PointIndex> changed,
                                                      std::optional<std::span<const PointIndex>> sign_changes) {
    // Pass over X (parallel): flag the affected fragments in B, and update the sign bits; a point
    // whose sign flipped queues the rows of its cells - only those cells can start or stop
    // crossing; every other row that may cross now is in its fragment's row bitmap already. With
    // the sign changes known, only those points' signs are synchronised (a second, short pass).
    for (auto& local : scratch_->locals) local.flagged.clear();
    const float* const values = phi.values().data();
    const bool check_signs = !sign_changes.has_value();
    const auto nx = static_cast<std::uint32_t>(signs_.dims.x);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, changed.size(), 2048), [&](const tbb::blocked_range<std::size_t>& r) {
        Scratch::Local& local = scratch_->locals.local();
        std::vector<FragmentId>& flagged = local.flagged;
        if (!x_spans_.empty()) {  // fragment sizes >= 3
            if (local.blocks.corners.size() != fragments_.size()) local.blocks.corners.assign(fragments_.size(), 0);
            if (check_signs) flag_points<true>(changed.data(), r.begin(), r.end(), values, local.blocks, flagged);
            else flag_points<false>(changed.data(), r.begin(), r.end(), values, local.blocks, flagged);
            return;
        }
        for (std::size_t k = r.begin(); k != r.end(); ++k) {  // fragment sizes 1 and 2
            const PointIndex x = changed[k];
            for_each_affected(decode_.coord(x), [&](FragmentId f) { flag(f, flagged); });
            const std::uint32_t row = row_of_.divide(x);
            if (check_signs) sync_sign(values, x, row, x - row * nx);
        }
    });
    if (!check_signs) {
        const std::span<const PointIndex> flips = *sign_changes;
        tbb::parallel_for(tbb::blocked_range<std::size_t>(0, flips.size(), 2048), [&](const tbb::blocked_range<std::size_t>& r) {
            for (std::size_t k = r.begin(); k != r.end(); ++k) {
                const std::uint32_t row = row_of_.divide(flips[k]);
                sync_sign(values, flips[k], row, flips[k] - row * nx);
            }
        });
    }
    std::vector<FragmentId> u;
    for (auto& local : scratch_->locals) u.insert(u.end(), local.flagged.begin(), local.flagged.end());
    std::sort(u.begin(), u.end());
    return u;
}

std::vector<FragmentId> FragmentMesher::update(const Grid<float>& phi, std::span<const PointIndex> changed,
                                               std::optional<std::span<const PointIndex>> sign_changes) {
    check_phi(phi);
    // Validated before anything changes; the largest index, a loop the compiler vectorises.
    const auto largest = [](std::span<const PointIndex> xs) {
        PointIndex m = 0;
        for (const PointIndex x : xs) m = std::max(m, x);
        return m;
    };
    if (!changed.empty() && largest(changed) >= lattice_.size()) throw std::out_of_range("changed point index outside the lattice");
    if (sign_changes && !sign_changes->empty() && largest(*sign_changes) >= lattice_.size())
        throw std::out_of_range("sign-change point index outside the lattice");
    if (fragments_.empty()) {
        stats_ = {};
        return {};
    }
    if (!initialised_) {  // nothing to be incremental against yet
        full_rebuild(phi);
        std::vector<FragmentId> all(fragments_.size());
        for (FragmentId i = 0; i < all.size(); ++i) all[i] = i;
        return all;
    }

    std::vector<FragmentId> u;
    try {
        u = flag_and_flip(phi, changed, sign_changes);
        rebuild(phi, u, false);
    } catch (...) {  // e.g. out of memory: forget every partial state, the next update starts from scratch
        std::fill(flags_.begin(), flags_.end(), 0);
        for (auto& local : scratch_->locals) {
            std::fill(local.blocks.corners.begin(), local.blocks.corners.end(), 0);
            local.blocks.bases.clear();
        }
        initialised_ = false;  // sign bits and row bitmaps may be stale
        throw;
    }
    for (FragmentId f : u) flags_[f] = 0;
    return u;
}

std::size_t FragmentMesher::triangle_count() const {
    std::size_t n = 0;
    for (const Fragment& f : fragments_) n += f.mesh.triangle_count();
    return n;
}

std::size_t FragmentMesher::vertex_count() const {
    std::size_t n = 0;
    for (const Fragment& f : fragments_) n += f.mesh.vertices.size();
    return n;
}

Mesh FragmentMesher::merged() const {
    std::vector<MeshView> parts;
    parts.reserve(fragments_.size());
    for (const Fragment& f : fragments_) parts.push_back(f.mesh.view());
    return concatenate(parts);
}

Mesh mesh_in_fragments(const Grid<float>& phi, int fragment_size, std::size_t* fragments) {
    FragmentMesher m(phi.lattice(), fragment_size);
    m.full_rebuild(phi);
    if (fragments) *fragments = m.fragment_count();
    return m.merged();
}

}  // namespace liveset
