// The viewer's frame budget: how many segmentation or swarm steps a frame takes, how often the
// panes are redrawn while they run, and when the 3D pane may show its coarse level of detail.
//
// Background (the default): the steps run on a worker thread (viewer_background.cpp) and a frame
// comes on input or every `handover_ms`; the step counts below apply with `background` off.
// Steps: as many per frame as fit in `frame_ms` together with the upload of what they changed,
// judged from running averages of the measured step and upload costs (at least one step per
// frame, so work always advances). The budget decides only how many steps a frame takes, never
// which: the steps are Session's, one after another, as the CLI takes them.
// Redraws while running: the panes showing the changing surface are redrawn only once the time
// since their last redraw is (1 / draw_share - 1) times what that redraw cost, so drawing takes at
// most ~draw_share of the time (on a GPU that is every frame; on llvmpipe with a whole brain every
// second or two). Input is processed every frame regardless.
// Level of detail: when drawing the full surface costs more than `lod_above_ms` (software OpenGL
// with a whole brain; never on a GPU), the 3D pane draws the coarse surface (φ subsampled by
// `lod_factor`) while the user interacts (a drag, a wheel step, a click, a key) or a segmentation
// runs, and the full surface once nothing happened for `still_ms` (the swarm's repairs are small:
// they are shown at full quality, paced as above).
// Times are passed in (milliseconds on any steady clock), so the decisions are testable.
#pragma once

namespace liveset::viewer {

struct FrameBudgetOptions {
    double frame_ms = 30.0;     // steps + meshing + upload per frame
    double draw_share = 0.05;   // of the running time, at most, redrawing the changing panes
    double still_ms = 300.0;    // no input for this long: the 3D pane is drawn at full quality
    double lod_above_ms = 50.0; // full 3D draws cheaper than this: no level of detail
    int lod_factor = 3;         // the coarse surface's subsampling (about 1 / factor² of the triangles)
    // Running steps on a worker thread (SessionRunner): the render thread takes the changes (meshes,
    // uploads, redraws as paced above) at most every `handover_ms` while nothing else asks for a
    // frame. Off: the steps that fit in frame_ms are taken in each frame on the render thread.
    bool background = true;
    double handover_ms = 150.0;
    void validate() const;      // throws std::invalid_argument
};

class FrameBudget {
public:
    explicit FrameBudget(const FrameBudgetOptions& options = {});
    const FrameBudgetOptions& options() const { return options_; }

    // --- steps ----------------------------------------------------------------------------
    // Whether another step fits after `steps_taken` steps that took `elapsed_ms` this frame.
    bool another_step(int steps_taken, double elapsed_ms) const;
    void record_step(double ms);    // one step's cost (level set or swarm, with its meshing)
    void record_upload(double ms);  // one frame's upload of what changed (fine and coarse buffers)
    double step_ms() const { return step_ms_; }
    double upload_ms() const { return upload_ms_; }

    // --- redraws while running --------------------------------------------------------------
    // Whether the panes showing the running work are due a redraw at `now_ms`.
    bool redraw_due(double now_ms) const;
    void record_redraw(double now_ms, double cost_ms);  // they were redrawn; it cost cost_ms

    // --- level of detail --------------------------------------------------------------------
    void record_input(double now_ms) { last_input_ms_ = now_ms; has_input_ = true; }
    void record_full_draw(double ms);  // what a full-quality draw of the 3D pane cost
    // Whether the 3D pane should draw its coarse surface at `now_ms` (`busy`: a segmentation runs
    // or a drag is held).
    bool coarse(double now_ms, bool busy) const;

private:
    FrameBudgetOptions options_;
    double step_ms_ = 0.0, upload_ms_ = 0.0;
    bool step_known_ = false, upload_known_ = false;
    double last_redraw_ms_ = 0.0, redraw_cost_ms_ = 0.0;
    bool redrawn_ = false;
    double full_draw_ms_ = 0.0;
    bool full_draw_known_ = false;
    double last_input_ms_ = 0.0;
    bool has_input_ = false;
};

}  // namespace liveset::viewer
