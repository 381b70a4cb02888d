// `liveset demo --brain`: the real-brain path on the bundled BrainWeb sample (data/brainweb) —
// N4 bias correction -> seeds only (the window from the tissue model) -> segment -> mesh -> eval against the crisp grey-
// matter labels, with a report like the phantom demo's and every output in one folder.
#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "demo_brain.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "liveset/render/surface_picture.hpp"

namespace liveset::cli {

namespace {

double ms_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// The seeds a user would click in clearly grey voxels all over the cortex (voxel indices).
const std::vector<Vec3i> kBrainSeeds = {{35, 83, 113}, {35, 125, 38}, {44, 164, 92},  {71, 74, 53},
                                        {122, 149, 47}, {140, 86, 74}, {38, 71, 26}, {83, 23, 71}};

}  // namespace

int run_brain_demo(const BrainDemoArgs& a, int threads) {
    namespace fs = std::filesystem;
    const auto guard = limit_threads(threads);
    const fs::path data(a.data), dir(a.out);
    for (const char* f : {"t1.mha", "labels_crisp.nii.gz", "brain_mask.nii.gz"})
        if (!fs::exists(data / f))
            throw UsageError(fmt::format("the BrainWeb sample is missing: {} not found (give --data DIR)", (data / f).string()));
    std::error_code ec;
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir)) throw UsageError(fmt::format("cannot create output folder {}", a.out));
    check_output_path((dir / "seg.nii.gz").string(), OutputKind::kImage, "--out");

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
    req.loop.step = sleeping_step();  // as `liveset segment`
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

    write_label_image(o.mask, (dir / "seg.nii.gz").string());
    write_image(o.field->phi(), (dir / "phi.nii.gz").string());
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
    try {  // the surface seen from above (headless EGL; a warning where there is no OpenGL)
        FragmentMesher mesher(t1.lattice(), 16);
        mesher.full_rebuild(o.field->phi(), o.field->zero_layer());
        render::render_surface_png(mesher, (dir / "surface.png").string(), "superior", 800, 800, 2);
        j["screenshots"] = {{"surface", "surface.png"}};
    } catch (const std::exception& e) {
        fmt::print(stderr, "liveset: warning: no picture: {}\n", e.what());
    }
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
        fmt::print("  outputs      {}/ (seg.nii.gz, phi.nii.gz, surface.ply, surface.png, report.json)\n", a.out);
    }
    return 0;
}

}  // namespace liveset::cli
