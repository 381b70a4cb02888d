// Session: every change of φ goes through Session::edit, then to the history and the mesher.
#include "liveset/session/session.hpp"

#include <algorithm>
#include <bit>
#include <chrono>
#include <cmath>
#include <functional>
#include <limits>
#include <stdexcept>

#include "liveset/levelset/invariants.hpp"
#include "liveset/levelset/shapes.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/segment/pipeline.hpp"
#include "liveset/segment/smoothing.hpp"
#include "liveset/segment/voxel_loops.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset {

namespace {

using Clock = std::chrono::steady_clock;

// The automatic regularisation's two values (segment/alpha.hpp), as segment_image takes them.
void take_automatic(ThresholdParams& p, const AlphaChoice& a) {
    p.alpha = a.alpha;
    p.smooth_mm = a.smooth_mm;
}

const SessionOptions& checked(const SessionOptions& o) {
    if (o.history < 20) throw std::invalid_argument("the undo history must keep at least 20 actions");
    o.window.validate();
    validate(o.segmentation);
    validate(o.repair);
    validate(o.params);
    return o;
}

// Appends to `list` the points of `add` whose flag `bit` is clear, setting it: X joined into the
// points deferred for the mesher, each once, in order. A strictly increasing `add` of many points
// (a whole-state change: the coarse start's end lists 11 M at 0.5 mm) by parts in parallel
// (voxel_loops::counted_writes; its points are distinct, so each flag is one part's); any other
// one point by point.
void append_unflagged(UninitVector<PointIndex>& list, Grid<std::uint8_t>& flags, std::span<const PointIndex> add, std::uint8_t bit) {
    constexpr std::size_t kGrain = std::size_t{1} << 15;
    if (add.size() < 2 * kGrain || std::adjacent_find(add.begin(), add.end(), std::greater_equal<>()) != add.end()) {
        for (PointIndex p : add)
            if (!(flags[p] & bit)) {
                list.push_back(p);
                flags[p] |= bit;
            }
        return;
    }
    voxel_loops::counted_writes(
        add.size(), kGrain, list.size(),
        [&](std::size_t b, std::size_t e) {
            std::size_t n = 0;
            for (std::size_t k = b; k < e; ++k) n += (flags[add[k]] & bit) ? 0 : 1;
            return n;
        },
        [&](std::size_t total) { list.resize(total); },
        [&](std::size_t b, std::size_t e, std::size_t at) {
            for (std::size_t k = b; k < e; ++k)
                if (!(flags[add[k]] & bit)) {
                    list[at++] = add[k];
                    flags[add[k]] |= bit;
                }
        });
}

// Whether `field` is the union of the seeds' balls as add_seed and init_from_seeds make it: φ's
// inside theirs point for point, and every zero-layer value their distance's, bit for bit (the
// outer layers are a function of those). A recovered session that took no step since its seeds is
// then pristine again (a recovery file does not keep the flag), so that its first step is the
// coarse start's, as it would have been, and removing a seed re-initialises from the others; an
// edit of the zero layer that changed no sign (a brush, the swarm) is told apart by its values.
// Where overlapping balls' rounding differs it says no: the session then steps as before 81.
bool is_seed_union(const SparseField& field, const std::vector<SeedBall>& seeds) {
    if (seeds.empty()) return false;
    std::vector<shapes::Sphere> balls;
    for (const SeedBall& s : seeds) balls.emplace_back(s.center, std::max(s.radius, 0.5));
    const shapes::SeedSpheres sdf(field.lattice(), std::move(balls));
    const Lattice& lattice = field.lattice();
    const Grid<float>& phi = field.phi();
    const auto distance = [&](PointIndex p) { return static_cast<float>(sdf(lattice.coord(p).cast<double>())); };
    const std::span<const PointIndex> zero = field.zero_layer();
    return voxel_loops::count_if(zero.size(), [&](std::size_t k) {
               return std::bit_cast<std::uint32_t>(phi[zero[k]]) != std::bit_cast<std::uint32_t>(distance(zero[k]));
           }) == 0 &&
           voxel_loops::count_if(phi.size(), [&](std::size_t i) {
               const auto p = static_cast<PointIndex>(i);
               return (phi[p] < 0.0f) != (distance(p) < 0.0f);
           }) == 0;
}

}  // namespace

Session::Session(Grid<float> image, const SessionOptions& options, std::optional<Grid<std::uint8_t>> roi)
    : options_(checked(options)),
      image_(std::move(image)),
      roi_(std::move(roi)),
      scale_(options.given_scale ? *options.given_scale : robust_scale(image_, roi_ ? &*roi_ : nullptr, options.scale)),
      unit_(normalise(image_, scale_)),
      field_(image_.lattice(), options.layers),
      mesher_(image_.lattice(), options.fragment_size),
      repair_options_(options.repair),
      history_(field_, options.history) {
    if (options_.model_region && !(options_.model_region->dims() == image_.dims()))
        throw std::invalid_argument("the tissue model's region differs in size from the image");
    marks_.params = options.params;
    marks_.alpha_automatic = options.alpha_automatic;  // α chosen once there is a window (fitting the model takes seconds)
    mesher_.full_rebuild(field_.phi(), field_.zero_layer());
    dirty_flags_.assign(mesher_.fragment_count(), 0);
}

// ---------------------------------------------------------------------------------------------
// Initial level set

void Session::load_mask(const Grid<std::uint8_t>& mask) {
    if (!(mask.dims() == lattice().dims())) throw std::invalid_argument("the mask's size differs from the image's");
    field_.init_from_mask(mask);
    reset_after_load();
}

void Session::load_phi(const Grid<float>& phi) {
    if (!(phi.dims() == lattice().dims())) throw std::invalid_argument("phi's size differs from the image's");
    field_.init_from_sdf([&](Vec3d p) {
        const Vec3i q{static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y)), static_cast<int>(std::lround(p.z))};
        return static_cast<double>(phi(q));
    });
    reset_after_load();
}

bool Session::load_recovered(const Grid<float>& phi, const Grid<std::int8_t>& status, const SessionMarks& marks) {
    if (!(phi.dims() == lattice().dims()) || !(status.dims() == lattice().dims()))
        throw std::invalid_argument("the recovered level set's size differs from the image's");
    for (const SeedBall& b : marks.seeds)
        if (!lattice().contains(b.center)) throw std::invalid_argument("a recovered seed lies outside the image");
    validate(marks.params);
    // Write back every point that differs from the current state: the saved state, bit for bit.
    std::vector<PointState> states;
    const auto& cur_phi = field_.phi();
    const auto& cur_status = field_.status();
    for (std::size_t i = 0; i < phi.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if (std::bit_cast<std::uint32_t>(phi[p]) != std::bit_cast<std::uint32_t>(cur_phi[p]) || status[p] != cur_status[p])
            states.push_back({p, phi[p], status[p]});
    }
    bool exact = false;
    try {
        field_.restore(states);
        exact = check_invariants(field_).ok();
    } catch (const std::invalid_argument&) {
    }
    if (exact)
        reset_after_load();
    else
        load_phi(phi);
    SessionMarks m = marks;
    m.pristine = marks.iterations == 0 && is_seed_union(field_, marks.seeds);
    adopt_marks(m);
    return exact;
}

void Session::reset_after_load() {
    clear_pending_flags();  // the full rebuild covers them
    pending_.clear();
    pending_signs_.clear();
    pending_signs_known_ = true;
    mesher_.full_rebuild(field_.phi(), field_.zero_layer());
    for (FragmentId f = 0; f < mesher_.fragment_count(); ++f)
        if (!dirty_flags_[f]) {
            dirty_flags_[f] = 1;
            dirty_.push_back(f);
        }
    history_.reset(field_);
    marks_.pristine = false;
    marks_.iterations = 0;
    segment_ = {};
    convergence_.reset();
    repair_.reset();
    target_.reset();
    ++revision_;
    ++inputs_;
}

// ---------------------------------------------------------------------------------------------
// Seeds and parameters

SessionUpdate Session::add_seed(SeedBall seed) {
    if (!all_finite(seed.center) || !lattice().contains(seed.center))
        throw std::invalid_argument("a seed lies outside the image");
    if (!std::isfinite(seed.radius) || seed.radius <= 0) throw std::invalid_argument("a seed's radius must be positive");
    check_seed_in_roi(seed);
    return edit("seed", Action::kOwn, [&] {
        // Union with the ball, min(φ, distance to the ball), re-initialised only around it: beyond
        // N + 1 voxels from the ball the distance cannot undercut φ.
        const shapes::Sphere ball(seed.center, std::max(seed.radius, 0.5));
        const double reach = ball.radius + field_.layers() + 1.0;
        const Vec3d lo = seed.center - Vec3d{reach, reach, reach}, hi = seed.center + Vec3d{reach, reach, reach};
        ChangedPoints changed = field_.unite_in_box(
            {static_cast<int>(std::floor(lo.x)), static_cast<int>(std::floor(lo.y)), static_cast<int>(std::floor(lo.z))},
            {static_cast<int>(std::ceil(hi.x)), static_cast<int>(std::ceil(hi.y)), static_cast<int>(std::ceil(hi.z))}, ball);
        marks_.seeds.push_back(seed);
        refresh_window();
        return Change{std::move(changed)};
    });
}

SessionUpdate Session::remove_seed(std::size_t index) {
    if (index >= marks_.seeds.size()) throw std::invalid_argument("no such seed");
    return edit("remove seed", Action::kOwn, [&] {
        marks_.seeds.erase(marks_.seeds.begin() + static_cast<std::ptrdiff_t>(index));
        refresh_window();
        if (!marks_.pristine) return Change{};  // grown regions stay: only the list changes
        if (marks_.seeds.empty()) {
            const double far = field_.layers() + 1.0;
            field_.init_from_sdf([far](Vec3d) { return far; }, {0, 0, 0}, {0, 0, 0});  // far everywhere: no front
        } else {
            init_from_seeds(field_, marks_.seeds);
        }
        return Change{{}, true};
    });
}

void Session::check_seed_in_roi(const SeedBall& seed) const {
    if (!roi_) return;
    const Vec3i c{static_cast<int>(std::lround(seed.center.x)), static_cast<int>(std::lround(seed.center.y)),
                  static_cast<int>(std::lround(seed.center.z))};
    if (ball_touches(*roi_, seed)) return;  // a seed astride the ROI's edge is clipped, as `segment` clips it
    throw std::invalid_argument("the seed at (" + std::to_string(c.x) + ", " + std::to_string(c.y) + ", " + std::to_string(c.z) +
                                ") lies outside the region of interest (the front may not grow there)");
}

std::optional<std::size_t> Session::seed_at(Vec3d p, double tolerance) const {
    std::optional<std::size_t> best;
    double best_gap = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < marks_.seeds.size(); ++i) {
        const double gap = norm(p - marks_.seeds[i].center) - marks_.seeds[i].radius;
        if (gap <= tolerance && gap < best_gap) {
            best_gap = gap;
            best = i;
        }
    }
    return best;
}

const Grid<float>& Session::speed_image() const {
    const double sigma = marks_.params.smooth_mm;
    if (sigma <= 0.0) return unit_;
    if (!smoothed_ || smoothed_->first != sigma) smoothed_.emplace(sigma, gaussian_smooth(unit_, sigma));
    return smoothed_->second;
}

SheetFit Session::sheet_fit() const {
    return {options_.model_region ? &*options_.model_region : nullptr, options_.model_region_is_brain, options_.model_region_grey_brighter,
            options_.brain_mask};
}

const std::optional<TissueModel>& Session::tissue_model() const {
    if (!model_) {
        std::vector<std::string> ignored;  // window_estimate() reports an unusable model
        const SheetFit f = sheet_fit();
        bool automatic = false;
        const Grid<std::uint8_t> fit = model_region(image_, f.region, roi(), options_.window.model.classes, &automatic, f.brain);
        model_ = fit_window_model(image_, fit, options_.window.model, ignored, automatic || f.region_is_brain, f.known_grey_brighter);
    }
    return *model_;
}

std::optional<WindowEstimate> Session::window_estimate() const {
    if (marks_.seeds.empty()) return std::nullopt;
    try {
        const auto& model = tissue_model();
        return estimate_window(image_, scale_, marks_.seeds, roi(), model ? &*model : nullptr, options_.window);
    } catch (const std::invalid_argument&) {
        return std::nullopt;  // e.g. no seed voxel inside the ROI
    }
}

std::optional<ThresholdParams> Session::estimated_window() const {
    const std::optional<WindowEstimate> w = window_estimate();
    if (!w) return std::nullopt;
    ThresholdParams p = marks_.params;
    p.mu = std::clamp(w->mu, 0.0, 1.0);
    p.epsilon = w->epsilon;
    return p;
}

void Session::refresh_window() {
    if (!marks_.window_from_seeds) return;
    if (const auto p = estimated_window()) {
        marks_.params.mu = p->mu;
        marks_.params.epsilon = p->epsilon;
    }
    if (marks_.alpha_automatic) take_automatic(marks_.params, alpha_choice_for(marks_.params, true));
    speed_.reset();
    segment_.converged = false;
}

AlphaChoice Session::alpha_choice_for(const ThresholdParams& params, bool window_from_seeds) const {
    // As the pipeline (segment/pipeline.cpp): the seeds' class when the window is theirs, else the
    // class nearest the window's centre; without seeds no model (the pipeline fits it from seeds
    // only: `segment --init-mask` takes the fallback).
    if (marks_.seeds.empty()) return automatic_alpha(nullptr, scale_.to_raw(params.mu), lattice().spacing_float());
    const std::optional<WindowEstimate> w = window_from_seeds ? window_estimate() : std::nullopt;
    const int window_class = w && w->model_window ? w->model_window->seed_class : -1;
    const std::optional<TissueModel>& model = tissue_model();
    return automatic_alpha(model ? &*model : nullptr, scale_.to_raw(params.mu), lattice().spacing_float(), window_class);
}

void Session::set_params(const ThresholdParams& params, bool window_from_seeds, bool alpha_automatic) {
    ThresholdParams p = params;
    if (window_from_seeds)
        if (const auto w = estimated_window()) {
            p.mu = w->mu;
            p.epsilon = w->epsilon;
        }
    if (alpha_automatic) take_automatic(p, alpha_choice_for(p, window_from_seeds));
    validate(p);
    begin_action("parameters");
    marks_.params = p;
    marks_.window_from_seeds = window_from_seeds;
    marks_.alpha_automatic = alpha_automatic;
    speed_.reset();
    segment_.converged = false;
    ++revision_;
    ++inputs_;
}

// ---------------------------------------------------------------------------------------------
// Segmentation and repair

void Session::ensure_speed() {
    if (speed_) return;
    // A level set loaded with no seed nor set window since: α for the window as it stands, within
    // the action (the same value set_params and the seeds' refresh give elsewhere).
    if (marks_.alpha_automatic) take_automatic(marks_.params, automatic_alpha_choice());
    speed_ = std::make_unique<ThresholdSpeed>(unit_, marks_.params, roi(), &speed_image());  // the blur kept
}

// The coarse start is due while φ is the union of the seeds (no step, edit or load since) on a grid
// where it applies; it then runs until its end replaces that union (marks_.pristine false).
const SparseField* Session::coarse_field() const { return coarse_run_current() && coarse_start_due() ? &coarse_->field() : nullptr; }

bool Session::coarse_run_current() const {
    return coarse_ && coarse_inputs_ == inputs_ && speed_ && coarse_speed_ == speed_->serial();
}

bool Session::coarse_start_due() const {
    return marks_.pristine && !marks_.seeds.empty() && coarse_start_applies(options_.coarse_start, lattice());
}

// One iteration of the coarse start's run (begun, or begun again after a change of what it reads since
// it began: inputs_ counts them; a coarse iteration changes none; or on another speed than the
// one it holds, whatever replaced it). The iteration that ends it replaces φ by its fine start
// (CoarseRun::fine_start) and the seeds' balls, as segment_image's evolve does, through the edit
// path; the fine steps then start from there with a fresh convergence count.
SessionUpdate Session::coarse_step() {
    begin_action("segment");  // the run's action, as a fine step's (its coarse iterations record nothing)
    const auto t0 = Clock::now();
    ensure_speed();
    if (!coarse_run_current()) {
        coarse_.reset();
        coarse_ = std::make_unique<CoarseRun>(*speed_, lattice(), roi(), marks_.seeds, options_.segmentation, options_.layers);
        coarse_inputs_ = inputs_;
        coarse_speed_ = speed_->serial();
    }
    coarse_->advance();
    ++coarse_serial_;
    segment_.coarse = true;
    segment_.coarse_iterations = coarse_->result().iterations;
    segment_.coarse_inside = coarse_->result().inside;
    segment_.converged = false;
    segment_.vanished = false;  // the seeds are a surface (an earlier step without one may have said otherwise)
    segment_.flips = 0;         // the image's grid's counts: nothing moved there
    segment_.dt = 0.0;
    if (!coarse_->ended()) {
        SessionUpdate u;
        u.level_set_ms = ms_since(t0);
        return u;
    }
    return edit("segment", Action::kContinued, [&] {
        CoarseStartReport report;
        const std::optional<Grid<std::uint8_t>> start = coarse_->fine_start(report);
        coarse_.reset();
        init_fine_start(field_, start, marks_.seeds);  // as segment_image's evolve
        marks_.pristine = false;
        convergence_.reset();
        segment_.vanished = field_.zero_layer().empty();
        Change c{{}, true};
        c.level_set_ms = ms_since(t0);
        return c;
    });
}

SessionUpdate Session::segment_step() {
    if (!has_surface()) {
        segment_.vanished = true;
        return {};
    }
    if (coarse_start_due()) return coarse_step();
    coarse_.reset();
    if (!convergence_) convergence_.emplace(field_.phi(), options_.segmentation);
    return edit("segment", Action::kContinued, [&] {
        ensure_speed();
        segment_.coarse = false;
        StepResult step = field_.step(*speed_, options_.segmentation.step);
        segment_.flips = convergence_->record_step(field_.phi(), step.changed.points);
        segment_.inside = convergence_->inside();
        segment_.dt = step.dt;
        segment_.iterations = ++marks_.iterations;
        segment_.converged = convergence_->converged(field_.zero_layer().size());
        segment_.vanished = field_.zero_layer().empty();
        marks_.pristine = false;
        return Change{std::move(step.changed)};
    });
}

void Session::make_repair_loop() { repair_ = std::make_unique<RepairLoop>(field_, unit_, roi(), repair_options_); }

void Session::set_step(const StepOptions& step) {
    validate(step);
    options_.segmentation.step = step;
    coarse_.reset();  // the coarse start's run steps as the session does: begun again
}

void Session::set_coarse_start(CoarseStart mode) {
    options_.coarse_start = mode;
    coarse_.reset();
}

void Session::set_repair_options(const RepairOptions& options) {
    validate(options);
    repair_options_ = options;
    if (!repair_) return;
    make_repair_loop();
    if (target_) {
        try {
            repair_->respawn(*target_);
        } catch (const std::invalid_argument&) {
            target_.reset();  // the surface moved away from the old target (e.g. undone)
        }
    }
    ++revision_;
}

void Session::aim_swarm(const RepairOptions& options, Vec3d target) {
    validate(options);
    if (!all_finite(target) || !lattice().contains(target)) throw std::invalid_argument("the target lies outside the image");
    end_action();  // each round is its own undoable action
    repair_options_ = options;
    make_repair_loop();
    repair_->set_target(target);  // a fresh loop: spawns the swarm on the surface nearest the target
    target_ = target;
    ++revision_;
}

void Session::set_target(Vec3d target) {
    if (!all_finite(target) || !lattice().contains(target)) throw std::invalid_argument("the target lies outside the image");
    end_action();  // each target's repair is its own undoable action
    if (!repair_) make_repair_loop();
    repair_->set_target(target);  // spawns the swarm there first, or again when the target is far from it
    target_ = target;
    ++revision_;
}

void Session::clear_target() {
    end_action();
    repair_.reset();
    target_.reset();
    ++revision_;
}

std::optional<Vec3d> Session::nearest_surface_point(Vec3d p, double radius) const {
    std::optional<Vec3d> best;
    double best_d = radius;
    for (PointIndex i : field_.zero_layer()) {
        const Vec3d q = lattice().coord(i).cast<double>();
        const double d = norm(q - p);
        if (d <= best_d) {
            best_d = d;
            best = q;
        }
    }
    return best;
}

SessionUpdate Session::swarm_step() {
    if (!repair_ || !repair_->spawned()) return {};
    SessionUpdate u = edit("repair", Action::kContinued, [&] {
        RepairStep step = repair_->step();
        if (!step.changed.empty()) {
            marks_.pristine = false;
            convergence_.reset();
        }
        Change c{std::move(step.changed)};
        c.level_set_ms = step.log.level_set_ms;
        c.agents_ms = std::max(0.0, step.log.ms - c.level_set_ms);
        c.swarm = step.log;
        return c;
    });
    u.swarm.fragments = u.fragments.size();  // the mesher's U for this step's X
    u.swarm.mesh_ms = u.mesh_ms;
    return u;
}

SessionUpdate Session::edit_box(Vec3i lo, Vec3i hi, const std::function<float(Vec3i, float)>& delta) {
    return edit("brush", Action::kOwn, [&] {
        ChangedPoints changed = field_.apply_in_box(lo, hi, delta);
        if (!changed.empty()) {
            marks_.pristine = false;
            convergence_.reset();
        }
        return Change{std::move(changed)};
    });
}

const std::vector<Agent>& Session::agents() const {
    static const std::vector<Agent> none;
    return repair_ ? repair_->swarm().agents() : none;
}

// ---------------------------------------------------------------------------------------------
// History

void Session::begin_action(const char* label) {
    if (history_.action_open() && history_.open_label() == label) return;
    end_action();
    history_.begin(label, marks());
}

void Session::end_action() {
    if (history_.action_open()) history_.commit(field_, marks());
}

void Session::clear_history() {
    end_action();
    history_.reset(field_);
}

void Session::adopt_marks(const SessionMarks& m) {
    marks_ = m;
    speed_.reset();
    convergence_.reset();
    segment_ = {};
    segment_.iterations = m.iterations;
}

SessionUpdate Session::undo() {
    end_action();
    if (!history_.can_undo()) return {};
    return edit("undo", Action::kHistory, [&] {
        HistoryStep step = history_.undo(field_);
        adopt_marks(step.marks);
        return Change{std::move(step.changed)};
    });
}

SessionUpdate Session::redo() {
    end_action();
    if (!history_.can_redo()) return {};
    return edit("redo", Action::kHistory, [&] {
        HistoryStep step = history_.redo(field_);
        adopt_marks(step.marks);
        return Change{std::move(step.changed)};
    });
}

// ---------------------------------------------------------------------------------------------
// The one edit path

SessionUpdate Session::edit(const char* label, Action action, const std::function<Change()>& change) {
    if (action == Action::kOwn) end_action();
    if (action != Action::kHistory) begin_action(label);  // continues an open action of the same label
    const auto t0 = Clock::now();
    Change c = change();
    if (c.whole_state) c.changed = history_.record_differences(field_);
    else if (action != Action::kHistory) history_.record(c.changed);
    const double level_set_ms = c.level_set_ms >= 0.0 ? c.level_set_ms : ms_since(t0);
    SessionUpdate u = finish_update(std::move(c.changed), level_set_ms);
    u.agents_ms = c.agents_ms;
    u.swarm = c.swarm;
    if (action == Action::kOwn) history_.commit(field_, marks());
    return u;
}

// ---------------------------------------------------------------------------------------------
// Renderer feed and outputs

SessionUpdate Session::finish_update(ChangedPoints changed, double level_set_ms) {
    SessionUpdate u;
    u.level_set_ms = level_set_ms;
    if (defer_mesh_) {
        // pending_flags_: bit 0 in pending_, bit 1 in pending_signs_ (a subset: a sign change is a change).
        if (!changed.sign_changes && !changed.points.empty()) pending_signs_known_ = false;
        if (changed.sign_changes) append_unflagged(pending_signs_, pending_flags_, *changed.sign_changes, 2);
        append_unflagged(pending_, pending_flags_, changed.points, 1);
    } else {
        const auto t0 = Clock::now();
        u.fragments = changed.sign_changes ? mesher_.update(field_.phi(), changed.points, *changed.sign_changes)
                                           : mesher_.update(field_.phi(), changed.points);
        u.mesh_ms = ms_since(t0);
        queue_dirty(u.fragments);
    }
    u.changed = std::move(changed);
    ++revision_;
    ++inputs_;
    return u;
}

void Session::queue_dirty(const std::vector<FragmentId>& fragments) {
    for (FragmentId f : fragments)
        if (!dirty_flags_[f]) {
            dirty_flags_[f] = 1;
            dirty_.push_back(f);
        }
}

void Session::set_deferred_meshing(bool on) {
    if (on == defer_mesh_) return;
    if (!on) flush_mesh();
    defer_mesh_ = on;
    if (on) pending_flags_ = Grid<std::uint8_t>(lattice(), 0);  // filled on every thread
    else pending_flags_ = {};
}

double Session::flush_mesh() {
    if (pending_.empty()) {
        pending_signs_known_ = true;
        return 0.0;
    }
    const auto t0 = Clock::now();
    queue_dirty(pending_signs_known_ ? mesher_.update(field_.phi(), pending_, pending_signs_) : mesher_.update(field_.phi(), pending_));
    clear_pending_flags();
    pending_.clear();
    pending_signs_.clear();
    pending_signs_known_ = true;
    return ms_since(t0);
}

void Session::clear_pending_flags() {
    voxel_loops::for_each(pending_.size(), [&](std::size_t k) { pending_flags_[pending_[k]] = 0; });  // distinct: each flag once
}

std::vector<FragmentId> Session::take_dirty_fragments() {
    flush_mesh();
    std::vector<FragmentId> out;
    out.swap(dirty_);
    for (FragmentId f : out) dirty_flags_[f] = 0;
    std::sort(out.begin(), out.end());
    return out;
}

Grid<std::uint8_t> Session::mask() const { return inside_mask(field_.phi(), roi()); }

Mesh Session::surface_mesh() const { return marching_cubes_band(field_.phi(), field_.zero_layer()); }

}  // namespace liveset
