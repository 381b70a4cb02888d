// Undo and redo of level-set edits for an interactive session. An action (a run of segmentation
// steps, a run of swarm steps, a seed placed) records, for every point of every X reported during
// it, the point's *first-touched* old φ and status (read from a shadow copy of the state at the
// start of the action), and when it closes the new φ and status of the same points. Undo writes the
// old states back through SparseField::restore, redo the new ones: bit-identical states, at a
// memory cost per action proportional to the points it changed (the shadow is one per session).
// Small session values that an action may change (the seeds, the threshold parameters, ...) are
// kept with it as SessionMarks.
#pragma once

#include <cstddef>
#include <deque>
#include <string>
#include <vector>

#include "liveset/levelset/sparse_field.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/threshold_speed.hpp"

namespace liveset {

// The session's small state that travels with undo/redo (everything but φ and status).
struct SessionMarks {
    std::vector<SeedBall> seeds;
    ThresholdParams params;
    bool window_from_seeds = true;  // µ, ε follow the seeds
    bool alpha_automatic = false;   // α and smooth_mm follow the image and the window (segment/alpha.hpp)
    bool pristine = true;           // φ is the union of the seed balls (no step taken since)
    int iterations = 0;             // segmentation steps taken
};

// An action's point states: elements left unset until written and arrays of 4 MiB or more on
// huge-page blocks (grid.hpp's allocator), so that the millions of states of a fine scan's run are
// first touched by the parallel passes that write them, a page fault per 2 MiB.
using StateList = std::vector<PointState, detail::GridAllocator<PointState>>;

// One undoable action.
struct EditAction {
    std::string label;
    StateList before, after;  // the same points, in the same order
    SessionMarks marks_before, marks_after;
    std::size_t bytes() const;
};

// What an undo or redo did: the points written back (X, for the mesher) and the marks to adopt.
struct HistoryStep {
    ChangedPoints changed;
    SessionMarks marks;
    std::string label;
};

class EditHistory {
public:
    // Keeps at most `limit` actions to undo (at least 1). The shadow copies `field`'s state.
    EditHistory(const SparseField& field, std::size_t limit);

    // Forgets every action and takes `field`'s state as the new starting point.
    void reset(const SparseField& field);

    bool action_open() const { return open_; }
    const std::string& open_label() const { return current_.label; }
    // Opens an action (none may be open: std::logic_error).
    void begin(std::string label, SessionMarks marks_before);
    // Records the first-touched old state of each point of X (an update within the open action).
    void record(const ChangedPoints& changed);
    // Records every point whose state differs from the shadow (after a whole-state replacement);
    // O(volume), over the lattice's planes in parallel. Returns them, as X for the mesher, with
    // the sign changes a mesher needs (ChangedPoints::sign_changes: those whose sign differs from
    // the shadow's, and every point recorded earlier in the action).
    ChangedPoints record_differences(const SparseField& field);
    // Closes the open action with the field's states and `marks_after`. An action that changed no
    // point and no mark is dropped. Returns true when an action was pushed (the redo list is then
    // cleared). Without an open action: false.
    bool commit(const SparseField& field, SessionMarks marks_after);

    bool can_undo() const { return !undo_.empty() && !open_; }
    bool can_redo() const { return !redo_.empty() && !open_; }
    std::size_t undo_depth() const { return undo_.size(); }
    std::size_t redo_depth() const { return redo_.size(); }
    const std::string& next_undo_label() const;
    const std::string& next_redo_label() const;
    std::size_t bytes() const;  // memory held by the recorded actions

    // Restores the last action's old states (redo: the next undone action's new states). Throws
    // std::logic_error while an action is open or when there is nothing to undo / redo.
    HistoryStep undo(SparseField& field);
    HistoryStep redo(SparseField& field);

private:
    void adopt(std::span<const PointState> states);  // shadow := states

    std::size_t limit_;
    Grid<float> shadow_phi_;
    Grid<std::int8_t> shadow_status_;  // kRecorded while a point's old state sits in current_.before
    bool open_ = false;
    EditAction current_;
    std::deque<EditAction> undo_;
    std::vector<EditAction> redo_;
};

}  // namespace liveset
