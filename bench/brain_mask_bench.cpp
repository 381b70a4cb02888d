// Automatic brain mask cost on BrainWeb (181x217x180, 1 mm) and its 2 mm version, 1 and 2 threads.
// Results and the commands that produced them: docs/BENCHMARKS.md.
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <limits>

#include "liveset/io/image_io.hpp"
#include "liveset/segment/brain_histogram.hpp"
#include "liveset/segment/brain_mask.hpp"
#include "liveset/segment/morphology.hpp"

using namespace liveset;

namespace {

const Grid<float>& brainweb(bool two_mm) {
    static const Grid<float> full = read_image(std::string(LIVESET_DATA_DIR) + "/brainweb/t1.mha");
    static const Grid<float> half = [] {
        const Lattice& l = full.lattice();
        const Vec3i d{(l.dims().x + 1) / 2, (l.dims().y + 1) / 2, (l.dims().z + 1) / 2};
        Grid<float> g(Lattice(d, l.spacing() * 2.0, l.origin(), l.direction()));
        for (int z = 0; z < d.z; ++z)
            for (int y = 0; y < d.y; ++y)
                for (int x = 0; x < d.x; ++x) g({x, y, z}) = full({2 * x, 2 * y, 2 * z});
        return g;
    }();
    return two_mm ? half : full;
}

// range(0): threads; range(1): 1 for the 2 mm version.
void BM_AutoBrainMask(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
    const Grid<float>& image = brainweb(state.range(1) != 0);
    BrainMaskReport r;
    for (auto _ : state) benchmark::DoNotOptimize(auto_brain_mask(image, {}, &r));
    state.counters["mask_ml"] = r.mask_volume_mm3 / 1000.0;
}
BENCHMARK(BM_AutoBrainMask)->Args({1, 0})->Args({2, 0})->Args({2, 1})->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);

// The brain mask's quantile over BrainWeb's whole image (its floor and percentiles; range(0) threads).
void BM_QuantileAbove(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
    const Grid<float>& image = brainweb(false);
    for (auto _ : state) {
        benchmark::DoNotOptimize(brain_detail::quantile_above(image, nullptr, -std::numeric_limits<double>::infinity(), 0.02));
        benchmark::DoNotOptimize(brain_detail::quantile_above(image, nullptr, 20.0, 0.98));
    }
}
BENCHMARK(BM_QuantileAbove)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Repetitions(5);

// The depth below the surface (mm) of every voxel of BrainWeb's brain mask, as the brain mask's
// contrast reading takes it (range(0) threads): the distance transform in single precision.
void BM_Depth(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
    static const Grid<std::uint8_t> brain = [] {
        const Grid<float> m = read_image(std::string(LIVESET_DATA_DIR) + "/brainweb/brain_mask.nii.gz");
        Grid<std::uint8_t> b(m.lattice());
        for (PointIndex i = 0; i < m.size(); ++i) b[i] = m[i] != 0.0f;
        return b;
    }();
    for (auto _ : state) benchmark::DoNotOptimize(depth_mm(brain));
}
BENCHMARK(BM_Depth)->Arg(1)->Arg(2)->Unit(benchmark::kMillisecond)->Repetitions(5);

// Dilation and erosion of BrainWeb's brain mask by a ball of range(0) mm (1 thread): the chords up
// to their limit, the distance transform beyond.
void BM_DilateErode(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, 1);
    static const Grid<std::uint8_t> brain = [] {
        const Grid<float> m = read_image(std::string(LIVESET_DATA_DIR) + "/brainweb/brain_mask.nii.gz");
        Grid<std::uint8_t> b(m.lattice());
        for (PointIndex i = 0; i < m.size(); ++i) b[i] = m[i] != 0.0f;
        return b;
    }();
    const double r = static_cast<double>(state.range(0));
    for (auto _ : state) {
        benchmark::DoNotOptimize(dilate_mm(brain, r));
        benchmark::DoNotOptimize(erode_mm(brain, r));
    }
}
BENCHMARK(BM_DilateErode)->Arg(2)->Arg(4)->Arg(6)->Arg(8)->Arg(10)->Arg(12)->Arg(16)->Unit(benchmark::kMillisecond)->Iterations(1)->Repetitions(3);

}  // namespace

BENCHMARK_MAIN();
