// Agent swarms on the zero level set (Feltell & Bai, §4): agents live in index space on φ = 0,
// move tangentially under a potential P with a pull-back onto the surface (Eq. 4), and propose
// local zero-layer edits (raise/lower the surface with a unit-peak Gaussian footprint) from
// population-level intensity statistics. Deterministic for any TBB thread count: every agent's
// random numbers come from its own stream keyed by (seed, agent, step) and moves are computed
// Jacobi-style from the previous positions.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/levelset/sparse_field.hpp"

namespace liveset {

// How an acting agent chooses to raise or lower the surface.
enum class EditDecision {
    kIntensity,  // population intensity statistics (the repair rule, see swarm.cpp)
    kRandom,     // raise or lower at random (the paper's frame-rate experiment, §4)
    kSheet,      // hole repair in a sheet: grow only into voxels of the sheet's own band (see swarm.cpp)
    kCut,        // cut a handle: lower the surface under the agent; the topology guard keeps only the
                 // flips that cut a handle (GuardOptions::cut_handles, set by the RepairLoop)
};

struct SwarmOptions {
    std::size_t agents = 200;
    double pull_back = 0.1;          // ε of Eq. 4, 0 ≤ ε < 1 (0 disables the pull-back)
    double attraction = 0.5;         // weight of unit(target − x) in P
    double random_walk = 0.3;        // weight of a random unit vector in P
    double separation = 0.4;         // weight of the repulsion from nearby agents in P
    double separation_radius = 2.0;  // voxels
    double max_step = 0.5;           // largest tangential displacement per step, voxels
    double act_probability = 0.1;    // p: chance that an agent edits the surface in one call
    double edit_radius = 2.0;        // support radius of an edit (Gaussian σ = radius/2), voxels
    double edit_amount = 0.2;        // A: |Δφ| under the agent per action, ≤ 0.5
    std::uint64_t seed = 1;
    // Decision rule of surface_edits (population mean μ, standard deviation σ):
    double expand_sigmas = 1.0;      // k: expand when |I_outside − μ| ≤ k·σ
    double contract_sigmas = 2.5;    // k': contract when |I_inside − μ| > k'·σ
    double min_sigma = 0.05;         // floor on σ (normalised intensity units)
    double stats_smoothing = 0.2;    // α of the exponential moving averages, 0 < α ≤ 1
    // Where the population samples the intensity: at the agent (0) or this many voxels inside
    // the surface along −n (the tissue already segmented around the agents).
    double sample_depth = 0.0;
    // Only agents within this distance (voxels) of the target edit — the "brush" around the point
    // the user designates; 0: no limit (and always none without a target).
    double edit_range = 0.0;
    EditDecision decision = EditDecision::kIntensity;
    // Decision kSheet: the sheet tissue's intensity band [sheet_lower, sheet_upper) (normalised
    // units), between the tissue the sheet encloses (above) and the outside (below); sampled
    // around the hole by local_sheet_band (repair_schedule.hpp). Must satisfy lower < upper.
    double sheet_lower = 0.0, sheet_upper = 0.0;
    // Decision kSheet: a voxel outside the band may still be raised when it lies between the sheet's
    // two sides (between_sheet_sides, within max(edit_range, sheet_reach) voxels; off without an edit range) — the
    // hole's own tissue whose intensity a bias or partial volume moved out of the band.
    bool sheet_between = true;
    // ... looking at least this far (voxels; 0: the brush alone).
    double sheet_reach = 0.0;
    // Decision kSheet: the sheet tissue's class mean (normalised units, inside the band; NaN: the
    // band's centre), and the smallest share s of the sheet's tissue that a voxel out of the band,
    // raised by a footprint because it lies between the sheet's sides, must hold by the
    // partial-volume model (a border voxel reads as the share-weighted mean of two class means; the
    // band's edges are the midpoints, so the neighbouring class means are 2·edge − mean): its
    // intensity within [lower − (1−2s)(mean − lower), upper + (1−2s)(upper − mean))
    // (sheet_between_range). Bias and noise move a hole's own tissue out of the band; a voxel three
    // quarters white matter or CSF (s = 0.25) is not the hole's tissue. 0 admits up to the
    // neighbouring class means; at most 0.5 (the band itself). An agent still decides to grow at a
    // gap whatever the voxel's intensity; only what its footprint raises is limited.
    double sheet_mean = std::numeric_limits<double>::quiet_NaN();
    double sheet_between_share = 0.25;
    // false: no intensity limit on between voxels (the phantom demo: its holes are grey matter a
    // bias bump lifted to the white matter's intensity).
    bool sheet_between_limited = true;
};

// Whether outside voxel `q` lies between the sheet's two sides, within `reach` voxels along rays
// in the 13 directions through it (±d): the sheet (φ < 0) lies on both sides of it along some
// direction (it is in the plane of the sheet, inside a hole's rim), and along some direction one
// ray passes the tissue the sheet encloses (intensity ≥ upper) and the other the outside (< lower,
// or the lattice's edge) before either meets the sheet (it is in a gap joining the two tissues the
// sheet separates). White matter under an intact sheet, or the CSF of a sulcus between two banks,
// fails the second test.
bool between_sheet_sides(const Grid<float>& phi, const Grid<float>& image_unit, Vec3i q, double reach, double lower, double upper);

// The intensity range [lo, hi) a voxel admitted by between_sheet_sides alone must lie in (see
// SwarmOptions::sheet_between_share).
std::pair<double, double> sheet_between_range(const SwarmOptions& options);

// Throws std::invalid_argument (one-line message) on an invalid option.
void validate(const SwarmOptions& options);

// The rule named as the CLI, Python and scripts name it ("intensity", "random", "sheet", "cut");
// nullopt for any other name.
std::optional<EditDecision> edit_decision_named(std::string_view name);

struct Agent {
    Vec3d position;  // index space
    Vec3d velocity;  // displacement of the last move (voxels per step)
};

struct StepReport {
    std::size_t on_surface = 0;   // agents with |φ(x)| < 0.5 after the move
    std::size_t reprojected = 0;  // agents that left |φ| ≤ 1 and were Newton-projected back
};

class Swarm {
public:
    explicit Swarm(const SwarmOptions& options);

    // Places options.agents agents on the zero-layer points nearest `near` within `radius`
    // (ties by point index; if there are fewer such points, they are reused cyclically), each
    // Newton-projected onto φ = 0. Resets velocities, step counters and intensity statistics.
    // Throws std::invalid_argument if no zero-layer point lies within `radius`.
    void spawn(const SparseField& field, Vec3d near, double radius);

    void set_target(std::optional<Vec3d> target) { target_ = target; }
    const std::optional<Vec3d>& target() const { return target_; }

    // One Eq. 4 step for every agent (see swarm.cpp for the exact rule).
    StepReport move(const SparseField& field);

    // Edits proposed by the agents this frame (sorted by point, duplicates merged, |Δ| ≤ 0.5),
    // ready for field.apply_edits(). image_unit must have the field's dimensions.
    std::vector<ZeroLayerEdit> surface_edits(const SparseField& field, const Grid<float>& image_unit);

    const std::vector<Agent>& agents() const { return agents_; }
    const SwarmOptions& options() const { return options_; }
    // Population intensity statistics (exponential moving averages); nullopt before the first
    // surface_edits call after spawn.
    std::optional<double> intensity_mean() const;
    std::optional<double> intensity_sigma() const;

private:
    // The population's intensity {µ, σ}, smoothed over the steps (surface_edits' decision rule).
    std::pair<double, double> population_statistics(const Grid<float>& phi, const Grid<float>& image_unit);
    SwarmOptions options_;
    std::vector<Agent> agents_;
    std::optional<Vec3d> target_;
    std::uint64_t move_steps_ = 0;
    std::uint64_t edit_steps_ = 0;
    bool have_stats_ = false;
    double mean_ = 0.0;    // EMA of the per-frame mean intensity
    double second_ = 0.0;  // EMA of the per-frame mean squared intensity
};

}  // namespace liveset
