// `liveset segment` (threshold level set from seeds, paper Eq. 2-3) and `liveset mesh` (φ or mask
// to a surface mesh). Outputs are checked before the run and written atomically; Ctrl-C stops the
// run and writes nothing.
#include <fmt/core.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "image_commands.hpp"
#include "phase_times.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/slab_marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "liveset/preprocess/bias_correction.hpp"
#include "threshold_args.hpp"

namespace liveset::cli {

namespace {

struct SegmentArgs : ThresholdArgs {
    std::string image;
    std::vector<std::string> seeds, seeds_mm;
    double seed_radius = 2.0;
    std::string init_mask, roi;
    std::string window_from = "model";
    std::string coarse_start = "auto";  // --coarse-start: coarse_start.hpp
    int classes = 3;
    int iterations = 2000;
    std::string out_mask, out_phi, out_mesh, out_roi, log;
    bool json = false, quiet = false;
    bool bias_correct = true;   // N4 before everything else (the corrected image replaces the input)
    bool bias_given = false;    // --bias-correct given: a failure is an error, not a skipped step
    bool iterations_given = false;  // --iterations given: stopping there is what was asked
    std::string out_corrected;
};

// Every option combination and output path checked before any work starts.
void check_segment_args(const SegmentArgs& a) {
    check_output_path(a.out_mask, OutputKind::kImage, "--out-mask");
    if (!a.out_phi.empty()) check_output_path(a.out_phi, OutputKind::kImage, "--out-phi");
    if (!a.out_mesh.empty()) check_output_path(a.out_mesh, OutputKind::kMesh, "--out-mesh");
    if (!a.log.empty()) check_output_path(a.log, OutputKind::kText, "--log");
    if (!a.out_roi.empty()) check_output_path(a.out_roi, OutputKind::kImage, "--out-roi");
    if (!a.out_roi.empty() && a.roi == "none") throw UsageError("--out-roi needs a ROI (a mask, auto, or the default on a head), not --roi none");
    if (!a.out_corrected.empty() && !a.bias_correct) throw UsageError("--out-corrected needs the bias correction (drop --no-bias-correct)");
    if (!a.out_corrected.empty()) check_output_path(a.out_corrected, OutputKind::kImage, "--out-corrected");
    check_threshold_args(a);
    if (a.seeds.empty() && a.seeds_mm.empty() && a.init_mask.empty())
        throw UsageError("give at least one --seed I,J,K[:R] (or --seed-mm, or --init-mask)");
    if (a.coarse_start == "on" && !a.init_mask.empty())
        throw UsageError("--coarse-start on starts from the seeds: it cannot start from --init-mask");
}

// The segmentation request the options describe (seeds parsed and checked inside the image).
SegmentRequest segment_request(const SegmentArgs& a, const Lattice& lattice) {
    SegmentRequest req;
    fill_segment_request(req, a, lattice);
    req.loop.step = step_options(a);
    return req;
}

// The request's regions: the ROI, the initial mask and where the tissue model is fitted.
void add_regions(SegmentRequest& req, const std::optional<Roi>& roi, const std::optional<Grid<std::uint8_t>>& init,
                 const Grid<std::uint8_t>* fit, const PreparedImage& prepared) {
    if (roi) req.roi = &roi->mask;
    if (init) req.initial_mask = &*init;
    req.model_region = fit;
    req.model_region_is_brain = prepared.fit_is_brain(roi);
    req.model_region_grey_brighter = prepared.grey_brighter;
}

// The report: the segmentation's, the bias correction's, the ROI and what was written.
nlohmann::json segment_report(const SegmentArgs& a, const SegmentOutcome& o, const Lattice& lattice, const std::optional<Roi>& roi,
                              const PreparedImage& prepared, std::size_t triangles) {
    nlohmann::json j = segmentation_report(o, lattice);
    add_bias_report(j, prepared, roi ? &roi->mask : nullptr);
    j["image"] = a.image;
    j["outputs"] = {{"mask", a.out_mask}};
    if (roi) j["roi"] = roi_report(*roi);
    if (!a.out_roi.empty()) j["outputs"]["roi"] = a.out_roi;
    if (!a.out_phi.empty()) j["outputs"]["phi"] = a.out_phi;
    if (!a.out_corrected.empty()) j["outputs"]["corrected"] = a.out_corrected;
    if (!a.out_mesh.empty()) {
        j["outputs"]["mesh"] = a.out_mesh;
        j["mesh_triangles"] = triangles;
    }
    return j;
}

// Ctrl-C during the run: the iterations of the stage it stopped in, nothing written.
int report_interrupt(const SegmentOutcome& o, bool quiet) {
    const bool coarse = o.coarse && o.coarse->result.reason == StopReason::kInterrupted;
    if (!quiet)
        fmt::print(stderr, "liveset: interrupted after {} iterations{}; nothing written\n",
                   coarse ? o.coarse->result.iterations : o.result.iterations, coarse ? " of the coarse start" : "");
    return 130;
}

// The mask and the outputs asked for, each written atomically; the mesh's triangle count (0: none).
std::size_t write_segment_outputs(const SegmentArgs& a, const Scan& scan, const SegmentOutcome& o, const std::optional<Roi>& roi) {
    const WriteOptions as_read{.orientation_known = scan.header.orientation_known};
    write_label_image(o.mask, a.out_mask, as_read);
    if (!a.out_phi.empty()) write_image(o.field->phi(), a.out_phi, as_read);
    if (!a.out_roi.empty()) write_label_image(roi->mask, a.out_roi, as_read);
    if (!a.out_corrected.empty()) write_image(scan.restored(scan.image), a.out_corrected, as_read);
    if (a.out_mesh.empty()) return 0;
    const Mesh mesh = marching_cubes_band(o.field->phi(), o.field->zero_layer());
    write_mesh(a.out_mesh, mesh.view(), o.field->lattice());
    return mesh.triangle_count();
}

int run_segment(const SegmentArgs& a, int threads) {
    const auto guard = limit_threads(threads);
    const InterruptGuard interrupt;
    check_segment_args(a);
    PhaseTimes phases;

    Scan scan = read_scan(a.image);
    phases.mark("read");
    Grid<float>& image = scan.image;
    const ImageHeader& header = scan.header;
    std::optional<Grid<std::uint8_t>> init;
    BrainLookup lookup;
    lookup.options = brain_mask_options(header);
    std::optional<Roi> roi = load_roi(a.roi, image, "--roi", &lookup);
    if (!a.out_roi.empty() && !roi)
        throw UsageError("--out-roi: no ROI to write (a skull-stripped brain, an image where no head is found, or a head where no brain is "
                         "found gets none by default: give --roi auto or a mask)");
    phases.mark("roi");
    SegmentRequest req = segment_request(a, image.lattice());
    if (!a.init_mask.empty()) init = load_mask_like(a.init_mask, image.lattice(), "--init-mask");
    // N4 first, on by default; asked for (or its image to be written), a failure is an error.
    const BiasCorrection mode = bias_mode(a.bias_correct, a.bias_given || !a.out_corrected.empty());
    PreparedImage prepared = prepare_image(image, roi, mode, &interrupt.flag(), &lookup, scan.no_data_mask());
    phases.mark("bias_correction");
    if (prepared.bias && prepared.bias->interrupted) {
        if (!a.quiet) fmt::print(stderr, "liveset: interrupted during bias correction; nothing written\n");
        return 130;
    }
    if (!a.quiet)
        for (const std::string& w : prepared.warnings()) fmt::print(stderr, "liveset: warning: {}\n", w);
    const SeedFit seed_fit = fit_seeds_to_roi(roi, prepared, req.seeds, init ? &*init : nullptr, "--roi none");
    if (!a.quiet)
        for (const std::string& w : seed_fit.warnings) fmt::print(stderr, "liveset: warning: {}\n", w);
    if (!a.out_roi.empty() && !roi) throw UsageError("--out-roi: no ROI to write (the default ROI was given up for the whole image)");
    const Grid<std::uint8_t>* roi_mask = roi ? &roi->mask : nullptr;
    const Grid<std::uint8_t>* fit = prepared.fit(roi_mask);

    add_regions(req, roi, init, fit, prepared);
    req.brain_mask = lookup.options;  // where no region was found: looked for again as the ROI was
    if (!a.quiet) scan.print_note(a.image);  // the inputs are good
    const Lattice lattice = image.lattice();
    // Unless it is to be written (--out-corrected), the image is handed over: freed once the speed
    // is built, one grid of the scan's size less while the front moves.
    const SegmentRun run = a.out_corrected.empty() ? segment_with_progress(std::move(image), req, a.quiet, a.log)
                                                   : segment_with_progress(image, req, a.quiet, a.log);
    if (run.interrupted) return report_interrupt(run.outcome, a.quiet);
    phases.mark("segmentation");
    const SegmentOutcome& o = run.outcome;
    const std::size_t triangles = write_segment_outputs(a, scan, o, roi);
    phases.mark("write");

    nlohmann::json j = segment_report(a, o, lattice, roi, prepared, triangles);
    j["no_data_voxels"] = scan.no_data_voxels;
    j["phase_seconds"] = phases.json();
    for (const std::string& w : seed_fit.warnings) j["warnings"].push_back(w);
    // The default limit reached before convergence: the mask is a front still moving (a grid whose
    // fine voxels keep the time step small, docs/BENCHMARKS.md session 49, or a very large image).
    if (o.result.reason == StopReason::kIterationLimit && !a.iterations_given) {
        const std::string w = fmt::format("the front had not converged after {} iterations (the default limit): give --iterations "
                                          "with a larger number to let it finish",
                                          o.result.iterations);
        if (!a.quiet) fmt::print(stderr, "liveset: warning: {}\n", w);
        j["warnings"].push_back(w);
    }
    const Grid<std::uint8_t>* brain = seed_fit.default_dropped ? nullptr : prepared.fit(nullptr);  // given up: the user's choice
    if (const std::string w = leak_warning(o.mask, brain, "--roi auto"); !w.empty()) {
        if (!a.quiet) fmt::print(stderr, "liveset: warning: {}\n", w);
        j["warnings"].push_back(w);
    }
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        print_segmentation_summary(j);
        if (roi) print_roi_summary(*roi);
        fmt::print("  wrote        {}{}{}{}{}\n", a.out_mask, a.out_phi.empty() ? "" : ", " + a.out_phi,
                   a.out_mesh.empty() ? "" : ", " + a.out_mesh, a.out_roi.empty() ? "" : ", " + a.out_roi,
                   a.out_corrected.empty() ? "" : ", " + a.out_corrected);
        fmt::print("  time         {}\n", phases.line());
    }
    return 0;
}

struct MeshArgs {
    std::string input, out, kind = "auto";
    int fragment = 0;
    bool json = false, quiet = false;
};

int run_mesh(const MeshArgs& a, int threads) {
    const auto guard = limit_threads(threads);
    check_output_path(a.out, OutputKind::kMesh, "--out");
    const Grid<float> input = read_image(a.input);
    const bool is_mask = a.kind == "mask" || (a.kind == "auto" && is_binary_mask(input));
    Grid<float> phi = input;
    if (is_mask) {  // a 0/1 mask: φ from the sparse field's mask initialisation (±0.5 at the border)
        SparseField f(input.lattice(), 2);
        f.init_from_mask(to_mask(input));
        phi = f.phi();
    }
    Mesh mesh;
    int fragments = 1;
    if (a.fragment > 0) {
        std::size_t count = 0;
        mesh = weld_vertices(mesh_in_fragments(phi, a.fragment, &count).view());
        fragments = static_cast<int>(count);
    } else {
        mesh = marching_cubes_slabs(phi);  // == marching_cubes_naive(phi), sign bits + parallel z-slabs
    }
    if (mesh.triangle_count() == 0) throw UsageError(fmt::format("{} holds no surface (no voxel changes sign)", a.input));
    write_mesh(a.out, mesh.view(), input.lattice());
    if (a.json) {
        nlohmann::json j{{"input", a.input}, {"input_kind", is_mask ? "mask" : "phi"}, {"output", a.out},
                         {"vertices", mesh.vertices.size()}, {"triangles", mesh.triangle_count()},
                         {"fragments", fragments}, {"euler", euler_characteristic(mesh.view())},
                         {"components", connected_components(mesh.view())}};
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        fmt::print("liveset mesh: {} ({}) -> {}: {} vertices, {} triangles, Euler characteristic {}\n", a.input,
                   is_mask ? "mask" : "phi", a.out, mesh.vertices.size(), mesh.triangle_count(),
                   euler_characteristic(mesh.view()));
    }
    return 0;
}

}  // namespace

void add_segment_commands(CLI::App& app, const int& threads) {
    static SegmentArgs sa;
    auto* seg = app.add_subcommand("segment", "threshold level-set segmentation from seeds (paper Eq. 2-3)");
    seg->add_option("image", sa.image, "input image: .nii/.nii.gz/.mha/.mhd/.nrrd/.mnc or a DICOM folder")->required();
    seg->add_option("--seed", sa.seeds, "seed voxel I,J,K[:R] (indices as ITK-SNAP shows them, radius in voxels); repeatable");
    seg->add_option("--seed-mm", sa.seeds_mm, "seed X,Y,Z[:R] in physical LPS mm (radius in mm); repeatable");
    seg->add_option("--seed-radius", sa.seed_radius, "default seed radius")->check(finite_number() & CLI::Range(0.5, 100.0))->capture_default_str();
    seg->add_option("--init-mask", sa.init_mask, "start from this mask instead of seeds (needs --mu/--epsilon)");
    seg->add_option("--roi", sa.roi, "region-of-interest mask the front may not leave (e.g. a brain mask); 'auto': a brain mask computed from the T1; "
                    "'none': the whole image. Default: the automatic brain mask when the image is a head, else none");
    add_threshold_options(*seg, sa);  // --mu, --epsilon, --mu-raw, --epsilon-raw, --n, --alpha
    seg->add_option("--window-from", sa.window_from, "estimate the window from the tissue model of the image (the seeds pick the class) or from the seeds' statistics")->check(CLI::IsMember({"model", "seeds"}))->capture_default_str();
    seg->add_option("--classes", sa.classes, "tissue classes of the model (T1 brain: CSF, GM, WM)")->check(CLI::Range(2, 6))->capture_default_str();
    seg->add_option("--coarse-start", sa.coarse_start, fmt::format("converge first on a grid of 2x2x2-voxel blocks, then refine from there: auto (where every voxel side is at most {} mm), on or off; only from seeds, on a grid of at least {} voxels an axis", kCoarseStartMaxSpacing, kCoarseStartMinDim))->check(CLI::IsMember({"auto", "on", "off"}))->capture_default_str();
    seg->add_option("--iterations", sa.iterations, "iteration limit (of each stage with a coarse start)")->check(CLI::Range(1, 10'000'000))->capture_default_str();
    seg->add_option("--out-mask", sa.out_mask, "output mask (0/1, uint8), e.g. seg.nii.gz")->required();
    seg->add_option("--out-phi", sa.out_phi, "output level-set function phi (float, <0 inside)");
    seg->add_option("--out-mesh", sa.out_mesh, "output surface mesh (.ply/.obj/.stl, LPS mm)");
    seg->add_option("--out-roi", sa.out_roi, "write the region of interest used (e.g. the --roi auto brain mask, uint8 0/1)");
    seg->add_option("--log", sa.log, "write one JSON line per iteration to this file");
    auto* iterations = seg->get_option("--iterations");
    auto* bias = seg->add_flag("--bias-correct,!--no-bias-correct", sa.bias_correct, "correct the intensity non-uniformity first (N4, fitted inside --roi, else the automatic brain mask, else Otsu's foreground). Default: on, skipped with a warning where it cannot run (asked for: an error)");
    seg->add_option("--out-corrected", sa.out_corrected, "write the bias-corrected image (float) here");
    seg->add_flag("--json", sa.json, "print the report as one JSON object on stdout");
    seg->add_flag("--quiet,-q", sa.quiet, "no progress line and no report");
    seg->callback([&threads, bias, iterations] {
        sa.bias_given = bias->count() > 0 && sa.bias_correct;
        sa.iterations_given = iterations->count() > 0;
        const int rc = run_segment(sa, threads);
        if (rc != 0) std::exit(rc);
    });

    static MeshArgs ma;
    auto* mesh = app.add_subcommand("mesh", "surface mesh (marching cubes) of a phi image or a 0/1 mask");
    mesh->add_option("input", ma.input, "phi (<0 inside) or mask image")->required();
    mesh->add_option("--out", ma.out, "output mesh .ply/.obj/.stl (LPS mm)")->required();
    mesh->add_option("--fragment", ma.fragment, "mesh with fragments of N cells (0: one whole-lattice pass)")->check(CLI::Range(0, 100000))->capture_default_str();
    mesh->add_option("--input-kind", ma.kind, "auto, phi or mask")->check(CLI::IsMember({"auto", "phi", "mask"}))->capture_default_str();
    mesh->add_flag("--json", ma.json, "print the report as one JSON object on stdout");
    mesh->add_flag("--quiet,-q", ma.quiet, "print nothing");
    mesh->callback([&threads] { run_mesh(ma, threads); });
}

}  // namespace liveset::cli
