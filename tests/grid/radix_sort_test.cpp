// The stable radix sort against std::stable_sort: the same order, ties included, on one thread and
// on two (long vectors sort in parallel chunks).
#include <gtest/gtest.h>

#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdint>
#include <vector>

#include "liveset/grid/radix_sort.hpp"

using namespace liveset;

namespace {
struct Item {
    std::uint32_t key;
    std::uint32_t tag;  // the input position: shows whether ties kept their order
    bool operator==(const Item&) const = default;
};
}  // namespace

TEST(RadixSort, GivesStableSortsOrderForEveryKeyWidth) {
    std::uint32_t h = 2463534242u;
    const auto next = [&] {
        h ^= h << 13;
        h ^= h >> 17;
        h ^= h << 5;
        return h;
    };
    const std::size_t sizes[] = {0, 1, 5, 4000, 65535, 65536, 200003};  // from 65 536: parallel chunks
    for (const int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        for (const std::uint32_t range : {1u, 7u, 300u, 70000u, 20000000u, 0xffffffffu}) {
            for (const std::size_t n : sizes) {
                std::vector<Item> v(n);
                for (std::size_t i = 0; i < n; ++i)
                    v[i] = {range == 0xffffffffu ? next() : next() % range, static_cast<std::uint32_t>(i)};
                std::vector<Item> expected = v;
                std::stable_sort(expected.begin(), expected.end(), [](const Item& a, const Item& b) { return a.key < b.key; });
                std::vector<Item> scratch(3, Item{7, 7});  // stale contents must not matter
                arena.execute([&] { stable_radix_sort(v, [](const Item& e) { return e.key; }, scratch); });
                EXPECT_EQ(v, expected) << "range " << range << ", n " << n << ", threads " << threads;
            }
        }
    }
}
