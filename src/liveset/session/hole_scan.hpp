// The truth-free hole finder (eval/holes.hpp) as an interactive tool runs it on a session's
// segmentation: the sheet's intensity band from the tissue model (as `liveset holes`), the ranked
// candidates, and - after a repair - the finder's verdict per repaired site (hole_verdict, as
// `liveset repair` reports "closed" per target), from the scan before and the scan after.
// Standard library only; pure functions of copies, so a viewer may run a scan on another thread.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "liveset/eval/holes.hpp"
#include "liveset/grid/grid.hpp"
#include "liveset/segment/window.hpp"

namespace liveset {

// `liveset repair` counts the finder's hole voxels this close to a target (voxels) for its verdict.
inline constexpr double kHoleVerdictRadius = 6.0;

struct HoleScanOptions {
    std::size_t min_voxels = 10;  // smallest candidate listed (as `liveset holes`)
    double min_sheet_share = HoleFinderOptions{}.min_sheet_share;
    // The sheet's band [lower, upper) in raw units; both absent: the tissue model's window for the
    // class most of the mask's voxels are in (sheet_window).
    std::optional<double> sheet_lower, sheet_upper;
    void validate() const;  // std::invalid_argument with a one-line message
};

struct HoleScan {
    Grid<std::uint8_t> mask;         // the segmentation scanned (non-zero inside)
    HoleFinderOptions finder;        // the band and limits used
    std::string band_from;           // "given" or "tissue model"
    std::vector<std::string> warnings;
    std::vector<HoleCandidate> holes;  // largest first
    double ms = 0.0;                 // wall time of the scan
};

// Scans `mask` (the segmentation, non-zero inside) of `image` (raw) within `roi` (optional); without
// a given band, the tissue model is fitted where `fit` says (a session's: Session::sheet_fit()).
// Throws std::invalid_argument (one line) on bad options, other sizes, or when the tissue model
// cannot tell the sheet's tissue and no band is given.
HoleScan scan_holes(Grid<std::uint8_t> mask, const Grid<float>& image, const Grid<std::uint8_t>* roi,
                    const HoleScanOptions& options, const SheetFit& fit = {});

// The finder's verdict at each of `sites` (index space) from the scan before a repair to the scan
// after it, both with before's band (hole_verdict with kHoleVerdictRadius, exactly as `liveset
// repair`). Throws std::invalid_argument when the scans' sizes differ.
std::vector<HoleVerdict> hole_verdicts(std::span<const Vec3d> sites, const HoleScan& before, const HoleScan& after,
                                       const Grid<float>& image, const Grid<std::uint8_t>* roi);

}  // namespace liveset
