// Truth-free hole repair as a user without ground truth does it: the hole finder picks the targets,
// one sheet-rule round per target (brush sized to the hole, the sheet's band sampled around it),
// the finder's verdict per target. Shared by `liveset demo --brain --repair`, `liveset repair --find-holes` and Python's `repair_holes`.
#pragma once

#include <atomic>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>

#include "liveset/eval/holes.hpp"
#include "liveset/grid/grid.hpp"
#include "liveset/segment/intensity.hpp"
#include "liveset/session/session.hpp"
#include "liveset/swarm/repair.hpp"

namespace liveset::cli {

// The sheet tissue's band and class mean, raw intensities.
struct SheetBand {
    double lower = 0, upper = 0, mean = 0;
    HoleFinderOptions finder() const;  // the finder's options with this band
};

// The tissue model's window and class mean for the class most of `mask`'s voxels are in
// (sheet_window, looking for the brain with `brain`: brain_mask_options(header); with a `roi`, the
// ROI read as `segment` reads it, fit_for_roi); nullopt when the model cannot tell the
// sheet's tissue.
std::optional<SheetBand> model_sheet_band(const Grid<float>& image, const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>* roi,
                                          const BrainMaskOptions& brain = {});

struct FoundHolesInput {
    const Grid<float>& image;            // the image the segmentation came from (raw units)
    const Grid<std::uint8_t>* roi;       // region of interest (outside counts as the outside tissue); may be null
    IntensityScale scale;                // the session's normalisation of `image`
    SheetBand band{};                    // the sheet tissue's (the tissue model's window and class mean)
    std::size_t max_targets = 10;        // the largest holes clicked, one round each
    std::size_t min_voxels = 50;         // the finder's smallest target
    int round_steps = 1000;              // swarm steps per target
    RepairOptions options = default_options();  // swarm settings (the decision is the sheet rule)

    // The paper's 200 agents, p = 0.3, edit radius 2.
    static RepairOptions default_options();
};

// Finder -> targets -> one round per target through `session` (which holds the segmentation) ->
// verdicts. Returns {targets, verdicts, closed, agents, p, steps, points_modified, voxels_added,
// ms_per_step, round_steps, finder: {band, min_voxels, before, after}}. Throws UsageError on a bad
// input (band not ordered, no targets wanted). Stops early when *interrupt is set (the caller checks it).
nlohmann::json repair_found_holes(const FoundHolesInput& in, Session& session, bool quiet, const std::atomic<bool>* interrupt = nullptr);

}  // namespace liveset::cli
