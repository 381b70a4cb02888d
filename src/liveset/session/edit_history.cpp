// EditHistory: per-action first-touched old states against a shadow of the level set.
#include "liveset/session/edit_history.hpp"

#include <tbb/parallel_for.h>

#include <bit>
#include <stdexcept>

#include "liveset/segment/voxel_loops.hpp"

namespace liveset {

namespace {

// Marks a shadow point whose old state is already in the open action's `before` list (a status
// no sparse field uses: its layers are within ±(kMaxLayers + 1)).
constexpr std::int8_t kRecorded = 127;

// A commit's recorded states in parts of at least kCommitGrain (voxel_loops::counted_writes).
constexpr std::size_t kCommitGrain = std::size_t{1} << 15;

bool same_marks(const SessionMarks& a, const SessionMarks& b) {
    if (a.seeds.size() != b.seeds.size()) return false;
    for (std::size_t i = 0; i < a.seeds.size(); ++i)
        if (!(a.seeds[i].center == b.seeds[i].center) || a.seeds[i].radius != b.seeds[i].radius) return false;
    return a.params.mu == b.params.mu && a.params.epsilon == b.params.epsilon && a.params.n == b.params.n &&
           a.params.alpha == b.params.alpha && a.params.smooth_mm == b.params.smooth_mm && a.window_from_seeds == b.window_from_seeds &&
           a.alpha_automatic == b.alpha_automatic && a.pristine == b.pristine &&
           a.iterations == b.iterations;
}

bool same_state(const PointState& a, const PointState& b) {
    return a.status == b.status && std::bit_cast<std::uint32_t>(a.phi) == std::bit_cast<std::uint32_t>(b.phi);
}

}  // namespace

std::size_t EditAction::bytes() const {
    return (before.capacity() + after.capacity()) * sizeof(PointState) +
           (marks_before.seeds.capacity() + marks_after.seeds.capacity()) * sizeof(SeedBall) + sizeof(EditAction);
}

EditHistory::EditHistory(const SparseField& field, std::size_t limit) : limit_(std::max<std::size_t>(limit, 1)) {
    reset(field);
}

void EditHistory::reset(const SparseField& field) {
    shadow_phi_ = field.phi();
    shadow_status_ = field.status();
    open_ = false;
    current_ = {};
    undo_.clear();
    redo_.clear();
}

void EditHistory::begin(std::string label, SessionMarks marks_before) {
    if (open_) throw std::logic_error("an action is already open");
    current_ = {};
    current_.label = std::move(label);
    current_.marks_before = std::move(marks_before);
    open_ = true;
}

void EditHistory::record(const ChangedPoints& changed) {
    if (!open_) throw std::logic_error("no action is open");
    for (PointIndex x : changed.points) {
        if (shadow_status_[x] == kRecorded) continue;
        current_.before.push_back({x, shadow_phi_[x], shadow_status_[x]});
        shadow_status_[x] = kRecorded;
    }
}

ChangedPoints EditHistory::record_differences(const SparseField& field) {
    if (!open_) throw std::logic_error("no action is open");
    const Grid<float>& phi = field.phi();
    const Grid<std::int8_t>& status = field.status();
    // The lattice's z-planes in parallel, twice: what each finds counted, then written at its
    // plane's offsets into lists of that exact size (no list grown point by point: a 0.5 mm
    // brain's switch from the coarse start lists 11 M points). Each point is its plane's alone,
    // its shadow mark too, and the marks are set only by the second pass, so both passes see the
    // same points: X, its sign changes and the old states in index order, on any thread count.
    const Vec3i d = phi.dims();
    const std::size_t plane = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y);
    const auto planes = static_cast<std::size_t>(d.z);
    struct Count {
        std::size_t points = 0, signs = 0, before = 0;
    };
    // f(i, recorded, sign) for every point the action has changed since the shadow: `recorded`
    // when changed earlier in this action (it may have changed again; its state before this change
    // is not the shadow's, and it is listed among the sign changes, harmlessly), else `sign` when
    // its sign differs from the shadow's.
    const auto scan = [&](std::size_t z, const auto& f) {
        for (std::size_t n = z * plane, end = n + plane; n < end; ++n) {
            const auto i = static_cast<PointIndex>(n);
            const std::int8_t old_status = shadow_status_[i];
            if (old_status == kRecorded) {
                f(i, true, true);
                continue;
            }
            const float old_phi = shadow_phi_[i];
            if (old_status == status[i] && std::bit_cast<std::uint32_t>(old_phi) == std::bit_cast<std::uint32_t>(phi[i])) continue;
            f(i, false, (old_phi < 0.0f) != (phi[i] < 0.0f));
        }
    };
    std::vector<Count> offset(planes + 1);
    tbb::parallel_for(std::size_t{0}, planes, [&](std::size_t z) {
        Count& c = offset[z + 1];
        scan(z, [&](PointIndex, bool recorded, bool sign) {
            ++c.points;
            c.signs += sign ? 1 : 0;
            c.before += recorded ? 0 : 1;
        });
    });
    offset[0].before = current_.before.size();  // appended to the states recorded so far
    for (std::size_t z = 0; z < planes; ++z) {
        offset[z + 1].points += offset[z].points;
        offset[z + 1].signs += offset[z].signs;
        offset[z + 1].before += offset[z].before;
    }
    ChangedPoints changed;
    changed.points.resize(offset[planes].points);
    std::vector<PointIndex> signs(offset[planes].signs);
    current_.before.resize(offset[planes].before);
    tbb::parallel_for(std::size_t{0}, planes, [&](std::size_t z) {
        Count at = offset[z];
        scan(z, [&](PointIndex i, bool recorded, bool sign) {
            changed.points[at.points++] = i;
            if (sign) signs[at.signs++] = i;
            if (recorded) return;
            current_.before[at.before++] = {i, shadow_phi_[i], shadow_status_[i]};
            shadow_status_[i] = kRecorded;
        });
    });
    // Every point whose sign may differ from what a mesher last meshed: those whose sign differs
    // from the shadow (the state the last update left, for a point not recorded in this action) and
    // every point recorded earlier in it.
    changed.sign_changes = std::move(signs);
    return changed;
}

bool EditHistory::commit(const SparseField& field, SessionMarks marks_after) {
    if (!open_) return false;
    open_ = false;
    EditAction action = std::move(current_);
    current_ = {};
    action.marks_after = std::move(marks_after);
    // New states; points that came back to their old state are left out. The recorded points are
    // distinct (each is recorded once per action), so fixed parts of the list can update their
    // shadow points in parallel: counted first, then written at each part's offset into lists of
    // the exact size, in the list's order on any thread count (a 0.5 mm brain's run records 11 M).
    const StateList& recorded = action.before;
    const auto now = [&](const PointState& b) { return PointState{b.point, field.phi()[b.point], field.status()[b.point]}; };
    StateList before;
    voxel_loops::counted_writes(
        recorded.size(), kCommitGrain, 0,
        [&](std::size_t b, std::size_t e) {
            std::size_t kept = 0;
            for (std::size_t k = b; k < e; ++k) kept += same_state(recorded[k], now(recorded[k])) ? 0 : 1;
            return kept;
        },
        [&](std::size_t total) {
            before.resize(total);
            action.after.resize(total);
        },
        [&](std::size_t b, std::size_t e, std::size_t at) {
            for (std::size_t k = b; k < e; ++k) {
                const PointState s = now(recorded[k]);
                shadow_phi_[s.point] = s.phi;
                shadow_status_[s.point] = s.status;
                if (same_state(recorded[k], s)) continue;
                before[at] = recorded[k];
                action.after[at] = s;
                ++at;
            }
        });
    action.before = std::move(before);
    if (action.before.empty() && same_marks(action.marks_before, action.marks_after)) return false;
    undo_.push_back(std::move(action));
    while (undo_.size() > limit_) undo_.pop_front();
    redo_.clear();
    return true;
}

const std::string& EditHistory::next_undo_label() const {
    static const std::string none;
    return undo_.empty() ? none : undo_.back().label;
}

const std::string& EditHistory::next_redo_label() const {
    static const std::string none;
    return redo_.empty() ? none : redo_.back().label;
}

std::size_t EditHistory::bytes() const {
    std::size_t n = 0;
    for (const EditAction& a : undo_) n += a.bytes();
    for (const EditAction& a : redo_) n += a.bytes();
    return n;
}

void EditHistory::adopt(std::span<const PointState> states) {
    for (const PointState& s : states) {
        shadow_phi_[s.point] = s.phi;
        shadow_status_[s.point] = s.status;
    }
}

HistoryStep EditHistory::undo(SparseField& field) {
    if (open_) throw std::logic_error("close the open action before undoing");
    if (undo_.empty()) throw std::logic_error("nothing to undo");
    EditAction action = std::move(undo_.back());
    undo_.pop_back();
    HistoryStep step{field.restore(action.before), action.marks_before, action.label};
    adopt(action.before);
    redo_.push_back(std::move(action));
    return step;
}

HistoryStep EditHistory::redo(SparseField& field) {
    if (open_) throw std::logic_error("close the open action before redoing");
    if (redo_.empty()) throw std::logic_error("nothing to redo");
    EditAction action = std::move(redo_.back());
    redo_.pop_back();
    HistoryStep step{field.restore(action.after), action.marks_after, action.label};
    adopt(action.after);
    undo_.push_back(std::move(action));
    return step;
}

}  // namespace liveset
