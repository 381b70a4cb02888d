// The hole finder for interactive use: band, candidates, verdicts (hole_scan.hpp).
#include "liveset/session/hole_scan.hpp"

#include <chrono>
#include <cmath>
#include <stdexcept>

#include "liveset/segment/window.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset {

void HoleScanOptions::validate() const {
    if (min_voxels < 1) throw std::invalid_argument("hole finder: min_voxels must be at least 1");
    if (!(min_sheet_share >= 0.0 && min_sheet_share <= 1.0)) throw std::invalid_argument("hole finder: min_sheet_share must be in [0, 1]");
    if (sheet_lower.has_value() != sheet_upper.has_value())
        throw std::invalid_argument("hole finder: give both ends of the sheet band, or neither");
    if (sheet_lower && !(std::isfinite(*sheet_lower) && std::isfinite(*sheet_upper) && *sheet_lower < *sheet_upper))
        throw std::invalid_argument("hole finder: the sheet band's lower end must be below its upper end");
}

HoleScan scan_holes(Grid<std::uint8_t> mask, const Grid<float>& image, const Grid<std::uint8_t>* roi, const HoleScanOptions& options,
                    const SheetFit& fit) {
    const auto t0 = std::chrono::steady_clock::now();
    options.validate();
    if (!(mask.dims() == image.dims()) || (roi && !(roi->dims() == image.dims())))
        throw std::invalid_argument("hole finder: the segmentation, the image and the ROI differ in size");
    HoleScan s;
    s.finder.min_voxels = options.min_voxels;
    s.finder.min_sheet_share = options.min_sheet_share;
    if (options.sheet_lower) {
        s.finder.sheet_lower = *options.sheet_lower;
        s.finder.sheet_upper = *options.sheet_upper;
        s.band_from = "given";
    } else {
        const std::optional<ModelWindow> w = sheet_window(image, mask, roi, TissueModelOptions{}, s.warnings, nullptr, fit);
        if (!w)
            throw std::invalid_argument("hole finder: cannot tell the sheet's tissue from the image (" +
                                        (s.warnings.empty() ? std::string("no tissue model") : s.warnings.back()) + "); give the sheet band");
        s.finder.sheet_lower = w->lower;
        s.finder.sheet_upper = w->upper;
        s.band_from = "tissue model";
    }
    s.holes = find_holes(mask, image, roi, s.finder);
    s.mask = std::move(mask);
    s.ms = ms_since(t0);
    return s;
}

std::vector<HoleVerdict> hole_verdicts(std::span<const Vec3d> sites, const HoleScan& before, const HoleScan& after,
                                       const Grid<float>& image, const Grid<std::uint8_t>* roi) {
    if (!(before.mask.dims() == after.mask.dims())) throw std::invalid_argument("hole verdicts: the two scans differ in size");
    std::vector<HoleVerdict> out;
    if (sites.empty()) return out;
    const Grid<std::uint8_t> hb = hole_voxels(before.mask, image, roi, before.finder);
    const Grid<std::uint8_t> ha = hole_voxels(after.mask, image, roi, before.finder);
    for (const Vec3d& p : sites) out.push_back(hole_verdict(p, kHoleVerdictRadius, hb, ha, before.mask, after.mask));
    return out;
}

}  // namespace liveset
