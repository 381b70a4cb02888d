// FrontActivity: which stretches of a sparse field's front are awake, for the incremental step's
// sleeping rule (docs/ARCHITECTURE.md, "Activity"). The lattice is cut into blocks of 2×2×2
// points; each block remembers the last step at which something woke it: a sign change of φ, or
// any change made outside a step (a local edit, an undo), within one block of it - that is, within
// 2 to 3 points. A zero-layer point is awake while its block was woken in the last `sleep_after`
// steps. Everything is awake for `sleep_after` steps after the first step, a re-initialisation or
// a new speed.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "liveset/grid/index_decoder.hpp"
#include "liveset/grid/large_page_allocator.hpp"
#include "liveset/grid/lattice.hpp"

namespace liveset {

// What a FrontActivity remembers, saved with a field (a workspace) so that a continued run sleeps
// and wakes exactly as the uninterrupted one would.
struct ActivitySnapshot {
    std::int64_t clock = 0;         // the field's global step count (the stamps' clock)
    std::int64_t all_woken_at = 0;
    bool speed_current = false;     // the stamps were taken under the speed the next step uses
    Vec3i blocks{};                 // 0 x 0 x 0: the rule never ran (nothing to restore)
    std::vector<std::int64_t> stamps;
};

class FrontActivity {
public:
    // Forgets everything (nothing allocated; the next begin_step wakes everything).
    void reset();
    bool enabled() const { return !stamp_.empty(); }
    // Called by a sleeping step with the step number `now` (steps count from 1): allocates the
    // blocks on first use, and wakes everything when the speed (by serial) is not the last one's.
    void begin_step(const Lattice& lattice, std::uint64_t speed_serial, std::int64_t now);
    // Wakes the blocks within one block of each point (no-op when not enabled).
    void wake_near(std::span<const PointIndex> points, const Lattice& lattice, std::int64_t now);
    // The rule at one step, for a loop over points: a point is awake iff the last wake of its
    // block or of everything is at least now - sleep_after, so everything is awake when the last
    // global wake is, and otherwise the test is one compare of the block's offset with a bound
    // (valid until the next begin_step or wake_near).
    struct AwakeTest {
        const std::int32_t* stamp = nullptr;
        std::size_t blocks_x = 0, blocks_y = 0;
        bool all = true;    // the last global wake is within the window
        bool none = false;  // no block's offset can reach the bound
        std::int32_t min_offset = 0;
        // The first block of lattice row (y, z); x's block is (x >> 1) further on.
        std::size_t row_blocks(std::size_t y, std::size_t z) const { return blocks_x * ((y >> 1) + blocks_y * (z >> 1)); }
        bool block_awake(std::size_t b) const { return all || (!none && stamp[b] >= min_offset); }
        bool operator()(Vec3i p) const {
            return block_awake(row_blocks(static_cast<std::size_t>(p.y), static_cast<std::size_t>(p.z)) + static_cast<std::size_t>(p.x >> 1));
        }
    };
    AwakeTest awake_test(std::int64_t now, int sleep_after) const;
    // The same test for a loop over lattice indices in (mostly) ascending order, such as the sorted
    // zero-layer list: the blocks of the lattice row (y, z) a point lies on are found once per row
    // (two divisions), so a point on the last point's row costs a compare, a shift and its block's
    // stamp. Stateful (the current row); one per loop.
    class AwakeScan {
    public:
        AwakeScan(const AwakeTest& test, const Lattice& lattice)
            : test_(test),
              nx_(static_cast<std::uint32_t>(lattice.dims().x)),
              ny_(static_cast<std::uint32_t>(lattice.dims().y)),
              row_of_(nx_),
              z_of_(ny_) {}
        bool operator()(PointIndex i) {
            if (test_.all) return true;  // no row to find
            if (i - row_start_ >= nx_) enter_row(i);  // unsigned: also a point before the row
            return test_.block_awake(row_blocks_ + ((i - row_start_) >> 1));
        }

    private:
        void enter_row(PointIndex i) {
            const std::uint32_t row = row_of_.divide(i);  // y + dims.y * z
            const std::uint32_t z = z_of_.divide(row);
            const std::uint32_t y = row - z * ny_;
            row_start_ = row * nx_;
            row_blocks_ = test_.row_blocks(y, z);
        }
        AwakeTest test_;
        std::uint32_t nx_, ny_;
        FastDivider row_of_, z_of_;
        PointIndex row_start_ = 0;  // the row of index 0 to begin with, whose blocks start at 0
        std::size_t row_blocks_ = 0;
    };
    // Whether lattice point p is awake at step `now` under the rule with window `sleep_after`.
    bool awake(Vec3i p, std::int64_t now, int sleep_after) const { return awake_test(now, sleep_after)(p); }

    // `speed_serial`: the serial of the speed the next step will use (0: none built yet).
    ActivitySnapshot snapshot(std::uint64_t speed_serial) const;
    // Takes a snapshot of the same lattice back; with speed_current, the next step's speed counts as
    // the one the stamps were taken under (whatever its serial). Throws std::invalid_argument when
    // the blocks do not fit the lattice.
    void restore(const ActivitySnapshot& snapshot, const Lattice& lattice);

private:
    bool adopt_next_speed_ = false;
    std::size_t blocks_x_ = 0, blocks_y_ = 0, blocks_z_ = 0;
    // Per block: the last step that woke it, as an offset from base_ (huge pages). 32 bits halve
    // the array a zero-layer point's awake test reads (BrainWeb: 3.5 MB instead of 7); base_ moves
    // up every 2^30 steps (rebase) so the offsets never overflow.
    LargeVector<std::int32_t> stamp_;
    std::int64_t base_ = 0;
    void rebase(std::int64_t now);
    std::int64_t all_woken_at_ = 0;
    std::uint64_t speed_serial_ = 0;
};

}  // namespace liveset
