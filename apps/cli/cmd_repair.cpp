// `liveset repair`: headless agent-swarm repair of a segmentation where the user points (paper §4),
// for scripts, tests and the demo. Each step: swarm move -> edits -> local level-set update ->
// incremental mesh; one JSON line per step in --log.
#include <fmt/core.h>

#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "liveset/swarm/repair.hpp"

namespace liveset::cli {

namespace {

struct RepairArgs {
    std::string input, image, roi;
    std::vector<std::string> targets, targets_mm;
    RepairOptions options;
    std::string out_phi, out_mask, out_mesh, log;
    std::string decision = "intensity";
    bool json = false, quiet = false;
};

// "I,J,K[@STEP]" -> target (coordinates parsed like a seed).
RepairTarget parse_target(const std::string& text, const Lattice& lattice, bool mm) {
    std::string coords = text;
    int step = 0;
    if (const auto at = text.find('@'); at != std::string::npos) {
        coords = text.substr(0, at);
        const std::string s = text.substr(at + 1);
        try {
            std::size_t used = 0;
            step = std::stoi(s, &used);
            if (used != s.size() || step < 0) throw std::invalid_argument(s);
        } catch (const std::exception&) {
            throw UsageError(fmt::format("bad target '{}': the step after '@' must be a non-negative integer", text));
        }
    }
    if (coords.find(':') != std::string::npos) throw UsageError(fmt::format("bad target '{}': targets take no radius", text));
    const SeedBall b = mm ? parse_seed_mm(coords, lattice, 1.0) : parse_seed_voxel(coords, 1.0);
    if (!lattice.contains(b.center)) throw UsageError(fmt::format("target {} lies outside the image", text));
    return {b.center, step};
}

int run_repair_command(RepairArgs a, int threads) {
    const auto guard = limit_threads(threads);
    const InterruptGuard interrupt;
    if (a.out_phi.empty() && a.out_mask.empty()) throw UsageError("give --out-phi and/or --out-mask");
    if (!a.out_phi.empty()) check_output_path(a.out_phi, OutputKind::kImage, "--out-phi");
    if (!a.out_mask.empty()) check_output_path(a.out_mask, OutputKind::kImage, "--out-mask");
    if (!a.out_mesh.empty()) check_output_path(a.out_mesh, OutputKind::kMesh, "--out-mesh");
    if (!a.log.empty()) check_output_path(a.log, OutputKind::kText, "--log");
    a.options.swarm.decision = a.decision == "random" ? EditDecision::kRandom : EditDecision::kIntensity;
    if (a.targets.empty() && a.targets_mm.empty()) throw UsageError("give at least one --target I,J,K[@STEP] (or --target-mm)");
    try {
        validate(a.options.swarm);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }

    const Grid<float> image = read_image(a.image);
    std::optional<Grid<std::uint8_t>> roi;
    if (!a.roi.empty()) roi = load_mask_like(a.roi, image.lattice(), "--roi");
    std::vector<RepairTarget> targets;
    for (const std::string& t : a.targets) targets.push_back(parse_target(t, image.lattice(), false));
    for (const std::string& t : a.targets_mm) targets.push_back(parse_target(t, image.lattice(), true));
    SparseField field = load_level_set(a.input, image.lattice());
    const Grid<float> unit = normalise(image, robust_scale(image, roi ? &*roi : nullptr));

    FragmentMesher mesher(image.lattice(), 8);
    mesher.full_rebuild(field.phi(), field.zero_layer());
    const std::vector<RepairStepLog> log =
        run_repair(field, unit, roi ? &*roi : nullptr, targets, a.options, &mesher, &interrupt.flag());
    if (interrupt.interrupted()) {
        if (!a.quiet) fmt::print(stderr, "liveset: interrupted after {} steps; nothing written\n", log.size());
        return 130;
    }
    const Grid<std::uint8_t> mask = inside_mask(field.phi(), roi ? &*roi : nullptr);
    if (!a.out_phi.empty()) write_image(field.phi(), a.out_phi);
    if (!a.out_mask.empty()) write_label_image(mask, a.out_mask);
    if (!a.out_mesh.empty()) write_mesh(a.out_mesh, marching_cubes_band(field.phi(), field.zero_layer()).view(), image.lattice());
    std::size_t modified = 0, fragments = 0;
    double ms = 0;
    std::string lines;
    for (const RepairStepLog& r : log) {
        modified += r.modified;
        fragments += r.fragments;
        ms += r.ms;
        lines += fmt::format("{{\"step\":{},\"agents_on_surface\":{},\"points_modified\":{},\"changed\":{},\"fragments_rebuilt\":{},\"ms\":{:.4f}}}\n",
                             r.step, r.on_surface, r.modified, r.changed, r.fragments, r.ms);
    }
    if (!a.log.empty()) write_atomically(a.log, lines);
    nlohmann::json j{{"steps", log.size()}, {"agents", a.options.swarm.agents}, {"points_modified", modified},
                     {"fragments_rebuilt", fragments}, {"ms_per_step", log.empty() ? 0.0 : ms / static_cast<double>(log.size())},
                     {"agents_on_surface_end", log.empty() ? 0 : log.back().on_surface}};
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        fmt::print("liveset repair: {} steps of {} agents, {} point edits, {} fragment rebuilds, {:.3f} ms/step\n", log.size(),
                   a.options.swarm.agents, modified, fragments, j["ms_per_step"].get<double>());
    }
    return 0;
}

}  // namespace

void add_repair_command(CLI::App& app, const int& threads) {
    static RepairArgs ra;
    auto* r = app.add_subcommand("repair", "agent-swarm repair of a segmentation around target points (paper section 4)");
    r->add_option("input", ra.input, "phi (<0 inside) or 0/1 mask to repair")->required();
    r->add_option("--image", ra.image, "the image the segmentation came from")->required();
    r->add_option("--target", ra.targets, "target voxel I,J,K[@STEP] (from step STEP on; default 0); repeatable");
    r->add_option("--target-mm", ra.targets_mm, "target X,Y,Z[@STEP] in physical LPS mm; repeatable");
    r->add_option("--roi", ra.roi, "region-of-interest mask the surface may not grow out of");
    r->add_option("--agents", ra.options.swarm.agents, "number of agents")->check(CLI::Range(1, 1'000'000))->capture_default_str();
    r->add_option("--steps", ra.options.steps, "swarm steps")->check(CLI::Range(0, 10'000'000))->capture_default_str();
    r->add_option("--p", ra.options.swarm.act_probability, "probability that an agent edits per step")->check(finite_number())->capture_default_str();
    r->add_option("--radius", ra.options.swarm.edit_radius, "edit radius, voxels")->check(finite_number())->capture_default_str();
    r->add_option("--respawn-distance", ra.options.respawn_distance, "a target farther than this (voxels) from the swarm respawns it there (0: never)")->check(CLI::Range(0.0, 1e6))->capture_default_str();
    r->add_option("--seed", ra.options.swarm.seed, "random seed")->capture_default_str();
    r->add_option("--amount", ra.options.swarm.edit_amount, "|dphi| under an acting agent (<= 0.5)")->check(finite_number())->capture_default_str();
    r->add_option("--expand-sigmas", ra.options.swarm.expand_sigmas, "expand where the outside intensity is within this many population sigmas")->check(finite_number())->capture_default_str();
    r->add_option("--contract-sigmas", ra.options.swarm.contract_sigmas, "contract where the inside intensity is beyond this many sigmas")->check(finite_number())->capture_default_str();
    r->add_option("--sample-depth", ra.options.swarm.sample_depth, "population samples this many voxels inside the surface (0: at the agents)")->check(finite_number())->capture_default_str();
    r->add_option("--edit-range", ra.options.swarm.edit_range, "only agents within this many voxels of the target edit (0: all)")->check(finite_number())->capture_default_str();
    r->add_option("--decision", ra.decision, "how acting agents edit: intensity (the repair rule) or random (raise/lower at random, the paper's speed test)")
        ->check(CLI::IsMember({"intensity", "random"}))
        ->capture_default_str();
    r->add_flag("--no-topology-guard{false}", ra.options.topology_guard, "let edits bridge pieces or open tunnels (by default they cannot)");
    r->add_option("--out-phi", ra.out_phi, "repaired phi");
    r->add_option("--out-mask", ra.out_mask, "repaired mask");
    r->add_option("--out-mesh", ra.out_mesh, "repaired surface (.ply/.obj/.stl)");
    r->add_option("--log", ra.log, "one JSON line per step: step, agents_on_surface, points_modified, changed, fragments_rebuilt, ms");
    r->add_flag("--json", ra.json, "print the summary as one JSON object");
    r->add_flag("--quiet,-q", ra.quiet, "print nothing");
    r->callback([&threads] {
        const int rc = run_repair_command(ra, threads);
        if (rc != 0) std::exit(rc);
    });
}

}  // namespace liveset::cli
