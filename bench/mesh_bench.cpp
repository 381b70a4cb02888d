// Mesher benchmarks: (a) full meshing of a 256³ sphere signed distance (r = 100) - naive scan of
// every cell, slab-parallel sign-bit scan, band-driven single mesh (band given or computed), fragment full rebuild (S = 16, scan and band), 1 and 2
// threads; (b) latency of one local edit of radius 3 (SparseField::apply_in_box) followed by
// FragmentMesher::update of the affected fragments on spheres of radius 0.4·N in N³, N = 64..512,
// for S = 16 and S = 8, 1 and 2 threads (must stay flat in N). Results and commands: docs/BENCHMARKS.md.
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <chrono>
#include <cmath>
#include <map>
#include <memory>

#include "liveset/levelset/shapes.hpp"
#include "liveset/levelset/sparse_field.hpp"
#include "liveset/mesh/fragment_mesher.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/slab_marching_cubes.hpp"

using namespace liveset;

namespace {

constexpr int kSphereN = 256;
constexpr double kSphereR = 100.0;

// The 256³ sphere signed distance and its zero-crossing points (the band a level set would give).
struct SphereSdf {
    Grid<float> phi;
    std::vector<PointIndex> zero;
};

const SphereSdf& sphere_sdf() {
    static const SphereSdf s = [] {
        SphereSdf r{Grid<float>(Lattice({kSphereN, kSphereN, kSphereN})), {}};
        const double c = (kSphereN - 1) / 2.0;
        const shapes::Sphere sphere({c, c, c}, kSphereR);
        for (int z = 0; z < kSphereN; ++z)
            for (int y = 0; y < kSphereN; ++y)
                for (int x = 0; x < kSphereN; ++x)
                    r.phi({x, y, z}) = static_cast<float>(sphere(Vec3d{double(x), double(y), double(z)}));
        r.zero = zero_crossing_points(r.phi);
        return r;
    }();
    return s;
}

void set_cell_rate(benchmark::State& state, std::size_t triangles) {
    const double cells = std::pow(double(kSphereN - 1), 3);
    state.counters["Mcells_per_s"] =
        benchmark::Counter(cells * double(state.iterations()) / 1e6, benchmark::Counter::kIsRate);
    state.counters["triangles"] = double(triangles);
}

std::unique_ptr<tbb::global_control> threads(const benchmark::State& state) {
    return std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                 static_cast<std::size_t>(state.range(0)));
}

// Naive marching cubes over all 255³ cells (serial by design: the paper's baseline).
void BM_FullNaive(benchmark::State& state) {
    const auto t = threads(state);
    const SphereSdf& s = sphere_sdf();
    std::size_t tris = 0;
    for (auto _ : state) {
        const Mesh m = marching_cubes_naive(s.phi);
        tris = m.triangle_count();
        benchmark::DoNotOptimize(m.indices.data());
    }
    set_cell_rate(state, tris);
}

// Band-driven single mesh: only the cells around the zero-crossing points.
void BM_FullBand(benchmark::State& state) {
    const auto t = threads(state);
    const SphereSdf& s = sphere_sdf();
    std::size_t tris = 0;
    for (auto _ : state) {
        const Mesh m = marching_cubes_band(s.phi, s.zero);
        tris = m.triangle_count();
        benchmark::DoNotOptimize(m.indices.data());
    }
    set_cell_rate(state, tris);
}

// Slab-parallel whole-volume marching cubes (sign bits + z-slabs): needs no band, output == naive.
void BM_FullSlabs(benchmark::State& state) {
    const auto t = threads(state);
    const SphereSdf& s = sphere_sdf();
    std::size_t tris = 0;
    for (auto _ : state) {
        const Mesh m = marching_cubes_slabs(s.phi);
        tris = m.triangle_count();
        benchmark::DoNotOptimize(m.indices.data());
    }
    set_cell_rate(state, tris);
}

// Band-driven single mesh with the band computed from phi (a phi read from a file has none).
void BM_FullBandFromPhi(benchmark::State& state) {
    const auto t = threads(state);
    const SphereSdf& s = sphere_sdf();
    std::size_t tris = 0;
    for (auto _ : state) {
        const Mesh m = marching_cubes_band(s.phi, zero_crossing_points(s.phi));
        tris = m.triangle_count();
        benchmark::DoNotOptimize(m.indices.data());
    }
    set_cell_rate(state, tris);
}

// FragmentMesher(S = 16).full_rebuild(phi): every fragment scanned, fragments in parallel.
void BM_FragmentFullScan(benchmark::State& state) {
    const auto t = threads(state);
    const SphereSdf& s = sphere_sdf();
    FragmentMesher mesher(s.phi.lattice(), 16);
    for (auto _ : state) mesher.full_rebuild(s.phi);
    set_cell_rate(state, mesher.triangle_count());
}

// FragmentMesher(S = 16).full_rebuild(phi, zero layer): band-driven, fragments in parallel.
void BM_FragmentFullBand(benchmark::State& state) {
    const auto t = threads(state);
    const SphereSdf& s = sphere_sdf();
    FragmentMesher mesher(s.phi.lattice(), 16);
    for (auto _ : state) mesher.full_rebuild(s.phi, s.zero);
    set_cell_rate(state, mesher.triangle_count());
}

BENCHMARK(BM_FullNaive)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FullSlabs)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FullBandFromPhi)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FullBand)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FragmentFullScan)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_FragmentFullBand)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->UseRealTime();

// Sphere level sets of radius 0.4·N in N³, built once per N (512³ takes seconds).
SparseField& sphere_field(int n) {
    static std::map<int, std::unique_ptr<SparseField>> cache;
    auto& slot = cache[n];
    if (!slot) {
        slot = std::make_unique<SparseField>(Lattice({n, n, n}), 2);
        const double c = (n - 1) / 2.0;
        slot->init_from_sdf(shapes::Sphere({c, c, c}, 0.4 * n));
    }
    return *slot;
}

// One iteration = a radius-3 Gaussian bump (raised or lowered, whichever moves the front back
// towards the pole point) on the sphere's +x pole with apply_in_box, then FragmentMesher::update with the changed points. Args: N, S,
// TBB threads (the update re-polygonises its few fragments with tbb::parallel_for).
void BM_EditRemesh(benchmark::State& state) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism,
                                    static_cast<std::size_t>(state.range(2)));
    const int n = static_cast<int>(state.range(0));
    const int size = static_cast<int>(state.range(1));
    SparseField& f = sphere_field(n);
    FragmentMesher mesher(f.lattice(), size);
    mesher.full_rebuild(f.phi(), f.zero_layer());  // not timed
    const double c = (n - 1) / 2.0;
    const Vec3i centre{static_cast<int>(std::lround(c + 0.4 * n)), static_cast<int>(std::lround(c)),
                       static_cast<int>(std::lround(c))};
    std::size_t changed = 0, rebuilt = 0, cells = 0, updates = 0;
    double remesh_s = 0.0;
    for (auto _ : state) {
        // Push the front back towards the bump centre (a plain +/- alternation drifts off it after
        // thousands of iterations and then edits nothing).
        const float sign = f.phi()(centre) > 0.0f ? -1.0f : 1.0f;
        const ChangedPoints x = f.apply_in_box(centre - Vec3i{3, 3, 3}, centre + Vec3i{3, 3, 3}, [&](Vec3i p, float) {
            const Vec3i d = p - centre;
            const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
            return d2 > 9.0 ? 0.0f : sign * 0.4f * static_cast<float>(std::exp(-d2 / 9.0));
        });
        const auto t0 = std::chrono::steady_clock::now();
        const std::vector<FragmentId> u = mesher.update(f.phi(), x.points);
        remesh_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        benchmark::DoNotOptimize(u.data());
        changed += x.size();
        rebuilt += u.size();
        cells += mesher.last_stats().cells_visited;
        ++updates;
    }
    if (updates > 0 && changed == 0) state.SkipWithError("the edits changed no points");
    const double k = static_cast<double>(std::max<std::size_t>(updates, 1));
    state.counters["changed_points"] = double(changed) / k;
    state.counters["fragments"] = double(rebuilt) / k;
    state.counters["cells"] = double(cells) / k;
    state.counters["remesh_us"] = 1e6 * remesh_s / k;
}

BENCHMARK(BM_EditRemesh)
    ->ArgNames({"N", "S", "threads"})
    ->ArgsProduct({{64, 128, 256, 512}, {16, 8}, {1, 2}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
