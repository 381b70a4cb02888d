// One interactive editing session, shared by the viewer's window, its scripts and `liveset demo`:
// the image (raw and normalised to [0, 1]), the seeds, the threshold parameters, the sparse-field
// level set, the incremental fragment mesher, the threshold speed, the swarm repair loop and the
// undo/redo history. Every change of φ — seeds, segmentation steps, swarm steps, brush edits, undo
// and redo — goes through one private path, Session::edit, which records X in the history, meshes
// it, queues U for the renderer and bumps the revision once:
//
//   add_seed() / segment_step() / swarm_step() / edit_box() / undo() ...  ->  edit()  ->  X
//       ->  EditHistory::record  ->  FragmentMesher::update  ->  U  ->  take_dirty_fragments()
//
// (Loading a mask, φ or a recovery file replaces the state instead: it re-meshes everything and
// starts a new history.)
//
// With deferred meshing (set_deferred_meshing, what a background run uses: session_runner.hpp), an
// edit still records X in the history at once but only accumulates it for the mesher; flush_mesh()
// (or take_dirty_fragments()) meshes the union later, at the renderer's pace. φ is the same either way.
//
// Standard library + oneTBB only (no GL, no ITK). Not thread-safe: one thread drives a session at a
// time (SessionRunner hands it between a worker and the renderer under a mutex).
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/segment/alpha.hpp"
#include "liveset/segment/coarse_start.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/threshold_speed.hpp"
#include "liveset/segment/window.hpp"
#include "liveset/session/edit_history.hpp"
#include "liveset/swarm/repair.hpp"
#include "liveset/swarm/repair_schedule.hpp"

namespace liveset {

struct SessionOptions {
    int layers = 2;               // sparse-field layers N
    int fragment_size = 16;       // cells per mesh fragment edge (one GPU buffer each)
    std::size_t history = 32;     // undoable actions kept (at least 20)
    ScaleOptions scale;           // intensity normalisation
    // The normalisation to use instead of robust_scale(image, roi, scale): a segmentation's, so a
    // session continuing it sees the same [0, 1] image.
    std::optional<IntensityScale> given_scale;
    WindowOptions window;         // how µ, ε are estimated from the seeds (as `liveset segment`)
    // Where the tissue model is fitted, as SegmentRequest::model_region (the front ends pass the
    // brain mask they found before bias correction, as `segment` does); none: the ROI, else the
    // automatic brain mask of the image, else its foreground. Same dimensions as the image.
    std::optional<Grid<std::uint8_t>> model_region;
    bool model_region_is_brain = false;  // as SegmentRequest::model_region_is_brain
    bool model_region_grey_brighter = false;  // as SegmentRequest::model_region_grey_brighter
    BrainMaskOptions brain_mask;         // as SegmentRequest::brain_mask (also the hole finder's, HoleScanOptions)
    // Convergence window/tolerance and the step; max_iterations bounds only the coarse start's run
    // (as `segment`'s), a session's own steps are counted by its caller.
    SegmentationOptions segmentation;
    // The coarse-to-fine start from seeds (coarse_start.hpp), as `liveset segment --coarse-start`:
    // on a fine grid (auto: every voxel side at most 0.85 mm) the first segment_step()s run the front
    // from the seeds to convergence on 2x2x2 blocks, one coarse iteration each, and the step that
    // ends that run replaces the seeds with its front upsampled (and the seeds' balls): then the
    // steps go on on the image's grid, bit for bit as segment_image's fine run.
    CoarseStart coarse_start = CoarseStart::kAuto;
    RepairOptions repair;              // swarm settings (steps unused: the caller steps)
    ThresholdParams params;            // initial n and α (µ, ε too when there are no seeds)
    // α and the pre-smoothing chosen as `liveset segment` chooses them (segment/alpha.hpp) instead
    // of params.alpha and params.smooth_mm - once there is a window (a seed, set_params, or the
    // first step) - and re-chosen whenever the window changes, until set_params sets them itself.
    bool alpha_automatic = false;
};

// What one call changed, for the renderer and the status line.
struct SessionUpdate {
    ChangedPoints changed;              // X
    std::vector<FragmentId> fragments;  // U: fragments the mesher rebuilt (sorted)
    double level_set_ms = 0.0;          // sparse-field update (step, edits, restore, re-init)
    double agents_ms = 0.0;             // swarm move and edit proposals
    double mesh_ms = 0.0;               // incremental marching cubes
    RepairStepLog swarm;                // a swarm step's log (fragments = |U|); zeros otherwise
};

struct SegmentStatus {
    int iterations = 0;        // steps taken on the image's grid since the level set was (re)initialised
    bool coarse = false;       // the last step was one of the coarse start's (SessionOptions::coarse_start)
    int coarse_iterations = 0; // the coarse start's iterations so far (kept after its front was upsampled)
    std::size_t coarse_inside = 0;  // its inside points (2x2x2 blocks) after its last iteration
    bool converged = false;    // the last step met the convergence rule
    bool vanished = false;     // no zero layer left (nothing to evolve)
    std::size_t flips = 0;     // points that changed side in the last step
    std::size_t inside = 0;    // inside points after the last step
    double dt = 0.0;
};

class Session {
public:
    // `image` raw intensities; `roi` (optional, same dimensions) bounds the front and the output
    // mask. The level set starts empty (no surface): add seeds or load a mask / φ.
    // Throws std::invalid_argument on bad options, a flat image or a ROI of other dimensions.
    Session(Grid<float> image, const SessionOptions& options, std::optional<Grid<std::uint8_t>> roi = {});
    Session(const Session&) = delete;
    Session& operator=(const Session&) = delete;

    // --- data -------------------------------------------------------------------------------
    const Lattice& lattice() const { return image_.lattice(); }
    const Grid<float>& image() const { return image_; }
    const Grid<float>& unit_image() const { return unit_; }
    // The image the threshold term reads: unit_image() blurred by params().smooth_mm (the same
    // values the speed tabulates; computed on first use for each σ). For the slice preview.
    const Grid<float>& speed_image() const;
    const IntensityScale& scale() const { return scale_; }
    const Grid<std::uint8_t>* roi() const { return roi_ ? &*roi_ : nullptr; }
    // Where tissue_model() is fitted, for sheet_window and scan_holes (the hole finder reads the
    // sheet's band from the region the session's window came from); its region points into this
    // session's options.
    SheetFit sheet_fit() const;
    const SparseField& field() const { return field_; }
    const FragmentMesher& mesher() const { return mesher_; }
    bool has_surface() const { return !field_.zero_layer().empty(); }

    // --- initial level set (each clears the history) ----------------------------------------
    void load_mask(const Grid<std::uint8_t>& mask);  // non-zero inside; same dimensions
    void load_phi(const Grid<float>& phi);           // < 0 inside, any scale; same dimensions
    // φ, status and the small state saved in a recovery file (seeds, parameters, iterations).
    // Returns true when the sparse field was restored bit for bit; false when the saved status was
    // not a consistent sparse field and φ's signs were used instead (as load_phi). Throws
    // std::invalid_argument (changing nothing) on other dimensions, seeds outside, bad parameters.
    // With no iteration recorded and φ's inside the union of the seeds' balls, the session is as
    // before its first step again (its next step the coarse start's where that applies).
    bool load_recovered(const Grid<float>& phi, const Grid<std::int8_t>& status, const SessionMarks& marks);

    // --- seeds (undoable) -------------------------------------------------------------------
    const std::vector<SeedBall>& seeds() const { return marks_.seeds; }
    // Adds a seed ball (index space; centre inside the image and, with a ROI, a voxel of it in the ROI) and
    // unites it with the level set. Throws std::invalid_argument (changing nothing) otherwise.
    SessionUpdate add_seed(SeedBall seed);
    // Throws std::invalid_argument when no voxel of the seed's ball lies in the ROI (none: no-op).
    void check_seed_in_roi(const SeedBall& seed) const;
    // Removes seed `index`. While the level set is still the union of the seeds (no step taken
    // since), it is re-initialised from the remaining ones; later, only the list (and the window
    // estimate) changes - undo takes back grown regions.
    SessionUpdate remove_seed(std::size_t index);
    // The seed whose ball contains `p` (or lies within `tolerance` voxels of it), nearest first.
    std::optional<std::size_t> seed_at(Vec3d p, double tolerance = 1.0) const;

    // --- threshold speed (Eq. 2-3; µ, ε in normalised units) --------------------------------
    const ThresholdParams& params() const { return marks_.params; }
    bool window_from_seeds() const { return marks_.window_from_seeds; }
    bool alpha_automatic() const { return marks_.alpha_automatic; }
    // Sets n and, unless `window_from_seeds`, µ and ε (then estimated from the seeds as
    // `liveset segment` does: the tissue model's window for the seeds' class, window.hpp), and,
    // unless `alpha_automatic`, α and the smoothing σ (then chosen as `liveset segment` chooses
    // them for that window, and again whenever the seeds move the window). Throws std::invalid_argument.
    void set_params(const ThresholdParams& params, bool window_from_seeds, bool alpha_automatic = false);
    // The α `liveset segment` would choose for the current window, with its reasons.
    AlphaChoice automatic_alpha_choice() const { return alpha_choice_for(marks_.params, marks_.window_from_seeds); }
    // The window the seeds give (nullopt without seeds).
    std::optional<ThresholdParams> estimated_window() const;
    // The same with where it came from and its warnings (nullopt without seeds).
    std::optional<WindowEstimate> window_estimate() const;
    // The tissue model of the image (inside the ROI, else its foreground), fitted on first use.
    const std::optional<TissueModel>& tissue_model() const;

    // --- segmentation -----------------------------------------------------------------------
    // One global sparse-field step of the threshold speed; consecutive steps form one action. While
    // the level set is still the union of the seeds and the coarse start applies, one iteration of
    // the coarse start's run instead (X empty: φ is not touched), and at its end the seeds are
    // replaced by its fine start (CoarseRun::fine_start; X: every point that changed). A change of the seeds, the
    // parameters, the step or φ meanwhile (not of the swarm's target or options) begins that run
    // again on the next step.
    SessionUpdate segment_step();
    const SegmentStatus& segment_status() const { return segment_; }
    // The coarse start's front while its run is under way (begun and still current: nothing it
    // reads changed since), on coarse_lattice(lattice()); null otherwise. What a viewer previews
    // (upsampled_phi) while φ is still the seeds. Valid until the session's next step or edit.
    const SparseField* coarse_field() const;
    // Coarse iterations this session has taken (never reset): while coarse_field() is the same
    // run, an unchanged count means an unchanged coarse front.
    std::uint64_t coarse_serial() const { return coarse_serial_; }

    // --- swarm repair -----------------------------------------------------------------------
    const RepairOptions& repair_options() const { return repair_options_; }
    const SessionOptions& options() const { return options_; }
    // The global step from the next one on (a recovery file's, restored: StepOptions as `liveset
    // view --step` builds them). Throws std::invalid_argument (changing nothing) on invalid options.
    void set_step(const StepOptions& step);
    // The coarse start from seeds from the next step on (a recovery file's or a workspace's,
    // restored before the first step): SessionOptions::coarse_start; a coarse run under way begins again.
    void set_coarse_start(CoarseStart mode);
    // The sleeping step's memory, saved with φ and the statuses (a workspace) so that a continued
    // session steps bit for bit as the uninterrupted one; restore it after load_recovered().
    ActivitySnapshot activity_snapshot() const { return field_.activity_snapshot(speed_ ? speed_->serial() : 0); }
    void restore_activity(const ActivitySnapshot& snapshot) { field_.restore_activity(snapshot); }
    // New swarm settings (agents, p, radius, ...): the swarm is re-created and, when it had a
    // target, respawned there. Throws std::invalid_argument on invalid options.
    void set_repair_options(const RepairOptions& options);
    // Aims the swarm at `target` (index space). The first target, or one farther than the
    // options' respawn distance from the swarm (a click elsewhere), spawns it on the surface there.
    // Throws std::invalid_argument outside the image or with no surface near a spawn point.
    void set_target(Vec3d target);
    void clear_target();
    const std::optional<Vec3d>& target() const { return target_; }
    // The zero-layer point nearest `p` within `radius` voxels (nullopt: none).
    std::optional<Vec3d> nearest_surface_point(Vec3d p, double radius) const;
    // A fresh swarm with `options` (the session's swarm settings from now on), spawned on the
    // surface nearest `target` and aimed there: a repair round of a schedule. Throws
    // std::invalid_argument like set_repair_options and set_target.
    void aim_swarm(const RepairOptions& options, Vec3d target);
    // One swarm step (move, edits, local level-set update); consecutive steps form one action.
    // A no-op without a target.
    SessionUpdate swarm_step();
    const std::vector<Agent>& agents() const;

    // --- brush --------------------------------------------------------------------------------
    // A local edit of the zero-layer points in the box [lo, hi] (SparseField::apply_in_box:
    // delta(p, φ(p)) is each point's Δ); its own undoable action.
    SessionUpdate edit_box(Vec3i lo, Vec3i hi, const std::function<float(Vec3i, float)>& delta);

    // --- history ----------------------------------------------------------------------------
    // Closes the open action (a run paused, a script entry done, another kind of edit begins).
    void end_action();
    bool can_undo() const { return history_.undo_depth() > 0; }
    bool can_redo() const { return history_.redo_depth() > 0; }
    std::size_t undo_depth() const { return history_.undo_depth(); }
    std::size_t redo_depth() const { return history_.redo_depth(); }
    std::string next_undo_label() const { return history_.next_undo_label(); }
    std::string next_redo_label() const { return history_.next_redo_label(); }
    std::size_t history_bytes() const { return history_.bytes(); }
    // Forgets every undoable action (the set-up of a session - what was loaded, the start
    // parameters - cannot be undone into hard-coded defaults). φ, seeds and parameters stay.
    void clear_history();
    // Each closes the open action first; a no-op (empty update) when there is nothing to undo/redo.
    SessionUpdate undo();
    SessionUpdate redo();

    // The seeds, parameters and iteration count (what a recovery file keeps besides φ).
    const SessionMarks& marks() const { return marks_; }

    // --- renderer feed ----------------------------------------------------------------------
    // Fragments rebuilt since the last call (sorted, unique): the buffers to re-upload. Meshes the
    // accumulated X first (flush_mesh).
    std::vector<FragmentId> take_dirty_fragments();
    // Deferred meshing: while on, edits accumulate X (deduplicated) instead of meshing it (their
    // SessionUpdate lists no fragments); turning it off meshes what is pending. mesher() is up to
    // date only after flush_mesh().
    void set_deferred_meshing(bool on);
    bool deferred_meshing() const { return defer_mesh_; }
    // Meshes the accumulated X and queues the rebuilt fragments; returns the meshing's ms (0: none).
    double flush_mesh();
    std::size_t pending_mesh_points() const { return pending_.size(); }
    // Counts every change of φ, the seeds, the target or the agents (for redraw decisions).
    std::uint64_t revision() const { return revision_; }

    // --- outputs ----------------------------------------------------------------------------
    Grid<std::uint8_t> mask() const;  // φ < 0 within the ROI
    Mesh surface_mesh() const;        // marching cubes of the zero layer (index space)

private:
    // What an edit's change did: X (or the whole state replaced, X found by comparison), and the
    // time of its level-set part (< 0: the change's wall time) and of its agents.
    struct Change {
        ChangedPoints changed;
        bool whole_state = false;
        double level_set_ms = -1.0;
        double agents_ms = 0.0;
        RepairStepLog swarm{};  // a swarm step's log
    };
    // kOwn: an action of its own (seed, brush); kContinued: steps continue an open action of the
    // same label (segmentation, swarm); kHistory: undo/redo (the history itself wrote the states).
    enum class Action { kOwn, kContinued, kHistory };
    // The one edit path: opens or continues the history action, runs `change`, records its X,
    // meshes it, queues the rebuilt fragments and bumps the revision once.
    SessionUpdate edit(const char* label, Action action, const std::function<Change()>& change);
    void begin_action(const char* label);  // continues an open action of the same label
    SessionUpdate finish_update(ChangedPoints changed, double level_set_ms);
    void queue_dirty(const std::vector<FragmentId>& fragments);
    void clear_pending_flags();  // every pending point's flags cleared (pending_ holds each point once)
    void adopt_marks(const SessionMarks& marks);
    void reset_after_load();
    void refresh_window();
    AlphaChoice alpha_choice_for(const ThresholdParams& params, bool window_from_seeds) const;
    void make_repair_loop();
    void ensure_speed();
    bool coarse_start_due() const;
    // coarse_ exists and was begun on the inputs and the speed the session has now.
    bool coarse_run_current() const;
    SessionUpdate coarse_step();

    SessionOptions options_;
    Grid<float> image_;
    std::optional<Grid<std::uint8_t>> roi_;
    IntensityScale scale_;
    Grid<float> unit_;
    SparseField field_;
    FragmentMesher mesher_;
    SessionMarks marks_;
    std::unique_ptr<ThresholdSpeed> speed_;  // for marks_.params; rebuilt lazily
    std::unique_ptr<CoarseRun> coarse_;      // the coarse start's run in progress (it holds *speed_ for its fine start)
    std::uint64_t coarse_speed_ = 0;         // speed_'s serial when coarse_ was begun: another speed begins it again
    // Changes of what a coarse run reads - φ and the seeds (every edit, undo and redo), the
    // parameters, a load - counted; coarse_ begun at another count is begun again (set_step drops it).
    std::uint64_t inputs_ = 0;
    std::uint64_t coarse_inputs_ = 0;        // inputs_ when coarse_ was begun
    std::uint64_t coarse_serial_ = 0;        // coarse_serial()
    mutable std::optional<std::optional<TissueModel>> model_;  // fitted lazily (inner nullopt: failed)
    mutable std::optional<std::pair<double, Grid<float>>> smoothed_;  // speed_image()'s σ and values
    std::optional<FrontConvergence> convergence_;
    SegmentStatus segment_;
    RepairOptions repair_options_;
    std::unique_ptr<RepairLoop> repair_;
    std::optional<Vec3d> target_;
    EditHistory history_;
    std::vector<std::uint8_t> dirty_flags_;
    std::vector<FragmentId> dirty_;
    bool defer_mesh_ = false;
    UninitVector<PointIndex> pending_;          // X accumulated while meshing is deferred
    Grid<std::uint8_t> pending_flags_;          // lattice-sized while deferring: bit 0 in pending_, bit 1 in pending_signs_
    UninitVector<PointIndex> pending_signs_;    // the union of their sign changes (a subset of pending_)...
    bool pending_signs_known_ = true;           // ...while every update with points reported them
    std::uint64_t revision_ = 0;
};

// A repair schedule (swarm/repair_schedule.hpp) run through a session: each round aims a fresh
// swarm (Session::aim_swarm) and every step goes through the session's edit path (history, mesher).
class SessionRepairDriver : public RepairDriver {
public:
    explicit SessionRepairDriver(Session& session) : session_(session) {}
    const SparseField& field() const override { return session_.field(); }
    void aim(const RepairOptions& options, Vec3d target) override { session_.aim_swarm(options, target); }
    RepairStepLog step() override { return session_.swarm_step().swarm; }

private:
    Session& session_;
};

}  // namespace liveset
