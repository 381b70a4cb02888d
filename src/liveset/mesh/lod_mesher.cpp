// Coarse level of detail: φ subsampled by k, meshed in fragments, updated from the fine U.
#include "liveset/mesh/lod_mesher.hpp"

#include <algorithm>
#include <stdexcept>

namespace liveset {

namespace {

int checked_factor(int factor) {
    if (factor < 2 || factor > 8) throw std::invalid_argument("LodMesher: the factor must be 2 to 8");
    return factor;
}

}  // namespace

Lattice coarsened(const Lattice& fine, int factor) {
    const int k = checked_factor(factor);
    const Vec3i d = fine.dims();
    const Vec3d s = fine.spacing();
    return Lattice({(d.x + k - 1) / k, (d.y + k - 1) / k, (d.z + k - 1) / k}, {k * s.x, k * s.y, k * s.z}, fine.origin(),
                   fine.direction());
}

LodMesher::LodMesher(const Lattice& fine, int fine_fragment_size, int factor)
    : factor_(checked_factor(factor)),
      coarse_phi_(coarsened(fine, factor), 1.0f),
      mesher_(coarse_phi_.lattice(), std::max(1, fine_fragment_size)) {
    if (fine_fragment_size < 1) throw std::invalid_argument("LodMesher: the fragment size must be at least 1");
}

void LodMesher::rebuild(const Grid<float>& phi) {
    const Vec3i d = coarse_phi_.lattice().dims();
    const int k = factor_;
    if (coarsened(phi.lattice(), k).dims() != d) throw std::invalid_argument("LodMesher: φ has other dimensions");
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) coarse_phi_({x, y, z}) = phi({k * x, k * y, k * z});
    mesher_.full_rebuild(coarse_phi_);
    built_ = true;
}

std::vector<FragmentId> LodMesher::rebuild_all(const Grid<float>& phi) {
    rebuild(phi);
    std::vector<FragmentId> all(mesher_.fragment_count());
    for (FragmentId f = 0; f < all.size(); ++f) all[f] = f;
    return all;
}

std::vector<FragmentId> LodMesher::update(const Grid<float>& phi, const FragmentMesher& fine, std::span<const FragmentId> fine_ids) {
    const int k = factor_;
    if (coarsened(phi.lattice(), k).dims() != coarse_phi_.lattice().dims())
        throw std::invalid_argument("LodMesher: φ has other dimensions");
    if (!built_) return rebuild_all(phi);
    const Vec3i fd = phi.lattice().dims();
    std::vector<PointIndex> changed;
    for (FragmentId id : fine_ids) {
        const FragmentView v = fine.fragment(id);
        // The fragment's cells span points [origin, origin + extent]; the multiples of k are coarse points.
        Vec3i lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = (v.cell_origin[a] + k - 1) / k;
            hi[a] = std::min(v.cell_origin[a] + v.cell_extent[a], fd[a] - 1) / k;
        }
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) {
                    const float value = phi({k * x, k * y, k * z});
                    float& mine = coarse_phi_({x, y, z});
                    if (value == mine) continue;
                    mine = value;
                    changed.push_back(coarse_phi_.lattice().index({x, y, z}));
                }
    }
    if (changed.empty()) return {};
    return mesher_.update(coarse_phi_, changed);
}

std::vector<FragmentId> LodMesher::refresh(const Grid<float>& phi) {
    const Vec3i d = coarse_phi_.lattice().dims();
    const int k = factor_;
    if (coarsened(phi.lattice(), k).dims() != d) throw std::invalid_argument("LodMesher: φ has other dimensions");
    if (!built_) return rebuild_all(phi);
    std::vector<PointIndex> changed;
    PointIndex c = 0;
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x, ++c) {
                const float value = phi({k * x, k * y, k * z});
                float& mine = coarse_phi_[c];
                if (value == mine) continue;
                mine = value;
                changed.push_back(c);
            }
    if (changed.empty()) return {};
    return mesher_.update(coarse_phi_, changed);
}

}  // namespace liveset
