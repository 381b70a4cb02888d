// `liveset holes`: candidate holes of a segmented sheet found without ground truth (eval/holes.hpp):
// gaps of sheet-like voxels where the tissue the sheet encloses meets the outside, ranked by size,
// each with a site in the `--target` format of `liveset repair`.
#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "image_commands.hpp"
#include "liveset/eval/holes.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/window.hpp"

namespace liveset::cli {

namespace {

struct HolesArgs {
    std::string input, image, roi;
    std::size_t min_voxels = 10;
    double min_sheet_share = HoleFinderOptions{}.min_sheet_share;
    std::string out_mask;
    std::size_t max_sites = 20;
    std::optional<double> lower, upper;  // the sheet's band (raw); from the tissue model when absent
    bool json = false;
};

int run_holes(const HolesArgs& a, int threads) {
    const auto guard = limit_threads(threads);
    if (a.lower.has_value() != a.upper.has_value()) throw UsageError("give both --sheet-lower and --sheet-upper, or neither");
    const Scan scan = read_scan(a.image);
    const Grid<float>& image = scan.image;
    const ImageHeader& header = scan.header;
    const Grid<float> in = read_image(a.input);
    if (!(in.dims() == image.dims()))
        throw UsageError(fmt::format("{} ({}x{}x{}) does not match the image's size", a.input, in.dims().x, in.dims().y, in.dims().z));
    std::optional<Grid<std::uint8_t>> roi;
    if (!a.roi.empty()) roi = load_mask_like(a.roi, image.lattice(), "--roi");
    const Grid<std::uint8_t>* r = roi ? &*roi : nullptr;
    const Grid<std::uint8_t> mask = is_binary_mask(in) ? to_mask(in) : inside_mask(in, r);

    HoleFinderOptions fo;
    fo.min_voxels = a.min_voxels;
    fo.min_sheet_share = a.min_sheet_share;
    if (!a.out_mask.empty()) check_output_path(a.out_mask, OutputKind::kImage, "--out-mask");
    std::vector<std::string> warnings;
    std::string band_from = "user";
    if (a.lower) {
        fo.sheet_lower = *a.lower;
        fo.sheet_upper = *a.upper;
    } else {
        const BrainMaskOptions brain = brain_mask_options(header);  // a ROI from a file: the contrast read off the head, as segment's
        const std::optional<ModelWindow> w =
            sheet_window(image, mask, r, TissueModelOptions{}, warnings, nullptr, fit_for_roi(image, r, brain));
        if (!w) throw UsageError(fmt::format("cannot tell the sheet's tissue from the image ({}); give --sheet-lower and --sheet-upper",
                                             warnings.empty() ? "no tissue model" : warnings.back()));
        fo.sheet_lower = w->lower;
        fo.sheet_upper = w->upper;
        band_from = "tissue model";
    }
    try {
        fo.validate();
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    scan.print_note(a.image);  // the inputs are good
    const std::vector<HoleCandidate> holes = find_holes(mask, image, r, fo);
    if (!a.out_mask.empty()) write_label_image(hole_voxels(mask, image, r, fo), a.out_mask, {.orientation_known = header.orientation_known});
    std::size_t total = 0;
    for (const HoleCandidate& h : holes) total += h.voxels;
    nlohmann::json sites = nlohmann::json::array();
    for (std::size_t k = 0; k < holes.size() && k < a.max_sites; ++k) {
        const HoleCandidate& h = holes[k];
        sites.push_back({{"voxels", h.voxels}, {"rim", h.rim}, {"sheet", h.sheet}, {"target", {h.site.x, h.site.y, h.site.z}},
                         {"centroid", {h.centroid.x, h.centroid.y, h.centroid.z}}});
    }
    nlohmann::json j{{"holes", holes.size()}, {"voxels", total}, {"sheet_band", {fo.sheet_lower, fo.sheet_upper}},
                     {"band_from", band_from}, {"min_voxels", a.min_voxels}, {"sites", sites}, {"warnings", warnings}};
    if (a.json) {
        fmt::print("{}\n", j.dump());
        return 0;
    }
    for (const std::string& w : warnings) fmt::print(stderr, "liveset: warning: {}\n", w);
    fmt::print("liveset holes: {} candidate hole(s) of >= {} voxels ({} voxels), sheet band [{:.4g}, {:.4g}) from the {}\n",
               holes.size(), a.min_voxels, total, fo.sheet_lower, fo.sheet_upper, band_from);
    for (std::size_t k = 0; k < holes.size() && k < a.max_sites; ++k)
        fmt::print("  {:>3}  {:>7} voxels  rim {:>6}  --target {},{},{}\n", k + 1, holes[k].voxels, holes[k].rim, holes[k].site.x,
                   holes[k].site.y, holes[k].site.z);
    return 0;
}

}  // namespace

void add_holes_command(CLI::App& app, const int& threads) {
    static HolesArgs ha;
    auto* h = app.add_subcommand("holes", "candidate holes of a segmented sheet without ground truth, largest first, with --target sites");
    h->add_option("input", ha.input, "phi (<0 inside) or 0/1 mask of the segmented sheet")->required();
    h->add_option("--image", ha.image, "the image the segmentation came from: segment's --out-corrected image (segment corrects the bias by default), or the input with --no-bias-correct")->required();
    h->add_option("--roi", ha.roi, "region of interest (outside it counts as the outside tissue)");
    h->add_option("--min-voxels", ha.min_voxels, "smallest candidate listed")->check(CLI::Range(std::size_t{1}, std::size_t{1} << 40))->capture_default_str();
    h->add_option("--min-sheet-share", ha.min_sheet_share, "leave out candidates with a smaller share of voxels touching the segmentation")->check(CLI::Range(0.0, 1.0))->capture_default_str();
    h->add_option("--out-mask", ha.out_mask, "write every candidate's voxels as a 0/1 mask");
    h->add_option("--max-sites", ha.max_sites, "sites listed")->check(CLI::Range(std::size_t{0}, std::size_t{1} << 40))->capture_default_str();
    h->add_option("--sheet-lower", ha.lower, "the sheet tissue's lowest intensity (raw; default from the tissue model)")->check(finite_number());
    h->add_option("--sheet-upper", ha.upper, "the sheet tissue's highest intensity (raw; default from the tissue model)")->check(finite_number());
    h->add_flag("--json", ha.json, "print one JSON object (holes, voxels, sheet_band, sites[{voxels, rim, target, centroid}])");
    h->callback([&threads] {
        const int rc = run_holes(ha, threads);
        if (rc != 0) std::exit(rc);
    });
}

}  // namespace liveset::cli
