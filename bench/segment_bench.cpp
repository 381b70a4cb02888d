// The segmentation's step (`liveset segment`'s: sleeping, thin fronts) on BrainWeb grey matter from
// issue 16's 8 seeds, window 94 ± 22 raw, the shipped brain mask as the ROI and no bias correction:
// a stretch of steps timed alone, without the command's preprocessing, reading or writing.
// Results and the commands that produced them: docs/BENCHMARKS.md.
#include <benchmark/benchmark.h>

#include <tbb/global_control.h>

#include <array>

#include "liveset/io/image_io.hpp"
#include "liveset/segment/pipeline.hpp"

using namespace liveset;

namespace {

struct Setup {
    Grid<float> unit;
    Grid<std::uint8_t> roi;
    ThresholdParams params;
    std::vector<SeedBall> seeds;
};

const Setup& brainweb() {
    static const Setup s = [] {
        Setup out;
        const Grid<float> image = read_image(std::string(LIVESET_DATA_DIR) + "/brainweb/t1.mha");
        const Grid<float> m = read_image(std::string(LIVESET_DATA_DIR) + "/brainweb/brain_mask.nii.gz");
        out.roi = Grid<std::uint8_t>(m.lattice());
        for (PointIndex i = 0; i < m.size(); ++i) out.roi[i] = m[i] != 0.0f;
        const std::array<Vec3d, 8> at{{{35, 83, 113}, {35, 125, 38}, {44, 164, 92}, {71, 74, 53},
                                       {122, 149, 47}, {140, 86, 74}, {38, 71, 26}, {83, 23, 71}}};
        for (const Vec3d& c : at) out.seeds.push_back({c, 2.0});
        SegmentRequest req;
        req.seeds = out.seeds;
        req.roi = &out.roi;
        req.mu_raw = 94.0;
        req.epsilon_raw = 22.0;
        req.loop.max_iterations = 1;
        req.loop.step = segment_step();
        const SegmentOutcome o = segment_image(image, req);
        out.params = o.params;
        out.unit = normalise(image, o.scale);
        return out;
    }();
    return s;
}

// range(0): threads; range(2)..range(1): the steps timed (0: the first from the seeds), after
// range(2) untimed ones. 7-18: fronts of 1 100-2 700 zero-layer points; 18-40: 2 700-10 000 (issue
// 16's per-iteration bins against ITK); 120-200: the largest fronts' busiest steps.
void BM_SegmentSteps(benchmark::State& state) {
    const tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(state.range(0)));
    const Setup& s = brainweb();
    const ThresholdSpeed speed(s.unit, s.params, &s.roi);
    const StepOptions step = segment_step();
    std::size_t zero = 0;
    for (auto _ : state) {
        state.PauseTiming();
        SparseField field(s.unit.lattice(), 2);
        init_from_seeds(field, s.seeds);
        for (int k = 0; k < state.range(2); ++k) field.step(speed, step);
        state.ResumeTiming();
        for (int k = static_cast<int>(state.range(2)); k < state.range(1); ++k) zero = field.step(speed, step).zero_layer;
    }
    state.counters["zero_layer"] = static_cast<double>(zero);  // after the last step timed
    state.counters["steps"] = static_cast<double>(state.range(1) - state.range(2));
}
BENCHMARK(BM_SegmentSteps)->Args({1, 18, 7})->Args({1, 40, 18})->Args({1, 200, 120})->Args({2, 200, 120})->Unit(benchmark::kMillisecond)->MinTime(0.2)->Repetitions(3);

}  // namespace

BENCHMARK_MAIN();
