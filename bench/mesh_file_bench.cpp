// Whole-volume meshing of a φ image read from a file (no band: it must be found), 1 and 2 threads:
// marching_cubes_slabs, marching_cubes_naive, and marching_cubes_band with zero_crossing_points
// computed in the timing; the CPU column is the whole process (all threads). The peer on the same file: bench/peers/vtk_flying_edges.cpp.
// Usage: mesh_file_bench --phi FILE [Google Benchmark flags]. Results: docs/BENCHMARKS.md.
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "liveset/io/image_io.hpp"
#include "liveset/mesh/marching_cubes.hpp"
#include "liveset/mesh/slab_marching_cubes.hpp"

using namespace liveset;

namespace {

const Grid<float>* g_phi = nullptr;

template <class MeshFn>
void run(benchmark::State& state, MeshFn&& fn) {
    const tbb::global_control limit(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
    std::size_t tris = 0;
    for (auto _ : state) {
        const Mesh m = fn(*g_phi);
        tris = m.triangle_count();
        benchmark::DoNotOptimize(m.indices.data());
    }
    state.counters["triangles"] = double(tris);
}

void BM_FileSlabs(benchmark::State& s) { run(s, [](const Grid<float>& p) { return marching_cubes_slabs(p); }); }
void BM_FileNaive(benchmark::State& s) { run(s, [](const Grid<float>& p) { return marching_cubes_naive(p); }); }
void BM_FileBandFromPhi(benchmark::State& s) {
    run(s, [](const Grid<float>& p) { return marching_cubes_band(p, zero_crossing_points(p)); });
}

BENCHMARK(BM_FileSlabs)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_FileNaive)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();
BENCHMARK(BM_FileBandFromPhi)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->MeasureProcessCPUTime()->UseRealTime();

}  // namespace

int main(int argc, char** argv) {
    std::string path;
    std::vector<char*> rest{argv[0]};
    for (int i = 1; i < argc; ++i) {
        if (std::strcmp(argv[i], "--phi") == 0 && i + 1 < argc) path = argv[++i];
        else rest.push_back(argv[i]);
    }
    if (path.empty()) {
        std::fprintf(stderr, "mesh_file_bench: --phi FILE is required\n");
        return 2;
    }
    try {
        static const Grid<float> phi = read_image(path);
        g_phi = &phi;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "mesh_file_bench: %s\n", e.what());
        return 1;
    }
    int n = static_cast<int>(rest.size());
    benchmark::Initialize(&n, rest.data());
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
