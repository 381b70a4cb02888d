// Block-wise wake stamps for the incremental step's sleeping rule.
#include "liveset/levelset/activity.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace liveset {

namespace {
constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min() / 2;
// A stored offset this low means "never woken" (or woken so long ago that it no longer matters:
// every window is at most 1 000 000 steps, far below 2^30).
constexpr std::int32_t kNeverOffset = std::numeric_limits<std::int32_t>::min() / 2;
constexpr std::int64_t kRebaseAfter = std::int64_t{1} << 30;

std::int32_t offset_of(std::int64_t stamp, std::int64_t base) {
    const std::int64_t d = stamp - base;  // callers keep it below 2^31 (rebase; restore's base)
    return d <= kNeverOffset ? kNeverOffset : static_cast<std::int32_t>(std::min<std::int64_t>(d, std::numeric_limits<std::int32_t>::max()));
}
}  // namespace

void FrontActivity::rebase(std::int64_t now) {
    if (now - base_ < kRebaseAfter) return;
    for (std::int32_t& s : stamp_) s = offset_of(base_ + s, now);
    base_ = now;
}

FrontActivity::AwakeTest FrontActivity::awake_test(std::int64_t now, int sleep_after) const {
    AwakeTest t;
    t.stamp = stamp_.data();
    t.blocks_x = blocks_x_;
    t.blocks_y = blocks_y_;
    const std::int64_t since = now - sleep_after;  // awake iff the last wake is at or after it
    t.all = all_woken_at_ >= since;
    const std::int64_t need = since - base_;  // the smallest offset that is
    t.none = need > std::numeric_limits<std::int32_t>::max();  // then min_offset is not read
    t.min_offset = static_cast<std::int32_t>(std::clamp<std::int64_t>(need, std::numeric_limits<std::int32_t>::min(),
                                                                      std::numeric_limits<std::int32_t>::max()));
    return t;
}

void FrontActivity::reset() {
    stamp_.clear();
    stamp_.shrink_to_fit();
    blocks_x_ = blocks_y_ = blocks_z_ = 0;
    base_ = 0;
    all_woken_at_ = 0;
    speed_serial_ = 0;
    adopt_next_speed_ = false;
}

ActivitySnapshot FrontActivity::snapshot(std::uint64_t speed_serial) const {
    ActivitySnapshot s;
    if (stamp_.empty()) return s;
    s.all_woken_at = all_woken_at_;
    s.speed_current = adopt_next_speed_ || (speed_serial != 0 && speed_serial == speed_serial_);
    s.blocks = {static_cast<int>(blocks_x_), static_cast<int>(blocks_y_), static_cast<int>(blocks_z_)};
    s.stamps.resize(stamp_.size());
    for (std::size_t b = 0; b < stamp_.size(); ++b) s.stamps[b] = stamp_[b] == kNeverOffset ? kNever : base_ + stamp_[b];
    return s;
}

void FrontActivity::restore(const ActivitySnapshot& s, const Lattice& lattice) {
    reset();
    if (s.blocks == Vec3i{0, 0, 0}) return;
    const Vec3i d = lattice.dims();
    const Vec3i want{(d.x + 1) / 2, (d.y + 1) / 2, (d.z + 1) / 2};
    if (!(s.blocks == want) || s.stamps.size() != static_cast<std::size_t>(want.x) * want.y * want.z)
        throw std::invalid_argument("activity snapshot of another lattice");
    blocks_x_ = static_cast<std::size_t>(want.x);
    blocks_y_ = static_cast<std::size_t>(want.y);
    blocks_z_ = static_cast<std::size_t>(want.z);
    // The base at or above every stamp (a saved clock is; a damaged file need not be), so that
    // every offset fits.
    base_ = s.clock;
    for (const std::int64_t t : s.stamps) base_ = std::max(base_, t);
    stamp_.resize(s.stamps.size());
    for (std::size_t b = 0; b < stamp_.size(); ++b) stamp_[b] = offset_of(s.stamps[b], base_);
    all_woken_at_ = s.all_woken_at;
    adopt_next_speed_ = s.speed_current;
}

void FrontActivity::begin_step(const Lattice& lattice, std::uint64_t speed_serial, std::int64_t now) {
    if (stamp_.empty()) {
        const Vec3i d = lattice.dims();
        blocks_x_ = static_cast<std::size_t>((d.x + 1) / 2);
        blocks_y_ = static_cast<std::size_t>((d.y + 1) / 2);
        blocks_z_ = static_cast<std::size_t>((d.z + 1) / 2);
        base_ = now;
        stamp_.assign(blocks_x_ * blocks_y_ * blocks_z_, kNeverOffset);
        speed_serial_ = speed_serial;
        all_woken_at_ = now - 1;  // this step is the first of the window
        return;
    }
    rebase(now);
    if (adopt_next_speed_) {  // restored: this speed is the one the stamps were taken under
        adopt_next_speed_ = false;
        speed_serial_ = speed_serial;
    }
    if (speed_serial != speed_serial_) {
        speed_serial_ = speed_serial;
        all_woken_at_ = now - 1;
    }
}

void FrontActivity::wake_near(std::span<const PointIndex> points, const Lattice& lattice, std::int64_t now) {
    if (stamp_.empty()) return;
    const auto bx = static_cast<int>(blocks_x_), by = static_cast<int>(blocks_y_), bz = static_cast<int>(blocks_z_);
    rebase(now);
    const std::int32_t at = offset_of(now, base_);
    const IndexDecoder decoder(lattice);  // no division per point (a step's sign changes: half its front)
    std::int32_t* const stamp = stamp_.data();
    const std::size_t sy = blocks_x_, sz = blocks_x_ * blocks_y_;
    std::size_t last = std::numeric_limits<std::size_t>::max();
    for (PointIndex i : points) {
        const Vec3i p = decoder.coord(i);
        const Vec3i b{p.x >> 1, p.y >> 1, p.z >> 1};
        const std::size_t block = static_cast<std::size_t>(b.x) + sy * static_cast<std::size_t>(b.y) + sz * static_cast<std::size_t>(b.z);
        if (block == last) continue;  // its 27 blocks already hold `at` (points come in runs along x)
        last = block;
        if (b.x > 0 && b.y > 0 && b.z > 0 && b.x < bx - 1 && b.y < by - 1 && b.z < bz - 1) {
            for (std::size_t z = block - sz - sy - 1; z <= block + sz - sy - 1; z += sz)
                for (std::size_t row = z; row <= z + 2 * sy; row += sy) stamp[row] = stamp[row + 1] = stamp[row + 2] = at;
            continue;
        }
        for (int z = std::max(b.z - 1, 0); z <= std::min(b.z + 1, bz - 1); ++z)
            for (int y = std::max(b.y - 1, 0); y <= std::min(b.y + 1, by - 1); ++y)
                for (int x = std::max(b.x - 1, 0); x <= std::min(b.x + 1, bx - 1); ++x)
                    stamp[static_cast<std::size_t>(x) + sy * static_cast<std::size_t>(y) + sz * static_cast<std::size_t>(z)] = at;
    }
}

}  // namespace liveset
