// The hole-repair schedule a user follows (and the demos, the viewer and the tests replay): rounds,
// each aimed at the largest hole left with the brush sized to that hole, the swarm running a fixed
// number of steps per round; plus the sheet repair's local intensity band sampled around a hole.
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <vector>

#include "liveset/swarm/repair.hpp"

namespace liveset {

// The brush a user sizes to a hole before clicking at its centre (ITK-SNAP users size the paint
// brush the same way): the radius of a disc of `hole_voxels` voxels through a shell
// `shell_thickness` voxels thick, plus one voxel so the brush reaches the hole's rim, clamped to
// [3, max_range] voxels. A fixed 8-voxel brush keeps editing the shell around a hole that has
// shrunk to a few voxels and grows it into white matter and CSF (docs/BENCHMARKS.md).
// Throws std::invalid_argument for a non-positive thickness or max_range < 3.
double hole_brush_range(std::size_t hole_voxels, double shell_thickness = 3.0, double max_range = 8.0);

struct HoleSite {
    Vec3d position;          // index space: where the round aims the swarm
    std::size_t voxels = 0;  // the hole's size (sizes the brush)
    int stalled_rounds = 0;  // set by run_repair_schedule: earlier rounds at this site that stalled
    bool cut = false;        // a handle of tissue to cut (its round runs EditDecision::kCut), not a hole to fill
};

struct RepairScheduleOptions {
    int rounds = 20;        // at most this many rounds (one target each)
    int round_steps = 100;  // swarm steps per round
    double shell_thickness = 3.0;  // brush sizing (hole_brush_range)
    double max_range = 8.0;
    void validate() const;  // std::invalid_argument with a one-line message
};

struct RepairRoundLog {
    HoleSite target;
    std::size_t holes = 0;   // holes the finder listed before the round
    double edit_range = 0;   // the brush
    int steps = 0;
    std::size_t modified = 0, fragments = 0;
    double ms = 0.0;
};

struct RepairScheduleResult {
    std::vector<RepairRoundLog> rounds;
    std::size_t holes_left = 0;  // what the finder listed after the last round
    bool interrupted = false;
};

// What a schedule drives: the level set it reads and a swarm it aims and steps. The Session is one
// (session/session.hpp: its edit path records, meshes and reports every step); FieldRepairDriver
// drives a bare SparseField (tests, experiments).
class RepairDriver {
public:
    virtual ~RepairDriver() = default;
    virtual const SparseField& field() const = 0;
    // A fresh swarm with `options`, spawned on the surface nearest `target` and aimed there.
    virtual void aim(const RepairOptions& options, Vec3d target) = 0;
    virtual RepairStepLog step() = 0;  // one swarm step, its edits applied
};

// A RepairLoop on a bare field (nothing meshed, no history).
class FieldRepairDriver : public RepairDriver {
public:
    FieldRepairDriver(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi)
        : field_(field), image_unit_(image_unit), roi_(roi) {}
    const SparseField& field() const override { return field_; }
    void aim(const RepairOptions& options, Vec3d target) override;
    RepairStepLog step() override;

private:
    SparseField& field_;
    const Grid<float>& image_unit_;
    const Grid<std::uint8_t>* roi_;
    std::unique_ptr<RepairLoop> loop_;
};

// The holes left on the current surface, the one to aim at first.
using HoleSiteFinder = std::function<std::vector<HoleSite>(const SparseField& field)>;
// Where a truth hole site lies: at the centroid of the hole's voxels, or in its widest opening (the
// hole's voxel farthest, in face steps through the hole, from the mask; ties: nearest the centroid)
// — a large hole's centroid can lie where its rim has grown shut while what is left open lies at
// its edge. The intensity rule spills into the tissue beside a deep opening (Dice falls), so the
// demo aims it at centroids and the sheet rule at openings (docs/BENCHMARKS.md).
enum class HoleAim { kCentroid, kOpening };

// `mask` with the pieces of `inner` it has walled off from the inner core counted in: every
// 6-connected component of inner voxels outside the mask but the largest (the core). A repair that
// grew into the inner tissue can wall a pocket of it off; a missed-truth tube from the outside into
// such a pocket is no perforation of the shell (filling it seals the pocket, a spurious cavity,
// and closes no tunnel). Throws std::invalid_argument when the sizes differ.
Grid<std::uint8_t> with_walled_inner(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& inner);

// The holes a user who sees the truth points at, largest first: the perforations of `mask` between
// `truth` and the inner core (eval/perforations.hpp, on with_walled_inner(mask, inner): a missed
// region that reaches only a walled-off pocket is none), and when none is left, its spurious
// cavities (bubbles) in `inner`, then the tunnels that missed truth closes (pinholes, cracks;
// counted with the walled-off pockets in, so a tube whose filling only seals a pocket is none),
// then the handles of `inner` tissue the mask took in (find_inner_handles; sites to cut, aimed at
// the handle's voxel nearest its centroid).
// The phantom demo's finder (and its test's). Throws std::invalid_argument when the sizes differ.
std::vector<HoleSite> truth_hole_sites(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth, const Grid<std::uint8_t>& inner,
                                       HoleAim aim = HoleAim::kCentroid);

// Adjusts a round's options for its target (e.g. the sheet band sampled there); may be empty.
using RoundSetup = std::function<void(RepairOptions& round, const HoleSite& target)>;

// Round r: holes = find(field); none left -> stop; else aim a fresh swarm (seed base.seed + r) at
// the first hole (the largest) among those with the fewest stalled rounds — a round stalled when
// a hole of more than 95 % of its target's voxels is left within 2 voxels of its target: as a user
// whose click changed nothing clicks the next hole and comes back later — with edit_range = hole_brush_range(its voxels) and run round_steps steps.
// `setup` adjusts the round's options; a site to cut then gets EditDecision::kCut. Throws
// std::invalid_argument on bad options.
RepairScheduleResult run_repair_schedule(RepairDriver& driver, const RepairOptions& base, const RepairScheduleOptions& schedule,
                                         const HoleSiteFinder& find, const RoundSetup& setup = {},
                                         const std::atomic<bool>* interrupt = nullptr);
// The same on a bare field (a FieldRepairDriver).
RepairScheduleResult run_repair_schedule(SparseField& field, const Grid<float>& image_unit, const Grid<std::uint8_t>* roi,
                                         const RepairOptions& base, const RepairScheduleOptions& schedule,
                                         const HoleSiteFinder& find, const RoundSetup& setup = {},
                                         const std::atomic<bool>* interrupt = nullptr);

// The sheet's own band around a hole: the model's band [lower, upper) of the sheet tissue (class
// mean `mean`; normalised units) shifted by (m − mean), m the median intensity of the voxels inside
// the surface (φ < 0) within `radius` of `site` whose intensity lies in the band (a local bias moves
// the sheet's intensities, and its neighbours' with it). The model's band unchanged when fewer than
// 20 such voxels exist. Returns {lower, upper}.
std::pair<double, double> local_sheet_band(const Grid<float>& image_unit, const Grid<float>& phi, Vec3d site, double radius,
                                           double lower, double upper, double mean);

}  // namespace liveset
