// `liveset demo --brain`: the real-brain path on the bundled BrainWeb sample (data/brainweb) —
// N4 bias correction -> seeds only (the window from the tissue model) -> segment -> mesh -> eval against the crisp grey-
// matter labels, with a report like the phantom demo's and every output in one folder.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "demo_brain.hpp"
#include "finder_repair.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "demo_pictures.hpp"
#include "liveset/render/surface_picture.hpp"
#include "liveset/segment/window.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::cli {

namespace {

constexpr double kLowThreshold = 0.8;           // ε of the --repair segmentation: 80 % of the model window's
constexpr double kLowThresholdMinSigmas = 2.4;  // ... but at least 2.4 σ of the GM class (low_threshold)

// The seeds a user would click in clearly grey voxels all over the cortex (voxel indices).
const std::vector<Vec3i> kBrainSeeds = {{35, 83, 113}, {35, 125, 38}, {44, 164, 92},  {71, 74, 53},
                                        {122, 149, 47}, {140, 86, 74}, {38, 71, 26}, {83, 23, 71}};

// The demo's sub-optimally low threshold (--repair): the tissue model's window for the seeds' class,
// narrowed to kLowThreshold of its half width around the same centre — but never
// below kLowThresholdMinSigmas of the class's fitted σ (noise included), nor wider than the
// window: on a noisy scan the plain narrowing leaves so much of the grey matter outside that the
// front stalls at the seeds (BrainWeb + noise σ 9: Dice 0.18) instead of leaving holes. Also fills
// the grey matter's band and class mean for the finder and the sheet rule.
void low_threshold(const Grid<float>& t1, const Grid<std::uint8_t>& roi, SegmentRequest& req, FoundHolesInput& band) {
    std::vector<std::string> warnings;
    const Grid<std::uint8_t> region = model_region(t1, nullptr, &roi, 3);
    const std::optional<TissueModel> model = fit_window_model(t1, region, TissueModelOptions{}, warnings);
    if (!model || !model->usable()) throw UsageError("demo --brain --repair: the tissue model cannot be fitted to the T1");
    std::vector<float> seed_values;
    for (const Vec3i& s : kBrainSeeds)
        for (int dz = -2; dz <= 2; ++dz)
            for (int dy = -2; dy <= 2; ++dy)
                for (int dx = -2; dx <= 2; ++dx)
                    if (dx * dx + dy * dy + dz * dz <= 4) seed_values.push_back(t1(s + Vec3i{dx, dy, dz}));
    const ModelWindow w = model_window(*model, seed_values);
    req.mu_raw = w.mu();
    const double sigma = model->classes[static_cast<std::size_t>(w.seed_class)].sigma;
    req.epsilon_raw = std::max(kLowThreshold * w.epsilon(), std::min(w.epsilon(), kLowThresholdMinSigmas * sigma));
    req.alpha = 0.1;  // the paper's Figure 5 set-up: a small curvature, holes from the window alone
    band.band = {w.lower, w.upper, model->classes[static_cast<std::size_t>(w.seed_class)].mean};
}

// The sample's three files present and the output folder writable (one line each otherwise).
void check_brain_inputs(const BrainDemoArgs& a) {
    namespace fs = std::filesystem;
    const fs::path data(a.data), dir(a.out);
    for (const char* f : {"t1.mha", "labels_crisp.nii.gz", "brain_mask.nii.gz"})
        if (!fs::exists(data / f))
            throw UsageError(fmt::format("the BrainWeb sample is missing: {} not found (give --data DIR)", (data / f).string()));
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) throw UsageError(fmt::format("cannot create output folder {}", a.out));
    check_output_path((dir / "seg.nii.gz").string(), OutputKind::kImage, "--out");
}

// The superior-view pictures (surface.png; with --repair before.png and after.png) and, with
// --repair, the report's before/after/targets/repair objects.
void add_pictures(nlohmann::json& j, const BrainDemoArgs& a, const std::filesystem::path& dir, const Grid<float>& phi_before,
                  const FragmentMesher& mesher, const nlohmann::json& ev, const nlohmann::json& after, const nlohmann::json& repair) {
    if (a.repair) {
        j["demo"] = "BrainWeb T1 -> sub-optimally low threshold (the tissue model's window, epsilon x 0.8) -> segment -> truth-free hole "
                    "finder -> 200-agent sheet-rule repair at its 10 largest holes -> eval before/after against the grey-matter labels";
        j["before"] = ev;
        j["after"] = after;
        j["targets"] = repair["targets"];
        j["repair"] = repair;
        j["dice"] = after["dice"];
        j["screenshots"] = write_before_after_pictures(dir, phi_before, mesher);  // superior view, headless
    } else {
        try {  // the surface seen from above (headless EGL; a warning where there is no OpenGL)
            render::render_surface_png(mesher, (dir / "surface.png").string(), "superior", 800, 800, 2);
            j["screenshots"] = {{"surface", "surface.png"}};
        } catch (const std::exception& e) {
            fmt::print(stderr, "liveset: warning: no picture: {}\n", e.what());
        }
    }
}

// The text summary of --repair: the finder's targets, their verdicts, Dice and holes before/after.
void print_repair_summary(const nlohmann::json& j) {
    const nlohmann::json& r = j["repair"];
    fmt::print("  repair       {} targets from the truth-free finder (>= {} voxels), {} agents x {} steps each, sheet rule:\n"
               "               {} of {} closed by the finder's verdict, {} voxels added, {:.3f} ms/step; finder holes {} -> {}\n",
               r["targets"].size(), r["finder"]["min_voxels"].get<std::size_t>(), r["agents"].get<std::size_t>(), r["round_steps"].get<int>(),
               r["closed"].get<std::size_t>(), r["targets"].size(), r["voxels_added"].get<std::size_t>(), r["ms_per_step"].get<double>(),
               r["finder"]["before"].get<std::size_t>(), r["finder"]["after"].get<std::size_t>());
    fmt::print("  before       dice {:.4f}  holes {}\n", j["before"]["dice"].get<double>(), j["before"]["holes"].get<long>());
    fmt::print("  after        dice {:.4f}  holes {}\n", j["after"]["dice"].get<double>(), j["after"]["holes"].get<long>());
}

}  // namespace

// The real-brain demo step by step (N4, segmentation, the session's mesh, evaluation, optional
// repair, outputs, report): a little over 80 lines, kept in one piece so it reads as the pipeline.
int run_brain_demo(const BrainDemoArgs& a, int threads) {
    namespace fs = std::filesystem;
    const auto guard = limit_threads(threads);
    const fs::path data(a.data), dir(a.out);
    check_brain_inputs(a);

    Grid<float> t1 = read_image((data / "t1.mha").string());
    Grid<std::uint8_t> truth = read_label_image((data / "labels_crisp.nii.gz").string());  // read once
    if (!truth.lattice().same_geometry(t1.lattice())) throw UsageError("labels_crisp.nii.gz does not overlay t1.mha");
    for (std::uint8_t& v : truth.values()) v = v == 2;  // grey matter
    const Grid<std::uint8_t> roi = load_mask_like((data / "brain_mask.nii.gz").string(), t1.lattice(), "brain mask");

    // As `liveset segment` does by default: N4 inside the brain mask first.
    BiasCorrectionReport bias;
    const InterruptGuard interrupt;
    t1 = correct_bias(t1, &roi, {}, &bias, &interrupt.flag());
    if (bias.interrupted) {
        fmt::print(stderr, "liveset: interrupted; nothing written\n");
        return 130;
    }
    SegmentRequest req;
    for (const Vec3i& s : kBrainSeeds) req.seeds.push_back({{double(s.x), double(s.y), double(s.z)}, 2.0});
    req.roi = &roi;
    req.loop.step = segment_step();  // as `liveset segment`
    FoundHolesInput rin{t1, &roi, {}};
    if (a.repair) low_threshold(t1, roi, req, rin);
    const SegmentRun run = segment_with_progress(t1, req, a.quiet || a.json);
    if (run.interrupted) {
        fmt::print(stderr, "liveset: interrupted; nothing written\n");
        return 130;
    }
    const SegmentOutcome& o = run.outcome;
    auto t0 = std::chrono::steady_clock::now();
    const Mesh surface = marching_cubes_band(o.field->phi(), o.field->zero_layer());
    const double mesh_ms = ms_since(t0);
    t0 = std::chrono::steady_clock::now();
    const nlohmann::json ev = evaluation_report(o.mask, truth);
    const double eval_ms = ms_since(t0);
    nlohmann::json repair, after;
    // The rest edits through a Session (the viewer's edit path), which takes the segmentation over
    // bit for bit with its intensity scale, and meshes it (16³-cell fragments).
    SessionOptions session_options;
    session_options.given_scale = o.scale;
    Session session(t1, session_options, roi);
    if (!session.load_recovered(o.field->phi(), o.field->status(), SessionMarks{}))
        throw std::logic_error("the session did not take the segmentation's level set over exactly");
    const FragmentMesher& mesher = session.mesher();
    const Grid<float> phi_before = o.field->phi();
    if (a.repair) {
        if (!a.quiet && !a.json) fmt::print("  segmented with a low threshold (epsilon {:.1f} raw, the model's {:.1f} x {}, at least {} sigma); repairing...\n", req.epsilon_raw.value_or(0.0),
                       rin.band.upper / 2 - rin.band.lower / 2, kLowThreshold, kLowThresholdMinSigmas);
        rin.scale = o.scale;
        repair = repair_found_holes(rin, session, true);
        repair["low_threshold"] = kLowThreshold;
        repair["low_threshold_min_sigmas"] = kLowThresholdMinSigmas;
        after = evaluation_report(inside_mask(session.field().phi(), &roi), truth);
    }

    write_label_image(o.mask, (dir / "seg.nii.gz").string());
    write_image(phi_before, (dir / "phi.nii.gz").string());
    if (a.repair) {
        write_label_image(inside_mask(session.field().phi(), &roi), (dir / "seg_repaired.nii.gz").string());
        write_image(session.field().phi(), (dir / "phi_repaired.nii.gz").string());
    }
    write_mesh(dir / "surface.ply", surface.view(), t1.lattice());
    nlohmann::json j;
    j["demo"] = "BrainWeb T1 -> seeds only (tissue-model window) -> segment -> mesh -> eval against the grey-matter labels";
    j["data"] = a.data;
    nlohmann::json seeds = nlohmann::json::array();
    for (const Vec3i& s : kBrainSeeds) seeds.push_back({s.x, s.y, s.z});
    j["seeds"] = seeds;
    j["roi"] = "brain_mask.nii.gz";
    j["bias_correction"] = bias_correction_report(bias);
    j["segmentation"] = segmentation_report(o, t1.lattice());
    j["mesh"] = {{"triangles", surface.triangle_count()}, {"vertices", surface.vertices.size()}, {"ms", mesh_ms}};
    j["eval"] = ev;
    j["dice"] = ev["dice"];
    j["timings_ms"] = {{"bias_correction", bias.ms}, {"segment", 1000.0 * o.result.seconds}, {"mesh", mesh_ms}, {"eval", eval_ms}};
    j["outputs"] = a.out;
    add_pictures(j, a, dir, phi_before, mesher, ev, after, repair);
    write_atomically((dir / "report.json").string(), j.dump(2) + "\n");
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        fmt::print("liveset demo --brain: grey matter of the BrainWeb T1 ({}) from {} seeds alone\n", a.data, kBrainSeeds.size());
        fmt::print("  bias field   N4 inside the brain mask, {:.1f} s, field {:.2f} .. {:.2f}\n", bias.ms / 1000.0, bias.field_min,
                   bias.field_max);
        print_segmentation_summary(j["segmentation"]);
        fmt::print("  mesh         {} triangles, {:.1f} ms\n", surface.triangle_count(), mesh_ms);
        fmt::print("  evaluation   against BrainWeb's grey-matter labels ({:.0f} ms):\n", eval_ms);
        print_evaluation(ev, "               ");
        if (a.repair) print_repair_summary(j);
        fmt::print("  outputs      {}/ (seg{}.nii.gz, phi.nii.gz, surface.ply, {}, report.json)\n", a.out, a.repair ? ", seg_repaired" : "",
                   a.repair ? "before.png, after.png" : "surface.png");
    }
    return 0;
}

}  // namespace liveset::cli
