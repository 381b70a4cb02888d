// Small 3-vector value types used throughout liveset (lattice indices, index-space and world
// positions). Deliberately tiny: the core library depends on nothing but the standard library.
#pragma once

#include <cmath>
#include <cstdint>
#include <ostream>

namespace liveset {

template <class T>
struct Vec3 {
    T x{}, y{}, z{};

    constexpr T& operator[](int axis) { return axis == 0 ? x : (axis == 1 ? y : z); }
    constexpr const T& operator[](int axis) const { return axis == 0 ? x : (axis == 1 ? y : z); }

    friend constexpr Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
    friend constexpr Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
    friend constexpr Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
    friend constexpr Vec3 operator*(Vec3 a, T s) { return {a.x * s, a.y * s, a.z * s}; }
    friend constexpr Vec3 operator*(T s, Vec3 a) { return {a.x * s, a.y * s, a.z * s}; }
    friend constexpr Vec3 operator/(Vec3 a, T s) { return {a.x / s, a.y / s, a.z / s}; }
    constexpr Vec3& operator+=(Vec3 b) { x += b.x; y += b.y; z += b.z; return *this; }
    constexpr Vec3& operator-=(Vec3 b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
    constexpr Vec3& operator*=(T s) { x *= s; y *= s; z *= s; return *this; }
    friend constexpr bool operator==(const Vec3&, const Vec3&) = default;

    template <class U>
    constexpr Vec3<U> cast() const { return {static_cast<U>(x), static_cast<U>(y), static_cast<U>(z)}; }

    friend std::ostream& operator<<(std::ostream& os, const Vec3& v) {
        return os << '(' << v.x << ',' << v.y << ',' << v.z << ')';
    }
};

using Vec3i = Vec3<int>;
using Vec3f = Vec3<float>;
using Vec3d = Vec3<double>;

template <class T>
constexpr T dot(Vec3<T> a, Vec3<T> b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

template <class T>
constexpr Vec3<T> cross(Vec3<T> a, Vec3<T> b) {
    return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

template <class T>
T norm(Vec3<T> a) { return std::sqrt(dot(a, a)); }

template <class T>
bool all_finite(Vec3<T> a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

// Component-wise product (e.g. index * spacing).
template <class T>
constexpr Vec3<T> hadamard(Vec3<T> a, Vec3<T> b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }

}  // namespace liveset
