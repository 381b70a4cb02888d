// Mean curvature by the difference of normals, and the curvature speed term.
#include "liveset/levelset/speed.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

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

#if defined(__SSE2__)
// The six half-point normals of an interior point four lanes at a time (x86-64's baseline SSE2):
// lanes (x+, x-, y+, y-) and (z+, z-, z+, z-). Each lane does half_point_normal_interior's
// arithmetic in its order, and SSE's square root and division round exactly as the scalar ones,
// so the curvature has the same bits; the six square roots and divisions (most of the scalar
// form's time) become two of each.
[[gnu::always_inline]] inline __m128 lanes(float a, float b, float c, float e) { return _mm_set_ps(e, c, b, a); }

[[gnu::always_inline]] inline __m128 quarter_difference(__m128 p1, __m128 p2, __m128 m1, __m128 m2) {
    return _mm_mul_ps(_mm_set1_ps(0.25f), _mm_sub_ps(_mm_sub_ps(_mm_add_ps(p1, p2), m1), m2));
}

[[gnu::always_inline]] inline __m128 unit_normal_lanes(__m128 ga, __m128 gb, __m128 gc) {
    const __m128 sq = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ga, ga), _mm_mul_ps(gb, gb)), _mm_mul_ps(gc, gc));
    const __m128 len = _mm_sqrt_ps(sq);
    return _mm_and_ps(_mm_cmpgt_ps(len, _mm_set1_ps(1e-6f)), _mm_div_ps(ga, len));
}

float interior_curvature_sse2(const float* v, std::size_t i, std::size_t sy, std::size_t sz) {
    const float c = v[i], xp = v[i + 1], xm = v[i - 1], yp = v[i + sy], ym = v[i - sy], zp = v[i + sz], zm = v[i - sz];
    const __m128 sign = lanes(1.0f, -1.0f, 1.0f, -1.0f);
    const __m128 centre = _mm_set1_ps(c);
    // Lanes x+, x-, y+, y-: the x normals' b and c are y and z, the y normals' are z and x.
    const __m128 ga_a = _mm_mul_ps(_mm_sub_ps(lanes(xp, xm, yp, ym), centre), sign);
    const __m128 gb_a = quarter_difference(lanes(yp, yp, zp, zp), lanes(v[i + 1 + sy], v[i - 1 + sy], v[i + sy + sz], v[i - sy + sz]),
                                           lanes(ym, ym, zm, zm), lanes(v[i + 1 - sy], v[i - 1 - sy], v[i + sy - sz], v[i - sy - sz]));
    const __m128 gc_a = quarter_difference(lanes(zp, zp, xp, xp), lanes(v[i + 1 + sz], v[i - 1 + sz], v[i + sy + 1], v[i - sy + 1]),
                                           lanes(zm, zm, xm, xm), lanes(v[i + 1 - sz], v[i - 1 - sz], v[i + sy - 1], v[i - sy - 1]));
    // Lanes z+, z-, z+, z-: b and c are x and y.
    const float zpx = v[i + sz + 1], zmx = v[i - sz + 1], zpxm = v[i + sz - 1], zmxm = v[i - sz - 1];
    const float zpy = v[i + sz + sy], zmy = v[i - sz + sy], zpym = v[i + sz - sy], zmym = v[i - sz - sy];
    const __m128 ga_b = _mm_mul_ps(_mm_sub_ps(lanes(zp, zm, zp, zm), centre), sign);
    const __m128 gb_b = quarter_difference(_mm_set1_ps(xp), lanes(zpx, zmx, zpx, zmx), _mm_set1_ps(xm), lanes(zpxm, zmxm, zpxm, zmxm));
    const __m128 gc_b = quarter_difference(_mm_set1_ps(yp), lanes(zpy, zmy, zpy, zmy), _mm_set1_ps(ym), lanes(zpym, zmym, zpym, zmym));
    const __m128 n_a = unit_normal_lanes(ga_a, gb_a, gc_a), n_b = unit_normal_lanes(ga_b, gb_b, gc_b);
    // (+) - (-) per axis: lanes 0 and 2 of n - swap(n).
    const __m128 d_a = _mm_sub_ps(n_a, _mm_shuffle_ps(n_a, n_a, _MM_SHUFFLE(2, 3, 0, 1)));
    const __m128 d_b = _mm_sub_ps(n_b, _mm_shuffle_ps(n_b, n_b, _MM_SHUFFLE(2, 3, 0, 1)));
    float k = 0.0f;
    k += _mm_cvtss_f32(d_a);
    k += _mm_cvtss_f32(_mm_movehl_ps(d_a, d_a));
    k += _mm_cvtss_f32(d_b);
    return k;
}
#endif

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
        const std::size_t i = l.index(p);
        const float* v = phi.values().data();
#if defined(__SSE2__)
        return interior_curvature_sse2(v, i, l.stride_y(), l.stride_z());
#else
        const std::size_t stride[3] = {1, l.stride_y(), l.stride_z()};
        k += half_point_normal_interior<0, +1>(v, i, stride) - half_point_normal_interior<0, -1>(v, i, stride);
        k += half_point_normal_interior<1, +1>(v, i, stride) - half_point_normal_interior<1, -1>(v, i, stride);
        k += half_point_normal_interior<2, +1>(v, i, stride) - half_point_normal_interior<2, -1>(v, i, stride);
        return k;
#endif
    }
    for (int a = 0; a < 3; ++a) k += half_point_normal(phi, p, a, +1) - half_point_normal(phi, p, a, -1);
    return k;
}

CurvatureSpeed::CurvatureSpeed(float weight) : weight_(weight) {
    if (!std::isfinite(weight) || weight < 0)
        throw std::invalid_argument("curvature weight must be finite and non-negative");
}

}  // namespace liveset
