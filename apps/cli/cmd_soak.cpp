// `liveset bench soak`: the long-run check. On a real surface (a φ or mask, e.g. the BrainWeb grey
// matter), each iteration applies one random local edit (a Gaussian bump raised or lowered at a
// random zero-layer point) and one swarm step of agents editing at random, both through a Session
// (the viewer's edit path: local sparse-field update, undo history, incremental mesher); every K iterations it runs the level-set
// invariant checker and compares the fragment meshes with a whole-band marching cubes, and records
// the resident memory. Exit status 1 on the first failed check.
#include <fmt/core.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <unistd.h>

#include "cli_common.hpp"
#include "commands.hpp"
#include "cli_support.hpp"
#include "image_commands.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/levelset/invariants.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"
#include "liveset/session/session.hpp"
#include "liveset/base/stopwatch.hpp"

namespace liveset::cli {

namespace {

struct SoakArgs {
    std::string input, image, roi, log;
    long iterations = 100000;
    long check_every = 1000;
    double p = 0.1;
    std::uint64_t seed = 1;
    bool json = false, quiet = false;
};

double resident_mb() {
    std::ifstream statm("/proc/self/statm");
    long pages_total = 0, pages_resident = 0;
    statm >> pages_total >> pages_resident;
    return static_cast<double>(pages_resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2), v.end());
    return v[v.size() / 2];
}

int run_soak(const SoakArgs& a, int threads) {
    const auto guard = limit_threads(threads);
    const InterruptGuard interrupt;
    if (!a.log.empty()) check_output_path(a.log, OutputKind::kText, "--log");
    const Grid<float> image = read_image(a.image);
    std::optional<Grid<std::uint8_t>> roi;
    if (!a.roi.empty()) roi = load_mask_like(a.roi, image.lattice(), "--roi");
    // Everything goes through a Session, as in the viewer: edits, swarm steps, history, mesher.
    SessionOptions so;
    so.fragment_size = 8;
    so.repair.swarm.decision = EditDecision::kRandom;
    so.repair.swarm.act_probability = a.p;
    so.repair.swarm.seed = a.seed;
    Session session(image, so, roi);
    load_level_set(session, a.input);
    const SparseField& field = session.field();
    const FragmentMesher& mesher = session.mesher();
    std::mt19937_64 rng(a.seed);
    const Lattice& lat = field.lattice();

    std::string lines;
    std::vector<double> ms;
    double first_rss = 0.0, peak_rss = 0.0;
    std::size_t checks = 0;
    using clock = std::chrono::steady_clock;
    const auto start = clock::now();
    for (long it = 0; it < a.iterations; ++it) {
        if (interrupt.interrupted()) break;
        if (field.zero_layer().empty()) throw UsageError(fmt::format("the surface vanished at iteration {}", it));
        const auto t0 = clock::now();
        // A random local edit: a radius-2 Gaussian bump of ±0.4 at a random zero-layer point.
        const auto zero = field.zero_layer();
        const Vec3i c = lat.coord(zero[rng() % zero.size()]);
        const float amplitude = (rng() & 1) ? 0.4f : -0.4f;
        session.edit_box(c - Vec3i{2, 2, 2}, c + Vec3i{2, 2, 2}, [&](Vec3i q, float) {
            const Vec3i d = q - c;
            return amplitude * static_cast<float>(std::exp(-0.5 * static_cast<double>(d.x * d.x + d.y * d.y + d.z * d.z)));
        });
        // One swarm step, re-aimed at the edited point every 500 iterations.
        if (it % 500 == 0) session.set_target(c.cast<double>());
        session.swarm_step();
        ms.push_back(ms_since(t0));

        if ((it + 1) % a.check_every == 0 || it + 1 == a.iterations) {
            const InvariantReport inv = check_invariants(field);
            const bool mesh_equal = canonical_triangles(mesher.merged().view()) ==
                                    canonical_triangles(marching_cubes_band(field.phi(), field.zero_layer()).view());
            const double rss = resident_mb();
            if (checks++ == 0) first_rss = rss;
            peak_rss = std::max(peak_rss, rss);
            const nlohmann::json j{{"iteration", it + 1},     {"ms_median", median(ms)}, {"zero_layer", field.zero_layer().size()},
                                   {"band", field.band_size()}, {"triangles", mesher.triangle_count()}, {"rss_mb", rss},
                                   {"invariants_ok", inv.ok()}, {"mesh_equal", mesh_equal}};
            lines += j.dump() + "\n";
            ms.clear();
            if (!a.quiet && !a.json)
                fmt::print("soak {:>7}: {:.3f} ms/iteration, zero layer {}, {} triangles, RSS {:.1f} MB{}{}\n", it + 1,
                           j["ms_median"].get<double>(), field.zero_layer().size(), mesher.triangle_count(), rss,
                           inv.ok() ? "" : ", INVARIANTS BROKEN: " + inv.summary(), mesh_equal ? "" : ", MESH DIFFERS");
            if (!inv.ok() || !mesh_equal) {
                if (!a.log.empty()) write_atomically(a.log, lines);
                throw UsageError(fmt::format("soak check failed at iteration {}: {}", it + 1,
                                             !inv.ok() ? "level-set invariants broken (" + inv.summary() + ")"
                                                       : "fragment meshes differ from the whole-band mesh"));
            }
        }
    }
    if (!a.log.empty()) write_atomically(a.log, lines);
    const nlohmann::json summary{{"iterations", a.iterations}, {"checks", checks}, {"seconds", std::chrono::duration<double>(clock::now() - start).count()},
                                 {"rss_first_check_mb", first_rss}, {"rss_peak_mb", peak_rss}, {"rss_last_mb", resident_mb()}};
    if (a.json) fmt::print("{}\n", summary.dump());
    else if (!a.quiet)
        fmt::print("liveset bench soak: {} iterations, {} checks passed, RSS {:.1f} MB at the first check, {:.1f} MB peak\n",
                   a.iterations, checks, first_rss, peak_rss);
    return interrupt.interrupted() ? 130 : 0;
}

}  // namespace

void add_soak_command(CLI::App* bench, const int& threads) {
    static SoakArgs sa;
    auto* soak = bench->add_subcommand("soak", "long run: random local edits and swarm steps with invariant and mesh checks, memory recorded");
    soak->add_option("input", sa.input, "phi (< 0 inside) or 0/1 mask, e.g. the BrainWeb grey matter")->required();
    soak->add_option("--image", sa.image, "the image the swarm samples")->required();
    soak->add_option("--roi", sa.roi, "region-of-interest mask");
    soak->add_option("--iterations", sa.iterations, "iterations (one random edit + one swarm step each)")->check(CLI::Range(1L, 100'000'000L))->capture_default_str();
    soak->add_option("--check-every", sa.check_every, "run the invariant and mesh checks every K iterations")->check(CLI::Range(1L, 100'000'000L))->capture_default_str();
    soak->add_option("--p", sa.p, "probability that an agent edits per step")->check(CLI::Range(0.0, 1.0))->capture_default_str();
    soak->add_option("--seed", sa.seed, "random seed")->capture_default_str();
    soak->add_option("--log", sa.log, "one JSON line per check: iteration, ms_median, zero_layer, band, triangles, rss_mb, invariants_ok, mesh_equal");
    soak->add_flag("--json", sa.json, "print the summary as one JSON object");
    soak->add_flag("--quiet,-q", sa.quiet, "print nothing");
    soak->callback([&threads] {
        const int rc = run_soak(sa, threads);
        if (rc != 0) std::exit(rc);
    });
}

}  // namespace liveset::cli
