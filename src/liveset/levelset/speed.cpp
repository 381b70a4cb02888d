// Mean curvature by the difference of normals (in 1/mm: the lattice's voxel size), and the curvature speed term.
#include "liveset/levelset/speed.hpp"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <atomic>
#include <cstddef>
#include <cmath>
#include <stdexcept>

#include "liveset/grid/index_decoder.hpp"
#include "liveset/grid/sampling.hpp"

namespace liveset {

namespace {

// 1 / the voxel size along each axis, from the size rounded to float (Lattice::spacing_float): a
// 1 mm voxel gives 1.0f exactly, so every product below keeps the index-unit curvature's bits there.
std::array<float, 3> inverse_spacing(const Lattice& lattice) {
    const Vec3f h = lattice.spacing_float();
    return {1.0f / h.x, 1.0f / h.y, 1.0f / h.z};
}

// h_min / h per axis (sizes rounded to float as above): what turns an index difference into one
// per finest voxel (per mm times h_min). 1.0f on every axis of an isotropic grid.
Vec3f finest_scale(const Lattice& lattice) {
    const Vec3f h = lattice.spacing_float();
    const float lo = std::min({h.x, h.y, h.z});
    return {lo / h.x, lo / h.y, lo / h.z};
}

// The central |∇φ| per finest voxel.
float central_norm(const Grid<float>& phi, Vec3i p, Vec3f scale) {
    const Vec3f g = central_gradient(phi, p);
    return norm(Vec3f{g.x * scale.x, g.y * scale.y, g.z * scale.z});
}

// Unit normal component along `a` at the half-way point p + ½·dir·e_a (dir = ±1), of the physical
// gradient (each index difference times the inverse voxel size along its axis, `inv`).
float half_point_normal(const Grid<float>& phi, Vec3i p, int a, int dir, const std::array<float, 3>& inv) {
    const int b = (a + 1) % 3, c = (a + 2) % 3;
    Vec3i q = p;
    q[a] += dir;  // the other end of the half edge
    Vec3i eb{0, 0, 0}, ec{0, 0, 0};
    eb[b] = 1;
    ec[c] = 1;
    const float ga = static_cast<float>(dir) * (phi.clamped(q) - phi.clamped(p)) * inv[a];
    const float gb = 0.25f * (phi.clamped(p + eb) + phi.clamped(q + eb) - phi.clamped(p - eb) - phi.clamped(q - eb)) * inv[b];
    const float gc = 0.25f * (phi.clamped(p + ec) + phi.clamped(q + ec) - phi.clamped(p - ec) - phi.clamped(q - ec)) * inv[c];
    const float len = std::sqrt(ga * ga + gb * gb + gc * gc);
    return len > 1e-6f ? ga / len : 0.0f;
}

// half_point_normal() for points whose whole stencil (±2 along a, ±1 across) is inside the
// lattice: the same arithmetic in the same order, so bit-identical, without per-read clamping; the
// axis and the direction are compile-time constants, so the three axes unroll.
template <int A, int Dir>
[[gnu::always_inline]] inline float half_point_normal_interior(const float* v, std::size_t i, const std::size_t stride[3],
                                                             const std::array<float, 3>& inv) {
    constexpr int b = (A + 1) % 3, c = (A + 2) % 3;
    const std::size_t j = Dir > 0 ? i + stride[A] : i - stride[A];
    const std::size_t sb = stride[b], sc = stride[c];
    const float ga = static_cast<float>(Dir) * (v[j] - v[i]) * inv[A];
    const float gb = 0.25f * (v[i + sb] + v[j + sb] - v[i - sb] - v[j - sb]) * inv[b];
    const float gc = 0.25f * (v[i + sc] + v[j + sc] - v[i - sc] - v[j - sc]) * inv[c];
    const float len = std::sqrt(ga * ga + gb * gb + gc * gc);
    return len > 1e-6f ? ga / len : 0.0f;
}

#if defined(__SSE2__)
// The curvature and the central |∇φ| of four interior points at once, one point per lane (x86-64's
// baseline SSE2). Each lane does half_point_normal_interior's and central_gradient's arithmetic in
// their order, and SSE's square root and division round exactly as the scalar ones, so every lane
// has the single call's bits; four points' chains of square roots and divisions run side by side.
struct Stencil4 {
    const float* v;
    std::ptrdiff_t i[4];
    // The four points' values at offset o.
    [[gnu::always_inline]] __m128 at(std::ptrdiff_t o) const { return _mm_set_ps(v[i[3] + o], v[i[2] + o], v[i[1] + o], v[i[0] + o]); }
};

// One point in every lane (a single call): one load per value.
struct Stencil1 {
    const float* v;
    std::ptrdiff_t i;
    [[gnu::always_inline]] __m128 at(std::ptrdiff_t o) const { return _mm_set1_ps(v[i + o]); }
};

[[gnu::always_inline]] inline __m128 quarter_difference(__m128 p1, __m128 p2, __m128 m1, __m128 m2) {
    return _mm_mul_ps(_mm_set1_ps(0.25f), _mm_sub_ps(_mm_sub_ps(_mm_add_ps(p1, p2), m1), m2));
}

// The unit normal's component along a from its differences along a (ga) and across (gb, gc).
[[gnu::always_inline]] inline __m128 unit_normal(__m128 ga, __m128 gb, __m128 gc) {
    const __m128 len = _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(ga, ga), _mm_mul_ps(gb, gb)), _mm_mul_ps(gc, gc)));
    return _mm_and_ps(_mm_cmpgt_ps(len, _mm_set1_ps(1e-6f)), _mm_div_ps(ga, len));
}

// upwind_gradient_norm()'s arithmetic (sampling.hpp) in four lanes, each with its own speed's
// sign: per axis the larger square of the one-sided differences pointing upwind, summed from 0 in
// x, y, z order, then the square root. SSE's min and max may give another zero's sign than
// min_of and max_of, but only squares of them are used, so every lane has the scalar bits.
template <bool kScaled>
[[gnu::always_inline]] inline __m128 upwind_gradient_norm4(__m128 speed, __m128 c, __m128 xm, __m128 xp, __m128 ym, __m128 yp,
                                                           __m128 zm, __m128 zp, __m128 sx, __m128 sy, __m128 sz) {
    const __m128 zero = _mm_setzero_ps();
    const __m128 rising = _mm_cmpgt_ps(speed, zero);  // φ increases: the scalar form's speed > 0
    const auto pick = [rising](__m128 if_rising, __m128 otherwise) {
        return _mm_or_ps(_mm_and_ps(rising, if_rising), _mm_andnot_ps(rising, otherwise));
    };
    const auto axis = [&](__m128 minus, __m128 plus, __m128 scale) {
        __m128 dm = _mm_sub_ps(c, minus), dp = _mm_sub_ps(plus, c);
        if constexpr (kScaled) {  // per finest voxel, as the scalar form's scale
            dm = _mm_mul_ps(dm, scale);
            dp = _mm_mul_ps(dp, scale);
        }
        const __m128 a1 = pick(_mm_min_ps(dm, zero), _mm_max_ps(dm, zero));
        const __m128 a2 = pick(_mm_max_ps(dp, zero), _mm_min_ps(dp, zero));
        return _mm_max_ps(_mm_mul_ps(a1, a1), _mm_mul_ps(a2, a2));
    };
    const __m128 sum = _mm_add_ps(_mm_add_ps(_mm_add_ps(zero, axis(xm, xp, sx)), axis(ym, yp, sy)), axis(zm, zp, sz));
    return _mm_sqrt_ps(sum);
}

// The inverse voxel sizes and the per-finest-voxel scales in every lane.
struct InverseSpacing4 {
    __m128 x, y, z;
    __m128 sx, sy, sz;
    InverseSpacing4(const std::array<float, 3>& inv, Vec3f scale)
        : x(_mm_set1_ps(inv[0])),
          y(_mm_set1_ps(inv[1])),
          z(_mm_set1_ps(inv[2])),
          sx(_mm_set1_ps(scale.x)),
          sy(_mm_set1_ps(scale.y)),
          sz(_mm_set1_ps(scale.z)) {}
};

// With `speed` (four lanes' speeds), also each lane's upwind |∇φ| (per finest voxel) into `upwind`.
// Without kScaled (a 1 mm lattice, where every inverse size is 1.0f and each product would give its
// factor's bits) the multiplications are left out: the same bits, and the box flow's step 5 % faster
// than with them (the three factors' registers spill the stencil's).
template <bool kScaled, class Stencil>
[[gnu::always_inline]] inline void curvature_and_gradient4(const Stencil& st, std::ptrdiff_t sy, std::ptrdiff_t sz,
                                                           const InverseSpacing4& inv, float kappa[4], float gradient_norm[4],
                                                           const float* speed = nullptr, float* upwind = nullptr) {
    const __m128 c = st.at(0), xp = st.at(1), xm = st.at(-1), yp = st.at(sy), ym = st.at(-sy), zp = st.at(sz), zm = st.at(-sz);
    if (speed != nullptr)
        _mm_storeu_ps(upwind, upwind_gradient_norm4<kScaled>(_mm_loadu_ps(speed), c, xm, xp, ym, yp, zm, zp, inv.sx, inv.sy, inv.sz));
    const __m128 xpyp = st.at(1 + sy), xpym = st.at(1 - sy), xmyp = st.at(-1 + sy), xmym = st.at(-1 - sy);
    const __m128 xpzp = st.at(1 + sz), xpzm = st.at(1 - sz), xmzp = st.at(-1 + sz), xmzm = st.at(-1 - sz);
    const __m128 ypzp = st.at(sy + sz), ypzm = st.at(sy - sz), ymzp = st.at(-sy + sz), ymzm = st.at(-sy - sz);
    const __m128 minus = _mm_set1_ps(-1.0f);
    // Half-point normals along x (across: y, z), y (across: z, x) and z (across: x, y) of the physical
    // gradient; the minus side's difference is multiplied by -1 as the scalar form's
    // static_cast<float>(Dir) is, then every difference by its axis's inverse voxel size.
    const auto normal = [](__m128 ga, __m128 gb, __m128 gc, __m128 ia, __m128 ib, __m128 ic) {
        if constexpr (!kScaled) return unit_normal(ga, gb, gc);
        return unit_normal(_mm_mul_ps(ga, ia), _mm_mul_ps(gb, ib), _mm_mul_ps(gc, ic));
    };
    const auto per_mm = [](__m128 d, __m128 inv_h) {
        if constexpr (!kScaled) return d;
        return _mm_mul_ps(d, inv_h);
    };
    const auto per_finest = per_mm;  // the same product, by h_min/h (the central |∇φ|)
    const __m128 nxp = normal(_mm_sub_ps(xp, c), quarter_difference(yp, xpyp, ym, xpym), quarter_difference(zp, xpzp, zm, xpzm),
                              inv.x, inv.y, inv.z);
    const __m128 nxm = normal(_mm_mul_ps(minus, _mm_sub_ps(xm, c)), quarter_difference(yp, xmyp, ym, xmym),
                              quarter_difference(zp, xmzp, zm, xmzm), inv.x, inv.y, inv.z);
    const __m128 nyp = normal(_mm_sub_ps(yp, c), quarter_difference(zp, ypzp, zm, ypzm), quarter_difference(xp, xpyp, xm, xmyp),
                              inv.y, inv.z, inv.x);
    const __m128 nym = normal(_mm_mul_ps(minus, _mm_sub_ps(ym, c)), quarter_difference(zp, ymzp, zm, ymzm),
                              quarter_difference(xp, xpym, xm, xmym), inv.y, inv.z, inv.x);
    const __m128 nzp = normal(_mm_sub_ps(zp, c), quarter_difference(xp, xpzp, xm, xmzp), quarter_difference(yp, ypzp, ym, ymzp),
                              inv.z, inv.x, inv.y);
    const __m128 nzm = normal(_mm_mul_ps(minus, _mm_sub_ps(zm, c)), quarter_difference(xp, xpzm, xm, xmzm),
                              quarter_difference(yp, ypzm, ym, ymzm), inv.z, inv.x, inv.y);
    __m128 k = _mm_setzero_ps();  // the scalar form's k = 0, then += per axis, each difference per millimetre
    k = _mm_add_ps(k, per_mm(_mm_sub_ps(nxp, nxm), inv.x));
    k = _mm_add_ps(k, per_mm(_mm_sub_ps(nyp, nym), inv.y));
    k = _mm_add_ps(k, per_mm(_mm_sub_ps(nzp, nzm), inv.z));
    _mm_storeu_ps(kappa, k);
    const __m128 two = _mm_set1_ps(2.0f);
    const __m128 gx = per_finest(_mm_div_ps(_mm_sub_ps(xp, xm), two), inv.sx), gy = per_finest(_mm_div_ps(_mm_sub_ps(yp, ym), two), inv.sy),
                 gz = per_finest(_mm_div_ps(_mm_sub_ps(zp, zm), two), inv.sz);
    _mm_storeu_ps(gradient_norm, _mm_sqrt_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(gx, gx), _mm_mul_ps(gy, gy)), _mm_mul_ps(gz, gz))));
}
#endif

}  // namespace

std::uint64_t Speed::next_serial() {
    static std::atomic<std::uint64_t> counter{0};
    return ++counter;
}

float mean_curvature(const Grid<float>& phi, Vec3i p) {
    const Vec3i d = phi.dims();
    const std::array<float, 3> inv = inverse_spacing(phi.lattice());
    float k = 0.0f;
    if (p.x >= 1 && p.y >= 1 && p.z >= 1 && p.x <= d.x - 2 && p.y <= d.y - 2 && p.z <= d.z - 2) {
        const Lattice& l = phi.lattice();
        const std::size_t i = l.index(p);
        const float* v = phi.values().data();
#if defined(__SSE2__)
        const auto at = static_cast<std::ptrdiff_t>(i);
        float kappa[4], gradient_norm[4];
        curvature_and_gradient4<true>(Stencil1{v, at}, static_cast<std::ptrdiff_t>(l.stride_y()),
                                      static_cast<std::ptrdiff_t>(l.stride_z()), InverseSpacing4(inv, finest_scale(l)), kappa,
                                      gradient_norm);
        return kappa[0];
#else
        const std::size_t stride[3] = {1, l.stride_y(), l.stride_z()};
        k += (half_point_normal_interior<0, +1>(v, i, stride, inv) - half_point_normal_interior<0, -1>(v, i, stride, inv)) * inv[0];
        k += (half_point_normal_interior<1, +1>(v, i, stride, inv) - half_point_normal_interior<1, -1>(v, i, stride, inv)) * inv[1];
        k += (half_point_normal_interior<2, +1>(v, i, stride, inv) - half_point_normal_interior<2, -1>(v, i, stride, inv)) * inv[2];
        return k;
#endif
    }
    for (int a = 0; a < 3; ++a)
        k += (half_point_normal(phi, p, a, +1, inv) - half_point_normal(phi, p, a, -1, inv)) * inv[static_cast<std::size_t>(a)];
    return k;
}

namespace {

// Whether every voxel size is 1 mm (as float): the curvature's factors are then all 1.0f.
bool unit_spacing(const Lattice& lattice) {
    const std::array<float, 3> inv = inverse_spacing(lattice);
    return inv[0] == 1.0f && inv[1] == 1.0f && inv[2] == 1.0f;
}

// The batch loop of both forms below; `speed` and `upwind` empty for mean_curvature_and_gradient.
template <bool kScaled>
void batch_stencils(const Grid<float>& phi, std::span<const PointIndex> points, std::span<const float> speed,
                    std::span<CurvatureAndGradient> out, std::span<float> upwind) {
    const bool with_upwind = !upwind.empty();
    const Lattice& l = phi.lattice();
    const IndexDecoder decoder(l);
    [[maybe_unused]] const Vec3i d = l.dims();  // the interior test of the SSE2 batch
#if defined(__SSE2__)
    const auto sy = static_cast<std::ptrdiff_t>(l.stride_y()), sz = static_cast<std::ptrdiff_t>(l.stride_z());
    Stencil4 st{phi.values().data(), {}};
    const InverseSpacing4 inv(inverse_spacing(l), finest_scale(l));
#endif
    const Vec3f scale = finest_scale(l);  // the scalar stencils' (lattice border)
#if defined(__SSE2__)
    std::size_t slot[4];  // where each filled lane's result goes
    float lane_speed[4] = {0.0f, 0.0f, 0.0f, 0.0f};
    int filled = 0;
    const auto flush = [&] {
        for (int k = filled; k < 4; ++k) st.i[k] = st.i[0];  // a partial batch repeats its first point
        float kappa[4], gradient_norm[4], lane_upwind[4];
        curvature_and_gradient4<kScaled>(st, sy, sz, inv, kappa, gradient_norm, with_upwind ? lane_speed : nullptr, lane_upwind);
        for (int k = 0; k < filled; ++k) out[slot[k]] = {kappa[k], gradient_norm[k]};
        if (with_upwind)
            for (int k = 0; k < filled; ++k) upwind[slot[k]] = lane_upwind[k];
        filled = 0;
    };
    // The points are scattered once stretches of front sleep, and a stencil spans nine lattice
    // lines (its own and those ±y, ±z and ±y±z): fetched 8 points (some 1 500 instructions) ahead,
    // a hint with no effect on any result; indices clamped to the lattice.
    constexpr std::size_t kAhead = 8;
    const float* const values = phi.values().data();
    const auto last = static_cast<std::ptrdiff_t>(l.size() - 1);
    const auto prefetch = [&](std::ptrdiff_t i) {
        for (const std::ptrdiff_t z : {-sz, std::ptrdiff_t{0}, sz})
            for (const std::ptrdiff_t y : {-sy, std::ptrdiff_t{0}, sy})
                __builtin_prefetch(values + std::clamp(i + y + z, std::ptrdiff_t{0}, last), 0);
    };
#endif
    for (std::size_t n = 0; n < points.size(); ++n) {
#if defined(__SSE2__)
        if (n + kAhead < points.size()) prefetch(static_cast<std::ptrdiff_t>(points[n + kAhead]));
#endif
        const Vec3i p = decoder.coord(points[n]);
#if defined(__SSE2__)
        if (p.x >= 1 && p.y >= 1 && p.z >= 1 && p.x <= d.x - 2 && p.y <= d.y - 2 && p.z <= d.z - 2) {
            st.i[filled] = static_cast<std::ptrdiff_t>(points[n]);
            if (with_upwind) lane_speed[filled] = speed[n];
            slot[filled++] = n;
            if (filled == 4) flush();
            continue;
        }
#endif
        out[n] = {mean_curvature(phi, p), central_norm(phi, p, scale)};
        if (with_upwind) upwind[n] = upwind_gradient_norm(phi, p, speed[n], scale);
    }
#if defined(__SSE2__)
    if (filled > 0) flush();
#endif
}

}  // namespace

void mean_curvature_and_gradient(const Grid<float>& phi, std::span<const PointIndex> points, std::span<CurvatureAndGradient> out) {
    if (out.size() != points.size()) throw std::invalid_argument("mean_curvature_and_gradient: output size differs from the points'");
    if (unit_spacing(phi.lattice()))
        batch_stencils<false>(phi, points, {}, out, {});
    else
        batch_stencils<true>(phi, points, {}, out, {});
}

void curvature_gradient_and_upwind(const Grid<float>& phi, std::span<const PointIndex> points, std::span<const float> speed,
                                   std::span<CurvatureAndGradient> out, std::span<float> upwind) {
    if (out.size() != points.size() || speed.size() != points.size() || upwind.size() != points.size())
        throw std::invalid_argument("curvature_gradient_and_upwind: sizes differ from the points'");
    if (points.empty()) return;
    if (unit_spacing(phi.lattice()))
        batch_stencils<false>(phi, points, speed, out, upwind);
    else
        batch_stencils<true>(phi, points, speed, out, upwind);
}

double rate_of(SpeedSample s, const Grid<float>& phi, Vec3i p) {
    const Vec3f scale = finest_scale(phi.lattice());
    double r = 0.0;
    if (s.propagation != 0.0f) r += static_cast<double>(s.propagation) * upwind_gradient_norm(phi, p, s.propagation, scale);
    if (s.curvature != 0.0f) r += static_cast<double>(s.curvature) * central_norm(phi, p, scale);
    return r;
}

void Speed::rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const {
    if (out.size() != points.size()) throw std::invalid_argument("Speed::rates: output size differs from the points'");
    const IndexDecoder decoder(phi.lattice());
    for (std::size_t n = 0; n < points.size(); ++n) {
        const Vec3i p = decoder.coord(points[n]);
        out[n] = rate_of(at(phi, p), phi, p);
    }
}

void CurvatureSpeed::rates(const Grid<float>& phi, std::span<const PointIndex> points, std::span<double> out) const {
    if (out.size() != points.size()) throw std::invalid_argument("Speed::rates: output size differs from the points'");
    std::array<CurvatureAndGradient, 256> batch;
    for (std::size_t b = 0; b < points.size(); b += batch.size()) {
        const std::size_t m = std::min(batch.size(), points.size() - b);
        mean_curvature_and_gradient(phi, points.subspan(b, m), std::span(batch).first(m));
        for (std::size_t k = 0; k < m; ++k) {
            const float curvature = weight_ * batch[k].kappa;  // at()'s curvature part
            double r = 0.0;  // rate_of's sum (0.0 + x makes a -0.0 +0.0, as there)
            if (curvature != 0.0f) r += static_cast<double>(curvature) * batch[k].gradient_norm;
            out[b + k] = r;
        }
    }
}

CurvatureSpeed::CurvatureSpeed(float weight) : weight_(weight) {
    if (!std::isfinite(weight) || weight < 0)
        throw std::invalid_argument("curvature weight must be finite and non-negative");
}

}  // namespace liveset
