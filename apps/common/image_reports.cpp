// The JSON reports and the one-line summaries of the image commands (image_commands.hpp): the ROI,
// the bias correction, the leak warning, the segmentation, the tissue model and the evaluation.
#include <fmt/core.h>

#include <cmath>
#include <cstddef>
#include <string>

#include "image_commands.hpp"

namespace liveset::cli {

void add_bias_report(nlohmann::json& report, const PreparedImage& prepared, const Grid<std::uint8_t>* roi) {
    if (prepared.bias) {
        report["bias_correction"] = bias_correction_report(*prepared.bias);
        report["bias_correction"]["mask"] = prepared.fit_name(roi);
        if (prepared.brain_mask_after_n4) report["bias_correction"]["brain_mask_after_voxels"] = prepared.brain_mask_after_n4;
        if (prepared.bias_offset != 0.0f) report["bias_correction"]["offset"] = prepared.bias_offset;
    }
    for (const std::string& w : prepared.warnings()) report["warnings"].push_back(w);
}

std::string leak_warning(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>* brain_mask, std::string_view roi_hint) {
    if (brain_mask == nullptr) return {};
    const Grid<std::uint8_t>& brain = *brain_mask;
    std::size_t inside = 0, outside = 0;
    for (std::size_t i = 0; i < mask.size(); ++i) {
        const auto p = static_cast<PointIndex>(i);
        if (mask[p] == 0) continue;
        ++inside;
        outside += brain[p] == 0;
    }
    const double share = inside > 0 ? static_cast<double>(outside) / static_cast<double>(inside) : 0.0;
    if (share <= kLeakShare) return {};
    return fmt::format("{:.0f} % of the segmented voxels ({} of {}) lie outside the automatic brain mask: without a ROI the front "
                       "may have leaked into scalp, muscle or eyes; for brain tissue pass {} (or your own brain mask)",
                       100.0 * share, outside, inside, roi_hint);
}

std::string session_leak_warning(const Session& session, std::string_view roi_hint) {
    const std::optional<Grid<std::uint8_t>>& brain = session.options().model_region;
    if (session.roi() || !brain) return {};
    return leak_warning(session.mask(), &*brain, roi_hint);
}

nlohmann::json roi_report(const Roi& roi) {
    const Vec3d s = roi.mask.lattice().spacing();
    std::size_t voxels = 0;
    for (std::uint8_t v : roi.mask.values()) voxels += v != 0;
    nlohmann::json j{{"source", roi.source}, {"voxels", voxels}, {"volume_mm3", static_cast<double>(voxels) * s.x * s.y * s.z},
                     {"default", roi.by_default}, {"whole_brain", roi.brain_mask.has_value() || roi.file_is_brain}};
    if (const auto& b = roi.brain_mask)
        j["auto"] = {{"skull_stripped", b->skull_stripped}, {"background_threshold", b->background_threshold},
                     {"background_noise", b->background_noise}, {"head_threshold", b->head_threshold},
                     {"tissue_low", b->tissue_low}, {"tissue_high", b->tissue_high}, {"wm_peak", b->wm_peak},
                     {"deep_skew", b->deep_skew}, {"deep_above", b->deep_above}, {"deep_below", b->deep_below}, {"wm_swamped", b->wm_swamped},
                     {"deep_grey_peak", std::isnan(b->deep_grey_peak) ? nlohmann::json(nullptr) : nlohmann::json(b->deep_grey_peak)},
                     {"contrast", to_string(b->contrast)}, {"flair", b->flair},
                     {"flair_grey_peak", std::isnan(b->flair_grey_peak) ? nlohmann::json(nullptr) : nlohmann::json(b->flair_grey_peak)},
                     {"surface_contact", b->surface_contact}, {"head_voxels", b->head_voxels},
                     {"below_head_voxels", b->below_voxels}, {"inferior_exit_mm2", b->inferior_exit_mm2},
                     {"brain_extent_mm", b->brain_extent_mm}, {"cut_contact_mm2", b->cut_contact_mm2}, {"head_diameter_mm", b->head_diameter_mm},
                     {"csf_voxels", b->csf_voxels},
                     {"superior", b->superior_from_header ? "header" : "from the head"},
                     {"mid_range_fill", std::isnan(b->mid_range_fill) ? nlohmann::json(nullptr) : nlohmann::json(b->mid_range_fill)}};
    return j;
}

std::string brain_mask_summary(const BrainMaskReport& b) {
    std::string s = fmt::format("{}, tissue window {:.1f}..{:.1f}", b.skull_stripped ? "skull-stripped input" : "full head",
                                b.tissue_low, b.tissue_high);
    if (b.contrast == TissueContrast::kGreyBrighter) s += " (mirrored: grey matter brighter than white, as in a T2 or PD)";
    if (b.flair) s += " (mirrored: grey matter brighter than white with CSF dark, as in a FLAIR)";
    if (b.wm_swamped) s += ", white matter at the deep head's brightest peak (its tallest swamped: large ventricles?)";
    if (!std::isnan(b.mid_range_fill)) s += fmt::format(", masked outside at {:g} within the tissue's range", b.mid_range_fill);
    if (b.head_threshold > b.background_threshold)
        s += fmt::format(", noisy air σ {:.1f}: head threshold {:.1f}", b.background_noise, b.head_threshold);
    if (b.below_voxels > 0 && !b.skull_stripped)
        s += fmt::format(", {:.0f} ml of neck left out", static_cast<double>(b.below_voxels) * b.mask_volume_mm3 /
                                                              static_cast<double>(std::max<std::size_t>(b.mask_voxels, 1)) / 1000.0);
    return s;
}

void print_roi_summary(const Roi& roi) {
    const nlohmann::json j = roi_report(roi);
    const std::string how = roi.brain_mask ? fmt::format("auto brain mask{} ({})", roi.by_default ? " by default, --roi none for the whole image" : "",
                                                         brain_mask_summary(*roi.brain_mask))
                                           : roi.source + (roi.file_is_brain ? " (a whole brain: it agrees with the automatic brain mask)" : "");
    fmt::print("  roi          {}: {} voxels, {:.1f} ml\n", how, j["voxels"].get<std::size_t>(), j["volume_mm3"].get<double>() / 1000.0);
}

nlohmann::json segmentation_report(const SegmentOutcome& o, const Lattice& lattice) {
    const Vec3d s = lattice.spacing();
    const double voxel_mm3 = s.x * s.y * s.z;
    std::size_t inside = 0;
    for (std::uint8_t v : o.mask.values()) inside += v;
    nlohmann::json j;
    j["iterations"] = o.result.iterations;
    j["stop"] = to_string(o.result.reason);
    j["seconds"] = o.result.seconds;
    j["ms_per_iteration"] = o.result.iterations > 0 ? 1000.0 * o.result.seconds / o.result.iterations : 0.0;
    j["mu"] = o.params.mu;
    j["epsilon"] = o.params.epsilon;
    j["mu_raw"] = o.scale.to_raw(o.params.mu);
    j["epsilon_raw"] = o.scale.raw_length(o.params.epsilon);
    j["n"] = o.params.n;
    j["alpha"] = o.params.alpha;
    j["smooth_mm"] = o.params.smooth_mm;
    j["step"] = step_name(o.step);
    j["thin_fronts"] = o.step.thin_fronts;
    j["alpha_choice"] = {{"source", o.alpha.automatic ? "automatic" : "given"}};
    if (o.alpha.automatic) {
        j["alpha_choice"]["anisotropy"] = o.alpha.anisotropy;
        if (o.alpha.tissue_class >= 0 && o.model) {
            j["alpha_choice"]["noise_ratio"] = o.alpha.noise_ratio;
            j["alpha_choice"]["class"] = tissue_class_name(*o.model, o.alpha.tissue_class);
        }
    }
    j["window_estimated"] = o.window_source != WindowSource::kUser;
    j["window"] = {{"mu_raw", o.scale.to_raw(o.params.mu)},
                   {"epsilon_raw", o.scale.raw_length(o.params.epsilon)},
                   {"lower_raw", o.scale.to_raw(o.params.mu - o.params.epsilon)},
                   {"upper_raw", o.scale.to_raw(o.params.mu + o.params.epsilon)},
                   {"source", to_string(o.window_source)}};
    if (o.model) j["tissue_model"] = tissue_model_report(*o.model, o.model_window ? &*o.model_window : nullptr);
    j["warnings"] = o.warnings;
    j["intensity_scale"] = {{"low", o.scale.low}, {"high", o.scale.high}};
    j["voxels"] = inside;
    j["volume_mm3"] = static_cast<double>(inside) * voxel_mm3;
    j["zero_layer"] = o.field->zero_layer().size();
    if (o.coarse) {  // the coarse start: its grid, run, and whether the fine run started from it
        const CoarseStartReport& c = *o.coarse;
        j["coarse_start"] = {{"dims", {c.dims.x, c.dims.y, c.dims.z}}, {"spacing", {c.spacing.x, c.spacing.y, c.spacing.z}},
                             {"iterations", c.result.iterations}, {"stop", to_string(c.result.reason)},
                             {"seconds", c.result.seconds}, {"used", c.used}, {"start_voxels", c.upsampled}, {"refused_voxels", c.refused}};
    } else {
        j["coarse_start"] = nullptr;
    }
    return j;
}

nlohmann::json tissue_model_report(const TissueModel& m, const ModelWindow* w) {
    nlohmann::json classes = nlohmann::json::array();
    for (std::size_t c = 0; c < m.classes.size(); ++c) {
        const TissueClass& t = m.classes[c];
        classes.push_back({{"name", tissue_class_name(m, static_cast<int>(c))}, {"mean", t.mean}, {"sigma", t.sigma}, {"weight", t.weight},
                           {"peak_sigma", std::isfinite(t.peak_sigma) ? nlohmann::json(t.peak_sigma) : nlohmann::json(nullptr)}});
    }
    nlohmann::json j{{"classes", classes}, {"partial_volume", m.mixed}, {"voxels", m.voxels},
                     {"iterations", m.iterations}, {"converged", m.converged}, {"usable", m.usable()},
                     {"start", m.start}, {"contrast", m.contrast ? nlohmann::json(to_string(*m.contrast)) : nlohmann::json(nullptr)},
                     {"floor", m.floor ? nlohmann::json(*m.floor) : nlohmann::json(nullptr)}};
    if (!m.usable()) j["degenerate"] = m.degenerate;
    if (m.smooth_mm > 0) j["fitted_smooth_mm"] = m.smooth_mm;  // fitted on the image blurred by this σ
    if (w) j["seed_class"] = {{"name", tissue_class_name(m, w->seed_class)}, {"index", w->seed_class}, {"share", w->seed_class_share}};
    return j;
}

nlohmann::json bias_correction_report(const BiasCorrectionReport& r) {
    const auto vec = [](Vec3i v) { return nlohmann::json::array({v.x, v.y, v.z}); };
    return {{"ms", r.ms}, {"n4_ms", r.n4_ms}, {"field_min", r.field_min}, {"field_max", r.field_max},
            {"mask", r.otsu_mask ? "otsu" : "roi"}, {"mask_voxels", r.mask_voxels},
            {"shrink_factors", vec(r.shrink_factors)}, {"shrunk_dims", vec(r.shrunk_dims)},
            {"control_points", vec(r.control_points)}, {"level_iterations", r.level_iterations},
            {"final_convergence", r.final_convergence}};
}

namespace {

// "given", or how the automatic α came about: "automatic: GM's noise over contrast 0.17, voxels 1:1";
// without a ratio "automatic: no noise ratio from a tissue model, 0.1 / 3³ for voxels 3:1".
std::string alpha_source(const nlohmann::json& j) {
    if (!j.contains("alpha_choice") || j["alpha_choice"]["source"] != "automatic") return "given";
    const nlohmann::json& a = j["alpha_choice"];
    const double shape = a["anisotropy"].get<double>();
    if (!a.contains("noise_ratio"))
        return fmt::format("automatic: no noise ratio from a tissue model, 0.1 / {:.3g}³ for voxels {:.3g}:1", shape, shape);
    return fmt::format("automatic: {}'s noise over contrast {:.2f}, voxels {:.3g}:1", a["class"].get<std::string>(),
                       a["noise_ratio"].get<double>(), shape);
}

}  // namespace

void print_segmentation_summary(const nlohmann::json& j) {
    if (j.contains("bias_correction")) {
        const nlohmann::json& b = j["bias_correction"];
        fmt::print("  bias field   {:.3f} .. {:.3f} inside the {} ({:.2f} s, N4 on a {}x{}x{} grid)\n",
                   b["field_min"].get<double>(), b["field_max"].get<double>(),
                   b["mask"].get<std::string>() == "otsu" ? "Otsu foreground" : b["mask"].get<std::string>(), b["ms"].get<double>() / 1000.0,
                   b["shrunk_dims"][0].get<int>(), b["shrunk_dims"][1].get<int>(), b["shrunk_dims"][2].get<int>());
    }
    if (j.contains("coarse_start") && j["coarse_start"].is_object()) {
        const nlohmann::json& c = j["coarse_start"];
        fmt::print("  coarse start {} iterations ({}), {:.2f} s on 2x2x2-voxel blocks, a {}x{}x{} grid ({:.3g} x {:.3g} x {:.3g} mm){}\n",
                   c["iterations"].get<int>(), c["stop"].get<std::string>(), c["seconds"].get<double>(), c["dims"][0].get<int>(),
                   c["dims"][1].get<int>(), c["dims"][2].get<int>(), c["spacing"][0].get<double>(), c["spacing"][1].get<double>(),
                   c["spacing"][2].get<double>(), c["used"].get<bool>() ? fmt::format("; {} voxels of its upsampled front left out where the image's own data term refuses them",
                                                                   c.value("refused_voxels", std::size_t{0}))
                                                     : "; nothing of its front was left (the ROI, the data term): started from the seeds");
    }
    fmt::print("  segmentation {} iterations ({}), {:.2f} s, {:.2f} ms/iteration\n", j["iterations"].get<int>(),
               j["stop"].get<std::string>(), j["seconds"].get<double>(), j["ms_per_iteration"].get<double>());
    if (j.contains("tissue_model")) {
        const nlohmann::json& m = j["tissue_model"];
        std::string line;
        for (const auto& c : m["classes"])
            line += fmt::format("{}{} {:.1f} ± {:.1f} ({:.0f} %)", line.empty() ? "" : ", ", c["name"].get<std::string>(),
                                c["mean"].get<double>(), c["sigma"].get<double>(), 100.0 * c["weight"].get<double>());
        double pv = 0;
        for (const auto& v : m["partial_volume"]) pv += v.get<double>();
        fmt::print("  tissues      {}; partial volume {:.0f} %{}\n", line, 100.0 * pv, m["usable"].get<bool>() ? "" : " (not usable)");
    }
    const nlohmann::json& w = j["window"];
    const std::string source = w["source"].get<std::string>();
    std::string from = source == "user" ? "given" : source == "seeds" ? "from the seeds' statistics" : "from the tissue model";
    if (source == "model")
        from += fmt::format(": {}, {:.0f} % of the seed voxels", j["tissue_model"]["seed_class"]["name"].get<std::string>(),
                            100.0 * j["tissue_model"]["seed_class"]["share"].get<double>());
    fmt::print("  window       {:.1f} .. {:.1f} raw (mu {:.1f} ± {:.1f}; {}), n {}, alpha {:.3g} ({})\n", w["lower_raw"].get<double>(),
               w["upper_raw"].get<double>(), w["mu_raw"].get<double>(), w["epsilon_raw"].get<double>(), from,
               j["n"].get<double>(), j["alpha"].get<double>(), alpha_source(j));
    if (j.contains("smooth_mm") && j["smooth_mm"].get<double>() > 0.0)
        fmt::print("  smoothing    Gaussian sigma {:.3g} mm before the threshold term ({})\n", j["smooth_mm"].get<double>(),
                   j["alpha_choice"]["source"] == "automatic" ? "automatic: the noise ratio is over 0.2" : "given");
    fmt::print("  volume       {} voxels, {:.1f} ml\n", j["voxels"].get<std::size_t>(), j["volume_mm3"].get<double>() / 1000.0);
}

namespace {

nlohmann::json number(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); }

}  // namespace

nlohmann::json evaluation_report(const Grid<std::uint8_t>& mask, const Grid<std::uint8_t>& truth) {
    const OverlapMetrics ov = compare_overlap(mask, truth);
    const SurfaceDistance sd = surface_distance(mask, truth);
    const Topology tm = mask_topology(mask);
    const Topology tt = mask_topology(truth);
    nlohmann::json j;
    j["dice"] = ov.dice;
    j["jaccard"] = ov.jaccard;
    j["volume_difference"] = number(ov.volume_difference);
    j["mask_volume_mm3"] = ov.mask_volume_mm3;
    j["truth_volume_mm3"] = ov.truth_volume_mm3;
    j["hausdorff95_mm"] = number(sd.hausdorff95_mm);
    j["hausdorff_mm"] = number(sd.hausdorff_mm);
    j["mean_surface_mm"] = number(sd.mean_mm);
    j["components"] = tm.components;
    j["cavities"] = tm.cavities;
    j["euler"] = tm.euler;
    j["genus"] = tm.genus;
    j["holes"] = holes_between(tt, tm);
    j["truth"] = {{"components", tt.components}, {"cavities", tt.cavities}, {"euler", tt.euler}, {"genus", tt.genus}};
    return j;
}

void print_evaluation(const nlohmann::json& j, const std::string& in) {
    auto num = [](const nlohmann::json& v, const char* f) { return v.is_null() ? std::string("n/a") : fmt::format(fmt::runtime(f), v.get<double>()); };
    fmt::print("{}dice {:.4f}  jaccard {:.4f}  volume difference {}  HD95 {} mm  (HD {} mm, mean {} mm)\n", in,
               j["dice"].get<double>(), j["jaccard"].get<double>(), (j["volume_difference"].is_null() ? std::string("n/a") : fmt::format("{:+.2f}%", 100.0 * j["volume_difference"].get<double>())),
               num(j["hausdorff95_mm"], "{:.2f}"), num(j["hausdorff_mm"], "{:.2f}"), num(j["mean_surface_mm"], "{:.2f}"));
    fmt::print("{}topology: {} component(s), {} cavity(ies), Euler characteristic {}, genus {}; holes {} (truth: euler {}, genus {})\n",
               in, j["components"].get<std::size_t>(), j["cavities"].get<std::size_t>(), j["euler"].get<long>(),
               j["genus"].get<long>(), j["holes"].get<long>(), j["truth"]["euler"].get<long>(), j["truth"]["genus"].get<long>());
}

// φ image or 0/1 mask -> sparse field on the image's lattice.
}  // namespace liveset::cli
