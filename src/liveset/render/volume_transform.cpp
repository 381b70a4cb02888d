// Index <-> world matrices of a lattice.
#include "liveset/render/volume_transform.hpp"

#include <algorithm>

namespace liveset::render {

glm::dmat4 index_to_world(const Lattice& lattice) {
    glm::dmat4 m(1.0);
    const Mat3d& d = lattice.direction();  // row-major, columns = lattice axes in world space
    const Vec3d s = lattice.spacing();
    for (int col = 0; col < 3; ++col)
        for (int row = 0; row < 3; ++row) m[col][row] = d[static_cast<std::size_t>(row * 3 + col)] * s[col];
    const Vec3d o = lattice.origin();
    m[3] = glm::dvec4(o.x, o.y, o.z, 1.0);
    return m;
}

glm::dmat4 world_to_index(const Lattice& lattice) { return glm::inverse(index_to_world(lattice)); }

Bounds world_bounds(const Lattice& lattice) {
    const glm::dmat4 m = index_to_world(lattice);
    const Vec3i d = lattice.dims();
    glm::dvec3 lo(1e300), hi(-1e300);
    for (int c = 0; c < 8; ++c) {
        const glm::dvec4 p = m * glm::dvec4((c & 1) ? d.x - 1 : 0, (c & 2) ? d.y - 1 : 0, (c & 4) ? d.z - 1 : 0, 1.0);
        lo = glm::min(lo, glm::dvec3(p));
        hi = glm::max(hi, glm::dvec3(p));
    }
    Bounds b;
    b.centre = 0.5 * (lo + hi);
    b.radius = std::max(0.5 * glm::length(hi - lo), 1e-6);
    return b;
}

}  // namespace liveset::render
