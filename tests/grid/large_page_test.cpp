// Grid storage on huge pages: a grid of 4 MiB or more starts on a 2 MiB boundary and its memory is
// advised MADV_HUGEPAGE (the kernel's "hg" flag in /proc/self/smaps); values survive copies and moves, and a
// whole grid is filled and copied on any thread count; a freed block serves the next request of its
// size, within the kept blocks' bounds, on any thread.
#include <gtest/gtest.h>

#include <tbb/global_control.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "liveset/grid/grid.hpp"

using namespace liveset;

namespace {

bool huge_page_aligned(const void* p) { return reinterpret_cast<std::uintptr_t>(p) % detail::kHugePage == 0; }

// The VmFlags of the mapping holding `p` in /proc/self/smaps ("" when not found).
std::string vm_flags_at(const void* p) {
    const auto a = reinterpret_cast<std::uintptr_t>(p);
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        const auto dash = line.find('-');
        const auto space = line.find(' ');
        if (dash != std::string::npos && space != std::string::npos && dash < space &&
            line.find_first_not_of("0123456789abcdef") == dash) {
            const std::uintptr_t lo = std::stoull(line.substr(0, dash), nullptr, 16);
            const std::uintptr_t hi = std::stoull(line.substr(dash + 1, space - dash - 1), nullptr, 16);
            inside = a >= lo && a < hi;
            continue;
        }
        if (inside && line.rfind("VmFlags:", 0) == 0) return line.substr(8) + " ";
    }
    return "";
}

}  // namespace

TEST(LargePageGrid, LargeGridsStartOnHugePageBoundariesAndKeepTheirValues) {
    const Lattice lat({128, 128, 80});  // 1.25 M floats = 5 MiB
    Grid<float> g(lat, 1.5f);
    ASSERT_TRUE(huge_page_aligned(g.values().data()));
    for (std::size_t i = 0; i < g.size(); i += 4099) ASSERT_EQ(g[static_cast<PointIndex>(i)], 1.5f);
    g[static_cast<PointIndex>(g.size() - 1)] = -2.0f;
    Grid<float> copy = g;
    EXPECT_TRUE(huge_page_aligned(copy.values().data()));
    EXPECT_EQ(copy[static_cast<PointIndex>(g.size() - 1)], -2.0f);
    EXPECT_EQ(copy[0], 1.5f);
    const float* before = copy.values().data();
    Grid<float> moved = std::move(copy);
    EXPECT_EQ(moved.values().data(), before);  // a move keeps the block
    moved.fill(3.0f);
    EXPECT_EQ(moved[static_cast<PointIndex>(12345)], 3.0f);
    EXPECT_EQ(g[static_cast<PointIndex>(12345)], 1.5f);
    // A small grid is an ordinary allocation and works the same.
    Grid<std::int8_t> small(Lattice({10, 10, 10}), std::int8_t{4});
    EXPECT_EQ(small[static_cast<PointIndex>(999)], 4);
}

// A whole-lattice grid is filled and copied on every thread (its first touch): every element, at
// sizes that are not a multiple of the 2 MiB blocks, on 1 and 3 threads; a copy assigned to a grid
// of its size keeps that grid's storage, to another size takes new storage; self-assignment is a
// no-op; a grid of non-trivial elements (std::string) is filled and copied like any other.
TEST(LargePageGrid, WholeLatticeGridsAreFilledAndCopiedWhole) {
    for (const std::size_t threads : {1u, 3u}) {
        const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
        const Lattice lat({131, 127, 83});  // 1.38 M: 5.3 MiB of floats, 10.5 MiB of doubles
        Grid<float> g(lat, 2.5f);
        for (std::size_t i = 0; i < g.size(); ++i) ASSERT_EQ(g[static_cast<PointIndex>(i)], 2.5f) << threads << " threads, " << i;
        for (std::size_t i = 0; i < g.size(); ++i) g[static_cast<PointIndex>(i)] = static_cast<float>(i % 1000);
        const Grid<float> copy = g;
        for (std::size_t i = 0; i < g.size(); ++i) ASSERT_EQ(copy[static_cast<PointIndex>(i)], static_cast<float>(i % 1000)) << i;
        Grid<float> same(lat, -1.0f);
        const float* const storage = same.values().data();
        same = copy;
        EXPECT_EQ(same.values().data(), storage);
        for (std::size_t i = 0; i < g.size(); ++i) ASSERT_EQ(same[static_cast<PointIndex>(i)], copy[static_cast<PointIndex>(i)]) << i;
        Grid<float> other(Lattice({5, 5, 5}), 9.0f);
        other = copy;
        EXPECT_EQ(other.lattice().dims(), lat.dims());
        for (std::size_t i = 0; i < g.size(); ++i) ASSERT_EQ(other[static_cast<PointIndex>(i)], copy[static_cast<PointIndex>(i)]) << i;
        const Grid<float>& alias = other;
        other = alias;
        EXPECT_EQ(other[static_cast<PointIndex>(g.size() - 1)], copy[static_cast<PointIndex>(g.size() - 1)]);
        const Grid<double> d(lat, 0.25);
        for (std::size_t i = 0; i < d.size(); ++i) ASSERT_EQ(d[static_cast<PointIndex>(i)], 0.25) << i;
        const Grid<std::uint8_t> bytes(Lattice({601, 113, 67}), std::uint8_t{7});  // 4.3 MiB
        for (std::size_t i = 0; i < bytes.size(); ++i) ASSERT_EQ(bytes[static_cast<PointIndex>(i)], 7) << i;
    }
    const Grid<std::string> words(Lattice({64, 64, 64}), std::string(40, 'x'));  // 8 MiB of strings
    const Grid<std::string> words_copy = words;
    for (std::size_t i = 0; i < words.size(); i += 97) ASSERT_EQ(words_copy[static_cast<PointIndex>(i)], std::string(40, 'x')) << i;
}

TEST(LargePageGrid, LargeGridsAreAdvisedForTransparentHugePages) {
    if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled"))
        GTEST_SKIP() << "this kernel has no transparent huge pages";
    if (!std::filesystem::exists("/proc/self/smaps")) GTEST_SKIP() << "no /proc/self/smaps";
    const Grid<float> g(Lattice({128, 128, 80}), 0.0f);
    const std::string flags = vm_flags_at(g.values().data());
    ASSERT_FALSE(flags.empty()) << "no mapping holds the grid's data";
    EXPECT_NE(flags.find(" hg "), std::string::npos) << "VmFlags:" << flags;
}

TEST(LargePageGrid, AFreedBlockServesTheNextGridOfItsSizeWhichHoldsOnlyItsFill) {
    if (!detail::recycles_blocks()) GTEST_SKIP() << "blocks are not kept under AddressSanitizer";
    const Lattice lat({128, 128, 80});
    const float* first = nullptr;
    {
        Grid<float> g(lat, 1.5f);
        first = g.values().data();
        g.fill(-7.0f);
    }
    const auto [blocks, bytes] = detail::recycled();
    EXPECT_GE(blocks, 1u);
    EXPECT_GE(bytes, lat.size() * sizeof(float));
    {
        const Grid<float> again(lat, 2.0f);
        EXPECT_EQ(again.values().data(), first);  // the same block, taken back
        for (std::size_t i = 0; i < again.size(); ++i) ASSERT_EQ(again[static_cast<PointIndex>(i)], 2.0f) << i;
    }
    // A request of another size (10 MiB against 6 MiB, in 2 MiB granules) gets another block.
    const Grid<float> other(Lattice({128, 128, 160}), 0.0f);
    EXPECT_NE(other.values().data(), first);
}

TEST(LargePageGrid, ReleasedKeptBlocksServeNoLaterGrid) {
    if (!detail::recycles_blocks()) GTEST_SKIP() << "blocks are not kept under AddressSanitizer";
    const std::size_t bytes = detail::kLargeBlock + 3 * detail::kHugePage;
    void* const p = detail::allocate_large(bytes);
    detail::free_large(p, bytes);
    ASSERT_GE(detail::recycled().first, 1u);
    detail::release_recycled();
    EXPECT_EQ(detail::recycled(), (std::pair<std::size_t, std::size_t>{0, 0}));
    // The next block of its size is a fresh one from the system (freed, so the address may come
    // back; what matters is that nothing was kept to serve it).
    void* const q = detail::allocate_large(bytes);
    EXPECT_EQ(detail::recycled(), (std::pair<std::size_t, std::size_t>{0, 0}));
    detail::free_large(q, bytes);
    EXPECT_EQ(detail::recycled().first, 1u);
}

TEST(LargePageGrid, KeptBlocksStayWithinTheirBounds) {
    if (!detail::recycles_blocks()) GTEST_SKIP() << "blocks are not kept under AddressSanitizer";
    // More blocks than are kept, of several sizes, freed in turn (never touched: no memory used).
    std::vector<std::pair<void*, std::size_t>> held;
    for (std::size_t k = 0; k < 3 * detail::kRecycledBlocks; ++k) {
        const std::size_t bytes = detail::kLargeBlock + (k % 5) * detail::kHugePage + 100;
        held.emplace_back(detail::allocate_large(bytes), bytes);
    }
    for (const auto& [p, bytes] : held) {
        detail::free_large(p, bytes);
        const auto [blocks, kept] = detail::recycled();
        ASSERT_LE(blocks, detail::kRecycledBlocks);
        ASSERT_LE(kept, detail::kRecycledBytes);
    }
    // A block over the whole allowance is not kept: the blocks and bytes kept do not change.
    const auto before = detail::recycled();
    const std::size_t huge = detail::kRecycledBytes + detail::kHugePage;
    detail::free_large(detail::allocate_large(huge), huge);
    EXPECT_EQ(detail::recycled(), before);
    // A block of half the allowance makes its room by letting the oldest blocks go, and is kept; the
    // block freed just before it, the newest of the rest, is still there.
    const std::size_t half = detail::kRecycledBytes / 2 + 1;
    void* big = detail::allocate_large(half);
    const auto [last, last_bytes] = held.back();
    detail::free_large(big, half);
    EXPECT_GE(detail::recycled().second, half);
    EXPECT_LE(detail::recycled().second, detail::kRecycledBytes);
    EXPECT_EQ(detail::allocate_large(last_bytes), last);  // the newest kept block of its size
    EXPECT_EQ(detail::allocate_large(half), big);
    detail::free_large(big, half);
    detail::free_large(last, last_bytes);
}

TEST(LargePageGrid, BlocksTakenAndFreedOnSeveralThreadsAreNeverShared) {
    // Each thread writes its own mark through the whole of every block it holds, then checks it:
    // a block handed to two holders at once would show the other's mark.
    std::vector<std::thread> threads;
    std::vector<int> bad(4, 0);
    for (int t = 0; t < 4; ++t)
        threads.emplace_back([t, &bad] {
            for (int round = 0; round < 40; ++round) {
                const std::size_t n = (detail::kLargeBlock + static_cast<std::size_t>((round + t) % 3) * detail::kHugePage) / sizeof(std::uint32_t);
                LargeVector<std::uint32_t> v(n, static_cast<std::uint32_t>(t * 1000 + round));
                std::this_thread::yield();
                for (std::size_t i = 0; i < n; i += 1021) bad[static_cast<std::size_t>(t)] += v[i] != static_cast<std::uint32_t>(t * 1000 + round);
            }
        });
    for (std::thread& th : threads) th.join();
    for (int t = 0; t < 4; ++t) EXPECT_EQ(bad[static_cast<std::size_t>(t)], 0) << "thread " << t;
}
