// FragmentMesher: fragment lattice bookkeeping, affected-fragment search with the flag lattice B,
// and parallel (oneTBB) surface-proportional re-polygonisation of the affected fragments.
#include "liveset/mesh/fragment_mesher.hpp"

#include <algorithm>
#include <atomic>
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
void FragmentMesher::for_each_affected(PointIndex x, Visit&& visit) const {
    const Vec3i p = lattice_.coord(x);
    // Cells with a corner at p or at a 6-neighbour of p (the central-difference stencil).
    for (int k = 0; k < 7; ++k) {
        Vec3i q = p;
        if (k > 0) q[(k - 1) / 2] += (k % 2) ? -1 : 1;
        if (!lattice_.contains(q)) continue;
        Vec3i flo, fhi;
        bool empty = false;
        for (int a = 0; a < 3; ++a) {
            const int lo = std::max(q[a] - 1, 0), hi = std::min(q[a], cells_[a] - 1);
            if (lo > hi) empty = true;
            flo[a] = lo / size_;
            fhi[a] = hi / size_;
        }
        if (empty) continue;
        for (int z = flo.z; z <= fhi.z; ++z)
            for (int y = flo.y; y <= fhi.y; ++y)
                for (int xx = flo.x; xx <= fhi.x; ++xx) visit(fragment_id({xx, y, z}));
    }
}

std::vector<FragmentId> FragmentMesher::affected_fragments(std::span<const PointIndex> changed) const {
    std::vector<FragmentId> ids;
    for (PointIndex x : changed) {
        if (x >= lattice_.size()) throw std::out_of_range("changed point index outside the lattice");
        for_each_affected(x, [&](FragmentId f) { ids.push_back(f); });
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

void FragmentMesher::full_rebuild(const Grid<float>& phi) {
    check_phi(phi);
    std::vector<FragmentId> all(fragments_.size());
    for (FragmentId i = 0; i < all.size(); ++i) all[i] = i;
    rebuild(phi, all, true);
}

void FragmentMesher::full_rebuild(const Grid<float>& phi, std::span<const PointIndex> zero_layer) {
    check_phi(phi);
    const std::vector<CellKey> cells = cells_around_points(lattice_, zero_layer);  // validates indices
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
    std::vector<FragmentId> u;
    for (PointIndex x : changed) {
        for_each_affected(x, [&](FragmentId f) {
            if (!flags_[f]) {
                flags_[f] = 1;
                u.push_back(f);
            }
        });
        // Cells with x as a corner may change sign pattern: queue them in their fragments.
        const Vec3i p = lattice_.coord(x);
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
    std::sort(u.begin(), u.end());
    try {
        rebuild(phi, u, false);
    } catch (...) {
        for (FragmentId f : u) flags_[f] = 0;
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

}  // namespace liveset
