// `liveset.Session`: the interactive editing session (seeds, segmentation steps, swarm repair,
// undo/redo) for scripts. Runs of steps release the GIL and stop on Ctrl-C between steps.
#include <pybind11/stl.h>

#include "bindings.hpp"
#include "cli_common.hpp"
#include "image_commands.hpp"
#include "liveset/session/session.hpp"

namespace liveset::py {

namespace {

std::unique_ptr<Session> make_session(const pyb::array& v, const pyb::tuple& geo, const pyb::object& roi,
                                      const pyb::object& model_region, bool region_is_brain, bool region_grey_brighter, double n,
                                      std::optional<double> alpha, std::optional<double> smooth_mm, int layers, int fragment_size, std::size_t history,
                                      int agents, double p, std::uint64_t seed, bool sleeping, const std::string& decision,
                                      double edit_range, bool oriented, bool thin_fronts, const std::string& coarse_start) {
    if (v.ndim() != 3) throw std::invalid_argument("the image must be a 3D array");
    const Lattice l = lattice_from(pyb::make_tuple(v.shape(0), v.shape(1), v.shape(2)), geo[0], geo[1], geo[2]);
    Grid<float> image = grid_from_array(v, l);
    std::optional<Grid<std::uint8_t>> r;
    if (!roi.is_none()) r = mask_from_array(roi.cast<pyb::array>(), l);
    SessionOptions o;
    // Where the tissue model is fitted (the automatic brain mask prepare_image found, as the viewer).
    if (!model_region.is_none()) o.model_region = mask_from_array(model_region.cast<pyb::array>(), l);
    o.model_region_is_brain = region_is_brain;  // the ROI or that mask is an automatic brain mask
    o.model_region_grey_brighter = region_grey_brighter;  // read so before N4
    o.brain_mask = brain_options_for(oriented);  // where no region was found: looked for as segment looks
    o.layers = layers;
    o.fragment_size = fragment_size;
    o.history = history;
    o.params.n = n;
    if (smooth_mm && !alpha) throw std::invalid_argument("smooth_mm needs alpha: the automatic choice sets both");
    if (alpha) o.params.alpha = *alpha;
    if (smooth_mm) o.params.smooth_mm = *smooth_mm;
    o.alpha_automatic = !alpha;  // None: as `segment` chooses α and σ, and again as the seeds move the window
    if (agents < 1) throw std::invalid_argument("agents must be at least 1");
    o.repair.swarm.agents = static_cast<std::size_t>(agents);
    o.repair.swarm.act_probability = p;
    o.repair.swarm.seed = seed;
    // The swarm's rule, as `liveset repair --decision` (the sheet rule needs a band: repair_holes).
    const std::optional<EditDecision> rule = edit_decision_named(decision);
    if (!rule || *rule == EditDecision::kSheet) throw std::invalid_argument("decision must be 'intensity', 'random' or 'cut'");
    o.repair.swarm.decision = *rule;
    o.repair.swarm.edit_range = edit_range;
    if (sleeping) o.segmentation.step = segment_step();  // as `liveset segment` (the rule as asked, below)
    o.segmentation.step.thin_fronts = thin_fronts;
    o.coarse_start = parse_coarse_start(coarse_start);  // as segment(coarse_start=...)
    pyb::gil_scoped_release nogil;
    auto s = std::make_unique<Session>(std::move(image), o, std::move(r));
    // Scripts read φ and the mask, never the viewer's fragment meshes: the mesher only collects
    // the changed points (bounded by the lattice), and φ is the same bits either way.
    s->set_deferred_meshing(true);
    return s;
}

pyb::dict status_of(const Session& s) {
    const SegmentStatus& st = s.segment_status();
    return pyb::dict(pyb::arg("iterations") = st.iterations, pyb::arg("converged") = st.converged,
                     pyb::arg("vanished") = st.vanished, pyb::arg("flips") = st.flips, pyb::arg("inside") = st.inside,
                     pyb::arg("dt") = st.dt, pyb::arg("zero_layer") = s.field().zero_layer().size(), pyb::arg("coarse") = st.coarse,
                     pyb::arg("coarse_iterations") = st.coarse_iterations, pyb::arg("coarse_inside") = st.coarse_inside);
}

// `count` calls of a segment or swarm step; a run until converged stops early once converged, and
// counts only the steps on the image's grid against `count` (the coarse start's iterations are
// bounded by its own limit, as segment's stages each are).
pyb::dict run_steps(Session& s, int count, bool segment, bool until_converged) {
    if (count < 0) throw std::invalid_argument("steps must be >= 0");
    Interrupt interrupt;
    int counted = 0, taken = 0;
    {
        pyb::gil_scoped_release nogil;
        while (counted < count && interrupt.poll()) {
            ++taken;
            if (!segment) {
                s.swarm_step();
                ++counted;
                continue;
            }
            s.segment_step();
            if (!until_converged || !s.segment_status().coarse) ++counted;
            if (until_converged && (s.segment_status().converged || s.segment_status().vanished)) break;
        }
        s.end_action();
    }
    if (interrupt.raised()) interrupt.rethrow();
    pyb::dict d = status_of(s);
    d["steps"] = taken;
    // A segmentation that converged without a ROI, out of the brain mask its model was fitted in:
    // the warning `segment` and the viewer give (image_commands.hpp).
    std::vector<std::string> warnings;
    if (segment && s.segment_status().converged) {
        if (std::string w = cli::session_leak_warning(s, "roi='auto'"); !w.empty()) warnings.push_back(std::move(w));
    }
    d["warnings"] = warnings;
    return d;
}

Vec3d point(const std::vector<double>& p) {
    if (p.size() != 3) throw std::invalid_argument("a point needs 3 index coordinates (i, j, k)");
    return {p[0], p[1], p[2]};
}

}  // namespace

void register_session(pyb::module_& m) {
    pyb::class_<Session>(m, "_Session")
        .def(pyb::init(&make_session), pyb::arg("image"), pyb::arg("geometry"), pyb::arg("roi"), pyb::arg("model_region"),
             pyb::arg("region_is_brain"), pyb::arg("region_grey_brighter"), pyb::arg("n"),
             pyb::arg("alpha"), pyb::arg("smooth_mm"), pyb::arg("layers"), pyb::arg("fragment_size"), pyb::arg("history"), pyb::arg("agents"),
             pyb::arg("p"), pyb::arg("seed"), pyb::arg("sleeping"), pyb::arg("decision"), pyb::arg("edit_range"), pyb::arg("oriented"),
             pyb::arg("thin_fronts"), pyb::arg("coarse_start"))
        .def("add_seed", [](Session& s, const std::vector<double>& c, double r) {
            if (!s.lattice().contains(point(c))) throw std::invalid_argument("the seed lies outside the image");
            s.add_seed({point(c), r});
        })
        .def("remove_seed", [](Session& s, std::size_t i) {
            if (i >= s.seeds().size()) throw std::out_of_range("no seed with that index");
            s.remove_seed(i);
        })
        .def("seeds", [](const Session& s) {
            std::vector<std::tuple<double, double, double, double>> out;
            for (const SeedBall& b : s.seeds()) out.emplace_back(b.center.x, b.center.y, b.center.z, b.radius);
            return out;
        })
        .def("set_params", [](Session& s, double mu, double epsilon, double n, double alpha, double smooth_mm, bool from_seeds,
                              bool alpha_automatic) { s.set_params({mu, epsilon, n, alpha, smooth_mm}, from_seeds, alpha_automatic); })
        .def("params", [](const Session& s) {
            const ThresholdParams& p = s.params();
            return pyb::dict(pyb::arg("mu") = p.mu, pyb::arg("epsilon") = p.epsilon, pyb::arg("n") = p.n,
                             pyb::arg("alpha") = p.alpha, pyb::arg("smooth_mm") = p.smooth_mm, pyb::arg("window_from_seeds") = s.window_from_seeds(),
                             pyb::arg("alpha_automatic") = s.alpha_automatic(),
                             pyb::arg("mu_raw") = s.scale().to_raw(p.mu), pyb::arg("epsilon_raw") = s.scale().raw_length(p.epsilon));
        })
        .def("segment_steps", [](Session& s, int count, bool until) { return run_steps(s, count, true, until); })
        .def("swarm_steps", [](Session& s, int count) { return run_steps(s, count, false, false); })
        .def("status", &status_of)
        .def("set_target", [](Session& s, const std::vector<double>& t) { s.set_target(point(t)); })
        .def("clear_target", &Session::clear_target)
        .def("agents", [](const Session& s) {
            std::vector<std::tuple<double, double, double>> out;
            for (const Agent& a : s.agents()) out.emplace_back(a.position.x, a.position.y, a.position.z);
            return out;
        })
        .def("undo", [](Session& s) { return !s.undo().changed.empty(); })
        .def("redo", [](Session& s) { return !s.redo().changed.empty(); })
        .def("can_undo", &Session::can_undo)
        .def("can_redo", &Session::can_redo)
        .def("undo_depth", &Session::undo_depth)
        .def("next_undo_label", &Session::next_undo_label)
        .def("load_mask", [](Session& s, const pyb::array& v) { s.load_mask(mask_from_array(v, s.lattice())); })
        .def("load_phi", [](Session& s, const pyb::array& v) { s.load_phi(grid_from_array(v, s.lattice())); })
        .def("mask", [](const Session& s) { return array_from_grid(s.mask()); })
        .def("phi", [](const Session& s) { return array_from_grid(Grid<float>(s.field().phi())); });
}

}  // namespace liveset::py
