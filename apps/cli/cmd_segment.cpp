// `liveset segment` (threshold level set from seeds, paper Eq. 2-3) and `liveset mesh` (φ or mask
// to a surface mesh). Outputs are checked before the run and written atomically; Ctrl-C stops the
// run and writes nothing.
#include <fmt/core.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <optional>

#include "cli_common.hpp"
#include "cli_support.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/mesh/mesh_io.hpp"

namespace liveset::cli {

namespace {

struct SegmentArgs {
    std::string image;
    std::vector<std::string> seeds, seeds_mm;
    double seed_radius = 2.0;
    std::string init_mask, roi;
    std::optional<double> mu, epsilon, mu_raw, epsilon_raw;
    double n = 4.0, alpha = 0.1;
    int iterations = 2000;
    std::string out_mask, out_phi, out_mesh, log;
    bool json = false, quiet = false;
};

int run_segment(const SegmentArgs& a, int threads) {
    const auto guard = limit_threads(threads);
    const InterruptGuard interrupt;
    check_output_path(a.out_mask, OutputKind::kImage, "--out-mask");
    if (!a.out_phi.empty()) check_output_path(a.out_phi, OutputKind::kImage, "--out-phi");
    if (!a.out_mesh.empty()) check_output_path(a.out_mesh, OutputKind::kMesh, "--out-mesh");
    if (!a.log.empty()) check_output_path(a.log, OutputKind::kText, "--log");
    if (a.mu && a.mu_raw) throw UsageError("give --mu or --mu-raw, not both");
    if (a.epsilon && a.epsilon_raw) throw UsageError("give --epsilon or --epsilon-raw, not both");
    if (a.seeds.empty() && a.seeds_mm.empty() && a.init_mask.empty())
        throw UsageError("give at least one --seed I,J,K[:R] (or --seed-mm, or --init-mask)");

    const Grid<float> image = read_image(a.image);
    std::optional<Grid<std::uint8_t>> roi, init;
    if (!a.roi.empty()) roi = load_mask_like(a.roi, image.lattice(), "--roi");
    if (!a.init_mask.empty()) init = load_mask_like(a.init_mask, image.lattice(), "--init-mask");

    SegmentRequest req;
    for (const std::string& s : a.seeds) {
        req.seeds.push_back(parse_seed_voxel(s, a.seed_radius));
        check_seed_inside(req.seeds.back(), image.lattice(), s);
    }
    for (const std::string& s : a.seeds_mm) {
        req.seeds.push_back(parse_seed_mm(s, image.lattice(), a.seed_radius));
        check_seed_inside(req.seeds.back(), image.lattice(), s + " (mm)");
    }
    if (roi) req.roi = &*roi;
    if (init) req.initial_mask = &*init;
    req.n = a.n;
    req.alpha = a.alpha;
    req.loop.max_iterations = a.iterations;
    req.loop.step = sleeping_step();  // converged stretches of front sleep (docs/ARCHITECTURE.md)
    req.mu = a.mu;
    req.epsilon = a.epsilon;
    req.mu_raw = a.mu_raw;
    req.epsilon_raw = a.epsilon_raw;

    const SegmentRun run = segment_with_progress(image, req, a.quiet, a.log);
    if (run.interrupted) {
        if (!a.quiet) fmt::print(stderr, "liveset: interrupted after {} iterations; nothing written\n", run.outcome.result.iterations);
        return 130;
    }
    const SegmentOutcome& o = run.outcome;
    write_label_image(o.mask, a.out_mask);
    if (!a.out_phi.empty()) write_image(o.field->phi(), a.out_phi);
    std::size_t triangles = 0;
    if (!a.out_mesh.empty()) {
        const Mesh mesh = marching_cubes_band(o.field->phi(), o.field->zero_layer());
        triangles = mesh.triangle_count();
        write_mesh(a.out_mesh, mesh.view(), image.lattice());
    }

    nlohmann::json j = segmentation_report(o, image.lattice());
    j["image"] = a.image;
    j["outputs"] = {{"mask", a.out_mask}};
    if (!a.out_phi.empty()) j["outputs"]["phi"] = a.out_phi;
    if (!a.out_mesh.empty()) {
        j["outputs"]["mesh"] = a.out_mesh;
        j["mesh_triangles"] = triangles;
    }
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        print_segmentation_summary(j);
        fmt::print("  wrote        {}{}{}\n", a.out_mask, a.out_phi.empty() ? "" : ", " + a.out_phi,
                   a.out_mesh.empty() ? "" : ", " + a.out_mesh);
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
        FragmentMesher m(input.lattice(), a.fragment);
        m.full_rebuild(phi);
        fragments = static_cast<int>(m.fragment_count());
        mesh = weld_vertices(m.merged().view());
    } else {
        mesh = marching_cubes_naive(phi);
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
    seg->add_option("--roi", sa.roi, "region-of-interest mask the front may not leave (e.g. a brain mask)");
    seg->add_option("--mu", sa.mu, "ideal intensity, normalised to [0,1] (default: estimated from the seeds)")->check(finite_number());
    seg->add_option("--epsilon", sa.epsilon, "half window, normalised units (default: estimated from the seeds)")->check(finite_number());
    seg->add_option("--mu-raw", sa.mu_raw, "ideal intensity in the image's own units")->check(finite_number());
    seg->add_option("--epsilon-raw", sa.epsilon_raw, "half window in the image's own units")->check(finite_number());
    seg->add_option("--n", sa.n, "steepness of the threshold term")->check(finite_number())->capture_default_str();
    seg->add_option("--alpha", sa.alpha, "curvature weight in [0,1)")->check(finite_number())->capture_default_str();
    seg->add_option("--iterations", sa.iterations, "iteration limit")->check(CLI::Range(1, 10'000'000))->capture_default_str();
    seg->add_option("--out-mask", sa.out_mask, "output mask (0/1, uint8), e.g. seg.nii.gz")->required();
    seg->add_option("--out-phi", sa.out_phi, "output level-set function phi (float, <0 inside)");
    seg->add_option("--out-mesh", sa.out_mesh, "output surface mesh (.ply/.obj/.stl, LPS mm)");
    seg->add_option("--log", sa.log, "write one JSON line per iteration to this file");
    seg->add_flag("--json", sa.json, "print the report as one JSON object on stdout");
    seg->add_flag("--quiet,-q", sa.quiet, "no progress line and no report");
    seg->callback([&threads] {
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
