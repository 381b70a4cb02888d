// IndexDecoder: linear lattice index -> (x, y, z) without hardware division. Hot loops (the mesher
// decodes every changed point and every candidate cell) pay ~40 cycles per `/` by a run-time
// divisor; this uses Lemire, Kaser & Kurz's exact 32-bit "fastdiv" (a 64-bit magic multiplier and
// the high half of a 128-bit product), which is exact for every 32-bit dividend and divisor >= 1.
#pragma once

#include <cstdint>

#include "liveset/grid/lattice.hpp"

namespace liveset {

// Exact n / d for 32-bit n and a fixed divisor d >= 1.
class FastDivider {
public:
    FastDivider() = default;
    explicit FastDivider(std::uint32_t d) : d_(d), magic_(d > 1 ? ~std::uint64_t{0} / d + 1 : 0) {}
    std::uint32_t divisor() const { return d_; }
    std::uint32_t divide(std::uint32_t n) const {
        if (magic_ == 0) return n;  // d == 1 (the magic would overflow)
        return static_cast<std::uint32_t>((static_cast<unsigned __int128>(magic_) * n) >> 64);
    }

private:
    std::uint32_t d_ = 1;
    std::uint64_t magic_ = 0;
};

class IndexDecoder {
public:
    IndexDecoder() = default;
    explicit IndexDecoder(const Lattice& l)
        : nx_(static_cast<std::uint32_t>(l.dims().x)),
          nxy_(static_cast<std::uint32_t>(l.stride_z())),
          div_x_(nx_),
          div_xy_(nxy_) {}

    std::uint32_t z(PointIndex i) const { return div_xy_.divide(i); }

    Vec3i coord(PointIndex i) const {
        const std::uint32_t z = div_xy_.divide(i);
        const std::uint32_t r = i - z * nxy_;
        const std::uint32_t y = div_x_.divide(r);
        return {static_cast<int>(r - y * nx_), static_cast<int>(y), static_cast<int>(z)};
    }

private:
    std::uint32_t nx_ = 1, nxy_ = 1;
    FastDivider div_x_, div_xy_;
};

}  // namespace liveset
