// Test helpers shared by the recovery-file tests (tests/session) and the viewer's crash-path test
// (tests/render): a fresh folder, a sample state with a rotated lattice, a bit-exact comparison.
#pragma once

#include <gtest/gtest.h>

#include <bit>
#include <filesystem>
#include <string>

#include "liveset/session/recovery.hpp"
#include "scratch_dir.hpp"

namespace liveset {

inline std::filesystem::path fresh_dir(const std::string& name) { return testing::scratch_dir("recovery_" + name); }

inline RecoveryState sample_state() {
    const Mat3d flip{-1, 0, 0, 0, 0, 1, 0, 1, 0};
    const Lattice lattice({7, 5, 4}, {0.9, 1.1, 2.5}, {-12.5, 30.0, 4.25}, flip);
    RecoveryState s;
    s.image = "/data/subject 01/t1.nii.gz";
    s.unix_time = 1795000000;
    s.marks.seeds = {{{1.5, 2.0, 3.0}, 2.0}, {{4.0, 1.0, 0.0}, 0.75}};
    s.marks.params = {0.42, 0.07, 3.0, 0.2, 0.45};
    s.marks.window_from_seeds = false;
    s.marks.alpha_automatic = true;
    s.marks.pristine = false;
    s.marks.iterations = 137;
    s.roi_checksum = 0x0123456789abcdefull;
    s.step = RecordedStep{false, false};  // not the default: the exact step without the rule
    s.coarse_start = CoarseStart::kOn;     // nor the default coarse start
    s.phi = Grid<float>(lattice);
    int k = 0;
    for (float& v : s.phi.values()) v = static_cast<float>(k++ % 11) * 0.37f - 1.5f;
    s.status = Grid<std::int8_t>(lattice);
    k = 0;
    for (std::int8_t& v : s.status.values()) v = static_cast<std::int8_t>(k++ % 7 - 3);
    return s;
}

inline void expect_same(const RecoveryState& a, const RecoveryState& b) {
    EXPECT_EQ(a.image, b.image);
    EXPECT_EQ(a.signal, b.signal);
    EXPECT_EQ(a.unix_time, b.unix_time);
    ASSERT_EQ(a.marks.seeds.size(), b.marks.seeds.size());
    for (std::size_t i = 0; i < a.marks.seeds.size(); ++i) {
        EXPECT_EQ(a.marks.seeds[i].center, b.marks.seeds[i].center);
        EXPECT_EQ(a.marks.seeds[i].radius, b.marks.seeds[i].radius);
    }
    EXPECT_EQ(a.marks.params.mu, b.marks.params.mu);
    EXPECT_EQ(a.marks.params.epsilon, b.marks.params.epsilon);
    EXPECT_EQ(a.marks.params.n, b.marks.params.n);
    EXPECT_EQ(a.marks.params.alpha, b.marks.params.alpha);
    EXPECT_EQ(a.marks.params.smooth_mm, b.marks.params.smooth_mm);
    EXPECT_EQ(a.marks.window_from_seeds, b.marks.window_from_seeds);
    EXPECT_EQ(a.marks.alpha_automatic, b.marks.alpha_automatic);
    EXPECT_EQ(a.marks.iterations, b.marks.iterations);
    EXPECT_EQ(a.roi_recorded, b.roi_recorded);
    EXPECT_EQ(a.roi_checksum, b.roi_checksum);
    EXPECT_EQ(a.step.has_value(), b.step.has_value());
    if (a.step && b.step) {
        EXPECT_EQ(a.step->sleeping, b.step->sleeping);
        EXPECT_EQ(a.step->thin_fronts, b.step->thin_fronts);
    }
    EXPECT_EQ(a.coarse_start.has_value(), b.coarse_start.has_value());
    if (a.coarse_start && b.coarse_start) {
        EXPECT_EQ(*a.coarse_start, *b.coarse_start);
    }
    EXPECT_TRUE(a.phi.lattice().same_geometry(b.phi.lattice(), 0.0));
    ASSERT_EQ(a.phi.size(), b.phi.size());
    for (std::size_t i = 0; i < a.phi.size(); ++i)
        ASSERT_EQ(std::bit_cast<std::uint32_t>(a.phi.values()[i]), std::bit_cast<std::uint32_t>(b.phi.values()[i])) << i;
    ASSERT_EQ(a.status.size(), b.status.size());
    EXPECT_TRUE(std::equal(a.status.values().begin(), a.status.values().end(), b.status.values().begin()));
}

}  // namespace liveset
