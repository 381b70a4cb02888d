// IndexDecoder / FastDivider: exact against hardware division for many divisors and dividends,
// including the extremes, and coord() equal to Lattice::coord on odd-shaped lattices.
#include <gtest/gtest.h>

#include <cstdint>
#include <random>

#include "liveset/grid/index_decoder.hpp"

using namespace liveset;

TEST(FastDivider, ExactForAllTestedDividendsAndDivisors) {
    std::mt19937_64 rng(7);
    std::vector<std::uint32_t> divisors{1, 2, 3, 5, 7, 10, 99, 100, 181, 217, 256, 511, 1000, 39277, 65535, 65536,
                                        1u << 20, 0x7FFF'FFFFu, 0xFFFF'FFFEu, 0xFFFF'FFFFu};
    for (int k = 0; k < 200; ++k) divisors.push_back(static_cast<std::uint32_t>(rng() >> 33) | 1u);
    for (std::uint32_t d : divisors) {
        const FastDivider div(d);
        const std::uint32_t edge[] = {0, 1, d - 1, d, d + 1, 2 * d - 1, 2 * d, 0xFFFF'FFFFu, 0xFFFF'FFFEu,
                                      0xFFFF'FFFFu / d * d, 0xFFFF'FFFFu / d * d - 1};
        for (std::uint32_t n : edge) ASSERT_EQ(div.divide(n), n / d) << n << " / " << d;
        for (int k = 0; k < 2000; ++k) {
            const auto n = static_cast<std::uint32_t>(rng());
            ASSERT_EQ(div.divide(n), n / d) << n << " / " << d;
        }
    }
}

TEST(IndexDecoder, MatchesLatticeCoord) {
    for (const Vec3i dims : {Vec3i{1, 1, 1}, Vec3i{7, 5, 3}, Vec3i{1, 9, 4}, Vec3i{181, 217, 180}, Vec3i{64, 1, 33}}) {
        const Lattice lat(dims);
        const IndexDecoder dec(lat);
        const std::size_t step = lat.size() > 100000 ? 997 : 1;
        for (std::size_t i = 0; i < lat.size(); i += step) {
            const auto p = static_cast<PointIndex>(i);
            ASSERT_EQ(dec.coord(p), lat.coord(p)) << i;
        }
        const auto last = static_cast<PointIndex>(lat.size() - 1);
        EXPECT_EQ(dec.coord(last), lat.coord(last));
    }
}
