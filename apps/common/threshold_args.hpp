// The threshold-speed options `liveset segment` and `liveset view` share (--mu, --epsilon, --mu-raw,
// --epsilon-raw, --n, --alpha, --smooth, --step, --thin-fronts): one registration with the same help and checks, one rule for the
// pairs, and the mapping of raw values to the normalised units the speed uses.
#pragma once

#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "liveset/segment/intensity.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/threshold_speed.hpp"

namespace liveset::cli {

struct ThresholdArgs {
    std::optional<double> mu, epsilon, mu_raw, epsilon_raw;  // the window, normalised or raw units
    double n = 4.0;
    std::optional<double> alpha;  // unset: `segment` chooses it (alpha.hpp); `view` keeps the session's
    std::optional<double> smooth_mm;  // --smooth: only with --alpha (the automatic choice sets both)
    std::string step = "sleeping";  // --step: sleeping (segmentation.hpp, segment_step) or exact
    bool thin_fronts = segment_step().thin_fronts;  // --thin-fronts / --no-thin-fronts: StepOptions::thin_fronts
};

// Registers --mu, --epsilon, --mu-raw, --epsilon-raw, --n, --alpha, --smooth, --step and --thin-fronts on `cmd`.
void add_threshold_options(CLI::App& cmd, ThresholdArgs& a);
// UsageError "give --mu or --mu-raw, not both" (and the same for ε), and for --smooth without --alpha.
void check_threshold_args(const ThresholdArgs& a);
// The window's µ / ε in normalised units through `scale` (raw values mapped as segment_image maps
// them); nullopt where not given.
std::optional<double> unit_mu(const ThresholdArgs& a, const IntensityScale& scale);
std::optional<double> unit_epsilon(const ThresholdArgs& a, const IntensityScale& scale);
// The level-set step --step names: segment_step() (the default) or the exact full-band step; the
// thin-front rule on or off as --thin-fronts / --no-thin-fronts say (on by default).
StepOptions step_options(const ThresholdArgs& a);

}  // namespace liveset::cli
