// The coarse-to-fine start of a finely sampled scan (issue 16, docs/ARCHITECTURE.md "Coarse start"):
// the front first runs to convergence from the seeds on 2x2x2-voxel blocks (their mean threshold term), and
// that result, upsampled onto the image's own grid less what the image's own data term refuses, is where
// the front starts there.
#pragma once

#include <atomic>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "liveset/grid/grid.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/threshold_speed.hpp"

namespace liveset {

// kAuto (the default) starts coarse where every voxel side is at most kCoarseStartMaxSpacing mm and
// the run starts from seeds; kOn wherever it starts from seeds; kOff never. Neither on a grid with
// an axis shorter than kCoarseStartMinDim voxels.
enum class CoarseStart { kAuto, kOn, kOff };

// A 0.7 mm (HCP-like) grid's front travels twice the voxels of a 1.4 mm one's at half the time
// step; on a 1 mm grid the coarse start gains nothing (docs/BENCHMARKS.md, sessions 77-78).
inline constexpr double kCoarseStartMaxSpacing = 0.85;
// No coarse start on a grid with an axis shorter than this (its coarse grid would be a few voxels).
inline constexpr int kCoarseStartMinDim = 16;

// "auto", "on", "off" as the command line and Python name them; parse throws std::invalid_argument.
std::string to_string(CoarseStart mode);
CoarseStart parse_coarse_start(const std::string& name);

// Whether a run from seeds on `lattice` starts coarse under `mode`.
bool coarse_start_applies(CoarseStart mode, const Lattice& lattice);

// The grid of 2x2x2 blocks: dims ceil(d / 2), spacing doubled, the first point at the centre of the
// first block (fine index 0.5 on each axis). Coarse point c lies at fine index 2c + 0.5.
Lattice coarse_lattice(const Lattice& fine);
// 1 where at least half of a block's voxels are non-zero.
Grid<std::uint8_t> downsample_majority(const Grid<std::uint8_t>& fine);
// The coarse threshold terms: at each block, the mean of `fine`'s D (Eq. 3, after its blur; +1
// outside its ROI) over the block's voxels (a block cut by an odd border averaging those it holds).
// Not D of the mean intensity: a block of tissue and its neighbour averages into the window (partial
// volume) where their mean D says half in, half out.
Grid<float> block_threshold_terms(const ThresholdSpeed& fine);
// A seed ball in the index space of `coarse` (the centre mapped and clamped into it, the radius halved).
SeedBall coarse_seed(const SeedBall& fine, const Lattice& coarse);
// The coarse φ, trilinear at fine voxel `fine`'s centre (clamped to the coarse grid): what
// upsample_inside tests, bit for bit (a viewer's preview of the coarse run on the image's grid).
float upsampled_phi(const Grid<float>& coarse_phi, Vec3i fine);
// Inside (1) where the coarse φ, trilinear at each fine voxel's centre (clamped to the coarse grid),
// is negative, and the ROI (when given, `fine`'s lattice) allows it.
Grid<std::uint8_t> upsample_inside(const Grid<float>& coarse_phi, const Lattice& fine, const Grid<std::uint8_t>* roi = nullptr);

// What the coarse stage did (a segmentation's report).
struct CoarseStartReport {
    Vec3i dims{0, 0, 0};
    Vec3d spacing{0, 0, 0};
    SegmentationResult result;   // the coarse run's iterations, stop reason and seconds
    std::size_t upsampled = 0;   // inside points of the fine start without the seeds' balls (after `refused`)
    std::size_t refused = 0;     // voxels of the upsampled front the image's data term refuses (D > 0), left out
    bool used = false;           // false: nothing of the coarse front was left (the ROI, the data term's refusal); the fine run started from the seeds
};

// The coarse stage as its caller steps it (run_coarse_start's loop; a session's coarse start, one
// iteration per Session::segment_step): the front from `seeds` (`fine`'s index space) under the
// threshold speed on the block_threshold_terms of `fine_speed` (with its α) and the ROI by
// majority, on coarse_lattice(fine), stepped as `loop` says. Throws std::invalid_argument (from the
// constructor) for a speed or ROI of another grid or a seed outside it. `fine_speed` and `roi`
// must outlive it.
class CoarseRun {
public:
    CoarseRun(const ThresholdSpeed& fine_speed, const Lattice& fine, const Grid<std::uint8_t>* roi, std::span<const SeedBall> seeds,
              const SegmentationOptions& loop, int layers);
    CoarseRun(const CoarseRun&) = delete;
    CoarseRun& operator=(const CoarseRun&) = delete;
    // One coarse iteration (SegmentationRun::advance); the hook sees it with level 1. True while
    // the run goes on.
    bool advance(const SegmentationHook& hook = {});
    void interrupt() { run_.interrupt(); }
    bool ended() const { return run_.ended(); }
    const SegmentationResult& result() const { return run_.result(); }
    const SparseField& field() const { return field_; }
    // After a run that ended otherwise than interrupted: the fine start, to which the caller unites
    // the seeds' balls - upsample_inside of its φ without the voxels where the image's own data
    // term is positive (the fine speed's propagation > 0: outside the window or the ROI), or
    // nothing when nothing of its front is left. A block half in the window lets in voxels the
    // image's grid refuses; a run from the seeds would never enter them, and a front started there
    // leaves them only as fast as their D, barely positive near the window's edge, pushes it
    // (docs/BENCHMARKS.md, session 82). `report` gets the grid, the run's result, what was upsampled
    // and what was refused.
    std::optional<Grid<std::uint8_t>> fine_start(CoarseStartReport& report) const;

private:
    Lattice fine_;
    const ThresholdSpeed& fine_speed_;  // the image's speed (must outlive the run)
    const Grid<std::uint8_t>* roi_;
    Grid<float> terms_;
    std::optional<Grid<std::uint8_t>> coarse_roi_;  // read by speed_
    ThresholdSpeed speed_;
    SparseField field_;
    SegmentationRun run_;
};

// The fine start from the coarse stage's result: `start` (fine_start) with every seed's ball united
// (a seed whose coarse front died - its tissue blurred out of the window by the blocks - is not lost
// while another seed's front lived), or the seeds alone where nothing of the coarse front is left.
void init_fine_start(SparseField& fine, const std::optional<Grid<std::uint8_t>>& start, std::span<const SeedBall> seeds);

// The coarse stage: the front from `seeds` (`fine`'s index space) under the threshold speed on the
// block_threshold_terms of `fine_speed` (with its α) and the ROI
// by majority, run as `loop` says; the hook sees its steps with level 1. Returns CoarseRun::fine_start
// (the fine start, to which segment_image unites the seeds' balls), or nothing when the run
// was interrupted (report.result.reason) or nothing of its front is left (report.used false).
std::optional<Grid<std::uint8_t>> run_coarse_start(const ThresholdSpeed& fine_speed, const Lattice& fine,
                                                   const Grid<std::uint8_t>* roi, std::span<const SeedBall> seeds,
                                                   const SegmentationOptions& loop, int layers, const SegmentationHook& hook,
                                                   const std::atomic<bool>* interrupt, CoarseStartReport& report);

}  // namespace liveset
