// Start parameters of `liveset view` and their source.
#include "view_params.hpp"

#include <fmt/core.h>

#include <algorithm>

#include "cli_common.hpp"
#include "liveset/segment/alpha.hpp"
#include "liveset/segment/window.hpp"

namespace liveset::viewer {

namespace {

// µ, ε of a level set loaded with no seeds: the tissue model's window for the class most of its
// inside voxels fall in (as the hole finder picks the sheet's class).
std::string model_window_for_level_set(const Session& s, ThresholdParams& p, bool& from_seeds) {
    std::vector<std::string> warnings;
    TissueModel model;
    const std::optional<ModelWindow> w = sheet_window(s.image(), s.mask(), s.roi(), TissueModelOptions{}, warnings, &model, s.sheet_fit());
    const IntensityScale& sc = s.scale();
    if (!w) {
        return fmt::format("µ, ε: no usable tissue model ({}); µ {:.4g}, ε {:.4g} (raw) are defaults: set them (panel or --mu-raw/--epsilon-raw)",
                           warnings.empty() ? "no reason given" : warnings.front(), sc.to_raw(p.mu), sc.raw_length(p.epsilon));
    }
    p.mu = std::clamp((w->mu() - sc.low) / (sc.high - sc.low), 0.0, 1.0);
    p.epsilon = sc.unit_length(w->epsilon());
    from_seeds = false;
    return fmt::format("µ, ε from the tissue model: the window of {} (most of the level set's inside), µ {:.4g}, ε {:.4g} (raw)",
                       tissue_class_name(model, w->seed_class), w->mu(), w->epsilon());
}

// Where the session's automatic α (and pre-smoothing) came from (Session::automatic_alpha_choice,
// segment/alpha.hpp).
std::string automatic_alpha_note(const Session& s) {
    const AlphaChoice a = s.automatic_alpha_choice();
    if (a.tissue_class < 0) return fmt::format("α {:.3g} automatic (no noise ratio from a tissue model: 0.1 / {:.3g}³)", a.alpha, a.anisotropy);
    const std::string blur = a.smooth_mm > 0.0 ? fmt::format("; the image blurred by σ {:.3g} mm, the noise ratio being over 0.2", a.smooth_mm) : "";
    return fmt::format("α {:.3g} automatic ({}'s noise over contrast {:.2f}, voxels {:.3g}:1, as liveset segment){}", a.alpha,
                       tissue_class_name(*s.tissue_model(), a.tissue_class), a.noise_ratio, a.anisotropy, blur);
}

}  // namespace

std::string choose_start_params(Session& s, const StartParams& start) {
    const cli::ThresholdArgs& a = *start.args;
    ThresholdParams p = s.params();
    bool from_seeds = s.window_from_seeds();
    // α follows the image (as `liveset segment` chooses it, and again as seeds move the window)
    // unless --alpha is given or a workspace brings its own choice.
    const bool auto_alpha = !start.alpha_given && (start.workspace.empty() || s.alpha_automatic());
    std::string source;
    bool changed = auto_alpha != s.alpha_automatic();
    const std::optional<double> mu = cli::unit_mu(a, s.scale()), epsilon = cli::unit_epsilon(a, s.scale());
    if (!start.workspace.empty()) {
        source = "µ, ε, n, α from the workspace " + start.workspace;
    } else if (start.level_set_loaded && s.seeds().empty()) {
        source = model_window_for_level_set(s, p, from_seeds);
        changed = true;
    } else if (!s.seeds().empty() && from_seeds) {
        source = "µ, ε from the tissue model's window for the seeds' class";
        changed |= auto_alpha;
    }
    if (mu) p.mu = *mu;
    if (epsilon) p.epsilon = *epsilon;
    if (start.n_given) p.n = a.n;
    if (start.alpha_given && a.alpha) p.alpha = *a.alpha;
    if (start.alpha_given) p.smooth_mm = a.smooth_mm.value_or(0.0);  // as `segment --alpha` (no blur unless --smooth)
    if (mu || epsilon) {
        from_seeds = false;
        const std::string given = mu && epsilon ? "µ, ε" : (mu ? "µ" : "ε");
        source = given + " from the command line" + (source.empty() || (mu && epsilon) ? "" : "; " + source);
    }
    if (start.n_given || start.alpha_given)
        source += (source.empty() ? "" : "; ") + std::string(a.smooth_mm ? "n, α, smoothing from the command line" : "n, α from the command line");
    if (changed || mu || epsilon || start.n_given || start.alpha_given) {
        try {
            s.set_params(p, from_seeds, auto_alpha);
        } catch (const std::invalid_argument& e) {
            throw cli::UsageError(fmt::format("threshold parameters: {} (µ {:.4g}, ε {:.4g} raw)", e.what(), s.scale().to_raw(p.mu),
                                              s.scale().raw_length(p.epsilon)));
        }
        s.clear_history();  // Ctrl+Z must not go back to the defaults these replaced
        // Without seeds or a level set there is no window yet to choose α for: said once there is.
        if (auto_alpha && start.workspace.empty() && (!s.seeds().empty() || start.level_set_loaded))
            source += (source.empty() ? "" : "; ") + automatic_alpha_note(s);
    }
    return source;
}

}  // namespace liveset::viewer
