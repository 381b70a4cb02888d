// Mean curvature by the difference of normals, and the curvature speed term.
#include "liveset/levelset/speed.hpp"

#include <atomic>
#include <cmath>
#include <stdexcept>

namespace liveset {

namespace {

// Unit normal component along `a` at the half-way point p + ½·dir·e_a (dir = ±1).
float half_point_normal(const Grid<float>& phi, Vec3i p, int a, int dir) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    Vec3i q = p;
    q[a] += dir;  // the other end of the half edge
    Vec3i eb{0, 0, 0}, ec{0, 0, 0};
    eb[b] = 1;
    ec[c] = 1;
    const float ga = static_cast<float>(dir) * (phi.clamped(q) - phi.clamped(p));
    const float gb = 0.25f * (phi.clamped(p + eb) + phi.clamped(q + eb) - phi.clamped(p - eb) - phi.clamped(q - eb));
    const float gc = 0.25f * (phi.clamped(p + ec) + phi.clamped(q + ec) - phi.clamped(p - ec) - phi.clamped(q - ec));
    const float len = std::sqrt(ga * ga + gb * gb + gc * gc);
    return len > 1e-6f ? ga / len : 0.0f;
}

// half_point_normal() for points whose whole stencil (±2 along a, ±1 across) is inside the
// lattice: the same arithmetic in the same order, so bit-identical, without per-read clamping; the
// axis and the direction are compile-time constants, so the three axes unroll.
template <int A, int Dir>
[[gnu::always_inline]] inline float half_point_normal_interior(const float* v, std::size_t i, const std::size_t stride[3]) {
    constexpr int b = (A + 1) % 3, c = (A + 2) % 3;
    const std::size_t j = Dir > 0 ? i + stride[A] : i - stride[A];
    const std::size_t sb = stride[b], sc = stride[c];
    const float ga = static_cast<float>(Dir) * (v[j] - v[i]);
    const float gb = 0.25f * (v[i + sb] + v[j + sb] - v[i - sb] - v[j - sb]);
    const float gc = 0.25f * (v[i + sc] + v[j + sc] - v[i - sc] - v[j - sc]);
    const float len = std::sqrt(ga * ga + gb * gb + gc * gc);
    return len > 1e-6f ? ga / len : 0.0f;
}

}  // namespace

std::uint64_t Speed::next_serial() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
}

float mean_curvature(const Grid<float>& phi, Vec3i p) {
    const Vec3i d = phi.dims();
    float k = 0.0f;
    if (p.x >= 1 && p.y >= 1 && p.z >= 1 && p.x <= d.x - 2 && p.y <= d.y - 2 && p.z <= d.z - 2) {
        const Lattice& l = phi.lattice();
        const std::size_t stride[3] = {1, l.stride_y(), l.stride_z()};
        const std::size_t i = l.index(p);
        const float* v = phi.values().data();
        k += half_point_normal_interior<0, +1>(v, i, stride) - half_point_normal_interior<0, -1>(v, i, stride);
        k += half_point_normal_interior<1, +1>(v, i, stride) - half_point_normal_interior<1, -1>(v, i, stride);
        k += half_point_normal_interior<2, +1>(v, i, stride) - half_point_normal_interior<2, -1>(v, i, stride);
        return k;
    }
    for (int a = 0; a < 3; ++a) k += half_point_normal(phi, p, a, +1) - half_point_normal(phi, p, a, -1);
    return k;
}

CurvatureSpeed::CurvatureSpeed(float weight) : weight_(weight) {
    if (!std::isfinite(weight) || weight < 0)
        throw std::invalid_argument("curvature weight must be finite and non-negative");
}

}  // namespace liveset
