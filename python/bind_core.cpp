// The module's functions: image IO through the C++ readers/writers, segment (as `liveset segment`),
// the tissue model and window estimate, mesh, evaluate. Long calls release the GIL and poll Ctrl-C.
#include <pybind11/stl.h>

#include <nlohmann/json.hpp>

#include "bindings.hpp"
#include "cli_common.hpp"
#include "cli_support.hpp"
#include "finder_repair.hpp"
#include "image_commands.hpp"
#include "phase_times.hpp"
#include "liveset/eval/holes.hpp"
#include "liveset/io/image_io.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_io.hpp"
#include "liveset/preprocess/bias_correction.hpp"
#include "liveset/segment/segmentation.hpp"
#include "liveset/segment/window.hpp"

namespace liveset::py {

namespace {

using cli::UsageError;

// (array, geometry, oriented: the file gave an orientation).
pyb::tuple read(const std::string& path, bool labels) {
    ImageHeader h;
    if (labels) {
        Grid<std::uint8_t> g = [&] { pyb::gil_scoped_release nogil; return read_label_image(path, kDefaultImageMemoryLimit, &h); }();
        const Lattice l = g.lattice();
        return pyb::make_tuple(array_from_grid(std::move(g)), geometry_of(l), h.orientation_known);
    }
    Grid<float> g = [&] { pyb::gil_scoped_release nogil; return read_image(path, kDefaultImageMemoryLimit, &h, NanVoxels::keep); }();
    const Lattice l = g.lattice();
    return pyb::make_tuple(array_from_grid(std::move(g)), geometry_of(l), h.orientation_known);
}

void write(const pyb::array& values, const Lattice& lattice, const std::string& path, bool labels, bool oriented) {
    if (labels) {
        const Grid<std::uint8_t> g = mask_from_array(values, lattice);
        pyb::gil_scoped_release nogil;
        write_label_image(g, path, {.orientation_known = oriented});
    } else {
        const Grid<float> g = grid_from_array(values, lattice, true);  // NaN: written as it was read
        pyb::gil_scoped_release nogil;
        write_image(g, path, {.orientation_known = oriented});
    }
}

// The ROI as `liveset segment --roi` takes it: None (the default: the automatic brain mask on a head,
// else none), "auto" (the automatic brain mask), "none" or a mask array.
std::optional<cli::Roi> roi_of(const pyb::object& roi, const Grid<float>& image, cli::BrainLookup* lookup) {
    if (roi.is_none() || pyb::isinstance<pyb::str>(roi)) {
        const std::string s = roi.is_none() ? std::string() : roi.cast<std::string>();
        if (s != "auto" && s != "none" && !s.empty()) throw std::invalid_argument("roi must be None, 'auto', 'none' or a mask array, not '" + s + "'");
        pyb::gil_scoped_release nogil;
        return cli::load_roi(s, image, "roi", lookup);
    }
    return cli::Roi{mask_from_array(roi.cast<pyb::array>(), image.lattice()), "array", std::nullopt, nullptr};
}

struct SegmentArgs {
    std::vector<std::string> seeds, seeds_mm;
    double seed_radius = 2.0;
    pyb::object roi = pyb::none(), init_mask = pyb::none();
    std::optional<double> mu, epsilon, mu_raw, epsilon_raw;
    std::string window_from = "model";
    int classes = 3, iterations = 2000;
    double n = 4.0;
    std::optional<double> alpha;  // unset: automatic (alpha.hpp), as the CLI
    std::optional<double> smooth_mm;  // only with alpha (the automatic choice sets both), as --smooth
    std::optional<bool> bias_correct;  // unset: on, skipped with a warning where it cannot run (as the CLI's default)
    bool oriented = true;  // Image.oriented: the file gave an orientation (BrainMaskOptions::superior_from_header)
    bool thin_fronts = segment_step().thin_fronts;  // StepOptions::thin_fronts, as --thin-fronts (the default) / --no-thin-fronts
    std::string coarse_start = "auto";  // as --coarse-start (coarse_start.hpp)
};

// The automatic brain mask's lookup for an image whose file did (not) give an orientation, as the CLI's.
cli::BrainLookup lookup_for(bool oriented) {
    cli::BrainLookup lookup;
    lookup.options = brain_options_for(oriented);
    return lookup;
}

// The request `liveset segment` builds from its options (cmd_segment.cpp), on an image in memory.
SegmentRequest request_for(const SegmentArgs& a, const Lattice& lattice, bool need_seeds = true) {
    if (a.mu && a.mu_raw) throw UsageError("give mu or mu_raw, not both");
    if (a.epsilon && a.epsilon_raw) throw UsageError("give epsilon or epsilon_raw, not both");
    if (a.window_from != "model" && a.window_from != "seeds") throw UsageError("window_from must be 'model' or 'seeds'");
    if (a.iterations < 1) throw UsageError("iterations must be at least 1");
    if (a.smooth_mm && !a.alpha) throw UsageError("smooth_mm needs alpha: the automatic choice sets both");
    SegmentRequest req;
    cli::fill_segment_request(req, a, lattice);
    if (need_seeds && req.seeds.empty() && a.init_mask.is_none()) throw UsageError("give at least one seed I,J,K[:R] (or seeds_mm, or init_mask)");
    return req;
}

// The bias correction a binding's option asks for: unset (the default) as the CLI's default.
cli::BiasCorrection bias_mode(const std::optional<bool>& bias_correct) {
    return cli::bias_mode(bias_correct.value_or(true), bias_correct.has_value());
}

pyb::dict segment(const pyb::array& values, const Lattice& lattice, const SegmentArgs& a, const pyb::object& progress) {
    cli::PhaseTimes phases;
    cli::Scan scan = scan_from_array(values, lattice);
    Grid<float>& image = scan.image;
    SegmentRequest req = request_for(a, lattice);
    cli::BrainLookup lookup = lookup_for(a.oriented);
    std::optional<cli::Roi> roi = roi_of(a.roi, image, &lookup);
    phases.mark("roi");
    std::optional<Grid<std::uint8_t>> init;
    if (!a.init_mask.is_none()) init = mask_from_array(a.init_mask.cast<pyb::array>(), lattice);
    Interrupt interrupt;
    interrupt.callback = progress;
    const cli::BiasCorrection mode = bias_mode(a.bias_correct);
    cli::PreparedImage prepared;
    std::optional<SegmentOutcome> out;
    const Grid<std::uint8_t>* roi_mask = nullptr;
    cli::SeedFit seed_fit;  // seeds outside the ROI
    {
        pyb::gil_scoped_release nogil;
        prepared = cli::prepare_image(image, roi, mode, &interrupt.flag(), &lookup, scan.no_data_mask());
        phases.mark("bias_correction");
        seed_fit = cli::fit_seeds_to_roi(roi, prepared, req.seeds, init ? &*init : nullptr, "roi='none'");
        roi_mask = roi ? &roi->mask : nullptr;
        const Grid<std::uint8_t>* fit = prepared.fit(roi_mask);
        if (roi) req.roi = &roi->mask;
        if (init) req.initial_mask = &*init;
        req.model_region = fit;
        req.model_region_is_brain = prepared.fit_is_brain(roi);
        req.model_region_grey_brighter = prepared.grey_brighter;
        req.brain_mask = lookup.options;
        const SegmentationHook hook = [&](const SegmentationProgress& p, const ChangedPoints&) {
            return interrupt.poll_with([&]() -> pyb::object {
                return pyb::dict(pyb::arg("iteration") = p.iteration, pyb::arg("zero_layer") = p.zero_layer,
                                 pyb::arg("band") = p.band, pyb::arg("awake") = p.awake, pyb::arg("changed") = p.changed, pyb::arg("flips") = p.flips,
                                 pyb::arg("inside") = p.inside, pyb::arg("dt") = p.dt, pyb::arg("ms") = p.ms,
                                 pyb::arg("level") = p.level == 1 ? "coarse" : "fine");
            });
        };
        if (!prepared.bias || !prepared.bias->interrupted) out.emplace(segment_image(image, req, hook, &interrupt.flag()));
    }
    if (interrupt.raised()) interrupt.rethrow();
    if (!out || out->result.reason == StopReason::kInterrupted) throw pyb::error_already_set();  // a pending KeyboardInterrupt
    phases.mark("segmentation");
    nlohmann::json j = cli::segmentation_report(*out, lattice);
    j["phase_seconds"] = phases.json();
    cli::add_bias_report(j, prepared, roi_mask);
    j["no_data_voxels"] = scan.no_data_voxels;
    for (const std::string& w : seed_fit.warnings) j["warnings"].push_back(w);
    const Grid<std::uint8_t>* brain = seed_fit.default_dropped ? nullptr : prepared.fit(nullptr);  // given up: the user's choice
    if (const std::string w = cli::leak_warning(out->mask, brain, "roi='auto'"); !w.empty()) j["warnings"].push_back(w);
    if (roi) j["roi"] = cli::roi_report(*roi);
    pyb::dict r;
    r["phi"] = array_from_grid(Grid<float>(out->field->phi()));
    r["mask"] = array_from_grid(std::move(out->mask));
    r["report"] = j.dump();
    if (roi && roi->source == "auto") r["roi"] = array_from_grid(Grid<std::uint8_t>(roi->mask));
    if (prepared.bias) r["corrected"] = array_from_grid(scan.restored(image));
    return r;
}

// The image a Session works on, prepared as `liveset view` prepares it (prepare_image: N4 per
// `bias_correct`, fitted in the ROI, else the automatic brain mask): the corrected image when N4
// ran, the ROI (a mask array, or "auto": the automatic brain mask, as segment), the region the
// tissue model is fitted in (the automatic brain mask; none with a ROI) and the report's
// bias_correction / warnings / roi.
pyb::dict prepare_session_image(const pyb::array& values, const Lattice& lattice, const pyb::object& roi_arg,
                                const std::optional<bool>& bias_correct, bool oriented) {
    cli::Scan scan = scan_from_array(values, lattice);
    Grid<float>& image = scan.image;
    cli::BrainLookup lookup = lookup_for(oriented);
    std::optional<cli::Roi> roi = roi_of(roi_arg, image, &lookup);  // "auto": as segment's
    cli::PreparedImage prepared;
    {
        pyb::gil_scoped_release nogil;
        prepared = cli::prepare_image(image, roi, bias_mode(bias_correct), nullptr, &lookup, scan.no_data_mask());
    }
    const Grid<std::uint8_t>* r = roi ? &roi->mask : nullptr;
    nlohmann::json j = nlohmann::json::object();
    cli::add_bias_report(j, prepared, r);
    if (roi) j["roi"] = cli::roi_report(*roi);
    j["no_data_voxels"] = scan.no_data_voxels;
    pyb::dict d;
    d["report"] = j.dump();
    d["roi"] = roi ? pyb::object(array_from_grid(Grid<std::uint8_t>(roi->mask))) : pyb::object(pyb::none());
    // The image the session works on: the corrected one, or the scan with its NaN lowered; None: the array as given.
    const bool changed = prepared.bias || scan.no_data_voxels;
    d["image"] = changed ? pyb::object(array_from_grid(std::move(image))) : pyb::object(pyb::none());
    d["corrected"] = prepared.bias.has_value();
    d["region_is_brain"] = prepared.fit_is_brain(roi);
    d["region_grey_brighter"] = prepared.grey_brighter;
    d["model_region"] = prepared.fit_region ? pyb::object(array_from_grid(std::move(*prepared.fit_region))) : pyb::object(pyb::none());
    return d;
}

// The tissue model fitted where segment() fits it, and the window the seeds would get.
std::string tissue_model(const pyb::array& values, const Lattice& lattice, const SegmentArgs& a) {
    cli::Scan scan = scan_from_array(values, lattice);
    Grid<float>& image = scan.image;
    SegmentRequest req = request_for(a, lattice, false);
    cli::BrainLookup lookup = lookup_for(a.oriented);
    std::optional<cli::Roi> roi = roi_of(a.roi, image, &lookup);
    pyb::gil_scoped_release nogil;
    cli::PreparedImage prepared = cli::prepare_image(image, roi, bias_mode(a.bias_correct), nullptr, &lookup, scan.no_data_mask());  // as segment
    const cli::SeedFit seed_fit = cli::fit_seeds_to_roi(roi, prepared, req.seeds, nullptr, "roi='none'");
    const Grid<std::uint8_t>* roi_mask = roi ? &roi->mask : nullptr;
    const Grid<std::uint8_t>* fit = prepared.fit(roi_mask);
    const IntensityScale scale = robust_scale(image, roi_mask, req.scale);
    std::vector<std::string> warnings;
    bool automatic = false;
    const Grid<std::uint8_t> region = model_region(image, fit, roi_mask, a.classes, &automatic, lookup.options);
    const std::optional<TissueModel> model =
        fit_window_model(image, region, req.window.model, warnings, automatic || prepared.fit_is_brain(roi), prepared.grey_brighter);
    nlohmann::json j;
    j["intensity_scale"] = {{"low", scale.low}, {"high", scale.high}};
    if (!req.seeds.empty()) {
        const WindowEstimate w = estimate_window(image, scale, req.seeds, roi_mask, model ? &*model : nullptr, req.window);
        j["window"] = {{"mu", w.mu}, {"epsilon", w.epsilon}, {"mu_raw", scale.to_raw(w.mu)},
                       {"epsilon_raw", scale.raw_length(w.epsilon)}, {"lower_raw", scale.to_raw(w.mu - w.epsilon)},
                       {"upper_raw", scale.to_raw(w.mu + w.epsilon)}, {"source", to_string(w.source)}};
        for (const std::string& s : w.warnings) warnings.push_back(s);
        for (const std::string& s : seed_fit.warnings) warnings.push_back(s);
        if (model) j["tissue_model"] = cli::tissue_model_report(*model, w.model_window ? &*w.model_window : nullptr);
    } else if (model) {
        j["tissue_model"] = cli::tissue_model_report(*model, nullptr);
    }
    j["warnings"] = warnings;
    cli::add_bias_report(j, prepared, roi_mask);
    return j.dump();
}

// Marching cubes of φ (< 0 inside) or of a 0/1 mask (φ from the sparse field's mask initialisation,
// as `liveset mesh`): vertices and normals in LPS mm, triangles as vertex indices; written too when
// `out` is given (.ply/.obj/.stl).
pyb::tuple mesh(const pyb::array& values, const Lattice& lattice, bool is_mask, const std::string& out) {
    Grid<float> phi = grid_from_array(values, lattice);
    Mesh m;
    {
        pyb::gil_scoped_release nogil;
        if (is_mask) {
            SparseField f(lattice, 2);
            f.init_from_mask(cli::to_mask(phi));
            phi = f.phi();
        }
        m = marching_cubes_naive(phi);
        if (m.triangle_count() == 0) throw std::invalid_argument("the input holds no surface (no voxel changes sign)");
        if (!out.empty()) write_mesh(out, m.view(), lattice);
    }
    const auto nv = static_cast<pyb::ssize_t>(m.vertices.size());
    pyb::array_t<double> vertices({nv, pyb::ssize_t{3}}), normals({nv, pyb::ssize_t{3}});
    auto vp = vertices.mutable_unchecked<2>();
    auto np = normals.mutable_unchecked<2>();
    for (pyb::ssize_t i = 0; i < nv; ++i) {
        const Vertex& v = m.vertices[static_cast<std::size_t>(i)];
        const Vec3d p = lattice.to_world({v.position[0], v.position[1], v.position[2]});
        const Vec3d n = lattice.direction_to_world({v.normal[0], v.normal[1], v.normal[2]});
        vp(i, 0) = p.x, vp(i, 1) = p.y, vp(i, 2) = p.z;
        np(i, 0) = n.x, np(i, 1) = n.y, np(i, 2) = n.z;
    }
    const auto nt = static_cast<pyb::ssize_t>(m.triangle_count());
    pyb::array_t<std::uint32_t> faces({nt, pyb::ssize_t{3}});
    std::copy(m.indices.begin(), m.indices.end(), faces.mutable_data());
    return pyb::make_tuple(vertices, faces, normals);
}

std::string evaluate(const pyb::array& mask, const pyb::array& truth, const Lattice& lattice) {
    const Grid<std::uint8_t> m = mask_from_array(mask, lattice), t = mask_from_array(truth, lattice);
    pyb::gil_scoped_release nogil;
    return cli::evaluation_report(m, t).dump();
}

// `liveset holes` (apps/cli/cmd_holes.cpp) on arrays: the sheet's band given or from the tissue
// model (sheet_window), the candidates largest first. Returns the JSON text.
std::string find_holes_json(const pyb::array& mask, const pyb::array& image, const pyb::object& roi, const Lattice& lattice,
                            const std::optional<std::pair<double, double>>& band, std::size_t min_voxels, double min_sheet_share,
                            bool oriented) {
    const Grid<std::uint8_t> m = mask_from_array(mask, lattice);
    const Grid<float> img = scan_from_array(image, lattice).image;
    std::optional<Grid<std::uint8_t>> r;
    if (!roi.is_none()) r = mask_from_array(roi.cast<pyb::array>(), lattice);
    pyb::gil_scoped_release nogil;
    HoleFinderOptions fo;
    fo.min_voxels = min_voxels;
    fo.min_sheet_share = min_sheet_share;
    std::vector<std::string> warnings;
    if (band) {
        fo.sheet_lower = band->first;
        fo.sheet_upper = band->second;
    } else {
        const BrainMaskOptions brain = brain_options_for(oriented);  // a ROI: the contrast read off the head, as segment's
        const std::optional<ModelWindow> w = sheet_window(img, m, r ? &*r : nullptr, TissueModelOptions{}, warnings, nullptr,
                                                          cli::fit_for_roi(img, r ? &*r : nullptr, brain));
        if (!w) throw std::invalid_argument("cannot tell the sheet's tissue from the image (" +
                                            (warnings.empty() ? std::string("no tissue model") : warnings.back()) +
                                            "); give sheet_band=(lower, upper)");
        fo.sheet_lower = w->lower;
        fo.sheet_upper = w->upper;
    }
    fo.validate();
    const std::vector<HoleCandidate> holes = find_holes(m, img, r ? &*r : nullptr, fo);
    nlohmann::json sites = nlohmann::json::array();
    for (const HoleCandidate& h : holes)
        sites.push_back({{"voxels", h.voxels}, {"rim", h.rim}, {"sheet", h.sheet}, {"target", {h.site.x, h.site.y, h.site.z}},
                         {"centroid", {h.centroid.x, h.centroid.y, h.centroid.z}}});
    return nlohmann::json{{"sheet_band", {fo.sheet_lower, fo.sheet_upper}}, {"band_from", band ? "user" : "tissue model"},
                          {"holes", sites}, {"warnings", warnings}}
        .dump();
}

// The arguments of `_repair_holes` (liveset.repair_holes) after the arrays.
struct RepairHolesArgs {
    std::optional<std::pair<double, double>> band;  // raw; the tissue model's when absent
    std::size_t holes = 10, min_voxels = 50, agents = 200;
    int round_steps = 1000;
    double p = 0.3;
    std::uint64_t seed = 1;
    double between_share = 0.25;  // SwarmOptions::sheet_between_share
    bool oriented = true;         // the image's header gave an orientation (Image.oriented)
};

// `liveset repair --find-holes` (finder_repair.hpp) on arrays: the finder's largest holes, one
// sheet-rule round each, through a Session on `image`. Returns (φ, report JSON).
pyb::tuple repair_holes(const pyb::array& level, bool is_mask, const pyb::array& image, const pyb::object& roi, const Lattice& lattice,
                        const RepairHolesArgs& a) {
    const Grid<float> img = scan_from_array(image, lattice).image;
    std::optional<Grid<std::uint8_t>> r;
    if (!roi.is_none()) r = mask_from_array(roi.cast<pyb::array>(), lattice);
    std::optional<Grid<float>> phi_in;
    std::optional<Grid<std::uint8_t>> mask_in;
    if (is_mask) mask_in = mask_from_array(level, lattice);
    else phi_in = grid_from_array(level, lattice);
    nlohmann::json report;
    std::optional<Grid<float>> phi;
    {
        pyb::gil_scoped_release nogil;
        SessionOptions so;
        so.fragment_size = 8;  // as `liveset repair`
        so.brain_mask = brain_options_for(a.oriented);
        Session session(img, so, r);
        if (mask_in) session.load_mask(*mask_in);
        else session.load_phi(*phi_in);
        const Grid<std::uint8_t>* roi_ptr = r ? &*r : nullptr;
        cli::FoundHolesInput in{img, roi_ptr, session.scale()};
        if (a.band) {
            in.band = {a.band->first, a.band->second, 0.5 * (a.band->first + a.band->second)};
        } else {
            const std::optional<cli::SheetBand> b = cli::model_sheet_band(img, inside_mask(session.field().phi(), roi_ptr), roi_ptr, so.brain_mask);
            if (!b) throw std::invalid_argument("cannot tell the sheet's tissue from the image; give sheet_band=(lower, upper)");
            in.band = *b;
        }
        in.max_targets = a.holes;
        in.min_voxels = a.min_voxels;
        in.round_steps = a.round_steps;
        in.options.swarm.agents = a.agents;
        in.options.swarm.act_probability = a.p;
        in.options.swarm.seed = a.seed;
        in.options.swarm.sheet_between_share = a.between_share;
        report = cli::repair_found_holes(in, session, true);
        phi = session.field().phi();
    }
    return pyb::make_tuple(array_from_grid(std::move(*phi)), report.dump());
}

SegmentArgs segment_args(const pyb::kwargs& kw) {
    SegmentArgs a;
    for (const auto& [key, value] : kw) {
        const std::string k = key.cast<std::string>();
        if (k == "seeds") a.seeds = value.cast<std::vector<std::string>>();
        else if (k == "seeds_mm") a.seeds_mm = value.cast<std::vector<std::string>>();
        else if (k == "seed_radius") a.seed_radius = value.cast<double>();
        else if (k == "roi") a.roi = pyb::reinterpret_borrow<pyb::object>(value);
        else if (k == "init_mask") a.init_mask = pyb::reinterpret_borrow<pyb::object>(value);
        else if (k == "mu") a.mu = value.cast<std::optional<double>>();
        else if (k == "epsilon") a.epsilon = value.cast<std::optional<double>>();
        else if (k == "mu_raw") a.mu_raw = value.cast<std::optional<double>>();
        else if (k == "epsilon_raw") a.epsilon_raw = value.cast<std::optional<double>>();
        else if (k == "window_from") a.window_from = value.cast<std::string>();
        else if (k == "classes") a.classes = value.cast<int>();
        else if (k == "iterations") a.iterations = value.cast<int>();
        else if (k == "n") a.n = value.cast<double>();
        else if (k == "alpha") a.alpha = value.cast<std::optional<double>>();
        else if (k == "smooth_mm") a.smooth_mm = value.cast<std::optional<double>>();
        else if (k == "bias_correct") a.bias_correct = value.cast<std::optional<bool>>();
        else if (k == "oriented") a.oriented = value.cast<bool>();
        else if (k == "thin_fronts") a.thin_fronts = value.cast<bool>();
        else if (k == "coarse_start") a.coarse_start = value.cast<std::string>();
        else throw std::invalid_argument("unknown segment option '" + k + "'");
    }
    if (a.classes < 2 || a.classes > 6) throw UsageError("classes must be in 2..6");
    if (a.coarse_start != "auto" && a.coarse_start != "on" && a.coarse_start != "off")
        throw UsageError("coarse_start must be 'auto', 'on' or 'off'");
    if (a.coarse_start == "on" && !a.init_mask.is_none()) throw UsageError("coarse_start='on' starts from the seeds: it cannot start from init_mask");
    return a;
}

}  // namespace

BrainMaskOptions brain_options_for(bool oriented) {
    ImageHeader h;
    h.orientation_known = oriented;
    return cli::brain_mask_options(h);
}

void register_core(pyb::module_& m) {
    m.def("_read_header", [](const std::string& path) {
        const ImageHeader h = [&] { pyb::gil_scoped_release nogil; return read_image_header(path); }();
        pyb::dict d;
        d["dims"] = pyb::make_tuple(h.dims.x, h.dims.y, h.dims.z);
        d["spacing"] = pyb::make_tuple(h.spacing.x, h.spacing.y, h.spacing.z);
        d["origin"] = pyb::make_tuple(h.origin.x, h.origin.y, h.origin.z);
        d["direction"] = std::vector<double>(h.direction.begin(), h.direction.end());
        d["dimension"] = h.dimension;
        d["components"] = h.components;
        d["pixel_type"] = h.pixel_type;
        d["format"] = h.format;
        d["oriented"] = h.orientation_known;
        return d;
    }, pyb::arg("path"));
    m.def("_read", &read, pyb::arg("path"), pyb::arg("labels") = false);
    m.def("_write", [](const pyb::array& v, const pyb::tuple& geo, const std::string& path, bool labels, bool oriented) {
        if (v.ndim() != 3) throw std::invalid_argument("the image must be a 3D array");
        write(v, lattice_from(pyb::make_tuple(v.shape(0), v.shape(1), v.shape(2)), geo[0], geo[1], geo[2]), path, labels, oriented);
    });
    m.def("_segment", [](const pyb::array& v, const pyb::tuple& geo, const pyb::object& progress, const pyb::kwargs& kw) {
        if (v.ndim() != 3) throw std::invalid_argument("the image must be a 3D array");
        const Lattice l = lattice_from(pyb::make_tuple(v.shape(0), v.shape(1), v.shape(2)), geo[0], geo[1], geo[2]);
        return segment(v, l, segment_args(kw), progress);
    });
    m.def("_tissue_model", [](const pyb::array& v, const pyb::tuple& geo, const pyb::kwargs& kw) {
        if (v.ndim() != 3) throw std::invalid_argument("the image must be a 3D array");
        const Lattice l = lattice_from(pyb::make_tuple(v.shape(0), v.shape(1), v.shape(2)), geo[0], geo[1], geo[2]);
        SegmentArgs a = segment_args(kw);
        return tissue_model(v, l, a);
    });
    m.def("_prepare_session_image", [](const pyb::array& v, const pyb::tuple& geo, const pyb::object& roi, const std::optional<bool>& bias_correct,
                                       bool oriented) {
        if (v.ndim() != 3) throw std::invalid_argument("the image must be a 3D array");
        const Lattice l = lattice_from(pyb::make_tuple(v.shape(0), v.shape(1), v.shape(2)), geo[0], geo[1], geo[2]);
        return prepare_session_image(v, l, roi, bias_correct, oriented);
    });
    m.def("_mesh", [](const pyb::array& v, const pyb::tuple& geo, bool is_mask, const std::string& out) {
        if (v.ndim() != 3) throw std::invalid_argument("the input must be a 3D array");
        return mesh(v, lattice_from(pyb::make_tuple(v.shape(0), v.shape(1), v.shape(2)), geo[0], geo[1], geo[2]), is_mask, out);
    });
    m.def("_find_holes", [](const pyb::array& mask, const pyb::array& image, const pyb::object& roi, const pyb::tuple& geo,
                            const std::optional<std::pair<double, double>>& band, std::size_t min_voxels, double min_sheet_share,
                            bool oriented) {
        if (mask.ndim() != 3) throw std::invalid_argument("the mask must be a 3D array");
        const Lattice l = lattice_from(pyb::make_tuple(mask.shape(0), mask.shape(1), mask.shape(2)), geo[0], geo[1], geo[2]);
        return find_holes_json(mask, image, roi, l, band, min_voxels, min_sheet_share, oriented);
    });
    m.def("_repair_holes", [](const pyb::array& level, bool is_mask, const pyb::array& image, const pyb::object& roi, const pyb::tuple& geo,
                              const std::optional<std::pair<double, double>>& band, std::size_t holes, std::size_t min_voxels, int round_steps,
                              std::size_t agents, double p, std::uint64_t seed, double between_share, bool oriented) {
        if (level.ndim() != 3) throw std::invalid_argument("phi_or_mask must be a 3D array");
        const Lattice l = lattice_from(pyb::make_tuple(level.shape(0), level.shape(1), level.shape(2)), geo[0], geo[1], geo[2]);
        return repair_holes(level, is_mask, image, roi, l, RepairHolesArgs{band, holes, min_voxels, agents, round_steps, p, seed, between_share, oriented});
    });
    m.def("_evaluate", [](const pyb::array& mask, const pyb::array& truth, const pyb::tuple& geo) {
        if (mask.ndim() != 3) throw std::invalid_argument("the mask must be a 3D array");
        return evaluate(mask, truth, lattice_from(pyb::make_tuple(mask.shape(0), mask.shape(1), mask.shape(2)), geo[0], geo[1], geo[2]));
    });
}

}  // namespace liveset::py
