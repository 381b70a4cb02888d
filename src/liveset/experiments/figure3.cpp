// The paper's Figure 3 experiment (see figure3.hpp).
#include "liveset/experiments/figure3.hpp"

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "liveset/levelset/curvature_flow.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/mesh_analysis.hpp"

namespace liveset {

namespace {

struct Column {
    Figure3Column out;
    FragmentMesher mesher;
    // The naive column: one polygoniser scanning every cell into one reused mesh (the paper's
    // whole-lattice marching cubes; no incremental bookkeeping such as the mesher's sign bits).
    CellPolygoniser scan;
    Mesh scan_mesh;
};

void naive_scan(Column& c, const Grid<float>& phi) {
    const Vec3i d = phi.dims();
    c.scan_mesh.clear();
    c.scan.polygonise_box(phi, {0, 0, 0}, {d.x - 1, d.y - 1, d.z - 1}, c.scan_mesh);
}

void verify(int step, const Grid<float>& phi, std::span<const PointIndex> zero_layer, const Column& c) {
    const Mesh ref = marching_cubes_band(phi, zero_layer);
    const Mesh m = c.out.naive ? c.scan_mesh : c.mesher.merged();
    std::string at = "figure 3 check failed at step ";  // appended: gcc 12's -Wrestrict misfires on "…" + string
    at += std::to_string(step) + ": " + c.out.name + " mesh ";
    if (m.triangle_count() != ref.triangle_count())
        throw std::runtime_error(at + "has " + std::to_string(m.triangle_count()) + " triangles, marching_cubes_band has " +
                                 std::to_string(ref.triangle_count()));
    if (canonical_triangles(m) != canonical_triangles(ref))
        throw std::runtime_error(at + "differs from marching_cubes_band (" + std::to_string(m.triangle_count()) +
                                 " triangles each)");
}

// FNV-1a over a step's X and its sign changes: every column's flow must hand its mesher the same.
std::uint64_t fingerprint(std::span<const PointIndex> changed, std::span<const PointIndex> signs) {
    std::uint64_t h = 1469598103934665603ull;
    const auto mix = [&](std::uint64_t v) { h = (h ^ v) * 1099511628211ull; };
    for (const PointIndex x : changed) mix(x);
    mix(~std::uint64_t{0});
    for (const PointIndex x : signs) mix(x);
    return h;
}

// One column: its own flow of the box from the start, re-meshed after every step by this column
// alone (as a session re-meshes with its one mesher), so no other column's meshes share its caches.
// The flow is deterministic: every column's flow must give the X of the first (`steps_x`, filled
// by the first column, checked by the others).
Figure3Column run_column(const Figure3Options& a, const BoxFlowOptions& box, const std::string& name, bool naive, int size,
                         std::vector<std::uint64_t>& steps_x, Figure3Result& r) {
    using clock = std::chrono::steady_clock;
    SparseField field = make_box_field(box);
    Column c{Figure3Column{}, FragmentMesher(field.lattice(), size), CellPolygoniser{}, Mesh{}};
    c.out.name = name;
    c.out.naive = naive;
    if (naive) naive_scan(c, field.phi());
    else c.mesher.full_rebuild(field.phi(), field.zero_layer());
    c.out.fragments = naive ? 1 : c.mesher.fragment_count();
    c.out.cumulative.reserve(static_cast<std::size_t>(a.steps));
    verify(0, field.phi(), field.zero_layer(), c);
    const bool first = steps_x.empty();
    const auto cells = static_cast<std::size_t>(a.lattice - 1);
    int checks = 1;
    const auto mesh_step = [&](int step, std::span<const PointIndex> changed, std::span<const PointIndex> signs) {
        const std::uint64_t x = fingerprint(changed, signs);
        const auto k = static_cast<std::size_t>(step - 1);
        if (first) {
            steps_x.push_back(x);
            r.changed_sum += changed.size();
        } else if (k >= steps_x.size() || steps_x[k] != x) {
            throw std::runtime_error("figure 3: column " + name + " saw a different X at step " + std::to_string(step) +
                                     " than the first column (the flow must be deterministic)");
        }
        std::size_t rebuilt = 1;
        const auto t0 = clock::now();
        if (naive) naive_scan(c, field.phi());
        else rebuilt = c.mesher.update(field.phi(), changed, signs).size();
        const auto t1 = clock::now();
        c.out.total_s += std::chrono::duration<double>(t1 - t0).count();
        c.out.cumulative.push_back(c.out.total_s);
        c.out.rebuilt_sum += rebuilt;
        c.out.rebuilt_max = std::max(c.out.rebuilt_max, rebuilt);
        c.out.cells_sum += naive ? cells * cells * cells : c.mesher.last_stats().cells_visited;
        if (!naive) c.out.vertices_only_sum += c.mesher.last_stats().vertices_only;
        if ((a.verify_every > 0 && step % a.verify_every == 0) || step == a.steps) {
            verify(step, field.phi(), field.zero_layer(), c);
            ++checks;
        }
    };
    const FlowHook hook = [&](const SparseField&, const StepResult& s, const FlowStepRecord& rec) {
        mesh_step(rec.step, s.changed.points, s.changed.sign_changes.value());
        return true;
    };
    // The driver's time step stays at 1/6 (the parabolic bound before session 15; the box vanishes
    // after step 1410), so the columns stay comparable with earlier runs: at the level set's own
    // bound of 1/4 it vanishes after 941 steps, which would only add idle steps to every column.
    const BoxFlowReport rep = run_curvature_flow(field, a.steps, {.cfl = box.cfl, .max_dt = 1.0f / 6.0f}, hook);
    const int flow_steps = static_cast<int>(rep.steps.size());
    for (int s = flow_steps + 1; s <= a.steps; ++s) mesh_step(s, {}, {});
    if (first) {
        r.flow_steps = flow_steps;
        for (const FlowStepRecord& rec : rep.steps) r.level_set_s += rec.ms / 1000.0;
        r.checks = checks;
    }
    return std::move(c.out);
}

}  // namespace

void Figure3Options::validate() const {
    const auto bad = [](const std::string& what) { throw std::invalid_argument(what); };
    if (steps < 1 || steps > 1'000'000) bad("steps must be in [1, 1000000], got " + std::to_string(steps));
    if (lattice < 4 || lattice > 1024) bad("lattice must be in [4, 1024], got " + std::to_string(lattice));
    if (box < 1 || box > lattice - 2)
        bad("box must be in [1, lattice - 2 = " + std::to_string(lattice - 2) + "], got " + std::to_string(box));
    if (verify_every < 0) bad("verify_every must not be negative, got " + std::to_string(verify_every));
    if (sizes.empty()) bad("sizes needs at least one fragment size");
    std::set<int> seen;
    for (int s : sizes) {
        if (s < 3 || s > 1'000'000)
            bad("fragment sizes must be in [3, 1000000] (3 is the smallest workable size), got " + std::to_string(s));
        if (!seen.insert(s).second) bad("fragment size " + std::to_string(s) + " given twice in sizes");
    }
}

Figure3Result run_figure3(const Figure3Options& a) {
    a.validate();
    BoxFlowOptions box;
    box.lattice = a.lattice;
    box.box = a.box;
    box.max_steps = a.steps;
    const int cells = a.lattice - 1;
    const auto name = [](int n, const char* suffix) {
        std::string x = "x";  // appended: gcc 12's -Wrestrict misfires on "x" + std::to_string(n)
        x += std::to_string(n);
        return x + suffix;
    };
    Figure3Result r;
    std::vector<std::uint64_t> steps_x;  // each step's X, as the first column's flow gave it
    for (int s : a.sizes) r.columns.push_back(run_column(a, box, name(s, ""), s >= cells, std::min(s, cells), steps_x, r));
    r.columns.push_back(run_column(a, box, name(a.lattice, "_band"), false, cells, steps_x, r));
    return r;
}

}  // namespace liveset
