// The repair's topology guard: swarm edits may close tunnels and fill cavities but never make any;
// a bridge across a one-voxel crack between two fronts is filled with its whole crack when that
// closes the tunnel the crack belongs to; in a cut, only removals that cut a handle pass.
#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <unordered_set>

#include "liveset/grid/digital_topology.hpp"
#include "liveset/swarm/pocket_flood.hpp"
#include "liveset/swarm/repair.hpp"

namespace liveset {

namespace {

constexpr std::size_t kMaxPocketLimit = 32768;
// A crack is gathered whole, up to this many voxels (a one-voxel slit where two fronts met can be
// tens of voxels long and, across a sheet a few voxels thick, a few hundred); a larger region of
// outside voxels between inside ones is no crack but a sulcus's worth, and is left alone.
constexpr std::size_t kMaxCrack = 512;
constexpr float kCrackEdit = -0.5f;    // the edit each crack point gets
constexpr float kFlippable = 0.5f;     // ... which flips it when φ is below this
// The two floods that tell a handle cut from a split stop (and the cut is refused) past this many voxels.
constexpr std::size_t kMaxJoinFlood = std::size_t{1} << 21;

Vec3i face_neighbour(Vec3i c, int k) {
    c[k / 2] += (k % 2) ? 1 : -1;
    return c;
}

// The guard's state over one batch: the flips accepted so far, read through inside().
class Guard {
public:
    Guard(const SparseField& field, const GuardOptions& o) : field_(field), lat_(field.lattice()), o_(o) {
        if (flip_filter_.size() != lat_.size()) flip_filter_.assign(lat_.size(), 0);
    }
    ~Guard() {
        for (const PointIndex i : filtered_) flip_filter_[i] = 0;  // clear what this batch set
    }
    Guard(const Guard&) = delete;
    Guard& operator=(const Guard&) = delete;
    bool inside_at(PointIndex i) const {
        if (flip_filter_[i] != 0)
            if (const auto it = flipped_.find(i); it != flipped_.end()) return it->second;
        return field_.phi()[i] < 0.0f;
    }
    bool inside(Vec3i q) const { return lat_.contains(q) && inside_at(lat_.index(q)); }
    bool keep(const ZeroLayerEdit& e);  // false: drop the edit
    const std::vector<PointIndex>& crack_points() const { return cracks_; }
    const std::vector<PointIndex>& deepened_points() const { return deepen_; }

private:
    bool seals_pocket_around(std::span<const Vec3i> cs);
    bool cuts_handle(Vec3i c, const TopologicalNumbers& t) const;
    bool joined(Vec3i a, Vec3i b) const;
    std::vector<PointIndex> gather_crack(Vec3i start) const;
    bool fill_crack(Vec3i start);
    void prepare_crack(const std::vector<PointIndex>& crack);
    bool in_roi(Vec3i q) const;
    bool flippable(PointIndex i) const;

    const SparseField& field_;
    const Lattice& lat_;
    GuardOptions o_;
    void flip(PointIndex i, bool in) {
        flipped_[i] = in;
        if (!flip_filter_[i]) filtered_.push_back(i);
        flip_filter_[i] = 1;  // stays set until the batch ends: inside_at() then asks flipped_
    }
    std::unordered_map<PointIndex, bool> flipped_;  // accepted flips of this batch: point -> inside
    // A byte per lattice point, set where flipped_ may hold the point (per thread, reused across
    // batches): most points the pocket flood asks about were never flipped, so no hash look-up.
    static thread_local std::vector<std::uint8_t> flip_filter_;
    std::vector<PointIndex> filtered_;  // the points this batch set in flip_filter_
    std::unordered_set<PointIndex> tried_;          // crack points already tried in this batch
    std::vector<PointIndex> cracks_;                // crack points filled (their edits become kCrackEdit)
    std::vector<PointIndex> deepen_;                // inside points deepened to prepare a crack (edits kCrackEdit)
    std::unordered_set<PointIndex> deepened_;       // ... as a set: no flip there is accepted in this batch
};

thread_local std::vector<std::uint8_t> Guard::flip_filter_;

// Whether the voxels of `cs` (counted inside) separate a pocket of at most pocket_limit voxels off
// the outside: their outside face neighbours lie in two or more regions, one of them small (see
// PocketFlood). Per thread: guard_topology may run on several threads.
bool Guard::seals_pocket_around(std::span<const Vec3i> cs) {
    thread_local PocketFlood flood;
    thread_local std::vector<Vec3i> starts;
    starts.clear();
    for (const Vec3i c : cs)
        for (int k = 0; k < 6; ++k) {
            const Vec3i q = face_neighbour(c, k);
            if (lat_.contains(q) && !inside(q)) starts.push_back(q);
        }
    return flood.seals(lat_, [this](PointIndex i) { return !inside_at(i); }, starts, o_.pocket_limit);
}

bool Guard::keep(const ZeroLayerEdit& e) {
    const float before = field_.phi()[e.point];
    const float after = before + std::clamp(e.delta, -0.5f, 0.5f);
    const bool was_in = before < 0.0f, is_in = after < 0.0f;
    const Vec3i c = lat_.coord(e.point);
    const auto numbers = [&] { return topological_numbers([this](Vec3i q) { return inside(q); }, c); };
    // A cut moves φ only where it may cut: at inside points whose inside neighbours form two or
    // more pieces (elsewhere in the brush the surface stays where it is, to the sub-voxel).
    if (was_in == is_in) return !(o_.cut_handles && was_in && e.delta > 0.0f) || numbers().foreground >= 2;
    if (deepened_.count(e.point)) return false;  // deepened to prepare a crack: stays inside
    const TopologicalNumbers t = numbers();
    if (o_.cut_handles && !is_in) {
        flip(e.point, false);
        const bool cut = cuts_handle(c, t);
        if (!cut) flipped_.erase(e.point);
        return cut;
    }
    bool ok = is_in ? t.foreground == 1 : (t.background == 1 && t.foreground <= 1);
    // Growth that splits the local background either closes a tunnel (good) or seals a small
    // pocket off (a spurious cavity): refuse the latter.
    if (ok && is_in && t.background >= 2) {
        flip(e.point, true);
        ok = !seals_pocket_around(std::span<const Vec3i>(&c, 1));
        flipped_.erase(e.point);
    }
    if (!ok && is_in && t.foreground >= 2 && o_.close_cracks) return fill_crack(c);
    if (ok) flip(e.point, is_in);
    return ok;
}

// With inside point `c` flipped out: whether that cut a handle — its inside neighbours form two
// 26-connected pieces (t, counted before the flip), its outside neighbours one, and the pieces are
// joined elsewhere.
bool Guard::cuts_handle(Vec3i c, const TopologicalNumbers& t) const {
    if (t.foreground != 2 || t.background != 1) return false;
    // One voxel of each piece: the first inside neighbour, and the first one not 26-connected to it
    // within the neighbourhood.
    std::vector<Vec3i> piece, other;
    for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
            for (int dx = -1; dx <= 1; ++dx) {
                const Vec3i q = c + Vec3i{dx, dy, dz};
                if ((dx || dy || dz) && inside(q)) other.push_back(q);
            }
    if (other.empty()) return false;
    piece.push_back(other.front());
    other.erase(other.begin());
    for (std::size_t head = 0; head < piece.size(); ++head)
        std::erase_if(other, [&](Vec3i q) {
            const Vec3i d = q - piece[head];
            if (std::max({std::abs(d.x), std::abs(d.y), std::abs(d.z)}) > 1) return false;
            piece.push_back(q);
            return true;
        });
    return !other.empty() && joined(piece.front(), other.front());
}

// Whether inside voxels `a` and `b` are joined by a 26-connected inside path: two floods, one from
// each, a voxel at a time from the smaller frontier; they meet -> true; one runs out (its piece is
// finite and holds no path to the other) or the two together pass kMaxJoinFlood voxels -> false.
// Marks and queues are per thread and reused across calls (a new pair of stamps per call).
bool Guard::joined(Vec3i a, Vec3i b) const {
    thread_local std::vector<std::uint32_t> mark;
    thread_local std::uint32_t base = 0;
    thread_local std::vector<Vec3i> queue[2];
    if (mark.size() != lat_.size() || base >= UINT32_MAX - 2) {
        mark.assign(lat_.size(), 0);
        base = 0;
    }
    base += 2;  // side 0 marks base, side 1 base + 1
    queue[0].assign(1, a);
    queue[1].assign(1, b);
    std::size_t head[2] = {0, 0};
    mark[lat_.index(a)] = base;
    mark[lat_.index(b)] = base + 1;
    for (std::size_t visited = 2; visited <= kMaxJoinFlood;) {
        const int s = queue[0].size() - head[0] <= queue[1].size() - head[1] ? 0 : 1;
        if (head[s] == queue[s].size()) return false;
        const Vec3i p = queue[s][head[s]++];
        for (int dz = -1; dz <= 1; ++dz)
            for (int dy = -1; dy <= 1; ++dy)
                for (int dx = -1; dx <= 1; ++dx) {
                    const Vec3i q = p + Vec3i{dx, dy, dz};
                    if (!inside(q)) continue;
                    std::uint32_t& m = mark[lat_.index(q)];
                    if (m == base + static_cast<std::uint32_t>(1 - s)) return true;
                    if (m == base + static_cast<std::uint32_t>(s)) continue;
                    m = base + static_cast<std::uint32_t>(s);
                    queue[s].push_back(q);
                    ++visited;
                }
    }
    return false;
}

bool Guard::in_roi(Vec3i q) const {
    if (!o_.roi) return true;
    for (int k = 0; k < 7; ++k) {
        const Vec3i r = k ? face_neighbour(q, k - 1) : q;
        if (!lat_.contains(r) || (*o_.roi)(r) == 0) return false;
    }
    return true;
}

// A crack voxel's edit flips it this step: a zero-layer point with φ below kFlippable.
bool Guard::flippable(PointIndex i) const { return field_.status()[i] == 0 && field_.phi()[i] < kFlippable; }

// The crack of a refused bridge at `start` (see guard_topology): the outside voxels 6-connected to
// it that each lie between two inside voxels along one of the 13 lines through them — the whole
// one-voxel slit where two fronts met, however long. Empty when it holds more than kMaxCrack
// voxels, a voxel outside the ROI or one already tried in this batch.
std::vector<PointIndex> Guard::gather_crack(Vec3i start) const {
    const auto between_fronts = [this](Vec3i q) {
        for (const auto& d : kLineDirections) {
            const Vec3i v{d[0], d[1], d[2]};
            if (inside(q + v) && inside(q - v)) return true;
        }
        return false;
    };
    const PointIndex s = lat_.index(start);
    if (tried_.count(s) || !in_roi(start)) return {};
    std::vector<Vec3i> queue{start};
    std::vector<PointIndex> crack{s};
    std::unordered_set<PointIndex> seen{s};
    for (std::size_t head = 0; head < queue.size(); ++head) {
        for (int k = 0; k < 6; ++k) {
            const Vec3i q = face_neighbour(queue[head], k);
            if (!lat_.contains(q) || inside(q)) continue;
            const PointIndex i = lat_.index(q);
            if (!seen.insert(i).second || !between_fronts(q)) continue;
            if (tried_.count(i) || !in_roi(q) || crack.size() >= kMaxCrack) return {};
            crack.push_back(i);
            queue.push_back(q);
        }
    }
    return crack;
}

// Fills the crack of the bridge at `start` when that closes a tunnel: the Euler characteristic
// (components − tunnels + cavities) counted in the crack's box rises with the whole crack filled,
// no component can appear, and no pocket is sealed, so a tunnel closed. A crack some of whose
// voxels this step's edit cannot flip yet (off the zero layer, or φ ≥ kFlippable: the fronts have
// not come close enough) is prepared instead: the inside zero-layer face neighbours of those voxels
// are deepened (their edits become kCrackEdit; no sign changes), which brings the crack onto the
// zero layer for a later step. Returns whether the crack is filled this step.
bool Guard::fill_crack(Vec3i start) {
    const std::vector<PointIndex> crack = gather_crack(start);
    for (PointIndex i : crack) tried_.insert(i);
    if (crack.empty()) return false;
    // χ changes only at the corner points around the crack voxels (counted there before and after).
    std::vector<Vec3i> voxels;
    voxels.reserve(crack.size());
    for (PointIndex i : crack) voxels.push_back(lat_.coord(i));
    const std::vector<Vec3i> corners = euler_corners_of(voxels);
    const auto in = [this](Vec3i q) { return inside(q); };
    const long chi_before = euler_at_corners_26(in, corners);
    // The crack voxels' states before (a voxel flipped out earlier in this batch keeps that flip
    // when the fill is refused).
    std::vector<std::pair<PointIndex, int>> saved;  // -1: no flip recorded, else the flip's state
    saved.reserve(crack.size());
    for (PointIndex i : crack) {
        const auto it = flipped_.find(i);
        saved.emplace_back(i, it == flipped_.end() ? -1 : int(it->second));
        flip(i, true);
    }
    const bool ok = euler_at_corners_26(in, corners) > chi_before && !seals_pocket_around(voxels);
    const bool ready = std::all_of(crack.begin(), crack.end(), [this](PointIndex i) { return flippable(i); });
    if (!ok || !ready) {
        for (const auto& [i, state] : saved) {
            if (state < 0) flipped_.erase(i);
            else flipped_[i] = state != 0;
        }
        if (ok) prepare_crack(crack);
        return false;
    }
    cracks_.insert(cracks_.end(), crack.begin(), crack.end());
    return true;
}

// Deepens the inside zero-layer face neighbours of the crack voxels that cannot flip yet.
void Guard::prepare_crack(const std::vector<PointIndex>& crack) {
    for (PointIndex i : crack) {
        if (flippable(i)) continue;
        const Vec3i c = lat_.coord(i);
        for (int k = 0; k < 6; ++k) {
            const Vec3i q = face_neighbour(c, k);
            if (!lat_.contains(q)) continue;
            const PointIndex j = lat_.index(q);
            if (field_.status()[j] == 0 && field_.phi()[j] < 0.0f && inside_at(j) && in_roi(q) && deepened_.insert(j).second)
                deepen_.push_back(j);
        }
    }
}

}  // namespace

std::size_t brush_pocket_limit(double edit_range) {
    if (!(edit_range > 0) || !std::isfinite(edit_range)) return kMaxPocketLimit;
    const double side = 2.0 * std::ceil(edit_range) + 1.0;
    return static_cast<std::size_t>(std::min(side * side * side, static_cast<double>(kMaxPocketLimit)));
}

std::size_t guard_topology(const SparseField& field, std::vector<ZeroLayerEdit>& edits, const GuardOptions& options) {
    Guard guard(field, options);
    std::size_t dropped = 0;
    std::erase_if(edits, [&](const ZeroLayerEdit& e) {
        if (guard.keep(e)) return false;
        ++dropped;
        return true;
    });
    const std::vector<PointIndex>& crack = guard.crack_points();
    if (crack.empty() && guard.deepened_points().empty()) return dropped;
    // Every crack point's edit, and every deepened point's, becomes kCrackEdit (added where the swarm
    // proposed none), in point order.
    std::unordered_set<PointIndex> filled(crack.begin(), crack.end());
    filled.insert(guard.deepened_points().begin(), guard.deepened_points().end());
    for (ZeroLayerEdit& e : edits)
        if (filled.erase(e.point)) e.delta = kCrackEdit;
    for (PointIndex i : filled) edits.push_back({i, kCrackEdit});
    std::sort(edits.begin(), edits.end(), [](const ZeroLayerEdit& a, const ZeroLayerEdit& b) { return a.point < b.point; });
    return dropped;
}

}  // namespace liveset
