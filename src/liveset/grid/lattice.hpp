// Lattice geometry: the shape of a 3D grid (x fastest), its linear indexing, and the mapping
// between lattice indices and physical (world) coordinates: world = origin + D * (spacing ⊙ ijk),
// the same convention ITK uses (LPS world space when the lattice comes from an image).
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>

#include "liveset/grid/vec3.hpp"

namespace liveset {

// Linear index of a lattice point. 32 bits keeps per-point bookkeeping small; lattices are limited
// to kMaxLatticePoints so every index fits.
using PointIndex = std::uint32_t;

inline constexpr std::uint64_t kMaxLatticePoints = 0xFFFF'FFF0ull;

// Row-major 3x3 direction cosine matrix (columns are the lattice axes in world space).
using Mat3d = std::array<double, 9>;
inline constexpr Mat3d kIdentity3{1, 0, 0, 0, 1, 0, 0, 0, 1};

class Lattice {
public:
    Lattice() = default;
    static constexpr double kMinSpacing = 1e-6, kMaxSpacing = 1e6;  // mm
    // Throws std::invalid_argument on non-positive dimensions, more than kMaxLatticePoints points,
    // a spacing outside [kMinSpacing, kMaxSpacing] mm (or not finite), a non-finite origin or a
    // singular direction matrix.
    explicit Lattice(Vec3i dims, Vec3d spacing = {1, 1, 1}, Vec3d origin = {0, 0, 0},
                     Mat3d direction = kIdentity3);

    Vec3i dims() const { return dims_; }
    Vec3d spacing() const { return spacing_; }
    // The voxel sizes rounded to float, as the level set's stencils take them (its curvature and
    // time step): a size stored in float (NIfTI) and the same size in double (MINC) agree here.
    Vec3f spacing_float() const {
        return {static_cast<float>(spacing_.x), static_cast<float>(spacing_.y), static_cast<float>(spacing_.z)};
    }
    Vec3d origin() const { return origin_; }
    const Mat3d& direction() const { return direction_; }

    std::size_t size() const {
        return static_cast<std::size_t>(dims_.x) * static_cast<std::size_t>(dims_.y) *
               static_cast<std::size_t>(dims_.z);
    }
    std::size_t stride_y() const { return static_cast<std::size_t>(dims_.x); }
    std::size_t stride_z() const {
        return static_cast<std::size_t>(dims_.x) * static_cast<std::size_t>(dims_.y);
    }

    bool contains(Vec3i p) const {
        return p.x >= 0 && p.y >= 0 && p.z >= 0 && p.x < dims_.x && p.y < dims_.y && p.z < dims_.z;
    }
    // True when p lies within the continuous index-space box [0, dims-1] on every axis.
    bool contains(Vec3d p) const {
        return p.x >= 0 && p.y >= 0 && p.z >= 0 && p.x <= dims_.x - 1 && p.y <= dims_.y - 1 &&
               p.z <= dims_.z - 1;
    }
    PointIndex index(Vec3i p) const {
        return static_cast<PointIndex>(static_cast<std::size_t>(p.x) + stride_y() * static_cast<std::size_t>(p.y) +
                                       stride_z() * static_cast<std::size_t>(p.z));
    }
    Vec3i coord(PointIndex i) const {
        const auto sz = static_cast<PointIndex>(stride_z());
        const auto sy = static_cast<PointIndex>(stride_y());
        const PointIndex z = i / sz;
        const PointIndex r = i - z * sz;
        const PointIndex y = r / sy;
        return {static_cast<int>(r - y * sy), static_cast<int>(y), static_cast<int>(z)};
    }

    // Continuous index coordinates <-> physical coordinates.
    Vec3d to_world(Vec3d ijk) const;
    Vec3d to_index(Vec3d world) const;
    // Maps a direction (e.g. a normal) given in index space to a unit world-space direction.
    Vec3d direction_to_world(Vec3d index_dir) const;

    // Same shape and the same physical placement (within a tolerance).
    bool same_geometry(const Lattice& other, double tol = 1e-6) const;

    std::string describe() const;  // "181x217x180, spacing 1x1x1"

private:
    Vec3i dims_{0, 0, 0};
    Vec3d spacing_{1, 1, 1};
    Vec3d origin_{0, 0, 0};
    Mat3d direction_ = kIdentity3;
    Mat3d inverse_ = kIdentity3;  // inverse of D * diag(spacing)
};

}  // namespace liveset
