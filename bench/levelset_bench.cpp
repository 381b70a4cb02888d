// Level-set benchmarks: the box mean-curvature-flow experiment (ms per step, 1 and 2 threads), the
// difference-of-normals curvature per zero-layer point (single and batched), local bump updates on spheres of growing
// lattices (must stay flat), level-set memory, and what a small parallel loop costs after a serial
// stretch (why a small step runs on one thread: StepOptions::parallel_band_min).
// Results and the commands that produced them: docs/BENCHMARKS.md.
#include <benchmark/benchmark.h>
#include <sys/resource.h>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include <chrono>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "liveset/levelset/curvature_flow.hpp"
#include "liveset/levelset/shapes.hpp"
#include "liveset/levelset/speed.hpp"

using namespace liveset;

namespace {

double peak_rss_mb() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// Box 50³ in 100³ until it vanishes; one iteration = one whole flow.
void BM_BoxFlow(benchmark::State& state) {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
    BoxFlowReport last;
    for (auto _ : state) {
        state.PauseTiming();
        SparseField f = make_box_field({});
        state.ResumeTiming();
        last = run_curvature_flow(f, 5000, {.cfl = 0.5f});
        benchmark::DoNotOptimize(last.steps.size());
    }
    state.counters["steps"] = static_cast<double>(last.steps.size());
    state.counters["median_step_ms"] = last.median_step_ms();
    state.counters["total_s"] = last.total_ms / 1000.0;
    state.counters["vanished"] = last.vanished ? 1 : 0;
}
BENCHMARK(BM_BoxFlow)->Arg(1)->Arg(2)->Iterations(1)->Repetitions(3)->Unit(benchmark::kMillisecond)->UseRealTime();

// A radius-30 sphere's signed distance in 100³ and its zero-layer points (|φ| ≤ 0.5), lattice order.
struct SphereZeroLayer {
    Grid<float> phi{Lattice({100, 100, 100})};
    std::vector<PointIndex> zero;
    SphereZeroLayer() {
        const shapes::Sphere sphere({50.0, 50.0, 50.0}, 30.0);
        for (int z = 0; z < 100; ++z)
            for (int y = 0; y < 100; ++y)
                for (int x = 0; x < 100; ++x) {
                    const auto v = static_cast<float>(sphere(Vec3d{double(x), double(y), double(z)}));
                    phi({x, y, z}) = v;
                    if (std::abs(v) <= 0.5f) zero.push_back(phi.lattice().index({x, y, z}));
                }
    }
};

void count_per_point(benchmark::State& state, std::size_t points) {
    state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * points));
    state.counters["ns_per_point"] = benchmark::Counter(static_cast<double>(points),
                                                        benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// mean_curvature at every zero-layer point of the sphere: ns per point, one call at a time (a
// speed's at(); steps use the batch below), the calls independent.
void BM_MeanCurvature(benchmark::State& state) {
    const SphereZeroLayer s;
    std::vector<Vec3i> zero;
    for (const PointIndex i : s.zero) zero.push_back(s.phi.lattice().coord(i));
    std::vector<float> kappa(zero.size());
    for (auto _ : state) {
        for (std::size_t n = 0; n < zero.size(); ++n) kappa[n] = mean_curvature(s.phi, zero[n]);
        benchmark::DoNotOptimize(kappa.data());
        benchmark::ClobberMemory();
    }
    count_per_point(state, zero.size());
}
BENCHMARK(BM_MeanCurvature)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly(true);

// The same points through the batched form a step uses (Speed::rates): the curvature and the
// central |∇φ| of four stencils per SSE2 pass, from lattice indices.
void BM_CurvatureAndGradientBatched(benchmark::State& state) {
    const SphereZeroLayer s;
    std::vector<CurvatureAndGradient> out(s.zero.size());
    for (auto _ : state) {
        mean_curvature_and_gradient(s.phi, s.zero, out);
        benchmark::DoNotOptimize(out.data());
        benchmark::ClobberMemory();
    }
    count_per_point(state, s.zero.size());
}
BENCHMARK(BM_CurvatureAndGradientBatched)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly(true);

// A radius-3 Gaussian bump raised or lowered (towards the centre point) on a sphere of radius 0.4·N in N³: each iteration is
// one local update (edits at the ~30 zero-layer points of the bump + layer repair around them).
void BM_LocalBump(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    static std::map<int, std::unique_ptr<SparseField>> cache;  // building 512³ takes seconds
    auto& slot = cache[n];
    if (!slot) {
        slot = std::make_unique<SparseField>(Lattice({n, n, n}), 2);
        const double c = (n - 1) / 2.0;
        slot->init_from_sdf(shapes::Sphere({c, c, c}, 0.4 * n));
    }
    SparseField& f = *slot;
    const double c = (n - 1) / 2.0;
    const Vec3i centre{static_cast<int>(std::lround(c + 0.4 * n)), static_cast<int>(std::lround(c)),
                       static_cast<int>(std::lround(c))};
    std::size_t touched = 0, updates = 0;
    for (auto _ : state) {
        // Push the front back towards the centre point, so it never drifts off the bump.
        const float sign = f.phi()(centre) < 0.0f ? 1.0f : -1.0f;
        const ChangedPoints x = f.apply_in_box(centre - Vec3i{3, 3, 3}, centre + Vec3i{3, 3, 3}, [&](Vec3i p, float) {
            const Vec3i d = p - centre;
            const double d2 = d.x * d.x + d.y * d.y + d.z * d.z;
            return d2 > 9.0 ? 0.0f : sign * 0.4f * static_cast<float>(std::exp(-d2 / 9.0));
        });
        if (x.empty()) {
            state.SkipWithError("a bump update changed nothing: the front left the bump");
            break;
        }
        touched += x.size();
        ++updates;
    }
    state.counters["changed_points"] = static_cast<double>(touched) / static_cast<double>(std::max<std::size_t>(updates, 1));
    state.counters["band"] = static_cast<double>(f.band_size());
}
BENCHMARK(BM_LocalBump)->Arg(64)->Arg(128)->Arg(256)->Arg(512)->Unit(benchmark::kMicrosecond)->Repetitions(5)->ReportAggregatesOnly(true);

// A seed ball (radius 2) added on the BrainWeb-sized lattice (181×217×180) holding a sphere, the way
// the session adds one: Arg 0 the local union (unite_in_box, what Session::add_seed does), Arg 1 the
// whole-lattice re-initialisation init_from_sdf(min(φ, ball)) it replaced. Each iteration adds the
// ball to the field reset to the sphere (the reset is not timed).
void BM_AddSeed(benchmark::State& state) {
    static std::unique_ptr<SparseField> base;
    if (!base) {
        base = std::make_unique<SparseField>(Lattice({181, 217, 180}), 2);
        base->init_from_sdf(shapes::Sphere({90.2, 108.4, 89.7}, 60.3));
    }
    const shapes::Sphere ball({40.3, 60.2, 50.6}, 2.0);  // outside the sphere: a new piece
    const bool whole = state.range(0) == 1;
    std::size_t changed = 0;
    SparseField f = *base;  // reset by copy-assignment (no allocation, no page faults) each iteration
    for (auto _ : state) {
        state.PauseTiming();
        f = *base;
        state.ResumeTiming();
        if (whole) {
            const Grid<float>& phi = f.phi();
            const Lattice& lat = f.lattice();
            f.init_from_sdf([&](Vec3d p) { return std::min(static_cast<double>(phi[lat.index(p.cast<int>())]), ball(p)); });
        } else {
            changed = f.unite_in_box({35, 55, 45}, {46, 66, 56}, ball).size();
        }
        benchmark::DoNotOptimize(f.zero_layer().size());
    }
    state.counters["changed_points"] = static_cast<double>(changed);
}
BENCHMARK(BM_AddSeed)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);

// Peak resident memory after building a sphere level set in N³ (run one size per process).
void BM_Memory(benchmark::State& state) {
    const int n = static_cast<int>(state.range(0));
    const double before = peak_rss_mb();
    for (auto _ : state) {
        SparseField f(Lattice({n, n, n}), 2);
        const double c = (n - 1) / 2.0;
        f.init_from_sdf(shapes::Sphere({c, c, c}, 0.4 * n));
        state.counters["band"] = static_cast<double>(f.band_size());
        state.counters["peak_rss_MB"] = peak_rss_mb();
    }
    state.counters["rss_before_MB"] = before;
}
BENCHMARK(BM_Memory)->Arg(256)->Arg(512)->Iterations(1)->Unit(benchmark::kMillisecond);

// One parallel loop over two 4 096-float chunks (a small step's loop) after `gap` µs of serial
// work, on 1 or 2 threads: once the gap has let the oneTBB worker sleep, waking it costs the loop
// more than the second core saves. Manual time: the loop alone.
void BM_ParallelLoopAfterSerialGap(benchmark::State& state) {
    tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
    const auto gap = std::chrono::microseconds(state.range(1));
    std::vector<float> v(8192, 1.0f);
    for (auto _ : state) {
        const auto serial_start = std::chrono::steady_clock::now();
        while (std::chrono::steady_clock::now() - serial_start < gap) {
        }
        const auto start = std::chrono::steady_clock::now();
        tbb::parallel_for(std::size_t{0}, std::size_t{2}, [&](std::size_t c) {
            for (std::size_t i = c * 4096; i < (c + 1) * 4096; ++i) v[i] = v[i] * 1.0001f + 0.5f;
        });
        state.SetIterationTime(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
        benchmark::DoNotOptimize(v.data());
    }
}
BENCHMARK(BM_ParallelLoopAfterSerialGap)
    ->Args({1, 0})->Args({2, 0})->Args({1, 500})->Args({2, 500})
    ->Iterations(2000)->Repetitions(3)->ReportAggregatesOnly(true)->UseManualTime()->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
