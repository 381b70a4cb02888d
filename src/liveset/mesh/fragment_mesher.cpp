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

namespace liveset {

struct FragmentMesher::Scratch {
    struct Local {
        CellPolygoniser poly;
        std::vector<CellKey> candidates;
        std::vector<CellKey> crossing;
        std::vector<FragmentId> flagged;   // fragments this thread flagged in B during update()
        std::vector<PointIndex> flipped;   // changed points whose sign flipped
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
    decode_ = IndexDecoder(lattice);
    inside_.assign(lattice.size() / 64 + 1, 0);
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
        }
    }
    for (FragmentId id = 0; id < n; ++id) {
        Fragment& f = fragments_[id];
        const Vec3i fc = fragment_coord(id);
        for (int a = 0; a < 3; ++a) {
            f.origin[a] = fc[a] * size_;
            f.extent[a] = std::min(size_, cells_[a] - f.origin[a]);
        }
    }
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
    return {id, f.origin, f.extent, f.mesh.vertices, f.mesh.indices};
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
    std::atomic<std::size_t> visited{0}, computed{0};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, ids.size(), 1), [&](const tbb::blocked_range<std::size_t>& r) {
        Scratch::Local& local = scratch_->locals.local();
        std::size_t my_visited = 0, my_computed = 0;
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
            Fragment& f = fragments_[ids[i]];
            const Vec3i hi = f.origin + f.extent;
            f.mesh.clear();
            local.crossing.clear();
            if (scan) {
                local.poly.polygonise_box(phi, f.origin, hi, f.mesh, &local.crossing);
                my_visited += static_cast<std::size_t>(f.extent.x) * static_cast<std::size_t>(f.extent.y) *
                              static_cast<std::size_t>(f.extent.z);
            } else {
                sort_unique(f.pending);
                local.candidates.clear();
                std::set_union(f.crossing.begin(), f.crossing.end(), f.pending.begin(), f.pending.end(),
                               std::back_inserter(local.candidates));
                local.poly.polygonise_cells(phi, f.origin, hi, local.candidates, f.mesh, &local.crossing);
                my_visited += local.candidates.size();
            }
            my_computed += local.poly.vertices_computed();
            f.crossing.swap(local.crossing);
            f.pending.clear();
        }
        visited += my_visited;
        computed += my_computed;
    });
    stats_.fragments_rebuilt = ids.size();
    stats_.cells_visited = visited;
    stats_.vertices_computed = computed;
}

void FragmentMesher::sync_signs(const Grid<float>& phi) {
    const std::span<const float> v = phi.values();
    const std::size_t n = v.size();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, inside_.size(), 256), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t w = r.begin(); w != r.end(); ++w) {
            std::uint64_t bits = 0;
            const std::size_t base = w * 64;
            const std::size_t stop = std::min(base + 64, n);
            for (std::size_t i = base; i < stop; ++i)
                if (is_inside(v[i])) bits |= std::uint64_t{1} << (i - base);
            inside_[w] = bits;
        }
    });
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
    for (Fragment& f : fragments_) {
        f.crossing.clear();
        f.pending.clear();
    }
    for (CellKey key : cells) fragments_[fragment_of_cell(lattice_.coord(key))].pending.push_back(key);
    std::vector<FragmentId> all(fragments_.size());
    for (FragmentId i = 0; i < all.size(); ++i) all[i] = i;
    rebuild(phi, all, false);
}

std::vector<FragmentId> FragmentMesher::update(const Grid<float>& phi, std::span<const PointIndex> changed) {
    check_phi(phi);
    for (PointIndex x : changed)
        if (x >= lattice_.size()) throw std::out_of_range("changed point index outside the lattice");
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

    // Pass over X (parallel): flag the affected fragments in B, and find the points whose sign
    // flipped - only their cells can start or stop crossing; every other cell that may cross now
    // is in its fragment's crossing list already.
    for (auto& local : scratch_->locals) {
        local.flagged.clear();
        local.flipped.clear();
    }
    const std::span<const float> values = phi.values();
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, changed.size(), 2048), [&](const tbb::blocked_range<std::size_t>& r) {
        Scratch::Local& local = scratch_->locals.local();
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
            if (k + 16 < r.end()) {  // X is in band-list order, scattered over the lattice
                const PointIndex ahead = changed[k + 16];
                __builtin_prefetch(values.data() + ahead);
                __builtin_prefetch(inside_.data() + (ahead >> 6));
            }
            const PointIndex x = changed[k];
            for_each_affected(decode_.coord(x), [&](FragmentId f) {
                std::atomic_ref<std::uint8_t> flag(flags_[f]);
                if (flag.load(std::memory_order_relaxed) == 0 && flag.exchange(1, std::memory_order_relaxed) == 0)
                    local.flagged.push_back(f);
            });
            const bool now = is_inside(values[x]);
            const std::uint64_t bit = std::uint64_t{1} << (x & 63u);
            std::atomic_ref<std::uint64_t> word(inside_[x >> 6]);
            if (((word.load(std::memory_order_relaxed) & bit) != 0) != now) {
                const std::uint64_t old = now ? word.fetch_or(bit, std::memory_order_relaxed)
                                              : word.fetch_and(~bit, std::memory_order_relaxed);
                if (((old & bit) != 0) != now) local.flipped.push_back(x);  // exactly one thread sees the flip
            }
        }
    });
    std::vector<FragmentId> u;
    std::vector<PointIndex> flipped;
    for (auto& local : scratch_->locals) {
        u.insert(u.end(), local.flagged.begin(), local.flagged.end());
        flipped.insert(flipped.end(), local.flipped.begin(), local.flipped.end());
    }
    std::sort(u.begin(), u.end());
    for (PointIndex x : flipped) {
        // Cells with x as a corner may change sign pattern: queue them in their fragments.
        const Vec3i p = decode_.coord(x);
        const int x0 = std::max(p.x - 1, 0), x1 = std::min(p.x, cells_.x - 1);
        const int y0 = std::max(p.y - 1, 0), y1 = std::min(p.y, cells_.y - 1);
        const int z0 = std::max(p.z - 1, 0), z1 = std::min(p.z, cells_.z - 1);
        for (int z = z0; z <= z1; ++z)
            for (int y = y0; y <= y1; ++y)
                for (int xx = x0; xx <= x1; ++xx) {
                    const Vec3i c{xx, y, z};
                    fragments_[fragment_of_cell(c)].pending.push_back(lattice_.index(c));
                }
    }
    try {
        rebuild(phi, u, false);
    } catch (...) {
        for (FragmentId f : u) flags_[f] = 0;
        initialised_ = false;  // crossing lists may be stale: the next update starts from scratch
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
