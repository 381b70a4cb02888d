// Block-wise wake stamps for the incremental step's sleeping rule.
#include "liveset/levelset/activity.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace liveset {

namespace {
constexpr std::int64_t kNever = std::numeric_limits<std::int64_t>::min() / 2;
}

void FrontActivity::reset() {
    stamp_.clear();
    stamp_.shrink_to_fit();
    blocks_x_ = blocks_y_ = blocks_z_ = 0;
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
    s.stamps.assign(stamp_.begin(), stamp_.end());
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
    stamp_.assign(s.stamps.begin(), s.stamps.end());
    all_woken_at_ = s.all_woken_at;
    adopt_next_speed_ = s.speed_current;
}

void FrontActivity::begin_step(const Lattice& lattice, std::uint64_t speed_serial, std::int64_t now) {
    if (stamp_.empty()) {
        const Vec3i d = lattice.dims();
        blocks_x_ = static_cast<std::size_t>((d.x + 1) / 2);
        blocks_y_ = static_cast<std::size_t>((d.y + 1) / 2);
        blocks_z_ = static_cast<std::size_t>((d.z + 1) / 2);
        stamp_.assign(blocks_x_ * blocks_y_ * blocks_z_, kNever);
        speed_serial_ = speed_serial;
        all_woken_at_ = now - 1;  // this step is the first of the window
        return;
    }
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
    for (PointIndex i : points) {
        const Vec3i p = lattice.coord(i);
        const Vec3i b{p.x >> 1, p.y >> 1, p.z >> 1};
        for (int z = std::max(b.z - 1, 0); z <= std::min(b.z + 1, bz - 1); ++z)
            for (int y = std::max(b.y - 1, 0); y <= std::min(b.y + 1, by - 1); ++y)
                for (int x = std::max(b.x - 1, 0); x <= std::min(b.x + 1, bx - 1); ++x)
                    stamp_[static_cast<std::size_t>(x) + blocks_x_ * (static_cast<std::size_t>(y) + blocks_y_ * static_cast<std::size_t>(z))] = now;
    }
}

}  // namespace liveset
