// EditHistory: per-action first-touched old states against a shadow of the level set.
#include "liveset/session/edit_history.hpp"

#include <tbb/parallel_for.h>

#include <bit>
#include <stdexcept>

namespace liveset {

namespace {

// Marks a shadow point whose old state is already in the open action's `before` list (a status
// no sparse field uses: its layers are within ±(kMaxLayers + 1)).
constexpr std::int8_t kRecorded = 127;

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
    // The lattice's z-planes in parallel (each point is its plane's alone: its shadow mark too),
    // each into its own lists, joined in plane order: X, its sign changes and the old states in
    // index order, as one pass would give them, on any thread count.
    const Vec3i d = phi.dims();
    const std::size_t plane = static_cast<std::size_t>(d.x) * static_cast<std::size_t>(d.y);
    struct Found {
        std::vector<PointIndex> points, signs;
        std::vector<PointState> before;
    };
    std::vector<Found> found(static_cast<std::size_t>(d.z));
    tbb::parallel_for(0, d.z, [&](int z) {
        Found& f = found[static_cast<std::size_t>(z)];
        for (std::size_t n = static_cast<std::size_t>(z) * plane, end = n + plane; n < end; ++n) {
            const auto i = static_cast<PointIndex>(n);
            const std::int8_t old_status = shadow_status_[i];
            if (old_status == kRecorded) {  // changed earlier in this action: may have changed again
                f.points.push_back(i);
                f.signs.push_back(i);  // its state before this change is not the shadow's: listed (harmless)
                continue;
            }
            const float old_phi = shadow_phi_[i];
            if (old_status == status[i] && std::bit_cast<std::uint32_t>(old_phi) == std::bit_cast<std::uint32_t>(phi[i])) continue;
            f.points.push_back(i);
            if ((old_phi < 0.0f) != (phi[i] < 0.0f)) f.signs.push_back(i);
            f.before.push_back({i, old_phi, old_status});
            shadow_status_[i] = kRecorded;
        }
    });
    ChangedPoints changed;
    std::vector<PointIndex> signs;
    std::size_t n_points = 0, n_signs = 0, n_before = 0;
    for (const Found& f : found) {
        n_points += f.points.size();
        n_signs += f.signs.size();
        n_before += f.before.size();
    }
    changed.points.reserve(n_points);
    signs.reserve(n_signs);
    current_.before.reserve(current_.before.size() + n_before);
    for (const Found& f : found) {
        changed.points.insert(changed.points.end(), f.points.begin(), f.points.end());
        signs.insert(signs.end(), f.signs.begin(), f.signs.end());
        current_.before.insert(current_.before.end(), f.before.begin(), f.before.end());
    }
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
    // New states; points that came back to their old state are left out.
    std::vector<PointState> before;
    before.reserve(action.before.size());
    action.after.reserve(action.before.size());
    for (const PointState& b : action.before) {
        const PointState now{b.point, field.phi()[b.point], field.status()[b.point]};
        shadow_phi_[b.point] = now.phi;
        shadow_status_[b.point] = now.status;
        if (same_state(b, now)) continue;
        before.push_back(b);
        action.after.push_back(now);
    }
    action.before = std::move(before);
    action.before.shrink_to_fit();
    action.after.shrink_to_fit();
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
