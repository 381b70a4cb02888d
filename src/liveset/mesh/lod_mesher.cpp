// Coarse level of detail: φ subsampled by 2, meshed in fragments, updated from the fine U.
#include "liveset/mesh/lod_mesher.hpp"

#include <algorithm>
#include <stdexcept>

namespace liveset {

Lattice half_resolution(const Lattice& fine) {
    const Vec3i d = fine.dims();
    const Vec3d s = fine.spacing();
    return Lattice({(d.x + 1) / 2, (d.y + 1) / 2, (d.z + 1) / 2}, {2.0 * s.x, 2.0 * s.y, 2.0 * s.z}, fine.origin(),
                   fine.direction());
}

LodMesher::LodMesher(const Lattice& fine, int fine_fragment_size)
    : coarse_phi_(half_resolution(fine), 1.0f),
      mesher_(coarse_phi_.lattice(), std::max(1, fine_fragment_size)) {
    if (fine_fragment_size < 1) throw std::invalid_argument("LodMesher: the fragment size must be at least 1");
}

void LodMesher::rebuild(const Grid<float>& phi) {
    const Vec3i d = coarse_phi_.lattice().dims();
    if (half_resolution(phi.lattice()).dims() != d) throw std::invalid_argument("LodMesher: φ has other dimensions");
    for (int z = 0; z < d.z; ++z)
        for (int y = 0; y < d.y; ++y)
            for (int x = 0; x < d.x; ++x) coarse_phi_({x, y, z}) = phi({2 * x, 2 * y, 2 * z});
    mesher_.full_rebuild(coarse_phi_);
    built_ = true;
}

std::vector<FragmentId> LodMesher::update(const Grid<float>& phi, const FragmentMesher& fine, std::span<const FragmentId> fine_ids) {
    if (half_resolution(phi.lattice()).dims() != coarse_phi_.lattice().dims())
        throw std::invalid_argument("LodMesher: φ has other dimensions");
    if (!built_) {
        rebuild(phi);
        std::vector<FragmentId> all(mesher_.fragment_count());
        for (FragmentId f = 0; f < all.size(); ++f) all[f] = f;
        return all;
    }
    const Vec3i fd = phi.lattice().dims();
    std::vector<PointIndex> changed;
    for (FragmentId id : fine_ids) {
        const FragmentView v = fine.fragment(id);
        // The fragment's cells span points [origin, origin + extent]; the even ones are coarse points.
        Vec3i lo, hi;
        for (int a = 0; a < 3; ++a) {
            lo[a] = (v.cell_origin[a] + 1) / 2;
            hi[a] = std::min(v.cell_origin[a] + v.cell_extent[a], fd[a] - 1) / 2;
        }
        for (int z = lo.z; z <= hi.z; ++z)
            for (int y = lo.y; y <= hi.y; ++y)
                for (int x = lo.x; x <= hi.x; ++x) {
                    const float value = phi({2 * x, 2 * y, 2 * z});
                    float& mine = coarse_phi_({x, y, z});
                    if (value == mine) continue;
                    mine = value;
                    changed.push_back(coarse_phi_.lattice().index({x, y, z}));
                }
    }
    if (changed.empty()) return {};
    return mesher_.update(coarse_phi_, changed);
}

}  // namespace liveset
