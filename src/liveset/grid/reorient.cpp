// Canonical axis order of a lattice and the reordered lattice.
#include "liveset/grid/reorient.hpp"

#include <cmath>

namespace liveset {

AxisOrder canonical_order(const Lattice& lattice) {
    const Mat3d& m = lattice.direction();  // row-major; column k is old axis k in the world
    AxisOrder order;
    std::array<bool, 3> taken{false, false, false};
    for (int k = 0; k < 3; ++k) {
        int best = -1;
        for (int w = 0; w < 3; ++w)
            if (!taken[static_cast<std::size_t>(w)] &&
                (best < 0 || std::abs(m[static_cast<std::size_t>(3 * w + k)]) > std::abs(m[static_cast<std::size_t>(3 * best + k)])))
                best = w;
        taken[static_cast<std::size_t>(best)] = true;
        order.axis[static_cast<std::size_t>(best)] = k;
        order.flip[static_cast<std::size_t>(best)] = m[static_cast<std::size_t>(3 * best + k)] < 0;
    }
    return order;
}

Lattice reordered(const Lattice& lattice, const AxisOrder& order) {
    const Vec3i d = lattice.dims();
    const Vec3d s = lattice.spacing();
    const Mat3d& m = lattice.direction();
    Vec3i dims{0, 0, 0};
    Vec3d spacing{0, 0, 0};
    Mat3d direction{};
    for (int a = 0; a < 3; ++a) {
        const int k = order.axis[static_cast<std::size_t>(a)];
        dims[a] = d[k];
        spacing[a] = s[k];
        const double sign = order.flip[static_cast<std::size_t>(a)] ? -1.0 : 1.0;
        for (int w = 0; w < 3; ++w) direction[static_cast<std::size_t>(3 * w + a)] = sign * m[static_cast<std::size_t>(3 * w + k)];
    }
    const Vec3i first = old_index({0, 0, 0}, order, d);
    const Vec3d origin = lattice.to_world({double(first.x), double(first.y), double(first.z)});
    return Lattice(dims, spacing, origin, direction);
}

}  // namespace liveset
