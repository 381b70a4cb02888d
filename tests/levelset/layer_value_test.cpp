// The outer-layer rule (layer_value.hpp, branch-free with SSE min/max) against the rule written out
// with branches and std::min / std::max: the same bits on random values, ties and zeros.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <limits>

#include "liveset/levelset/layer_value.hpp"

using namespace liveset;

namespace {

float reference(const Grid<float>& phi, const Grid<std::int8_t>& status, Vec3i c, bool outside, std::int8_t inner) {
    float best = outside ? std::numeric_limits<float>::infinity() : -std::numeric_limits<float>::infinity();
    const Vec3i d = phi.dims();
    for (int a = 0; a < 3; ++a)
        for (int dir : {-1, +1}) {
            Vec3i q = c;
            q[a] += dir;
            if (q[a] < 0 || q[a] >= d[a] || status(q) != inner) continue;
            best = outside ? std::min(best, phi(q) + 1.0f) : std::max(best, phi(q) - 1.0f);
        }
    return best;
}

}  // namespace

TEST(LayerValue, BranchFreeRuleHasTheBitsOfTheWrittenOutRule) {
    const Lattice lat({9, 8, 7});
    Grid<float> phi(lat);
    Grid<std::int8_t> status(lat);
    std::uint32_t state = 7;
    const auto next = [&] {
        state = state * 1664525u + 1013904223u;
        return state >> 8;
    };
    // Few distinct values, so that ties (equal offers), zero offers (φ = ∓1) and signed-zero values are common.
    const float values[] = {-1.0f, 1.0f, -0.0f, 0.0f, 0.25f, -0.25f, 1.5f, -1.5f, 3.0f, -3.0f};
    for (int round = 0; round < 20; ++round) {
        for (float& v : phi.values()) v = values[next() % 10];
        for (std::int8_t& s : status.values()) s = static_cast<std::int8_t>(static_cast<int>(next() % 7) - 3);
        for (int z = 0; z < 7; ++z)
            for (int y = 0; y < 8; ++y)
                for (int x = 0; x < 9; ++x)
                    for (const bool outside : {true, false})
                        for (int inner = -3; inner <= 3; ++inner) {
                            const Vec3i c{x, y, z};
                            const auto in = static_cast<std::int8_t>(inner);
                            const float got = detail::layer_value(phi, status, lat.index(c), c, outside,
                                                                  [in](std::int8_t s) { return s == in; });
                            const float want = reference(phi, status, c, outside, in);
                            ASSERT_EQ(std::bit_cast<std::uint32_t>(got), std::bit_cast<std::uint32_t>(want))
                                << x << "," << y << "," << z << " outside " << outside << " inner " << inner;
                        }
    }
}
