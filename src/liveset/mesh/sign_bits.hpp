// Packed is_inside() bits of a lattice, one row of words per (y, z) point row, and the per-row
// crossing-cell words computed from them (shared by the slab mesher and the fragment mesher).
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "liveset/grid/grid.hpp"

namespace liveset {

// is_inside() of every lattice point packed in bits: row (y, z) starts at word
// (y + dims.y * z) * words_per_row, bit x of that row is point (x, y, z); bits past dims.x are 0.
struct SignBits {
    Vec3i dims{};
    std::size_t words_per_row = 0;
    std::vector<std::uint64_t> words;
    const std::uint64_t* row(int y, int z) const {
        return words.data() + (static_cast<std::size_t>(y) + static_cast<std::size_t>(dims.y) * static_cast<std::size_t>(z)) *
                                  words_per_row;
    }
    // Word holding point x of point row `row` (= y + dims.y * z).
    std::size_t word_of(std::size_t row, std::uint32_t x) const { return row * words_per_row + (static_cast<std::size_t>(x) >> 6); }
};

// The four point rows around cell row (y, z): corner bit k of a cell = row k>>1 at x + (k & 1).
struct CellRows {
    const std::uint64_t* r[4];  // (y, z), (y + 1, z), (y, z + 1), (y + 1, z + 1)
    CellRows(const SignBits& s, int y, int z) : r{s.row(y, z), s.row(y + 1, z), s.row(y, z + 1), s.row(y + 1, z + 1)} {}

    // Bit x - 64k set when cell x of the row has corners of both signs; cells past the last point
    // of the row are not masked (see crossing()).
    std::uint64_t crossing_unmasked(std::size_t k, std::size_t wpr) const {
        const std::uint64_t o = r[0][k] | r[1][k] | r[2][k] | r[3][k];
        const std::uint64_t a = r[0][k] & r[1][k] & r[2][k] & r[3][k];
        const bool more = k + 1 < wpr;
        const std::uint64_t o1 = more ? (r[0][k + 1] | r[1][k + 1] | r[2][k + 1] | r[3][k + 1]) : 0;
        const std::uint64_t a1 = more ? (r[0][k + 1] & r[1][k + 1] & r[2][k + 1] & r[3][k + 1]) : 0;
        return (o | (o >> 1) | (o1 << 63)) & ~(a & ((a >> 1) | (a1 << 63)));
    }
    // As crossing_unmasked(), cells x < ncx only.
    std::uint64_t crossing(std::size_t k, std::size_t wpr, int ncx) const {
        std::uint64_t cross = crossing_unmasked(k, wpr);
        const int valid = ncx - static_cast<int>(64 * k);
        if (valid < 64) cross &= valid <= 0 ? 0 : (std::uint64_t{1} << valid) - 1;
        return cross;
    }
    static int bit(const std::uint64_t* row, int x) { return static_cast<int>((row[x >> 6] >> (x & 63)) & 1u); }
    // Bits x and x + 1 of a row (corners x and x + 1 of the cell) as bits 0 and 1.
    static int pair(const std::uint64_t* row, int x) {
        if ((x & 63) != 63) return static_cast<int>((row[x >> 6] >> (x & 63)) & 3u);
        return bit(row, x) | bit(row, x + 1) << 1;
    }
    int cell_case(int x) const { return pair(r[0], x) | pair(r[1], x) << 2 | pair(r[2], x) << 4 | pair(r[3], x) << 6; }
};

}  // namespace liveset
