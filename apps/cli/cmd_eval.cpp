// `liveset eval` (overlap, surface distance and topology of a mask against a ground truth) and
// `liveset phantom` (the synthetic cortex MR volume with its exact ground truth).
#include <fmt/core.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "image_commands.hpp"
#include "liveset/eval/perforations.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/phantom/phantom.hpp"

namespace liveset::cli {

namespace {

struct EvalArgs {
    std::string mask, truth;
    // Each a set of labels (none: non-zero); several name one structure (FreeSurfer's aseg: cortex 3
    // and 42, white matter 2 and 41).
    std::vector<int> label, mask_label, inner_label;
    int max_sites = 20;
    bool json = false;
};

// Hole sites as JSON: index-space centroid, the voxel nearest it (a ready --target) and the size.
nlohmann::json sites_json(const std::vector<Perforation>& sites, int limit) {
    nlohmann::json a = nlohmann::json::array();
    for (std::size_t k = 0; k < sites.size() && static_cast<int>(k) < limit; ++k) {
        const Perforation& p = sites[k];
        a.push_back({{"voxels", p.voxels}, {"centroid", {p.centroid.x, p.centroid.y, p.centroid.z}},
                     {"target", {p.nearest.x, p.nearest.y, p.nearest.z}}});
    }
    return a;
}

Grid<std::uint8_t> select_label(Grid<std::uint8_t> g, const std::vector<int>& labels) {
    std::array<std::uint8_t, 256> in{};
    for (int l : labels) in[static_cast<std::size_t>(l)] = 1;
    for (std::uint8_t& v : g.values()) v = labels.empty() ? v != 0 : in[v];
    return g;
}

std::string label_text(const std::vector<int>& labels) { return fmt::format("{}", fmt::join(labels, ",")); }

void run_eval(const EvalArgs& a, int threads) {
    const auto guard = limit_threads(threads);
    if (!a.inner_label.empty() && a.label.empty()) throw UsageError("--inner-label needs --label (both index the truth's label image)");
    for (int l : a.inner_label)
        if (std::find(a.label.begin(), a.label.end(), l) != a.label.end())
            throw UsageError(fmt::format("--inner-label {} is also a --label: the two must differ", l));
    const Grid<std::uint8_t> labels = read_label_image(a.truth);
    const Grid<std::uint8_t> truth = select_label(labels, a.label);
    const Grid<std::uint8_t> mask = select_label(read_label_image(a.mask), a.mask_label);
    try {
        require_same_geometry(mask.lattice(), truth.lattice(), "eval");
    } catch (const std::invalid_argument& e) {
        throw UsageError(fmt::format("{} and {} do not overlay: {}", a.mask, a.truth, e.what()));
    }
    std::size_t n = 0;
    for (std::uint8_t v : truth.values()) n += v;
    if (n == 0)
        throw UsageError(!a.label.empty() ? fmt::format("{} has no voxel with label {}", a.truth, label_text(a.label))
                                      : fmt::format("{} is empty (no non-zero voxel)", a.truth));
    nlohmann::json j = evaluation_report(mask, truth);
    j["mask"] = a.mask;
    j["truth"]["path"] = a.truth;
    if (a.label.size() == 1) j["truth"]["label"] = a.label[0];
    if (!a.label.empty()) j["truth"]["labels"] = a.label;
    std::vector<Perforation> perforations, cavities;
    if (!a.inner_label.empty()) {  // where to point a repair: tunnels through the structure, bubbles in it
        const Grid<std::uint8_t> inner = select_label(labels, a.inner_label);
        perforations = find_perforations(mask, truth, inner);
        cavities = find_cavities(mask, inner);
        j["perforations"] = perforations.size();
        j["cavities_spurious"] = cavities.size();
        j["sites"] = {{"perforations", sites_json(perforations, a.max_sites)}, {"cavities", sites_json(cavities, a.max_sites)}};
    }
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else {
        fmt::print("liveset eval: {} against {}{}\n", a.mask, a.truth,
                   a.label.empty() ? std::string() : fmt::format(" (label{} {})", a.label.size() > 1 ? "s" : "", label_text(a.label)));
        print_evaluation(j);
        if (!a.inner_label.empty()) {
            fmt::print("  hole sites: {} perforation(s) through the structure to label {}, {} spurious cavity(ies); largest:\n",
                       perforations.size(), label_text(a.inner_label), cavities.size());
            for (const auto* list : {&perforations, &cavities})
                for (std::size_t k = 0; k < list->size() && static_cast<int>(k) < std::min(a.max_sites, 5); ++k) {
                    const Perforation& p = (*list)[k];
                    fmt::print("    {:<11} {:>6} voxels  --target {},{},{}\n", list == &perforations ? "perforation" : "cavity", p.voxels,
                               p.nearest.x, p.nearest.y, p.nearest.z);
                }
        }
    }
}

struct PhantomArgs {
    std::string out;
    PhantomOptions options;
    bool json = false, quiet = false;
};

nlohmann::json voxels_json(const std::vector<Vec3i>& v) {
    nlohmann::json a = nlohmann::json::array();
    for (const Vec3i& p : v) a.push_back({p.x, p.y, p.z});
    return a;
}

void run_phantom(const PhantomArgs& a, int threads) {
    namespace fs = std::filesystem;
    const auto guard = limit_threads(threads);
    try {
        validate(a.options);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    std::error_code ec;
    fs::create_directories(a.out, ec);
    if (ec || !fs::is_directory(a.out)) throw UsageError(fmt::format("cannot create output folder {}", a.out));
    const fs::path dir(a.out);
    check_output_path((dir / "t1.nii.gz").string(), OutputKind::kImage, "--out");
    const Phantom ph = make_phantom(a.options);
    write_image(ph.image, (dir / "t1.nii.gz").string());
    write_label_image(ph.labels, (dir / "labels.nii.gz").string());
    write_label_image(ph.truth, (dir / "truth_gm.nii.gz").string());
    write_image(ph.bias_field, (dir / "bias.nii.gz").string());
    const IntensityWindow w = gm_window(ph);
    nlohmann::json j;
    j["size"] = a.options.size;
    j["spacing_mm"] = a.options.spacing_mm;
    j["seed"] = a.options.seed;
    j["noise"] = a.options.noise;
    j["bias"] = a.options.bias;
    j["intensities"] = {{"wm", ph.wm_intensity}, {"gm", ph.gm_intensity}, {"csf", ph.csf_intensity}, {"background", ph.background_intensity}};
    j["gm_window_raw"] = {{"lo", w.lo}, {"hi", w.hi}, {"mu", w.centre()}, {"epsilon", w.half_width()}};
    j["seeds"] = voxels_json(ph.seeds);
    j["weak_spots"] = voxels_json(ph.weak_spots);
    j["files"] = {{"image", "t1.nii.gz"}, {"labels", "labels.nii.gz"}, {"truth", "truth_gm.nii.gz"}, {"bias", "bias.nii.gz"}};
    write_atomically((dir / "phantom.json").string(), j.dump(2) + "\n");
    if (a.json) {
        fmt::print("{}\n", j.dump());
    } else if (!a.quiet) {
        std::string seeds;
        for (const Vec3i& s : ph.seeds) seeds += fmt::format(" --seed {},{},{}", s.x, s.y, s.z);
        fmt::print("liveset phantom: {}^3 voxels of {} mm in {} (t1.nii.gz, labels.nii.gz, truth_gm.nii.gz, bias.nii.gz, phantom.json)\n",
                   a.options.size, a.options.spacing_mm, a.out);
        fmt::print("  grey matter window {:.0f}..{:.0f}; segment it with:\n  liveset segment {}{} --out-mask seg.nii.gz\n", w.lo,
                   w.hi, (dir / "t1.nii.gz").string(), seeds);
    }
}

}  // namespace

void add_eval_commands(CLI::App& app, const int& threads) {
    static EvalArgs ea;
    auto* ev = app.add_subcommand("eval", "compare a mask with a ground truth: Dice, Jaccard, HD95, topology and holes");
    ev->add_option("--mask", ea.mask, "segmentation mask (non-zero = foreground)")->required();
    ev->add_option("--truth", ea.truth, "ground-truth mask or label image")->required();
    ev->add_option("--label", ea.label, "use truth == LABEL (e.g. 2 = grey matter in BrainWeb labels); several, repeated or comma-separated, are one structure (FreeSurfer aseg cortex: 3,42)")
        ->delimiter(',')->check(CLI::Range(0, 255));
    ev->add_option("--mask-label", ea.mask_label, "use mask == LABEL (several: any of them)")->delimiter(',')->check(CLI::Range(0, 255));
    ev->add_option("--inner-label", ea.inner_label, "also locate the holes to repair: perforations through the structure to truth == LABEL (e.g. 3 = white matter under grey matter; aseg: 2,41) and spurious cavities")
        ->delimiter(',')->check(CLI::Range(0, 255));
    ev->add_option("--max-sites", ea.max_sites, "hole sites listed per kind in the JSON report")->check(CLI::Range(0, 100000))->capture_default_str();
    ev->add_flag("--json", ea.json, "print one JSON object (dice, jaccard, volume_difference, hausdorff95_mm, components, euler, genus, holes)");
    ev->callback([&threads] { run_eval(ea, threads); });

    static PhantomArgs pa;
    auto* ph = app.add_subcommand("phantom", "write the synthetic cortex MR phantom and its ground truth");
    ph->add_option("--out", pa.out, "output folder")->required();
    ph->add_option("--size", pa.options.size, "voxels per axis")->check(CLI::Range(32, 512))->capture_default_str();
    ph->add_option("--spacing", pa.options.spacing_mm, "voxel size in mm")->check(finite_number())->capture_default_str();
    ph->add_option("--seed", pa.options.seed, "noise seed")->capture_default_str();
    ph->add_option("--anatomy-seed", pa.options.anatomy_seed, "folding pattern seed")->capture_default_str();
    ph->add_option("--noise", pa.options.noise, "noise sigma / WM intensity")->check(finite_number())->capture_default_str();
    ph->add_option("--bias", pa.options.bias, "peak bias-field gain")->check(finite_number())->capture_default_str();
    ph->add_flag("--json", pa.json, "print the description as one JSON object");
    ph->add_flag("--quiet,-q", pa.quiet, "print nothing");
    ph->callback([&threads] { run_phantom(pa, threads); });
}

}  // namespace liveset::cli
