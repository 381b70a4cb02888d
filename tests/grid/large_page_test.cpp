// Grid storage on huge pages: a grid of 4 MiB or more starts on a 2 MiB boundary and its memory is
// advised MADV_HUGEPAGE (the kernel's "hg" flag in /proc/self/smaps); values survive copies and moves.
#include <gtest/gtest.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

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

TEST(LargePageGrid, LargeGridsAreAdvisedForTransparentHugePages) {
    if (!std::filesystem::exists("/sys/kernel/mm/transparent_hugepage/enabled"))
        GTEST_SKIP() << "this kernel has no transparent huge pages";
    if (!std::filesystem::exists("/proc/self/smaps")) GTEST_SKIP() << "no /proc/self/smaps";
    const Grid<float> g(Lattice({128, 128, 80}), 0.0f);
    const std::string flags = vm_flags_at(g.values().data());
    ASSERT_FALSE(flags.empty()) << "no mapping holds the grid's data";
    EXPECT_NE(flags.find(" hg "), std::string::npos) << "VmFlags:" << flags;
}
