// The shared threshold-speed options: registration, the pair rule, raw -> normalised units.
#include "threshold_args.hpp"

#include "cli_common.hpp"
#include "liveset/segment/smoothing.hpp"

namespace liveset::cli {

void add_threshold_options(CLI::App& cmd, ThresholdArgs& a) {
    cmd.add_option("--mu", a.mu, "ideal intensity, normalised to [0,1] (default: the tissue model's window for the seeds' class)")->check(finite_number());
    cmd.add_option("--epsilon", a.epsilon, "half window, normalised units (default: from the tissue model)")->check(finite_number());
    cmd.add_option("--mu-raw", a.mu_raw, "ideal intensity in the image's own units")->check(finite_number());
    cmd.add_option("--epsilon-raw", a.epsilon_raw, "half window in the image's own units")->check(finite_number());
    cmd.add_option("--n", a.n, "steepness of the threshold term")->check(finite_number())->capture_default_str();
    cmd.add_option("--alpha", a.alpha, "curvature weight in [0,1), per millimetre (default: automatic, from the tissue model's noise over contrast for the window's class - 0 on a quiet scan, up to 0.15 - or 0.1 without a usable model, either divided by the cube of the voxels' longest-to-shortest side ratio)")->check(finite_number());
    cmd.add_option("--smooth", a.smooth_mm, "sigma in mm of the Gaussian blur of the image the threshold term reads, with --alpha (default: automatic with alpha - half the finest voxel side when the tissue model's noise over contrast exceeds 0.2, else none; 0 with a given --alpha)")
        ->check(finite_number())
        ->check(CLI::Range(0.0, kMaxSmoothMm));
    cmd.add_option("--step", a.step, "level-set step: sleeping (converged stretches of front sleep until something near them changes) or exact (the whole band every step)")
        ->check(CLI::IsMember({"sleeping", "exact"}))
        ->capture_default_str();
    cmd.add_flag("--thin-fronts,!--no-thin-fronts", a.thin_fronts, "the thin-front rule, on by default: the front carries into tissue one or two voxels thick, which the paper's sparse field cannot enter (a thinned cortex); --no-thin-fronts: the paper's sparse field, as the phantom demo steps (the rule can carry the front around a weak spot along its partial-volume rims; docs/ARCHITECTURE.md, \"Thin fronts\")");
}

StepOptions step_options(const ThresholdArgs& a) { return step_options(RecordedStep{a.step != "exact", a.thin_fronts}); }

void check_threshold_args(const ThresholdArgs& a) {
    if (a.mu && a.mu_raw) throw UsageError("give --mu or --mu-raw, not both");
    if (a.epsilon && a.epsilon_raw) throw UsageError("give --epsilon or --epsilon-raw, not both");
    if (a.smooth_mm && !a.alpha) throw UsageError("--smooth needs --alpha: the automatic choice sets both");
}

std::optional<double> unit_mu(const ThresholdArgs& a, const IntensityScale& scale) {
    if (a.mu_raw) return (*a.mu_raw - scale.low) / (scale.high - scale.low);
    return a.mu;
}

std::optional<double> unit_epsilon(const ThresholdArgs& a, const IntensityScale& scale) {
    if (a.epsilon_raw) return scale.unit_length(*a.epsilon_raw);
    return a.epsilon;
}

}  // namespace liveset::cli
